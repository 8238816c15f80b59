"""A fem run ended in any way (SIGTERM, SIGKILL, a workflow job killed) resumes to the same bytes.

Real processes are started and killed at several points of the reference case; the
killed files are rerun by the same command and compared, byte for byte, with an
uninterrupted run. While a run is going its file is read (SWMR), as
``stickslip increments`` does.
"""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import FEM_REFERENCE_CASE, kill_when_stored
from stickslip.cli import main
from stickslip.formats.fem_run import read_increments, read_run_attrs
from stickslip.h5io import FileFormatError, UnreadableFileError
from stickslip.workflow_api import partial_path

pytestmark = pytest.mark.slow


def _simulate_args(output):
    params = [arg for key, value in FEM_REFERENCE_CASE.items() for arg in ("--param", f"{key}={value}")]
    return ["simulate", "--solver", "fem", *params, "-o", str(output)]


def _cli(output):
    return [sys.executable, "-m", "stickslip", *_simulate_args(output)]


def _workflow_job(output):
    code = ("import sys, json; from stickslip.workflow_api import run_simulation; "
            "run_simulation('fem', sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], inputs={}, threads=1)")
    return [sys.executable, "-c", code, json.dumps(FEM_REFERENCE_CASE), str(output),
            str(output.with_suffix(".json")), str(output.with_suffix(".log"))]


def test_killed_runs_resume_to_the_bytes_of_an_uninterrupted_run(fem_reference_run, tmp_path):
    output = tmp_path / "run.h5"
    status, err, _ = kill_when_stored(_cli(output), output, 40, signal.SIGTERM)
    assert status == 128 + signal.SIGTERM, err
    assert "terminated by SIGTERM" in err and "Traceback" not in err
    for increments in (150, 260):  # as by a cluster's wall time after its grace period, or the OOM killer
        status, _, stored = kill_when_stored(_cli(output), output, increments, signal.SIGKILL)
        assert status == -signal.SIGKILL
        assert not read_run_attrs(output)["completed"] and read_run_attrs(output)["nstored"] >= stored
    done = subprocess.run(_cli(output), capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert output.read_bytes() == fem_reference_run.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5", "run.provenance.json"]  # no lock or temporary file left


def test_a_killed_workflow_job_resumes_to_the_same_bytes(fem_reference_run, tmp_path):
    output = tmp_path / "sim" / "fem" / "run.h5"
    partial, log = partial_path(output), output.with_suffix(".log")
    for signum, increments in ((signal.SIGKILL, 100), (signal.SIGTERM, 220), (signal.SIGINT, 280)):
        status, _, _ = kill_when_stored(_workflow_job(output), partial, increments, signum)
        assert status != 0
        assert not output.exists() and partial.exists()
        assert signum != signal.SIGTERM or "terminated by SIGTERM" in log.read_text()
    assert "KeyboardInterrupt" in log.read_text()  # Ctrl-C (wrapped in a SystemError if it came in a kernel)
    done = subprocess.run(_workflow_job(output), capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "resuming from" in log.read_text()
    assert output.read_bytes() == fem_reference_run.read_bytes() and os.path.samefile(partial, output)

    # Snakemake stopped (Ctrl-C) while the job completed: it deletes the job's outputs and runs it again
    output.unlink()
    output.with_suffix(".json").unlink()
    again = subprocess.run(_workflow_job(output), capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    assert "completed by an earlier job" in log.read_text() and "fem increments" not in log.read_text()
    assert output.read_bytes() == fem_reference_run.read_bytes()


def test_an_unreadable_file_is_moved_aside_and_the_run_starts_over(fem_reference_run, tmp_path, capsys):
    output = tmp_path / "run.h5"
    output.write_bytes(fem_reference_run.read_bytes()[:5000])  # truncated: HDF5 cannot open it
    with pytest.raises(UnreadableFileError):
        read_increments(output)
    assert main(_simulate_args(output)) == 0
    err = capsys.readouterr().err
    assert f"moved it to {output}.unreadable, starting the run over" in err
    assert output.read_bytes() == fem_reference_run.read_bytes()
    assert (tmp_path / "run.h5.unreadable").stat().st_size == 5000


def test_a_file_another_process_writes_is_refused(tmp_path):
    from stickslip.output_safety.lock import writer_lock

    output = tmp_path / "run.h5"
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time; from stickslip.output_safety.lock import writer_lock\n"
                               f"with writer_lock({str(output)!r}):\n print('locked', flush=True); time.sleep(60)"],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(FileFormatError, match="another process is writing it"), writer_lock(output):
            pass
    finally:
        holder.kill()
        holder.wait()
    with writer_lock(output):  # the lock of a killed process is free
        pass
