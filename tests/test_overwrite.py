"""One rule for every command that writes a file: an existing output of another run is refused, unless --overwrite.

Every writer is tried against a file it did not make (a completed fem run among them: the audit's
case, where `--solver lever -o F` replaced it without a word), against its own output (which passes:
resumed, skipped or written again) and with --overwrite (which replaces it, keeping the old file
aside until the new one is complete).
"""

import hashlib
import json
from unittest import mock

import pytest

from stickslip.cli import main
from stickslip.h5io import FileFormatError
from stickslip.output_safety.lock import writer_lock
from stickslip.output_safety.overwrite import OutputExistsError, claimed_output
from stickslip.workflow_api import run_analysis, run_simulation

LEVER = ["simulate", "--solver", "lever", "--param", "n=2", "--param", "duration=300"]
RATE_STATE = ["simulate", "--solver", "rate-state-lever", "--param", "n=2", "--param", "duration=300"]
FEM = ["simulate", "--solver", "fem", "--param", "N=9", "--param", "max_increments=6"]
FORCE = "t [s],F [N]\n0.00,2.5\n0.02,2.6\n0.04,2.7\n"
POSITIONS = "t [s],x1 [mm],x2 [mm]\n0.0,1.0,2.0\n0.2,1.1,2.3\n"


def sha256(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def refused(capsys, command, path):
    """Run ``command`` (writing ``path``, which exists); assert it is refused by one line and ``path`` kept."""
    before = sha256(path)
    capsys.readouterr()
    assert main(command) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"stickslip: error: {path}: holds ") or err.startswith(f"stickslip: error: {path}: exists")
    assert err.endswith("pass --overwrite to replace it, or choose another output") and "\n" not in err, err
    assert sha256(path) == before
    return err


@pytest.fixture(scope="module")
def fem_run(tmp_path_factory):
    """A completed fem run (6 increments)."""
    path = tmp_path_factory.mktemp("fem") / "fem.h5"
    assert main(FEM + ["-o", str(path)]) == 0
    return path


def csv_files(tmp_path):
    (tmp_path / "force.csv").write_text(FORCE)
    (tmp_path / "positions.csv").write_text(POSITIONS)
    return ["--force", str(tmp_path / "force.csv"), "--positions", str(tmp_path / "positions.csv"), "--n", "2",
            "--n-slabs", "2"]


def test_a_completed_fem_run_is_not_replaced_by_any_writer(fem_run, tmp_path, capsys):
    target = tmp_path / "run.h5"
    target.write_bytes(fem_run.read_bytes())
    err = refused(capsys, LEVER + ["-o", str(target)], target)
    assert "holds a fem-run file of solver fem 4 (this run: format 'timeseries')" in err
    refused(capsys, RATE_STATE + ["-o", str(target)], target)
    refused(capsys, ["import-csv", *csv_files(tmp_path), "-o", str(target)], target)
    refused(capsys, ["mesh", "-o", str(target)], target)
    err = refused(capsys, FEM[:-1] + ["max_increments=8", "-o", str(target)], target)
    assert "with other parameters: max_increments = 6 (this run: 8)" in err
    assert main(FEM + ["-o", str(target)]) == 0 and sha256(target) == sha256(fem_run)  # the same run: complete


def test_each_solver_refuses_another_run_passes_its_own_and_overwrites_when_asked(tmp_path, capsys):
    target = tmp_path / "run.h5"
    assert main(LEVER + ["-o", str(target)]) == 0
    made = sha256(target)
    assert main(LEVER + ["-o", str(target)]) == 0 and sha256(target) == made  # the same run again
    err = refused(capsys, LEVER + ["--param", "seed=3", "-o", str(target)], target)
    assert "holds a timeseries file of solver lever 2 with other parameters: seed = 0 (this run: 3)" in err
    err = refused(capsys, RATE_STATE + ["-o", str(target)], target)
    assert "(this run: solver 'rate-state-lever')" in err
    refused(capsys, FEM + ["-o", str(target)], target)

    assert main(RATE_STATE + ["--overwrite", "-o", str(target)]) == 0
    assert "--overwrite: moved it to" in capsys.readouterr().err
    assert sha256(target) != made and sorted(p.name for p in tmp_path.iterdir()) == ["run.h5", "run.provenance.json"]


def test_import_csv_and_mesh(tmp_path, capsys):
    output, mesh = tmp_path / "lab.h5", tmp_path / "mesh.h5"
    arguments = csv_files(tmp_path)
    assert main(["import-csv", *arguments, "-o", str(output)]) == 0
    assert main(["import-csv", *arguments, "-o", str(output)]) == 0  # the same import
    err = refused(capsys, ["import-csv", *arguments, "--lever-speed", "0.02", "-o", str(output)], output)
    assert "with V = 0.01 (this run: 0.02)" in err
    (tmp_path / "force.csv").write_text(FORCE.replace("2.7", "2.8"))  # another export
    err = refused(capsys, ["import-csv", *arguments, "-o", str(output)], output)
    assert "with other imported_from: force_csv" in err
    assert main(["import-csv", *arguments, "--overwrite", "-o", str(output)]) == 0

    assert main(["mesh", "--param", "N=9", "-o", str(mesh)]) == 0
    assert main(["mesh", "--param", "N=9", "-o", str(mesh)]) == 0
    refused(capsys, ["mesh", "--param", "N=27", "-o", str(mesh)], mesh)
    refused(capsys, LEVER + ["-o", str(mesh)], mesh)


def test_csv_outputs_are_replaced_only_by_the_same_content(fem_run, tmp_path, capsys):
    lever = tmp_path / "lever.h5"
    assert main(LEVER + ["-o", str(lever)]) == 0
    slips, table = tmp_path / "slips.csv", tmp_path / "increments.csv"
    for command, output in ((["analyze-experiment", str(lever)], slips), (["increments", str(fem_run)], table)):
        output.write_text("my notes\n")
        capsys.readouterr()
        assert main(command + ["-o", str(output)]) == 2
        assert capsys.readouterr().err.splitlines()[-1] == (f"stickslip: error: {output}: exists with other content; "
                                                            f"pass --overwrite to replace it, or choose another output")
        assert output.read_text() == "my notes\n"
        assert main(command + ["-o", str(output), "--overwrite"]) == 0
        written = output.read_bytes()
        assert main(command + ["-o", str(output)]) == 0 and output.read_bytes() == written  # the same content


def test_a_workflow_job_refuses_an_output_of_another_run(fem_run, tmp_path):
    output = tmp_path / "sim" / "lever" / "run.h5"
    output.parent.mkdir(parents=True)
    output.write_bytes(fem_run.read_bytes())  # not made by this job: no record of its run
    with pytest.raises(OutputExistsError, match="it is not this job's output: move it away"):
        run_simulation("lever", json.dumps({"duration": 300.0}), output, output.with_suffix(".provenance.json"),
                       tmp_path / "job.log", inputs={}, threads=1)
    events = tmp_path / "events" / "run.h5"
    events.parent.mkdir()
    events.write_bytes(fem_run.read_bytes())
    simulation = {"path": str(fem_run), "run_id": "0123456789abcdef", "plugin": "fem", "format": "fem-run"}
    with pytest.raises(OutputExistsError, match="holds a file without its provenance record"):
        run_analysis("numerical-events", "{}", json.dumps(simulation), events, events.with_suffix(".provenance.json"),
                     tmp_path / "analysis.log")
    assert sha256(output) == sha256(events) == sha256(fem_run)


def test_overwrite_keeps_the_replaced_file_until_the_new_one_is_complete(tmp_path):
    output = tmp_path / "out.h5"
    output.write_text("another run")
    with pytest.raises(RuntimeError), claimed_output(output, {"format": "x"}, overwrite=True):
        assert not output.exists()
        raise RuntimeError("the run fails before writing")
    assert output.read_text() == "another run"  # put back
    with pytest.raises(KeyboardInterrupt), claimed_output(output, {"format": "x"}, overwrite=True):
        output.write_text("half of the new run")
        raise KeyboardInterrupt
    assert output.read_text() == "half of the new run"  # resumable
    assert (tmp_path / "out.h5.replaced").read_text() == "another run"  # and nothing lost


def test_a_replaced_file_left_by_an_interrupted_overwrite_goes_when_the_run_completes(tmp_path, capsys):
    output = tmp_path / "out.h5"
    output.write_text("another run")
    with pytest.raises(KeyboardInterrupt), claimed_output(output, {"format": "x"}, overwrite=True):
        output.write_text("half of the new run")
        raise KeyboardInterrupt
    assert (tmp_path / "out.h5.replaced").exists()
    capsys.readouterr()
    with mock.patch("stickslip.output_safety.overwrite.refuse_other_run"):  # the rerun resumes its own file
        with claimed_output(output, {"format": "x"}):
            output.write_text("the new run")
    assert not (tmp_path / "out.h5.replaced").exists() and output.read_text() == "the new run"
    assert f"{output} is complete: removed {tmp_path / 'out.h5.replaced'}" in capsys.readouterr().err


def test_overwrite_onto_a_file_being_written_is_refused_before_anything_moves(tmp_path):
    output = tmp_path / "out.h5"
    output.write_text("a run being written")
    with writer_lock(output):  # held by "another process": flock conflicts between open files
        with pytest.raises(FileFormatError, match="another process is writing it"):
            with claimed_output(output, {"format": "x"}, overwrite=True):
                pytest.fail("the block must not run")
        assert output.read_text() == "a run being written"
        assert not list(tmp_path.glob("out.h5.replaced*"))
