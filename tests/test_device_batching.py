"""Runs that share a device in batches: a capability a solver declares (``device_batch``), not code of the study.

The study plans the batches and the workflow runs them through :class:`stickslip.registry.DeviceBatching`, so a
solver of a third party batches its runs on its device with no edit of the study or the workflow; the ``fem``
solver declares its GPU runs so. A local workflow whose jobs need a device that the machine lacks stops before any
job, with the solver's own message.
"""

import dataclasses
import subprocess

import pytest

from stickslip import registry
from stickslip.plugin_params import param
from stickslip.study_plan import Study, device_batches, runs_on_device
from stickslip.solvers.fem import GPU_BATCHING

from conftest import copy_workflow

NAME = "toy-device"


@dataclasses.dataclass(frozen=True)
class ToyDeviceParams:
    size: int = param(1, "what a batch shares", minimum=1)
    seed: int = param(0, "what its runs may differ in")
    device: bool = param(False, "run on the device")


@pytest.fixture
def toy_device():
    """A solver registered for this test only, whose runs with ``device`` share a device in batches of one ``size``."""
    ran = []
    batching = registry.DeviceBatching(on_device=lambda params: params["device"], shared=("size",),
                                       run=lambda members: ran.append(len(members)))

    def run(params, output, *, threads=1, inputs=None):
        """A solver of the test."""

    registry.available("solver")  # the built-in plugins first
    registry.register("solver", NAME, "1", ToyDeviceParams, produces="fem-run", device_batch=batching)(run)
    yield ran
    registry._plugins["solver"].pop(NAME)


def test_the_study_batches_the_runs_that_a_solver_puts_on_its_device_by_what_they_share(toy_device):
    config = {"study": "toy", "gpu_batch": 2,
              "solvers": {NAME: [{"params": {"device": True}, "grid": {"size": [1, 2], "seed": [1, 2, 3]}},
                                 {"params": {"device": False}, "grid": {"seed": [1, 2]}}]}}
    study = Study(config)
    on_device = [sim for sim in study.simulations if runs_on_device(sim)]
    assert len(study.simulations) == 8 and len(on_device) == 6
    batches = study.batches
    assert sorted(len(batch.runs) for batch in batches) == [1, 1, 2, 2]  # 3 runs of each size, in twos
    for batch in batches:
        assert batch.solver == NAME and len({sim.params["size"] for sim in batch.runs}) == 1
        assert all(sim.params["device"] for sim in batch.runs)
    assert device_batches(study.simulations, 1) == []  # gpu_batch < 2: one job per run


def test_a_device_batch_must_be_a_solver_s_and_share_parameters_it_has():
    batching = registry.DeviceBatching(on_device=bool, shared=("size", "colour"), run=list)
    with pytest.raises(registry.PluginError, match="device_batch shares parameters it does not have: colour"):
        registry.register("solver", "toy-device-bad", "1", ToyDeviceParams, produces="fem-run",
                          device_batch=batching)(lambda params, output, *, threads=1, inputs=None: None)
    assert "toy-device-bad" not in registry.available("solver")


def test_fem_declares_its_gpu_runs():
    plugin = registry.get("solver", "fem")
    assert plugin.device_batch is GPU_BATCHING
    assert GPU_BATCHING.on_device({"backend": "cuda"}) and not GPU_BATCHING.on_device({"backend": "structured"})
    assert {"N", "plates", "dt_scale", "interface_law"} <= set(GPU_BATCHING.shared)


GPU_RUN = """
solvers:
  fem:
    - params: {N: 9, plates: 2, max_increments: 1, backend: cuda}
analyses: {}
figures: {}
"""


def test_a_local_workflow_with_gpu_jobs_on_a_machine_without_one_stops_before_any_job(tmp_path):
    from stickslip.fem.backends.cuda import CudaBackend

    reason = CudaBackend.unavailable()
    if not reason:
        pytest.skip("a GPU is available here")
    directory = copy_workflow(tmp_path)
    (directory / "gpu.yaml").write_text(GPU_RUN)
    done = subprocess.run(["snakemake", "--cores", "1", "--configfile", "gpu.yaml"], cwd=directory,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode != 0
    assert ("1 job(s) run on a GPU (simulate_gpu, ...): parameter 'backend': 'cuda' cannot run on this machine: "
            f"{reason}") in done.stdout + done.stderr
    assert not (directory / "results" / "gpu" / "sim").exists()
