"""CSV import of lab exports: round trip against a virtual run, unit conversion, every error."""

import re

import numpy as np
import pytest

from stickslip.cli import main
from stickslip.experiment.csv_import import import_csv
from stickslip.experiment.timeseries import read_timeseries
from stickslip.h5io import FileFormatError
from stickslip.plugin_params import parse_params
from stickslip.experiment.virtual.model import simulate
from stickslip.solvers.lever import LeverParams

FORCE = "# exported by the lab\nt [s],F [N]\n0.00,2.5\n0.02,2.6\n0.04,2.7\n"
POSITIONS = "t [s],x1 [mm],x2 [mm]\n0.0,1.0,2.0\n0.2,1.1,2.3\n"


def write(tmp_path, force=FORCE, positions=POSITIONS):
    (tmp_path / "force.csv").write_text(force)
    (tmp_path / "positions.csv").write_text(positions)
    return tmp_path / "force.csv", tmp_path / "positions.csv"


def test_virtual_run_survives_export_and_import(tmp_path):
    record, _, _ = simulate(parse_params(LeverParams, {"n": 3, "duration": 300.0, "seed": 7}))
    lines = ["t [s],F [N]"] + [f"{float(t)!r},{float(F)!r}" for t, F in zip(record.t_F, record.F)]
    (tmp_path / "force.csv").write_text("\n".join(lines) + "\n")
    header = "t [s]," + ",".join(f"x{i} [mm]" for i in range(1, 6))
    rows = [",".join(repr(float(v)) for v in (t, *x)) for t, x in zip(record.t_x, record.x)]
    (tmp_path / "positions.csv").write_text("\n".join([header] + rows) + "\n")
    import_csv(tmp_path / "force.csv", tmp_path / "positions.csv", tmp_path / "run.h5", n=3)
    back = read_timeseries(tmp_path / "run.h5")
    for name in ("t_F", "F", "t_x", "x"):
        np.testing.assert_array_equal(getattr(back, name), getattr(record, name))
    assert (back.n, back.protocol, back.k_spring, back.V) == (3, "stack", 55.0, 0.01)


def test_units_are_converted(tmp_path):
    force = "t [ms],F [mN]\n0,2500\n20,2600\n"
    positions = "t [s],x1 [um],x2 [m]\n0.0,1000,0.002\n0.2,1100,0.0023\n"
    record = import_csv(*write(tmp_path, force, positions), tmp_path / "run.h5", n=2, n_slabs=2)
    np.testing.assert_allclose(record.t_F, [0.0, 0.02])
    np.testing.assert_allclose(record.F, [2.5, 2.6])
    np.testing.assert_allclose(record.x, [[1.0, 2.0], [1.1, 2.3]])


def test_declared_units_for_headers_without_units(tmp_path):
    force = "t,F\n0,2.5\n0.02,2.6\n"
    paths = write(tmp_path, force)
    record = import_csv(*paths, tmp_path / "run.h5", n=1, n_slabs=2, time_unit="s", force_unit="N")
    np.testing.assert_allclose(record.F, [2.5, 2.6])


ERRORS = [
    (dict(force="t [s]\n0\n0.02\n"), "force.csv: missing column F; expected exactly t, F"),
    (dict(positions="t [s],x1 [mm]\n0,1\n0.2,1\n"), "positions.csv: missing column x2"),
    (dict(positions="t [s],x1 [mm],x2 [mm],x3 [mm]\n0,1,2,3\n0.2,1,2,3\n"), "positions.csv: unexpected column x3"),
    (dict(force="t [s],F\n0,1\n0.02,1\n"), "force.csv: column 'F' has no unit; write it in the header as 'F [N]'"),
    (dict(force="t [s],F [mm]\n0,1\n0.02,1\n"), "force.csv: column 'F' has unit [mm], which is not a force unit"),
    (dict(force="t [h],F [N]\n0,1\n0.02,1\n"), "force.csv: column 't' has unit [h], which is not a time unit"),
    (dict(force="t [s],F [N]\n0,1\n0.02,nan\n0.04,1\n"), "force.csv: line 3, column 'F': expected a finite number, "
                                                          "got 'nan'"),
    (dict(force="t [s],F [N]\n0,1\n0.02,\n"), "force.csv: line 3, column 'F': expected a finite number"),
    (dict(force="t [s],F [N]\n0,1\n0.02,abc\n"), "force.csv: line 3, column 'F': expected a finite number, got 'abc'"),
    (dict(positions="t [s],x1 [mm],x2 [mm]\n0.0,1,2\n0.4,1,2\n0.2,1,2\n"),
     "positions.csv: line 4, column 't': time must increase strictly, got '0.2' after '0.4'"),
    (dict(force="t [s],F [N]\n0,1\n"), "force.csv: expected at least 2 data rows, got 1"),
    (dict(force="t [s],t [s],F [N]\n0,0,1\n1,1,1\n"), "column 't' appears twice"),
    (dict(force="t [s],F (N)\n0,1\n1,1\n"), "header column 2 'F (N)' is not of the form 'name [unit]'"),
    (dict(force=""), "force.csv: not a readable CSV file"),
]


@pytest.mark.parametrize("files, message", ERRORS)
def test_errors_name_file_column_and_line(tmp_path, files, message):
    with pytest.raises(FileFormatError, match=re.escape(message)):
        import_csv(*write(tmp_path, **files), tmp_path / "run.h5", n=2, n_slabs=2)
    assert not (tmp_path / "run.h5").exists()


def test_declared_unit_must_agree_with_the_header(tmp_path):
    with pytest.raises(FileFormatError, match=re.escape("column 't' is in [s] but the declared time unit is 'ms'")):
        import_csv(*write(tmp_path), tmp_path / "run.h5", n=2, n_slabs=2, time_unit="ms")


def test_inconsistent_metadata_is_rejected_naming_the_csv_files_not_the_output(tmp_path):
    force, positions = write(tmp_path)
    with pytest.raises(FileFormatError, match="'n' must be in 1..n_slabs=2") as error:
        import_csv(force, positions, tmp_path / "run.h5", n=3, n_slabs=2)
    assert str(error.value).startswith(f"import of {force} and {positions}: ")
    assert not (tmp_path / "run.h5").exists()


def test_cli(tmp_path, capsys):
    force, positions = write(tmp_path)
    output = tmp_path / "run.h5"
    assert main(["import-csv", "--force", str(force), "--positions", str(positions), "-o", str(output),
                 "--n", "2", "--n-slabs", "2"]) == 0
    assert read_timeseries(output).x.shape == (2, 2)
    assert main(["import-csv", "--force", str(tmp_path / "absent.csv"), "--positions", str(positions),
                 "-o", str(output), "--n", "2", "--n-slabs", "2"]) == 2
    assert "absent.csv: no such file" in capsys.readouterr().err


def test_a_semicolon_separated_file_gets_a_hint(tmp_path):
    force = tmp_path / "force.csv"
    force.write_text("t [s];F [N]\n0;1.5\n0,02;1.6\n")
    with pytest.raises(FileFormatError, match=r"force.csv: one column whose header 't \[s\];F \[N\]' holds ';': the "
                                              r"file seems separated by ';'"):
        import_csv(force, force, tmp_path / "run.h5", n=1)


def test_a_header_of_100000_unexpected_columns_is_one_short_line(tmp_path, capsys):
    # the audit of 575c37a (issue 59, item 8): one error line of 789 kB
    header = "t [s],F [N]," + ",".join(f"c{i} [N]" for i in range(100_000))
    force, positions = write(tmp_path, force=header + "\n0,1\n0.02,1\n")
    assert main(["import-csv", "--force", str(force), "--positions", str(positions), "--n", "1", "--n-slabs", "2",
                 "-o", str(tmp_path / "lab.h5")]) == 2
    error = capsys.readouterr().err
    assert error == (f"stickslip: error: {force}: unexpected columns c0, c1, c2, c3, c4, c5, c6, c7 and 99992 more; "
                     "expected exactly t, F\n")


def test_forces_beyond_what_the_springs_hold_are_warned_and_beyond_a_double_refused(tmp_path, capsys):
    # the audit of 575c37a (issue 59, item 7): forces of +-1e308 N were imported without a word
    rows = "\n".join(f"{0.02 * i:.2f},{value}" for i, value in enumerate([2.5, 1e308, -1e308, 2.6, 2.7]))
    force, positions = write(tmp_path, force="t [s],F [N]\n" + rows + "\n")
    args = ["import-csv", "--force", str(force), "--positions", str(positions), "--n", "1", "--n-slabs", "2",
            "-o", str(tmp_path / "lab.h5")]
    assert main(args) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert warnings == [f"stickslip: warning: {force}: the lever force reaches 1e+308 N, 1e+307 times the 9.8 N its "
                        "springs can hold (each at most the friction of the 2 interfaces at N = 49 N, on its arm j h / "
                        "H); check the units and the apparatus attributes"]
    force.write_text("t [s],F [kN]\n" + rows + "\n")
    assert main(args + ["--overwrite"]) == 2
    assert capsys.readouterr().err == (f"stickslip: error: {force}: line 3, column 'F': 1e+308 times 1000 (to N) is "
                                       "beyond the range of a double\n")
