"""An interrupted simulation job keeps its stored progress and the rerun resumes from it."""

import dataclasses
import json

import numpy as np
import pytest

from stickslip import registry
from stickslip.h5io import open_file, write_dataset
from stickslip.params import param
from stickslip.workflow_api import partial_path, run_simulation


@dataclasses.dataclass(frozen=True)
class StepsParams:
    steps: int = param(6, "steps to store", minimum=1)
    stop_after: int = param(0, "steps after which the first call is interrupted (0: never)", minimum=0)


class Interrupted(Exception):
    """Stands for the wall-time kill of a cluster job."""


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
    assert not partial_path(output).exists()
    with open_file(output) as file:
        assert file["done"][...].tolist() == [0, 1, 2, 3, 4, 5]
        assert file.attrs["interrupted"]  # the same file, continued, not a fresh run
    assert json.loads(record.read_text())["outputs"][0]["path"].endswith("run.h5")
