# The study: the config validated (each plugin section against its plugin's JSON-Schema, defaults
# filled) and expanded into jobs by stickslip.study_plan before any rule is defined.

import re
import tempfile
from pathlib import Path

import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from stickslip.plugin_params import ParameterError, did_you_mean
from stickslip.provenance.code import code_hash
from stickslip.provenance.record import record_path
from stickslip.study_plan import ANALYSIS_PRIORITY, Study, check_sweeps, normalise, plugin_sections


def _validate(section, schema, key):
    """Validate against a JSON-Schema file (defaults filled in); a failure is one message naming the key.

    jsonschema's message is followed by the whole schema that failed (a hundred lines for a plugin
    section): only its first paragraph is kept.
    """
    try:
        validate(section, schema)
    except WorkflowError as error:
        detail = str(error.args[0]).removeprefix("Error validating config file.").strip()
        instance = re.search(r"^On instance((?:\[[^\]]*\])*):", detail, re.M)
        for item in re.findall(r"\[([^\]]*)\]", instance.group(1) if instance else ""):
            key = f"{key}.{item.strip(chr(39))}" if item.startswith("'") else f"{key}[{item}]"
        message = detail.split("\n\n")[0].removeprefix("ValidationError: ")
        unexpected = re.search(r"Additional properties are not allowed \('([^']*)' was unexpected", message)
        if unexpected and not key:  # a top-level key: name it, not the (unnamed) config it is in
            path = Path(schema) if Path(schema).is_absolute() else Path(workflow.basedir, "workflow", "rules", schema)
            known = list(yaml.safe_load(path.read_text())["properties"])
            key, message = unexpected.group(1), (f"not a key of the config{did_you_mean(unexpected.group(1), known)}; "
                                                 f"allowed: {', '.join(known)}")
        raise WorkflowError(f"config key {key.lstrip('.')}: {message}") from None


def _validate_plugin_sections(config):
    """Validate every plugin section against its plugin's schema, naming the key on failure."""
    normalise(config)
    check_sweeps(config)  # before the validator fills the defaults into the sweeps' params
    with tempfile.TemporaryDirectory() as folder:
        for index, (key, section, schema) in enumerate(plugin_sections(config)):
            # one file per section: Snakemake caches a schema file's contents by path
            path = Path(folder) / f"section{index}.schema.yaml"
            path.write_text(yaml.safe_dump({"$schema": "https://json-schema.org/draft/2020-12/schema", **schema}))
            _validate(section, str(path), key)


try:
    _validate(config, "../schemas/config.schema.yaml", "")
    _validate_plugin_sections(config)
    STUDY = Study(config, workflow.configfiles)
except ParameterError as error:
    raise WorkflowError(str(error)) from None


#: The software of all jobs under `--software-deployment-method conda` (see the file's comments).
CONDA_ENV = "../envs/stickslip.yaml"


wildcard_constraints:
    solver=r"[a-z0-9][A-Za-z0-9_-]*",
    analysis=r"[a-z0-9][A-Za-z0-9_-]*(@[A-Za-z0-9][A-Za-z0-9_-]*)?",
    run_id=r"[0-9a-f]{16}",
    mesh_id=r"[0-9a-f]{16}",


def record_of(pattern):
    """The provenance record beside an output pattern."""
    return record_path(pattern).as_posix()


#: Every job on a GPU gets the resources that a profile (`set-resources`) or --set-resources sets for this one
#: (a single run on a GPU is made by it; a GPU batch by simulate_batch_<id>, named after its runs, which a profile
#: cannot name). No comment here may hold the word 'rule' and a colon on one line: snakemake --lint reads it as a
#: rule beside the functions.
GPU_RULE = "simulate_gpu"


def with_gpu_rule_resources(name):
    """Give the resources set for GPU_RULE to the rule ``name`` (a GPU batch); what is set for ``name`` itself wins."""
    overwrite = workflow.resource_settings.overwrite_resources
    for source in (GPU_RULE, name):
        workflow.get_rule(name).resources.update(overwrite.get(source, {}))


onstart:
    # A local run with jobs on a GPU (a solver's device_batch picks them) checks, before any job, that this machine
    # can run them.
    if workflow.executor_plugin is not None and workflow.executor_plugin.name == "local":
        gpu_jobs = [job for job in workflow.dag.needrun_jobs() if job.resources.get("gpu")]
        if gpu_jobs:
            try:
                STUDY.check_device_runs()
            except ParameterError as error:
                raise WorkflowError(f"{len(gpu_jobs)} job(s) run on a GPU ({gpu_jobs[0].rule.name}, ...): "
                                    f"{error}") from None
    # A SLURM run checks, before submitting anything, that it would not hang (stickslip.cluster).
    if workflow.executor_plugin is not None and workflow.executor_plugin.name == "slurm":
        from snakemake_executor_plugin_slurm.partitions import parse_gpu_requirements
        from stickslip.cluster import JobRequest, SlurmSetupError, check_slurm
        from stickslip.termination import raise_interrupt_on_sigterm

        requests = [JobRequest(job.rule.name, job.threads, job.resources.get("mem_mb"),
                               job.resources.get("slurm_partition") or None, *parse_gpu_requirements(job))
                    for job in workflow.dag.needrun_jobs() if not job.is_local]
        try:
            settings = workflow.executor_settings
            check_slurm(settings.status_command, settings.init_seconds_before_status_checks, requests)
        except SlurmSetupError as error:
            raise WorkflowError(f"SLURM: {error}") from None
        # SIGTERM (kill, a wall time or scancel of the job Snakemake runs in) ends the run as Ctrl-C does: the
        # submitted jobs are cancelled (scancel). Snakemake's own SIGTERM handler waits for them instead, for
        # hours or, for a job that never starts, forever.
        raise_interrupt_on_sigterm()


onsuccess:
    # A completed simulation keeps a second name under sim/{solver}/partial/ until Snakemake has seen its job
    # finish, so that a job that completed while Snakemake was stopped is not recomputed by the rerun
    # (stickslip.workflow_api.run_simulation); after a successful run Snakemake has seen them all.
    from stickslip.workflow_api import release_completed

    release_completed(STUDY.root)
