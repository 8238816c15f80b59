"""The jobs of the Snakemake workflow: each runs one plugin and writes its provenance record.

The scripts in ``workflow/scripts/`` are one call each to a function of this
module, so everything a rule does can be run and tested without Snakemake.
Every function writes a log, checks that its input files are readable HDF5
(a corrupted file is reported by name before any work), runs the plugin, and
writes the JSON record beside the output (:mod:`stickslip.provenance.record`).
Jobs receive their inputs with their lineage (:class:`stickslip.lineage.Artifact`
as JSON: run id, producer, format, parent) and record it; nothing is read back
from a path. An output that exists when a job starts (Snakemake deletes those of
the jobs it runs) must be the output of the same run, by the run id of its
record, or the job refuses it (:func:`stickslip.output_safety.overwrite.refuse_other_run`,
the rule of every command that writes a file).

A simulation is written under :func:`partial_path` until it is complete, and the
completed file keeps that second name (a hard link: no extra space) with its
record beside it, so that a job which completed while Snakemake was stopped
(Ctrl-C, a lost connection: Snakemake then deletes its outputs and runs it again)
is found complete by the rerun instead of being recomputed, unless its code
changed. :func:`release_completed` drops those second names once a workflow run
has succeeded.

This module imports nothing that imports numba: :func:`prepare_environment`
must set the numba variables before the first plugin is loaded.
"""

import atexit
import contextlib
import json
import os
import shutil
import sys
import tempfile
import traceback
from pathlib import Path
from types import SimpleNamespace

from . import registry
from .h5io import FileFormatError, open_file
from .hashing import sha256_file
from .lineage import Artifact
from .output_safety.overwrite import refuse_other_run
from .plugin_params import params_to_dict, parse_params
from .provenance.code import code_hash, plugin_code_hash
from .provenance.record import read_record, recording
from .termination import interrupts_raised

__all__ = ["prepare_environment", "partial_path", "kept_record", "run_mesh", "run_simulation", "run_analysis",
           "run_figure", "build_database", "build_browse", "release_completed"]

#: What a job says about an existing output of another run (jobs have no ``--overwrite``).
_NOT_THIS_JOBS = "it is not this job's output: move it away (or delete it) and rerun"


def prepare_environment(threads, numba_cache="shared"):
    """Set the numba environment of a job; call before anything imports numba.

    (In a process that has imported numba already, as a test, ``NUMBA_NUM_THREADS``
    no longer matters; the jobs also call :func:`stickslip.numba_options.set_num_threads`.)

    Parameters
    ----------
    threads : int
        The rule's threads: ``NUMBA_NUM_THREADS`` (numba's thread pool size).
    numba_cache : {"shared", "job"}
        ``"job"``: compile into a fresh cache directory of this job under
        ``$TMPDIR`` (``NUMBA_CACHE_DIR``, removed when the process ends), as on a
        cluster where many jobs share one file system; ``"shared"``: numba's cache
        beside the sources (or ``$NUMBA_CACHE_DIR``), common to all jobs.

    Returns
    -------
    str or None
        The job's cache directory, if one was made.
    """
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    os.environ["NUMBA_NUM_THREADS"] = str(int(threads))
    if numba_cache == "job":
        if "numba" in sys.modules:
            raise RuntimeError("numba_cache='job' needs prepare_environment before numba is imported")
        cache = tempfile.mkdtemp(prefix="stickslip-numba-")
        os.environ["NUMBA_CACHE_DIR"] = cache
        atexit.register(shutil.rmtree, cache, ignore_errors=True)
        return cache
    if numba_cache != "shared":
        raise ValueError(f"numba_cache must be 'shared' or 'job', got {numba_cache!r}")
    return None


@contextlib.contextmanager
def _logged(log):
    """Send stdout and stderr to ``log``; a failure's traceback goes there too, then propagates.

    Ctrl-C and SIGTERM (Snakemake, ``scancel``, a wall time) end the job at any moment, numba's
    compilation included (:func:`stickslip.termination.interrupts_raised`): files are closed.
    """
    Path(log).parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w", encoding="utf-8") as stream:
        try:
            with contextlib.redirect_stdout(stream), contextlib.redirect_stderr(stream), interrupts_raised():
                yield stream
        except BaseException:
            stream.write(traceback.format_exc())
            raise


def _check_hdf5(role, path):
    """Open an input once so that an unreadable or truncated file is reported by name."""
    try:
        with open_file(path) as handle:
            handle.attrs.keys()
    except FileFormatError as error:
        raise FileFormatError(f"{error} (input {role})") from None
    except OSError as error:  # h5py reports damaged content on first access
        raise FileFormatError(f"{path}: damaged HDF5 file ({error}) (input {role})") from None


def _artifacts(value):
    """Artifacts from the JSON (or the mapping) a rule passes: one, a list, or a mapping of them."""
    value = json.loads(value) if isinstance(value, str) else value
    if isinstance(value, Artifact):
        return value
    if isinstance(value, dict) and "path" in value:
        return Artifact.from_dict(value)
    if isinstance(value, list):
        return [_artifacts(item) for item in value]
    return {key: _artifacts(item) for key, item in value.items()}


def _plugin_recording(record, outputs, plugin, params, run_id, *, code=None, **extra):
    """:func:`recording` of a plugin run: identity, version and code hash (``code``, or computed) of the plugin.

    An output that exists already must be the output of ``run_id`` (:func:`_refuse_other_outputs`).
    """
    _refuse_other_outputs([path for _, path, *_ in outputs], record, run_id)
    return recording(record, outputs, run_id=run_id, kind=plugin.kind, plugin=plugin.name,
                     plugin_version=plugin.version, code_hash=code or plugin_code_hash(plugin, params),
                     params=params_to_dict(params), **extra)


def _refuse_other_outputs(outputs, record, run_id):
    """Raise OutputExistsError if one of ``outputs`` exists and its record ``record`` is not of ``run_id``."""
    def recorded(path, names):
        try:
            return {"run_id": read_record(record)["run_id"]}
        except FileFormatError:
            return {}

    def describe(stored):
        return "the output of another job" if stored else f"a file without its provenance record {record}"

    for path in outputs:
        refuse_other_run(path, {"run_id": run_id}, hint=_NOT_THIS_JOBS, read=recorded, describe=describe)


def _load(kind, name, params_json, module):
    plugin = registry.get(kind, registry.config_key(name)[0], module)
    params = parse_params(plugin.params, json.loads(params_json), owner=f"{kind} '{name}'")
    return plugin, params


def run_mesh(params_json, output, record, log, *, numba_cache="shared"):
    """Write one mesh file.

    Parameters
    ----------
    params_json : str
        :class:`stickslip.mesh.MeshParams` values as JSON.
    output, record, log : str or pathlib.Path
        Mesh file (HDF5), its provenance record, the log.
    numba_cache : {"shared", "job"}
        See :func:`prepare_environment`.
    """
    prepare_environment(1, numba_cache)
    with _logged(log):
        from . import mesh  # after prepare_environment: numba reads its threads and cache on import

        params = parse_params(mesh.MeshParams, json.loads(params_json), owner="mesh")
        as_dict = params_to_dict(params)
        with recording(record, [("output", output, "mesh")], run_id=mesh.mesh_id(params), kind="mesh", plugin="mesh",
                       plugin_version=str(mesh.MESH_FORMAT),
                       code_hash=code_hash(mesh.write_mesh.__module__), params=as_dict):
            print(f"mesh {json.dumps(as_dict, sort_keys=True)} -> {output}")
            mesh.write_mesh(params, Path(output))


def run_simulation(solver, params_json, output, record, log, *, inputs, threads, numba_cache="shared", module=None):
    """Run one solver.

    Parameters
    ----------
    solver : str
        Solver plugin name.
    params_json : str
        Its parameters as JSON (defaults may be missing; they are filled).
    output, record, log : str or pathlib.Path
        Simulation file (HDF5), its provenance record, the log.
    inputs : str or Mapping
        Upstream files by consumed format, as artifacts (``{"mesh": Artifact}``), or
        their JSON (:meth:`stickslip.study_plan.Study.dumps`).
    threads : int
        Threads of the parallel kernels.
    numba_cache : {"shared", "job"}
        See :func:`prepare_environment`.
    module : str, optional
        The module that registers the plugin (see :func:`stickslip.registry.get`).
    """
    prepare_environment(threads, numba_cache)
    with _logged(log):
        from .numba_options import set_num_threads  # after prepare_environment: numba reads its threads on import

        job = _solver_job(solver, params_json, output, record, inputs, module)
        if job is not None:
            _run_solver_job(job, set_num_threads(threads))


def run_simulation_batch(solver, params_jsons, outputs, records, log, *, inputs, threads, numba_cache="shared",
                         module=None):
    """Run several runs of one solver as one batch on a device: one job, one file per run.

    Every run is as :func:`run_simulation` makes it (its file, its provenance record, resumed or left
    alone as there); the runs not completed before advance together, one thread each, their
    minimisations sharing the device's launches (the solver's ``device_batch``,
    :class:`stickslip.registry.DeviceBatching`).

    Parameters
    ----------
    solver : str
    params_jsons, outputs, records : Sequence
        Per run, as :func:`run_simulation`'s ``params_json``, ``output``, ``record``.
    log : str or pathlib.Path
        The batch's log (every run's lines).
    inputs : Sequence[str or Mapping]
        Per run, as :func:`run_simulation`'s ``inputs``.
    threads, numba_cache, module
        As :func:`run_simulation`.
    """
    prepare_environment(threads, numba_cache)
    with _logged(log):
        from .numba_options import set_num_threads  # after prepare_environment: numba reads its threads on import

        batching = registry.get("solver", registry.config_key(solver)[0], module).device_batch
        if batching is None:
            raise registry.PluginError(f"solver {solver!r} declares no device_batch: its runs are one job each")
        jobs = [_solver_job(solver, *job, module) for job in zip(params_jsons, outputs, records, inputs)]
        pending = [job for job in jobs if job is not None]
        used = set_num_threads(threads)
        print(f"batch of {len(jobs)} runs, {len(jobs) - len(pending)} completed before")
        batching.run([lambda backend, job=job: _run_solver_job(job, used, backend) for job in pending])


def _solver_job(solver, params_json, output, record, inputs, module):
    """One solver run checked and ready to run, or None if an earlier job completed it (its files put in place).

    Raises what :func:`run_simulation` says of its inputs (the solver's preflight included) before any file is
    touched.
    """
    plugin, params = _load("solver", solver, params_json, module)
    if plugin.preflight is not None:  # e.g. a GPU backend without a GPU: said before any file is touched
        plugin.preflight(params)
    run_id, code = registry.run_id(plugin, params), plugin_code_hash(plugin, params)
    output, partial = Path(output), partial_path(output)
    _refuse_other_outputs([output], record, run_id)
    if _completed_before(partial, run_id, code):
        _publish(partial, output)
        _publish(kept_record(partial), Path(record))
        print(f"{plugin.name} run {run_id}: completed by an earlier job ({partial}), not recomputed")
        return None
    inputs = _artifacts(inputs)
    for role, path in inputs.items():
        _check_hdf5(role, path)
    return SimpleNamespace(plugin=plugin, params=params, run_id=run_id, code=code, output=output, partial=partial,
                           record=Path(record), inputs=inputs)


def _run_solver_job(job, threads, backend=None):
    """Run a :func:`_solver_job` into its second name, record it, and put it in place (``backend``: a batch's)."""
    plugin, inputs = job.plugin, job.inputs
    with _plugin_recording(job.record, [("output", job.output, plugin.produces)], plugin, job.params, job.run_id,
                           code=job.code, threads=threads, inputs=sorted(inputs.items())) as record:
        print(f"solver {plugin.name} {plugin.version}, {threads} thread(s), {json.dumps(record['params'])}")
        job.partial.parent.mkdir(parents=True, exist_ok=True)
        if job.partial.exists():
            print(f"resuming from {job.partial}")
        extra = {} if backend is None else {"backend": backend}
        plugin.run(job.params, job.partial, threads=threads, inputs={k: v.path for k, v in inputs.items()}, **extra)
        kept = _publish(job.partial, job.output)
    if kept:
        _publish(job.record, kept_record(job.partial))


def kept_record(partial):
    """The copy of a completed simulation's provenance record beside its second name ``partial``.

    Named ``<run_id>.kept.json``, not ``*.provenance.json``: the database's rebuild reads those.
    """
    return partial.with_suffix(".kept.json")


def _completed_before(partial, run_id, code):
    """Whether ``partial`` holds run ``run_id`` completed by code ``code`` (its kept record says so).

    A kept file of other code (or whose bytes no longer match its record) is removed: the run is
    made again.
    """
    kept = kept_record(partial)
    if not (partial.is_file() and kept.is_file()):
        return False
    try:
        record = read_record(kept)
        same = (record["run_id"] == run_id and record["code_hash"] == code
                and record["outputs"][0]["sha256"] == sha256_file(partial))
    except FileFormatError:
        same = False
    if not same:
        print(f"{partial}: completed by other code (or changed since); made again")
        partial.unlink()
        kept.unlink()
    return same


def _publish(source, target):
    """Give ``source`` the second name ``target`` (a hard link, replacing ``target`` atomically).

    Where the file system has no hard links, ``source`` is renamed to ``target``.

    Returns
    -------
    bool
        Whether ``source`` keeps its name (it is linked, not renamed).
    """
    link = target.with_name(f".{target.name}.{os.getpid()}.link")
    link.unlink(missing_ok=True)
    try:
        os.link(source, link)
    except OSError:
        os.replace(source, target)
        return False
    os.replace(link, target)
    return True


def release_completed(root):
    """Drop the second names (in ``partial/``) of the completed simulations of a study whose outputs are in place.

    Call when a workflow run has succeeded: Snakemake then holds every job it ran as complete, so
    no rerun will need to find them (:func:`run_simulation`).

    Parameters
    ----------
    root : str or pathlib.Path
        The study's results tree, ``results/{study}``.

    Returns
    -------
    int
        Number of simulations released.
    """
    released = 0
    for kept in sorted(Path(root).glob("sim/*/partial/*.kept.json")):
        partial = kept.parent / Path(read_record(kept)["outputs"][0]["path"]).name
        output = kept.parent.parent / partial.name
        if partial.is_file() and output.is_file() and os.path.samefile(partial, output):
            partial.unlink()
            kept.unlink()
            released += 1
    return released


def partial_path(output):
    """Where a simulation is written until it completes: ``<dir>/partial/<name>``.

    Snakemake deletes the output of a job that fails or is killed (a cluster's wall
    time, Ctrl-C). A solver that stores its progress as it goes (``fem`` appends every
    increment) writes here instead, outside Snakemake's outputs, and the finished
    file is renamed to ``output``; the rerun of an interrupted job resumes from it.

    Parameters
    ----------
    output : str or pathlib.Path
        The simulation file of the rule, ``results/{study}/sim/{solver}/{run_id}.h5``.

    Returns
    -------
    pathlib.Path
        ``results/{study}/sim/{solver}/partial/{run_id}.h5``.
    """
    output = Path(output)
    return output.parent / "partial" / output.name


def run_analysis(analysis, params_json, simulation, output, record, log, *, numba_cache="shared", module=None):
    """Run one analysis on one simulation output.

    Parameters
    ----------
    analysis : str
        Analysis plugin name.
    params_json : str
        Its parameters as JSON.
    simulation : str
        The simulation file as an artifact, JSON (path, run id, solver, format).
    output, record, log : str or pathlib.Path
        Table file (HDF5), its provenance record, the log.
    numba_cache : {"shared", "job"}
        See :func:`prepare_environment`.
    module : str, optional
        The module that registers the plugin (see :func:`stickslip.registry.get`).
    """
    prepare_environment(1, numba_cache)
    with _logged(log):
        plugin, params = _load("analysis", analysis, params_json, module)
        simulation = _artifacts(simulation)
        if simulation.format not in plugin.consumes:
            raise FileFormatError(f"{simulation}: a {simulation.format} file; analysis {analysis!r} reads "
                                  f"{', '.join(plugin.consumes)}")
        _check_hdf5("simulation", simulation)
        with _plugin_recording(record, [("output", output, plugin.produces)], plugin, params,
                               registry.derived_run_id(plugin, params, [simulation.run_id]),
                               inputs=[("simulation", simulation)]):
            print(f"analysis {plugin.name} {plugin.version} on {simulation} ({simulation.plugin} "
                  f"{simulation.run_id})")
            plugin.run(params, simulation, Path(output))


def run_figure(figure, params_json, inputs_json, output, record, log, *, numba_cache="shared", module=None):
    """Draw one figure.

    Parameters
    ----------
    figure : str
        Figure plugin name.
    params_json : str
        Its parameters as JSON.
    inputs_json : str
        JSON object: input category -> list of artifacts (an analysis output with its
        simulation as ``parent``).
    output, record, log : str or pathlib.Path
        The PDF (the PNG goes beside it), the provenance record, the log.
    numba_cache : {"shared", "job"}
        See :func:`prepare_environment`.
    module : str, optional
        The module that registers the plugin (see :func:`stickslip.registry.get`).
    """
    prepare_environment(1, numba_cache)
    with _logged(log):
        plugin, params = _load("figure", figure, params_json, module)
        inputs = _artifacts(inputs_json)
        files = [(category, item) for category, items in sorted(inputs.items()) for item in items]
        parents = {item.parent.run_id: item.parent for _, item in files if item.parent is not None}
        files += [("simulation", parents[key]) for key in sorted(parents)]
        for role, path in files:
            _check_hdf5(role, path)
        output = Path(output)
        outputs = [("pdf", output), ("png", output.with_suffix(".png"))]
        run_id = registry.derived_run_id(plugin, params, [item.run_id for items in inputs.values() for item in items])
        with _plugin_recording(record, outputs, plugin, params, run_id, inputs=files):
            print(f"figure {plugin.name} {plugin.version} from {len(files)} file(s)")
            plugin.run(params, inputs, output)


def build_database(records, database, log):
    """Build the results database from the study's records (the database rule).

    Parameters
    ----------
    records : Sequence[str or pathlib.Path]
        Provenance records of every job of the study.
    database : str or pathlib.Path
        SQLite file; replaced atomically, so a failure leaves the previous one.
    log : str or pathlib.Path
    """
    with _logged(log):
        from .provenance.ingest import ingest  # SQLAlchemy's ORM (~0.3 s), for the database job only

        counts = ingest(database, records, rebuild=True)
        print("ingested " + ", ".join(f"{count} {name}" for name, count in counts.items()))


def build_browse(study, output, log):
    """Write a study's pages as a static site (the browse rule; :func:`stickslip.browse.site.build_site`).

    Parameters
    ----------
    study : str
        The study's name (its results tree ``results/{study}`` in the working directory, the workflow's).
    output : str or pathlib.Path
        The site's folder.
    log : str or pathlib.Path
    """
    with _logged(log):
        from .browse.site import build_site  # matplotlib and the database layer: for this job only
        from .study_results import StudyResults

        print(build_site(StudyResults(study, workdir="."), output, progress=print))
