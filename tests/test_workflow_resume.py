"""An interrupted simulation job keeps its stored progress and the rerun resumes from it; a completed one is kept."""

import dataclasses
import json
import os

import numpy as np
import pytest

from stickslip import registry
from stickslip.h5io import open_file, write_dataset
from stickslip.plugin_params import param
from stickslip.workflow_api import partial_path, release_completed, run_simulation


@dataclasses.dataclass(frozen=True)
class StepsParams:
    steps: int = param(6, "steps to store", minimum=1)
    stop_after: int = param(0, "steps after which the first call is interrupted (0: never)", minimum=0)


class Interrupted(Exception):
    """Stands for the wall-time kill of a cluster job."""


#: Steps computed by every call of the solver, in order.
COMPUTED = []


@registry.register("solver", "test-resumable", "1", StepsParams, produces="fem-run")
def _resumable(params, output, *, threads, inputs):
    """Stores one row per step as it goes and resumes from what an earlier call stored."""
    mode = "r+" if output.exists() else "w"
    with open_file(output, mode) as file:
        if "done" not in file:
            write_dataset(file, "done", np.zeros(0, dtype=np.int64), maxshape=(None,), chunks=(16,))
        done = file["done"]
        for step in range(done.size, params.steps):
            done.resize((step + 1,))
            done[step] = step
            COMPUTED.append(step)
            file.flush()
            if step + 1 == params.stop_after and not file.attrs.get("interrupted", False):
                file.attrs["interrupted"] = True
                raise Interrupted(f"killed after step {step}")


def test_rerun_after_an_interruption_resumes_and_loses_nothing(tmp_path):
    output = tmp_path / "results" / "sim" / "test-resumable" / "run.h5"
    record = output.with_suffix(".provenance.json")
    args = ("test-resumable", json.dumps({"steps": 6, "stop_after": 3}), output, record, tmp_path / "job.log")

    with pytest.raises(Interrupted):
        run_simulation(*args, inputs={}, threads=1)
    assert not output.exists() and not record.exists()  # nothing half-done where Snakemake looks
    with open_file(partial_path(output)) as file:
        assert file["done"][...].tolist() == [0, 1, 2]  # what was stored is kept

    run_simulation(*args, inputs={}, threads=1)
    assert "resuming from" in (tmp_path / "job.log").read_text()
    assert os.path.samefile(partial_path(output), output)  # its second name until Snakemake has seen the job end
    with open_file(output) as file:
        assert file["done"][...].tolist() == [0, 1, 2, 3, 4, 5]
        assert file.attrs["interrupted"]  # the same file, continued, not a fresh run
    assert json.loads(record.read_text())["outputs"][0]["path"].endswith("run.h5")


def test_a_job_that_completed_unseen_by_snakemake_is_not_recomputed(tmp_path):
    """Snakemake stopped by Ctrl-C while a job completes marks it incomplete, deletes its outputs and reruns it."""
    output = tmp_path / "results" / "sim" / "test-resumable" / "run.h5"
    record, log = output.with_suffix(".provenance.json"), tmp_path / "job.log"
    args = ("test-resumable", json.dumps({"steps": 4}), output, record, log)
    COMPUTED.clear()
    run_simulation(*args, inputs={}, threads=1)
    made = output.read_bytes()
    output.unlink()
    record.unlink()  # what Snakemake's rerun of an incomplete job does first

    run_simulation(*args, inputs={}, threads=1)
    assert COMPUTED == [0, 1, 2, 3]  # once
    assert "completed by an earlier job" in log.read_text() and "not recomputed" in log.read_text()
    assert output.read_bytes() == made and json.loads(record.read_text())["run_id"]

    assert release_completed(tmp_path / "results") == 1  # the workflow succeeded: the second names go
    assert sorted(p.name for p in partial_path(output).parent.iterdir()) == []
    assert output.read_bytes() == made and record.exists()


def test_a_kept_run_of_other_code_is_made_again(tmp_path, monkeypatch):
    output = tmp_path / "sim" / "test-resumable" / "run.h5"
    record, log = output.with_suffix(".provenance.json"), tmp_path / "job.log"
    args = ("test-resumable", json.dumps({"steps": 3}), output, record, log)
    run_simulation(*args, inputs={}, threads=1)
    output.unlink()
    record.unlink()
    COMPUTED.clear()
    monkeypatch.setattr("stickslip.workflow_api.plugin_code_hash", lambda plugin, params: "0123456789abcdef")  # code changed
    run_simulation(*args, inputs={}, threads=1)
    assert COMPUTED == [0, 1, 2]
    assert "completed by other code" in log.read_text()
    assert json.loads(record.read_text())["code_hash"] == "0123456789abcdef"
