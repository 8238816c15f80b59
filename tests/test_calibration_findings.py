"""benchmarks/calibration_findings.py: a simulation's pace once its interfaces slip, read from its log."""

import importlib.util

from conftest import REPO

SPEC = importlib.util.spec_from_file_location("calibration_findings", REPO / "benchmarks" / "calibration_findings.py")
calibration_findings = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(calibration_findings)


def progress(increment, total, seconds, slips):
    """One progress line as the fem runner writes it (elapsed as m:ss, h:mm:ss past the hour)."""
    hours, rest = divmod(seconds, 3600)
    elapsed = f"{hours}:{rest // 60:02d}:{rest % 60:02d}" if hours else f"{rest // 60:02d}:{rest % 60:02d}"
    return (f"fem increments: {increment}/{total} increment ({100 * increment // total}%) [{elapsed} elapsed, "
            f"00:10 left,  1.00 increment/s, slips {slips}]")


def write_log(tmp_path, text):
    log = tmp_path / "study" / "logs" / "sim" / "fem" / "run.log"
    log.parent.mkdir(parents=True)
    log.write_text(text)
    return tmp_path / "study"


def test_the_pace_counts_from_the_first_slip_not_the_loading_before_it(tmp_path):
    # 100 cheap increments of loading (10 s), then 200 slipping ones at 2 s each, the last past the hour
    lines = [progress(i, 300, i // 10, 0) for i in range(0, 100, 20)]
    lines += [progress(100 + i, 300, 10 + 2 * i, 1 + i // 10) for i in range(0, 201, 50)]
    lines += [progress(300, 300, 3 * 3600 + 10, 30)]
    study = write_log(tmp_path, "solver fem 4, 1 thread(s), {}\n" + "\r".join(lines[:-1]) + "\n")
    assert calibration_findings.slipping_pace(study, "fem", "run") == (2.0, 100, 300)
    # an hour-long elapsed time is read as h:mm:ss
    study = write_log(tmp_path / "hours", "\r".join(lines[5:6] + lines[-1:]) + "\n")
    assert calibration_findings.slipping_pace(study, "fem", "run") == ((3 * 3600 + 10 - 10) / 200, 100, 300)


def test_a_resumed_run_is_paced_by_its_last_part_and_a_run_without_slips_has_none(tmp_path):
    before = [progress(50, 300, 100, 5), progress(150, 300, 400, 20)]
    after = [progress(150, 300, 0, 20), progress(200, 300, 50, 25), progress(300, 300, 150, 40)]
    study = write_log(tmp_path, "\r".join(before) + "\nresuming from partial/run.h5\n" + "\r".join(after) + "\n")
    assert calibration_findings.slipping_pace(study, "fem", "run") == (1.0, 150, 300)
    assert calibration_findings._resumed_at(study, "fem", "run") == 150
    study = write_log(tmp_path / "quiet", "\r".join(progress(i, 300, i, 0) for i in range(0, 301, 100)) + "\n")
    assert calibration_findings.slipping_pace(study, "fem", "run") is None
    assert calibration_findings._resumed_at(study, "fem", "run") == 0
    assert calibration_findings.slipping_pace(tmp_path / "missing", "fem", "run") is None
