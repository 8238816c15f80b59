"""stickslip.cluster's reading of SLURM's answers, without a cluster (the checks against a real one: tests/test_slurm.py)."""

import pytest

from stickslip import cluster
from stickslip.cluster import JobRequest, node_gpus, request_problem


@pytest.mark.parametrize("gres, gpus", [
    ("(null)", {}),
    ("gpu:4", {None: 4}),
    ("gpu:h100:4(S:0-1)", {"h100": 4}),
    ("gpu:a100:2(S:0,1),gpu:h100:2(S:1),mps:200", {"a100": 2, "h100": 2}),
    ("mps:100,gpu:testgpu:0", {"testgpu": 0}),
])
def test_the_gpus_of_a_node_are_read_from_its_generic_resources(gres, gpus):
    assert node_gpus(gres) == gpus


@pytest.fixture
def sinfo(monkeypatch):
    """Answer the module's sinfo with the given lines (one per node: CPUs, memory [MB], generic resources)."""
    def answer(*lines):
        monkeypatch.setattr(cluster, "_run", lambda *command: (0, "".join(f"{line}\n" for line in lines), ""))
    return answer


def test_a_gpu_job_for_a_partition_without_gpus_is_one_line(sinfo):
    sinfo("64 256000 (null)", "32 128000 (null)")
    problem = request_problem([JobRequest("mesh", 1, 2000, "cpu"), JobRequest("simulate_gpu", 1, 16000, "cpu", 1)])
    assert problem == ("rule simulate_gpu asks for 1 GPU per job, but the nodes of partition 'cpu' have none (sinfo: "
                       "(null)): sbatch would refuse the job; set STICKSLIP_SLURM_GPU_PARTITION to a partition with "
                       "GPUs (sinfo --format '%P %G' lists them)")


def test_a_gpu_job_that_some_node_can_run_passes(sinfo):
    sinfo("64 256000 gpu:a100:2(S:0)", "64 256000 gpu:a100:2(S:0),gpu:h100:4(S:1)")
    assert request_problem([JobRequest("simulate_gpu", 8, 16000, "gpu", 4, "h100"),
                            JobRequest("simulate_gpu", 8, 16000, "gpu", 6)]) is None
    assert request_problem([JobRequest("simulate_gpu", 8, 16000, "gpu", 3, "a100")]).startswith(
        "rule simulate_gpu asks for 3 GPUs of type a100 per job, but the nodes of partition 'gpu' have at most 2")
