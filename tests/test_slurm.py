"""The SLURM path against a real controller: a single-node slurmctld + slurmd on loopback (tests/slurm/cluster.sh).

The ci study runs through the SLURM profile (every job through sbatch) on a cluster without an
accounting database, and gives the same HDF5 files and database as a local run. With the wrong status
command, or more CPUs or memory per job than the node has, the workflow stops at start with a message
instead of hanging. Ctrl-C or SIGTERM cancels the jobs a run has submitted. Every snakemake run is under a
timeout: a hang fails the test.

Needs root and Debian's SLURM packages (tests/slurm/packages.txt; `bash .ci/run` installs them); skipped
with the reason otherwise (failed instead where STICKSLIP_REQUIRE_SLURM is set, as .ci/run does).
"""

import os
import signal
import sqlite3
import subprocess
import time

import pytest
import yaml

from conftest import REPO, copy_workflow, python_path
from stickslip.study import Study

CLUSTER = REPO / "tests" / "slurm" / "cluster.sh"
CI = ["--configfile", "workflow/config/ci.yaml"]
#: The profile, the accounting-less cluster's status command, status checks every few seconds.
SLURM = ["--workflow-profile", "profiles/slurm", "--slurm-status-command", "squeue",
         "--slurm-init-seconds-before-status-checks", "5"]

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
                  "multi, time, increment, extra FROM slip_events"):
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
