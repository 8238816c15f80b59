"""The SLURM path against a real controller: a single-node slurmctld + slurmd on loopback (tests/slurm/cluster.sh).

The ci study runs through the SLURM profile (every job through sbatch) on a cluster without an
accounting database, and gives the same HDF5 files and database as a local run. With the wrong status
command, or more CPUs, memory or GPUs per job than the node has, the workflow stops at start with a message
instead of hanging. Ctrl-C or SIGTERM cancels the jobs a run has submitted. The jobs on a GPU go to the GPU
partition asking for one GPU of the type named (the node's GPU is a generic resource without a device:
the jobs themselves stop with the cuda backend's one line where the machine has no GPU). Every snakemake
run is under a timeout: a hang fails the test.

Needs root and Debian's SLURM packages (tests/slurm/packages.txt; `bash .ci/run` installs them); skipped
with the reason otherwise (failed instead where STICKSLIP_REQUIRE_SLURM is set, as .ci/run does).
"""

import os
import re
import signal
import sqlite3
import subprocess
import time

import pytest
import yaml

from conftest import REPO, copy_workflow, python_path
from stickslip.fem.backends.cuda import CudaBackend
from stickslip.study_plan import Study

CLUSTER = REPO / "tests" / "slurm" / "cluster.sh"
CI = ["--configfile", "workflow/config/ci.yaml"]
#: The profile, the accounting-less cluster's status command, status checks every few seconds.
SLURM = ["--workflow-profile", "profiles/slurm", "--slurm-status-command", "squeue",
         "--slurm-init-seconds-before-status-checks", "5"]

#: fem runs on a GPU, one load increment each, in batches of at most 2 (config gpu_batch): two batch jobs.
GPU_STUDY = """
gpu_batch: 2
solvers:
  fem:
    - params: {N: 9, plates: 2, max_increments: 1, backend: cuda, relaxation: exact}
      grid: {seed: [1, 2, 3]}
analyses: {}
figures: {}
"""
#: The same beside a run on the CPU.
MIXED_STUDY = GPU_STUDY.replace("analyses:", "    - params: {N: 9, plates: 2, max_increments: 1}\nanalyses:")
#: Where the profile sends the jobs on a GPU, and the GPU type they ask for (tests/slurm/cluster.sh: its node's GPU).
GPU_ENV = {"STICKSLIP_SLURM_GPU_PARTITION": "gpu", "STICKSLIP_SLURM_GPU_MODEL": "testgpu"}

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """Environment of a running single-node cluster (SLURM_CONF, the partition 'stickslip' for the jobs)."""
    directory = tmp_path_factory.mktemp("slurm")
    started = subprocess.run(["bash", str(CLUSTER), "start", str(directory)], capture_output=True, text=True,
                             timeout=180, check=False)
    if started.returncode == 3:
        if os.environ.get("STICKSLIP_REQUIRE_SLURM"):  # set by .ci/run where it installed the packages
            pytest.fail(started.stderr.strip())
        pytest.skip(started.stderr.strip())
    assert started.returncode == 0, started.stdout + started.stderr
    env = dict(os.environ, SLURM_CONF=str(directory / "slurm.conf"), STICKSLIP_SLURM_PARTITION="stickslip",
               PYTHONPATH=python_path())
    yield env
    subprocess.run(["bash", str(CLUSTER), "stop", str(directory)], timeout=120, check=False)


def start_snakemake(directory, env, *args):
    """Start snakemake in ``directory`` as a terminal starts a command; its output goes to ``directory``/snakemake.log.

    It gets its own process group, and SIGINT at its default action whatever this process inherited: a
    shell ignores SIGINT in what it starts in the background (``pytest &``, ``nohup``), and a Python
    started so never raises ``KeyboardInterrupt``, so Ctrl-C could not be tested.
    """
    with open(directory / "snakemake.log", "w") as log:
        return subprocess.Popen(["env", "--default-signal=INT", "snakemake", *args], cwd=directory, env=env,
                                stdout=log, stderr=subprocess.STDOUT, start_new_session=True)


def finish(process, directory, timeout):
    """Wait for a snakemake of :func:`start_snakemake`; on a timeout kill its process group and fail.

    Returns
    -------
    (int, str)
        Exit status and output.
    """
    try:
        process.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        output = (directory / "snakemake.log").read_text()
        pytest.fail(f"{' '.join(process.args)} still running after {timeout} s (a hang):\n"
                    f"{output[-4000:]}")
    return process.returncode, (directory / "snakemake.log").read_text()


def run_snakemake(directory, env, *args, timeout):
    """Run snakemake under a timeout (see :func:`finish`)."""
    return finish(start_snakemake(directory, env, *args), directory, timeout)


def slurm_jobs(env):
    """SLURM jobs the controller knows (finished ones stay for MinJobAge): job id -> (partition, state)."""
    out = subprocess.run(["squeue", "--noheader", "--states=all", "--format", "%i %P %T"], env=env,
                         capture_output=True, text=True, timeout=60, check=True).stdout
    return {line.split()[0]: tuple(line.split()[1:]) for line in out.splitlines()}


def new_jobs(env, before):
    """Jobs of :func:`slurm_jobs` not in ``before``."""
    return {job: state for job, state in slurm_jobs(env).items() if job not in before}


def submitted_requests(env, jobs):
    """What each of ``jobs`` (SLURM job ids) asked for, from ``scontrol show job``: job id -> its fields."""
    out = subprocess.run(["scontrol", "show", "job", "--oneliner"], env=env, capture_output=True, text=True,
                         timeout=60, check=True).stdout
    fields = [dict(re.findall(r"(\S+?)=(\S*)", line)) for line in out.splitlines()]
    return {job["JobId"]: job for job in fields if job.get("JobId") in jobs}


def planned_resources(output):
    """The resources of every job of a dry run's plan: list of (rule, {resource: value as printed})."""
    jobs = re.findall(r"^rule (\S+):\n(?:    .*\n)*?    resources: (.*)$", output, re.M)
    return [(rule, dict(item.split("=", 1) for item in resources.split(", "))) for rule, resources in jobs]


def gpu_study(directory, text):
    """The workflow in ``directory`` with the study ``text`` as gpu.yaml; returns the snakemake arguments to run it."""
    copy_workflow(directory)
    (directory / "gpu.yaml").write_text(text)
    return ["--configfile", "gpu.yaml"]


def table(database, query):
    with sqlite3.connect(database) as connection:
        return sorted(connection.execute(query).fetchall(), key=repr)  # repr: rows may hold None beside numbers


def test_ci_study_through_slurm_equals_the_local_run(cluster, ci_study, tmp_path):
    local, remote = ci_study, copy_workflow(tmp_path)
    # The jobs load the kernels the local run compiled into numba's shared cache; the profile's default,
    # a cache per job, would compile them again in every job, as if each ran on another node (the per-job
    # cache itself: tests/test_workflow.py::test_job_environment_reaches_numba).
    env = dict(cluster, STICKSLIP_SLURM_NUMBA_CACHE="shared")
    before = slurm_jobs(cluster)
    status, output = run_snakemake(remote, env, *SLURM, *CI, timeout=1200)
    assert status == 0, output[-4000:]
    study = Study(yaml.safe_load((REPO / "workflow" / "config" / "ci.yaml").read_text()), ["ci.yaml"])
    submitted = new_jobs(cluster, before)
    # every job went through sbatch, into the partition named once in the environment, and completed
    assert len(submitted) == (len(study.meshes) + len(study.simulations) + len(study.analysis_jobs)
                              + len(study.figures) + 1)
    assert set(submitted.values()) == {("stickslip", "COMPLETED")}
    for path in study.outputs():
        if path.endswith(".h5"):
            assert (remote / path).read_bytes() == (local / path).read_bytes(), path
    for query in ("SELECT run_id, kind, plugin, params FROM runs", "SELECT * FROM simulations",
                  "SELECT run_id, direction, role, path, sha256, format, made_by FROM artifacts WHERE path LIKE '%.h5'",
                  "SELECT analysis_run_id, simulation_run_id, analysis, solver, source, event, interface, slip, dmu, "
                  "dmu_sig0, multi, time, t, increment, extra FROM slip_events"):
        assert table(remote / study.path("database"), query) == table(local / study.path("database"), query)
    again, output = run_snakemake(remote, env, *SLURM, *CI, "-n", timeout=300)
    assert again == 0 and "Nothing to be done" in output


@pytest.mark.parametrize("args, message", [
    (["--slurm-status-command", "sacct"],
     "SLURM: the SLURM status command sacct fails on this cluster (Slurm accounting storage is disabled), so "
     "finished jobs would never be noticed: without an accounting database run with --slurm-status-command squeue"),
    (["--config", "threads=64"],
     "SLURM: rule simulate asks for 64 CPUs per job, but the largest node of partition 'stickslip' has"),
    (["--set-resources", "simulate:mem_mb=100000000"],
     "SLURM: rule simulate asks for 100000000 MB, but the nodes of partition 'stickslip' with 1 CPUs have at most"),
])
def test_a_setup_that_would_hang_stops_at_start(cluster, tmp_path, args, message):
    directory = copy_workflow(tmp_path)
    before = slurm_jobs(cluster)
    status, output = run_snakemake(directory, cluster, *SLURM, *CI, *args, timeout=300)
    assert status != 0
    assert message in " ".join(output.split()), output[-4000:]
    assert slurm_jobs(cluster) == before  # nothing was submitted


@pytest.fixture
def partition_down(cluster):
    """Partition 'stickslip' down during the test: jobs are accepted and stay pending, as on a full cluster."""
    def set_state(state):
        subprocess.run(["scontrol", "update", "PartitionName=stickslip", f"State={state}"], env=cluster,
                       timeout=60, check=True)
    set_state("DOWN")
    yield
    set_state("UP")


@pytest.mark.parametrize("signal_number", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_an_interrupted_run_cancels_its_submitted_jobs(cluster, partition_down, tmp_path, signal_number):
    directory = copy_workflow(tmp_path)
    before = slurm_jobs(cluster)
    process = start_snakemake(directory, cluster, *SLURM, *CI)
    pending, steady = {}, 0
    for _ in range(300):  # until the first round of jobs is submitted: some jobs, none more for 5 s
        submitted = new_jobs(cluster, before)
        steady = steady + 1 if submitted and submitted == pending else 0
        pending = submitted
        if process.poll() is not None or steady == 5:
            break
        time.sleep(1)
    assert pending and set(pending.values()) == {("stickslip", "PENDING")}, (directory / "snakemake.log").read_text()
    os.killpg(process.pid, signal_number)  # a terminal's Ctrl-C reaches the whole foreground process group
    status, output = finish(process, directory, timeout=120)
    assert status != 0
    assert set(new_jobs(cluster, before).values()) == {("stickslip", "CANCELLED")}, output[-4000:]


@pytest.mark.parametrize("gpu_batch, gpu_rule, gpu_jobs", [(2, "simulate_batch_", 2), (0, "simulate_gpu", 3)])
def test_the_jobs_on_a_gpu_plan_with_the_gpu_partition_and_type(tmp_path, gpu_batch, gpu_rule, gpu_jobs):
    # a dry run (no cluster needed): every job on a GPU, a run alone (simulate_gpu) or a batch (a rule of its own,
    # named after its runs), has the profile's GPU resources; the other jobs the CPU partition and no GPU
    args = gpu_study(tmp_path, MIXED_STUDY)
    env = dict(os.environ, PYTHONPATH=python_path(), STICKSLIP_SLURM_PARTITION="stickslip", **GPU_ENV)
    status, output = run_snakemake(tmp_path, env, "-n", "--workflow-profile", "profiles/slurm", *args,
                                   "--config", f"gpu_batch={gpu_batch}", timeout=300)
    assert status == 0, output[-4000:]
    planned = planned_resources(output)
    on_gpu = [resources for rule, resources in planned if rule.startswith(gpu_rule)]
    assert len(on_gpu) == gpu_jobs
    for resources in on_gpu:
        assert (resources["slurm_partition"], resources["gpu"], resources["gpu_model"]) == ("gpu", "1", "testgpu")
        assert (resources["runtime"], resources["mem_mb"]) == ("1440", "16000")
    others = {rule: resources for rule, resources in planned if not rule.startswith(gpu_rule)}
    assert set(others) == {"mesh", "simulate", "database", "all"}
    assert all(resources["slurm_partition"] == "stickslip" and "gpu" not in resources for resources in others.values())


def test_the_jobs_on_a_gpu_are_submitted_to_the_gpu_partition_asking_for_the_gpu(cluster, tmp_path):
    args = gpu_study(tmp_path, GPU_STUDY)
    env = dict(cluster, STICKSLIP_SLURM_NUMBA_CACHE="shared", **GPU_ENV)
    before = slurm_jobs(cluster)
    # --retries 0: a failed job is not submitted again (the profile retries once)
    status, output = run_snakemake(tmp_path, env, *SLURM, *args, "--retries", "0", timeout=600)
    requests = submitted_requests(cluster, new_jobs(cluster, before))
    rules = {job["Comment"].removeprefix("rule_").split("_wildcards_")[0]: job for job in requests.values()}
    batches = [job for rule, job in rules.items() if rule.startswith("simulate_batch_")]
    assert len(requests) == 3 and "mesh" in rules and len(batches) == 2, output[-4000:]
    assert (rules["mesh"]["Partition"], rules["mesh"]["JobState"]) == ("stickslip", "COMPLETED")
    assert "TresPerJob" not in rules["mesh"]
    for job in batches:
        assert (job["Partition"], job["TresPerJob"]) == ("gpu", "gres:gpu:testgpu:1")
        assert (job["TimeLimit"], job["MinMemoryNode"]) == ("1-00:00:00", "16000M")
    logs = sorted((tmp_path / "results" / "gpu" / "logs" / "sim" / "fem").glob("batch-*.log"))
    assert len(logs) == 2
    if CudaBackend.unavailable():  # the node's GPU is a name only: each job stops with the backend's one line
        assert status != 0 and {job["JobState"] for job in batches} == {"FAILED"}
        for log in logs:
            assert "parameter 'backend': 'cuda' cannot run on this machine: " in log.read_text()
        assert not list((tmp_path / "results" / "gpu" / "sim" / "fem").glob("*.h5"))
    else:
        assert status == 0 and {job["JobState"] for job in batches} == {"COMPLETED"}, output[-4000:]


@pytest.mark.parametrize("env, args, message", [
    # --set-resources replaces the profile's set-resources: the partition of every job, any GPU type
    ({}, ["--set-resources", "simulate_gpu:gpu=2"],
     "asks for 2 GPUs per job, but the nodes of partition 'stickslip' have at most 1 (sinfo: gpu:testgpu:1): "
     "sbatch would refuse the job; set STICKSLIP_SLURM_GPU_PARTITION to a partition with GPUs"),
    ({"STICKSLIP_SLURM_GPU_MODEL": "h100"}, [],
     "asks for 1 GPU of type h100 per job, but the nodes of partition 'gpu' have none (sinfo: gpu:testgpu:1): "
     "sbatch would refuse the job; set STICKSLIP_SLURM_GPU_MODEL to a type they have (testgpu) or set "
     "STICKSLIP_SLURM_GPU_PARTITION to a partition with GPUs"),
], ids=["more-gpus-than-a-node-has", "a-gpu-type-the-partition-lacks"])
def test_a_gpu_job_that_no_node_can_run_stops_at_start(cluster, tmp_path, env, args, message):
    # the settings of every job on a GPU apply to the batches' rules as well (set-resources of simulate_gpu)
    study = gpu_study(tmp_path, GPU_STUDY)
    before = slurm_jobs(cluster)
    status, output = run_snakemake(tmp_path, {**cluster, **GPU_ENV, **env}, *SLURM, *study, *args, timeout=300)
    assert status != 0
    assert re.search(r"SLURM: rule simulate_batch_\w+ " + re.escape(message), " ".join(output.split())), output[-4000:]
    assert slurm_jobs(cluster) == before  # nothing was submitted
