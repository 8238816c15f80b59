"""Lab data in a wrong unit is never a silent wrong result: import and analysis warn, an empty result fails.

A virtual lever run (n = 3, 2000 s) is exported to the lab's CSV layout as it is, with its positions
in m under a header that says mm, and with its times in ms under a header that says s.
"""

import dataclasses

import pytest

from stickslip.cli import main
from stickslip.experiment.plausibility import (force_rate_warning, measured_loading_rate, no_slip_warning,
                                               travel_warning)
from stickslip.experiment.virtual.model import simulate
from stickslip.solvers.lever import LeverParams

RUN = LeverParams(n=3, duration=2000.0, seed=1)


@pytest.fixture(scope="module")
def record():
    signals, _, _ = simulate(RUN)
    return signals


def export(directory, record, position_scale=1.0, time_scale=1.0, force_time_scale=None):
    """Write the record as the lab's two CSV files, multiplied by the scales, headers in s, N and mm."""
    force_time_scale = time_scale if force_time_scale is None else force_time_scale
    force = ["t [s],F [N]"] + [f"{float(t) * force_time_scale!r},{float(F)!r}" for t, F in zip(record.t_F, record.F)]
    header = "t [s]," + ",".join(f"x{i} [mm]" for i in range(1, record.n_slabs + 1))
    rows = [",".join(repr(float(v)) for v in (t * time_scale, *(x * position_scale)))
            for t, x in zip(record.t_x, record.x)]
    (directory / "force.csv").write_text("\n".join(force) + "\n")
    (directory / "positions.csv").write_text("\n".join([header] + rows) + "\n")
    return ["import-csv", "--force", str(directory / "force.csv"), "--positions", str(directory / "positions.csv"),
            "--n", str(record.n), "-o", str(directory / "run.h5")]


def test_a_plausible_record_passes_without_a_word(record, tmp_path, capsys):
    assert main(export(tmp_path, record)) == 0
    assert main(["analyze-experiment", str(tmp_path / "run.h5"), "-o", str(tmp_path / "slips.csv")]) == 0
    assert "warning" not in capsys.readouterr().err


@pytest.mark.parametrize("scales, mistake", [((1e-3, 1.0), "positions in m (not mm)"),
                                             ((1.0, 1e3), "times in ms (not s)")])
def test_a_record_in_the_wrong_unit_is_named_at_import_and_fails_the_analysis(record, tmp_path, capsys, scales,
                                                                              mistake):
    run = tmp_path / "run.h5"
    assert main(export(tmp_path, record, *scales)) == 0  # written, with a warning naming the file
    warning = capsys.readouterr().err.splitlines()[-1]
    assert warning.startswith(f"stickslip: warning: {tmp_path / 'positions.csv'}: slab 3 moved ") and mistake in warning

    assert main(["analyze-experiment", str(run), "-o", str(tmp_path / "slips.csv")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert mistake in err[-3] and "no slip in " in err[-2], err
    assert err[-1] == ("stickslip: error: no slip found, and the records are implausible for their apparatus "
                       "(warnings above); nothing written")
    assert not (tmp_path / "slips.csv").exists()
    assert main(["analyze-experiment", str(run), "--aging"]) == 2
    assert capsys.readouterr().err.splitlines()[-1].endswith("implausible for their apparatus (warnings above); "
                                                             "nothing written")


def test_the_travel_check_measures_the_drive(record):
    """The driven slab follows its spring (3 h V / H) to within the spring's stretch; scaled records do not."""
    assert travel_warning(record, "run") is None
    travel = record.x[-1, 2] - record.x[0, 2]
    assert travel == pytest.approx(3 * RUN.h * RUN.V / RUN.H * RUN.duration, abs=RUN.normal_force / RUN.k_spring)
    for scale, mistake in ((1e-3, "positions in m (not mm)"), (0.1, "positions in cm (not mm)"),
                           (1e3, "positions in um (not mm)")):
        assert mistake in travel_warning(dataclasses.replace(record, x=record.x * scale), "run")
    assert "V in m/s (not mm/s)" in travel_warning(dataclasses.replace(record, V=record.V / 1e3), "run")
    longest = RUN.normal_force / (RUN.k_spring * 3 * RUN.h * RUN.V / RUN.H)  # 297 s: the spring loads by N
    assert f"{RUN.duration / longest:.2g} times the longest possible stick" in no_slip_warning(record, 0, "run")
    assert no_slip_warning(record, 1, "run") is None
    short = dataclasses.replace(record, t_x=record.t_x[:300], x=record.x[:300])  # 60 s: no slip is plausible
    assert no_slip_warning(short, 0, "run") is None


def test_a_force_file_in_ms_with_correct_positions_is_named_at_import_and_fails_the_analysis(record, tmp_path,
                                                                                            capsys):
    # the audit's case: every check of the positions passes; the force file alone shows the mistake
    run = tmp_path / "run.h5"
    assert main(export(tmp_path, record, force_time_scale=1e3)) == 0
    warnings = capsys.readouterr().err.splitlines()
    assert len(warnings) == 1 and warnings[0].startswith(f"stickslip: warning: {tmp_path / 'force.csv'}: the lever "
                                                         "force rises at ")
    assert "times in ms (not s)" in warnings[0]
    for argv in (["-o", str(tmp_path / "slips.csv")], ["--aging"]):
        assert main(["analyze-experiment", str(run), *argv]) == 2
        err = capsys.readouterr().err.splitlines()
        assert err[-1].startswith(f"stickslip: error: {run}: ") and "slips have no measured force drop" in err[-1]
        assert "times in ms (not s) in the force file" in err[-1], err[-1]
    assert not (tmp_path / "slips.csv").exists()


def test_the_force_check_measures_the_loading_rate(record):
    """The lever force rises at sum_j K (j h V / H)(j h / H) while the slabs stick; scaled records do not."""
    assert force_rate_warning(record, "force") is None
    expected = RUN.k_spring * RUN.V * (RUN.h / RUN.H) ** 2 * (1 + 4 + 9)  # n = 3 springs at arms 1, 2, 3 h / H
    assert measured_loading_rate(record.t_F, record.F) == pytest.approx(expected, rel=0.3)
    for change, mistake in ((dict(t_F=record.t_F * 1e3), "times in ms (not s)"),
                            (dict(t_F=record.t_F / 60), "times in min (not s)"),
                            (dict(F=record.F / 1e3), "force in kN (not N)"), (dict(V=record.V * 1e3),
                                                                              "V in um/s (not mm/s)")):
        assert mistake in force_rate_warning(dataclasses.replace(record, **change), "force")
