"""Checks of the SLURM path before any job is submitted, so that a run fails with a message instead of hanging.

Two ways a SLURM run of the workflow used to wait forever without a word:

- the executor plugin (snakemake-executor-plugin-slurm 2.8.0) learns that a job ended from its status
  command, ``sacct`` by default; on a cluster without an accounting database ``sacct`` fails ("Slurm
  accounting storage is disabled") and finished jobs are never noticed. ``squeue`` works there, as long
  as finished jobs stay in it (``MinJobAge``); with ``MinJobAge`` below 3 times the delay before its first
  status check (``--slurm-init-seconds-before-status-checks``, 40 s by default) the plugin falls back to
  ``sacct`` whenever ``sacct`` is installed;
- a job that asks for more CPUs or memory than any node of its partition has stays pending
  (``PD (PartitionConfig)``) on clusters that do not refuse it at submission. (A job that asks for more GPUs,
  or a GPU model, than the nodes have is refused by sbatch; checked too, so that a run stops before its
  first job rather than after the CPU jobs before its GPU jobs, maybe hours later.)

:func:`check_slurm` runs both checks (``sacct``, ``scontrol show config``, ``sinfo``) from the workflow's
``onstart`` handler and raises :class:`SlurmSetupError` with what to change.
"""

import dataclasses
import re
import shutil
import subprocess

__all__ = ["SlurmSetupError", "JobRequest", "STATUS_SWITCH", "check_slurm", "status_command_problem",
           "request_problem", "node_gpus"]

#: The command-line switch (and profile key ``slurm-status-command``) for clusters without accounting.
STATUS_SWITCH = "--slurm-status-command squeue"

#: The plugin falls back from ``squeue`` to ``sacct`` when ``MinJobAge`` is below this many times the delay
#: before its first status check.
SQUEUE_MIN_JOB_AGE_FACTOR = 3


class SlurmSetupError(RuntimeError):
    """The cluster cannot run the workflow as configured; the message says what to change."""


@dataclasses.dataclass(frozen=True)
class JobRequest:
    """What one job asks of SLURM.

    Attributes
    ----------
    rule : str
    threads : int
        CPUs per task.
    mem_mb : int or None
        Memory [MB]; None if the job states none.
    partition : str or None
        ``slurm_partition``; None: the cluster's default partition.
    gpus : int
        GPUs per job (the executor plugin's ``gpu`` resource, or the count in ``gres``).
    gpu_model : str or None
        The GPU type asked for (``gpu_model``: ``sbatch --gpus=MODEL:N``); None: any.
    """

    rule: str
    threads: int
    mem_mb: int | None
    partition: str | None
    gpus: int = 0
    gpu_model: str | None = None


def _run(*command):
    """Run a SLURM client command; return (exit status, stdout, first line of stderr)."""
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=60, check=False)
    except FileNotFoundError:
        return 127, "", f"{command[0]}: command not found"
    except subprocess.TimeoutExpired:
        return 124, "", f"{' '.join(command)}: no answer within 60 s"
    lines = done.stderr.strip().splitlines()
    return done.returncode, done.stdout, (lines[0] if lines else "")


def _min_job_age():
    """``MinJobAge`` of the controller [s], or None if it cannot be read."""
    status, out, _ = _run("scontrol", "show", "config")
    found = re.search(r"^\s*MinJobAge\s*=\s*(\d+)", out, re.M) if status == 0 else None
    return int(found[1]) if found else None


def status_command_problem(status_command, first_check_delay):
    """Return why the plugin's status command would not see jobs finish on this cluster, or None.

    Parameters
    ----------
    status_command : {"sacct", "squeue"}
        The plugin's setting ``slurm-status-command``.
    first_check_delay : int
        The plugin's setting ``slurm-init-seconds-before-status-checks`` [s].

    Returns
    -------
    str or None
        One line: what fails and the switch to use.
    """
    min_job_age = _min_job_age()
    least_job_age = SQUEUE_MIN_JOB_AGE_FACTOR * first_check_delay
    used = status_command
    if status_command == "squeue" and shutil.which("sacct") and (min_job_age or 0) < least_job_age:
        used = "sacct"
    if used == "sacct":
        status, _, error = _run("sacct", "--noheader", "--allocations", "--starttime", "now")
        if status != 0:
            if status_command == "squeue":
                return (f"the SLURM status command falls back to sacct because MinJobAge = {min_job_age} s is "
                        f"below {least_job_age} s ({SQUEUE_MIN_JOB_AGE_FACTOR} x "
                        f"--slurm-init-seconds-before-status-checks), and sacct fails on this cluster ({error}): "
                        f"ask for a MinJobAge of at least {least_job_age} s in slurm.conf, or lower that option")
            return (f"the SLURM status command sacct fails on this cluster ({error}), so finished jobs would never "
                    f"be noticed: without an accounting database run with {STATUS_SWITCH}")
    return None


def node_gpus(gres):
    """The GPUs of one node by type, from its generic resources as sinfo's ``%G`` gives them.

    Parameters
    ----------
    gres : str
        E.g. ``gpu:4``, ``gpu:h100:4(S:0-1)``, ``gpu:a100:2(S:0),gpu:h100:2(S:1),mps:200``; ``(null)``: none.

    Returns
    -------
    dict[str or None, int]
        Type (None: untyped) -> count; ``{"a100": 2, "h100": 2}`` for the third example.
    """
    gpus = {}
    for kind, count in re.findall(r"(?:^|,)gpu(?::([^:(,]+))?:(\d+)", gres):
        gpus[kind or None] = gpus.get(kind or None, 0) + int(count)
    return gpus


def _nodes(partition):
    """(CPUs, memory [MB], generic resources) of every node of a partition (None: the default partition), from sinfo."""
    if partition is None:
        status, out, error = _run("sinfo", "--noheader", "--format", "%P")
        defaults = [name[:-1] for name in out.split() if name.endswith("*")]
        if status != 0 or not defaults:
            raise SlurmSetupError(f"sinfo names no default partition ({error or out.strip()}): set slurm_partition "
                                  "(README, 'Running on a SLURM cluster')")
        partition = defaults[0]
    status, out, error = _run("sinfo", "--noheader", "--Node", "--partition", partition, "--format", "%c %m %G")
    nodes = [(int(cpus.rstrip("+")), int(memory.rstrip("+")), gres)
             for cpus, memory, gres in (line.split(maxsplit=2) for line in out.splitlines() if line.strip())]
    if status != 0 or not nodes:
        raise SlurmSetupError(f"partition '{partition}': sinfo lists no node ({error or 'empty answer'}); "
                              "set slurm_partition to a partition of this cluster (sinfo lists them)")
    return partition, nodes


def request_problem(jobs):
    """Return the first job that no node of its partition can run, as one line, or None.

    Parameters
    ----------
    jobs : Iterable[JobRequest]

    Returns
    -------
    str or None
    """
    nodes = {}
    for job in jobs:
        if job.partition not in nodes:
            nodes[job.partition] = _nodes(job.partition)
        partition, sizes = nodes[job.partition]
        cpus = max(size[0] for size in sizes)
        if job.threads > cpus:
            return (f"rule {job.rule} asks for {job.threads} CPUs per job, but the largest node of partition "
                    f"'{partition}' has {cpus}: the job would stay pending; set the config key threads to at "
                    f"most {cpus} (--config threads={cpus})")
        fitting = [memory for count, memory, _ in sizes if count >= job.threads]
        if job.mem_mb is not None and job.mem_mb > max(fitting):
            return (f"rule {job.rule} asks for {job.mem_mb} MB, but the nodes of partition '{partition}' with "
                    f"{job.threads} CPUs have at most {max(fitting)} MB: the job would stay pending; lower "
                    f"mem_mb of {job.rule} (set-resources in the profile)")
        problem = _gpu_problem(job, partition, [gres for *_, gres in sizes]) if job.gpus else None
        if problem:
            return problem
    return None


def _gpu_problem(job, partition, node_gres):
    """Why no node of ``partition`` (its nodes' sinfo ``%G``) has the GPUs ``job`` asks for, or None."""
    gpus = [node_gpus(gres) for gres in node_gres]
    most = max(node.get(job.gpu_model, 0) if job.gpu_model else sum(node.values()) for node in gpus)
    if job.gpus <= most:
        return None
    asked = f"{job.gpus} GPU{'s' if job.gpus > 1 else ''}" + (f" of type {job.gpu_model}" if job.gpu_model else "")
    models = sorted({kind for node in gpus for kind in node if kind})
    change = (f"set STICKSLIP_SLURM_GPU_MODEL to a type they have ({', '.join(models)}) or "
              if job.gpu_model and models else "")
    return (f"rule {job.rule} asks for {asked} per job, but the nodes of partition '{partition}' have "
            f"{f'at most {most}' if most else 'none'} (sinfo: {', '.join(sorted(set(node_gres)))}): sbatch would "
            f"refuse the job; {change}set STICKSLIP_SLURM_GPU_PARTITION to a partition with GPUs (sinfo --format "
            f"'%P %G' lists them)")


def check_slurm(status_command, first_check_delay, jobs):
    """Check the status command and every job's request against the cluster.

    Parameters
    ----------
    status_command : {"sacct", "squeue"}
    first_check_delay : int
        ``slurm-init-seconds-before-status-checks`` [s].
    jobs : Iterable[JobRequest]
        The jobs about to be submitted.

    Raises
    ------
    SlurmSetupError
        With one line saying what to change.
    """
    problem = status_command_problem(status_command, first_check_delay) or request_problem(jobs)
    if problem:
        raise SlurmSetupError(problem)
