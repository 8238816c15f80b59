"""The study: a workflow config turned into the jobs that the rules run.

Config layout (``workflow/config/*.yaml``, schema ``workflow/schemas/config.schema.yaml``)::

    study: default                  # results tree results/{study}/ (default: the config file's stem)
    threads: 1                      # numba threads of each simulation job
    solvers:                        # solver name -> list of sweeps
      lever:
        - params: {protocol: stack} # shared by the sweep's runs (defaults filled)
          grid: {n: [1, 2], seed: [1, 2, 3]}   # every combination is one run
    analyses:                       # analysis name -> parameters
      experiment-events: {}
    figures:                        # figure name -> parameters
      fig3: {}

A run's parameters are its sweep's ``params`` and one combination of its
``grid`` (a parameter is named in one of the two, a grid value listed once:
:func:`check_sweeps`); its id is :func:`stickslip.registry.run_id` of those parameters.
Stages are wired by format (:mod:`stickslip.formats`): an analysis runs on every
simulation whose solver produces the format it consumes, whatever the solver's
name; a solver that consumes ``mesh`` gets the mesh of its parameters; a figure
reads every output of each input category it declares (``analysis:<name>``, each
output paired with its simulation, or ``format:<name>``). Every job's inputs are
:class:`stickslip.lineage.Artifact` s: path, run id, producer, format, parent.

Each study writes under its own results tree, ``results/{study}/``: outputs
(:data:`PATHS`), logs and the database, so studies run in one clone never
overwrite each other.
"""

import dataclasses
import itertools
import json
import re
from pathlib import Path

from . import mesh, registry
from .hashing import short_hash
from .lineage import Artifact
from .plugin_params import ParameterError, json_schema, params_to_dict, parse_params
from .provenance.code import code_hash, plugin_code_hash
from .provenance.record import record_path

__all__ = ["RESULTS", "PATHS", "study_name", "check_study_name", "SimulationJob", "AnalysisJob", "FigureJob", "Study",
           "plugin_sections", "normalise", "check_sweeps"]

#: Directory of the studies' results trees (relative to the workflow's working directory).
RESULTS = "results"

#: Scheduling priority of an analysis job (rule ``events``): above every run's (:meth:`Study.run_priority`), so that
#: an analysis starts as soon as its run is stored instead of waiting behind runs that do not need it.
ANALYSIS_PRIORITY = 2

#: Path patterns inside a study's results tree ``results/{study}/``.
PATHS = {
    "mesh": "mesh/{mesh_id}.h5",
    "simulation": "sim/{solver}/{run_id}.h5",
    "events": "events/{analysis}/{solver}/{run_id}.h5",
    "figure": "figures/{figure}.pdf",
    "database": "stickslip.sqlite",
    "added": "added/{solver}/{run_id}.h5",
    "logs": "logs",
    "benchmark": "logs/benchmarks/sim/{solver}/{run_id}.tsv",
    "events_benchmark": "logs/benchmarks/events/{analysis}/{solver}/{run_id}.tsv",
}

_STUDY_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


def study_name(config, configfiles=()):
    """Return the name of a study: the config's ``study`` key, else the stem of its config file.

    Parameters
    ----------
    config : dict
        The workflow config.
    configfiles : Sequence[str or pathlib.Path]
        The config files it was read from (the last one names the study); none: ``"default"``.

    Returns
    -------
    str
        A path component: a letter or digit, then letters, digits, ``_``, ``.``, ``-``.

    Raises
    ------
    ParameterError
        If the name is not a valid path component.
    """
    name = config.get("study") or (Path(configfiles[-1]).stem if configfiles else "default")
    return check_study_name(name, "config key study")


def check_study_name(name, what):
    """``name`` as a study name: a path component of ``results/`` (never ``..``, never a path); else ParameterError.

    Parameters
    ----------
    name : object
    what : str
        Where the name comes from, for the message (``config key study``, ``--study``).
    """
    if not _STUDY_NAME.match(str(name)):
        raise ParameterError(f"{what}: expected a name matching {_STUDY_NAME.pattern} "
                             f"(it is a directory under {RESULTS}/), got {name!r}")
    return str(name)

SECTIONS = {"solvers": "solver", "analyses": "analysis", "figures": "figure"}


@dataclasses.dataclass(frozen=True)
class SimulationJob:
    """One solver run.

    Attributes
    ----------
    solver : str
    run_id : str
    params : dict
        Defaults-filled, JSON-safe parameters.
    path : str
        Output file.
    format : str
        Its format (the solver's ``produces``).
    mesh_id : str or None
        Id of the mesh file it reads (solvers that consume ``mesh``).
    """

    solver: str
    run_id: str
    params: dict
    path: str
    format: str
    mesh_id: str | None = None

    def artifact(self):
        """The output as an :class:`~stickslip.lineage.Artifact`."""
        return Artifact(self.path, self.run_id, self.solver, self.format)


@dataclasses.dataclass(frozen=True)
class SimulationBatch:
    """Runs of one solver made by one job on a device (its ``device_batch`` shared parameters equal): their
    minimisations share the device's launches.

    Attributes
    ----------
    solver : str
    batch_id : str
        A hash of its runs' ids (a rule name: letters, digits, ``_``).
    runs : tuple[SimulationJob, ...]
    """

    solver: str
    batch_id: str
    runs: tuple


def _batching(sim):
    """The ``device_batch`` of a :class:`SimulationJob`'s solver (:class:`stickslip.registry.DeviceBatching` or None)."""
    return registry.get("solver", registry.config_key(sim.solver)[0]).device_batch


def runs_on_device(sim):
    """Whether a :class:`SimulationJob` runs on a device (a GPU): its solver's ``device_batch`` says so."""
    batching = _batching(sim)
    return batching is not None and batching.on_device(sim.params)


def device_batches(simulations, size):
    """The device batches of a study's runs (:class:`SimulationBatch`): runs of one solver on a device that agree on
    the parameters its ``device_batch`` shares, in run-id order, at most ``size`` each; none if ``size`` < 2."""
    if size < 2:
        return []
    groups = {}
    for sim in filter(runs_on_device, simulations):
        key = json.dumps([sim.solver] + [sim.params.get(name) for name in _batching(sim).shared], sort_keys=True)
        groups.setdefault(key, []).append(sim)
    batches = []
    for key in sorted(groups):
        runs = groups[key]
        for first in range(0, len(runs), size):
            members = tuple(runs[first:first + size])
            batches.append(SimulationBatch(members[0].solver, "b" + short_hash([sim.run_id for sim in members]),
                                           members))
    return batches


@dataclasses.dataclass(frozen=True)
class AnalysisJob:
    """One analysis of one simulation output (``path``: the output file, of ``format``)."""

    analysis: str
    simulation: SimulationJob
    run_id: str
    path: str
    format: str

    def artifact(self):
        """The output as an :class:`~stickslip.lineage.Artifact`, its simulation as parent."""
        return Artifact(self.path, self.run_id, self.analysis, self.format, self.simulation.artifact())


@dataclasses.dataclass(frozen=True)
class FigureJob:
    """One figure and the files it reads.

    Attributes
    ----------
    figure : str
    params : dict
    inputs : dict[str, list[stickslip.lineage.Artifact]]
        Input category -> artifacts sorted by path.
    path : str
        Output PDF (the PNG is beside it).
    run_id : str
    """

    figure: str
    params: dict
    inputs: dict
    path: str
    run_id: str

    def files(self):
        """Every file it reads (analysis outputs and their simulations), sorted, no duplicates."""
        return sorted({path.as_posix() for items in self.inputs.values() for item in items
                       for path in item.files()})


def _where(section, name, *rest):
    return ".".join([section, name]) + "".join(rest)


def normalise(config):
    """Replace empty plugin sections (``fig3:`` with no value) by ``{}``, in place.

    Parameters
    ----------
    config : dict
        The workflow config (already checked against the config schema).
    """
    for section in ("analyses", "figures"):
        for name, values in (config.get(section) or {}).items():
            if values is None:
                config[section][name] = {}


def _grid_schema(params_cls):
    properties = {}
    for name, prop in json_schema(params_cls)["properties"].items():
        item = {k: v for k, v in prop.items() if k not in ("default", "description")}
        properties[name] = {"type": "array", "items": item, "minItems": 1,
                            "description": f"values of {name} to sweep over"}
    return {"type": "object", "properties": properties, "additionalProperties": False}


def _plugin(kind, key, where):
    """The plugin of a config key (``name`` or ``name@label``, see :func:`stickslip.registry.config_key`)."""
    try:
        return registry.get(kind, registry.config_key(key)[0])
    except registry.PluginError as error:
        raise ParameterError(f"config {where}: {error}") from None


def plugin_sections(config):
    """List the config sections that hold a plugin's parameters, with their JSON-Schema.

    Parameters
    ----------
    config : dict
        The workflow config (normalised, see :func:`normalise`).

    Returns
    -------
    list[tuple[str, dict, dict]]
        ``(key, section, schema)``: ``key`` names the section in messages (e.g.
        ``solvers.lever[0].grid``); ``section`` is the mapping itself (a schema
        validator that fills defaults changes it in place); ``schema`` comes from
        :func:`stickslip.plugin_params.json_schema` of the plugin's parameter class.

    Raises
    ------
    ParameterError
        If a plugin name is unknown; the message names the key and lists the plugins.
    """
    sections = []
    for section, kind in SECTIONS.items():
        for name, values in (config.get(section) or {}).items():
            plugin = _plugin(kind, name, _where(section, name))
            if kind == "solver":
                for i, sweep in enumerate(values):
                    sections.append((_where(section, name, f"[{i}].params"), sweep["params"],
                                     json_schema(plugin.params)))
                    sections.append((_where(section, name, f"[{i}].grid"), sweep["grid"],
                                     _grid_schema(plugin.params)))
            else:
                sections.append((_where(section, name), values, json_schema(plugin.params)))
    return sections


def _parse(plugin, values, where):
    try:
        return parse_params(plugin.params, values, owner=f"{plugin.kind} '{plugin.name}'")
    except ParameterError as error:
        raise ParameterError(f"config {where}: {error}") from None


def check_sweeps(config):
    """Refuse a parameter given in both ``params`` and ``grid`` of a sweep, and a grid value listed twice.

    Call it on the config as read, before a schema validator fills the defaults into ``params``.

    Parameters
    ----------
    config : dict
        The workflow config (checked against the config schema).

    Raises
    ------
    ParameterError
        Naming the sweep, the parameter and both values.
    """
    for name, sweeps in (config.get("solvers") or {}).items():
        for i, sweep in enumerate(sweeps):
            where = _where("solvers", name, f"[{i}]")
            params, grid = sweep.get("params") or {}, sweep.get("grid") or {}
            both = sorted(set(params) & set(grid))
            if both:
                raise ParameterError(f"config {where}: parameter '{both[0]}' is in both params "
                                     f"({params[both[0]]!r}) and grid ({grid[both[0]]!r}); expected it in one of them")
            for key, values in grid.items():
                if not isinstance(values, list):
                    raise ParameterError(f"config {where}.grid.{key}: expected a list of values, got {values!r} "
                                         f"(write [{values!r}], or put it in params)")
                for j, value in enumerate(values):
                    if value in values[:j]:
                        raise ParameterError(f"config {where}.grid.{key}: value {value!r} is listed twice; "
                                             "expected each value once")


def _mesh_for(params):
    """Return (mesh_id, mesh parameters) for a solver run: the solver's fields named as MeshParams fields."""
    fields = {f.name for f in dataclasses.fields(mesh.MeshParams)}
    mesh_params = parse_params(mesh.MeshParams, {k: v for k, v in params.items() if k in fields}, owner="mesh")
    return mesh.mesh_id(mesh_params), params_to_dict(mesh_params)


class Study:
    """All jobs of one workflow config.

    Parameters
    ----------
    config : dict
        The workflow config, checked against the schema (see :func:`plugin_sections`).
    configfiles : Sequence[str or pathlib.Path], optional
        The config files read; the last one's stem names the study when the config
        has no ``study`` key (see :func:`study_name`).

    Raises
    ------
    ParameterError
        For a bad parameter value, an unknown plugin, a solver input category
        that the workflow cannot make, an analysis or figure whose inputs the
        study does not produce; the message names the config key.

    Attributes
    ----------
    name : str
    root : str
        Its results tree, ``results/{name}``: every output, log and the database.
    threads : int
    simulations : list[SimulationJob]
        Sorted by solver, then run id; no duplicates.
    batches : list[SimulationBatch]
        The GPU batches (config ``gpu_batch``): each made by one job; the other runs one job each.
    meshes : dict[str, dict]
        Mesh id -> mesh parameters.
    analyses : dict[str, dict]
        Analysis name -> parameters.
    analysis_jobs : list[AnalysisJob]
    figures : dict[str, FigureJob]
    """

    def __init__(self, config, configfiles=()):
        normalise(config)
        self.name = study_name(config, configfiles)
        self.root = f"{RESULTS}/{self.name}"
        self.threads = int(config.get("threads", 1))
        self.meshes = {}
        self.simulations = self._simulations(config.get("solvers") or {})
        self.batches = device_batches(self.simulations, int(config.get("gpu_batch", 0)))
        self.analyses, self.analysis_jobs = self._analyses(config.get("analyses") or {})
        self.figures = self._figures(config.get("figures") or {})

    def _simulations(self, solvers):
        runs = {}
        for name, sweeps in solvers.items():
            plugin = _plugin("solver", name, _where("solvers", name))
            unknown = sorted(set(plugin.consumes) - {"mesh"})
            if unknown:
                raise ParameterError(f"config solvers.{name}: the workflow cannot make the input(s) "
                                     f"{', '.join(unknown)} that solver '{name}' declares (it makes: mesh)")
            for i, sweep in enumerate(sweeps):
                grid = sweep.get("grid") or {}
                keys = list(grid)
                for combination in itertools.product(*(grid[k] for k in keys)):
                    values = {**(sweep.get("params") or {}), **dict(zip(keys, combination))}
                    params = _parse(plugin, values, _where("solvers", name, f"[{i}]"))
                    run = registry.run_id(plugin, params)
                    as_dict = params_to_dict(params)
                    mesh_id = None
                    if "mesh" in plugin.consumes:
                        mesh_id, mesh_params = _mesh_for(as_dict)
                        self.meshes[mesh_id] = mesh_params
                    runs[(name, run)] = SimulationJob(name, run, as_dict, self.path("simulation", solver=name, run_id=run),
                                                   plugin.produces, mesh_id)
        return [runs[key] for key in sorted(runs)]

    def _analyses(self, analyses):
        chosen, jobs = {}, []
        for name, values in analyses.items():
            plugin = _plugin("analysis", name, _where("analyses", name))
            params = _parse(plugin, values, _where("analyses", name))
            chosen[name] = params_to_dict(params)
            mine = [AnalysisJob(name, sim, registry.derived_run_id(plugin, params, [sim.run_id]),
                                self.path("events", analysis=name, solver=sim.solver, run_id=sim.run_id),
                                plugin.produces)
                    for sim in self.simulations if sim.format in plugin.consumes]
            if not mine:
                raise ParameterError(f"config analyses.{name}: it reads {', '.join(plugin.consumes)} files, which "
                                     "no solver of the study produces")
            jobs.extend(mine)
        return chosen, jobs

    def mesh_artifact(self, mesh_id):
        """The mesh file of ``mesh_id`` as an :class:`~stickslip.lineage.Artifact`."""
        return Artifact(self.path("mesh", mesh_id=mesh_id), mesh_id, "mesh", "mesh")

    def _category(self, category, label):
        """Artifacts of one figure input category, sorted by path.

        ``analysis:<name>`` takes the analysis labelled like the figure (``name@label``) if
        the study has it, else the plain one.
        """
        kind, _, name = category.partition(":")
        if kind == "analysis":
            if label and f"{name}@{label}" in self.analyses:
                name = f"{name}@{label}"
            found = [job.artifact() for job in self.analysis_jobs if job.analysis == name]
        elif name == "mesh":
            found = [self.mesh_artifact(m) for m in self.meshes]
        else:
            found = [sim.artifact() for sim in self.simulations if sim.format == name]
        return sorted(found, key=lambda item: item.path)

    def _figures(self, figures):
        jobs = {}
        for name, values in figures.items():
            plugin = _plugin("figure", name, _where("figures", name))
            params = params_to_dict(_parse(plugin, values, _where("figures", name)))
            inputs = {}
            for category in plugin.inputs:
                inputs[category] = self._category(category, registry.config_key(name)[1])
                if not inputs[category]:
                    raise ParameterError(f"config figures.{name}: it reads {category} outputs, which the "
                                         "study does not produce (add the solver or analysis to the config)")
            run = registry.derived_run_id(plugin, parse_params(plugin.params, params),
                                          [item.run_id for items in inputs.values() for item in items])
            jobs[name] = FigureJob(name, params, inputs, self.path("figure", figure=name), run)
        return jobs

    # Look-ups used by the rules ------------------------------------------------------------

    def path(self, kind, **fields):
        """Return a path in the study's results tree.

        Parameters
        ----------
        kind : str
            A key of :data:`PATHS`.
        **fields
            Values of the pattern's fields; those left out stay as ``{field}``
            (a Snakemake wildcard).

        Returns
        -------
        str
            ``results/{study}/`` + the pattern.
        """
        pattern = PATHS[kind]
        for key, value in fields.items():
            pattern = pattern.replace("{" + key + "}", str(value))
        return f"{self.root}/{pattern}"

    def log(self, name):
        """Return the log file ``results/{study}/logs/{name}.log`` (``name`` may hold wildcards)."""
        return f"{self.root}/{PATHS['logs']}/{name}.log"

    def single_runs(self, on_gpu):
        """A regular expression of the run ids made one job each by rule ``simulate`` (``on_gpu`` False: every
        run not on a GPU) or ``simulate_gpu`` (True: the runs on a GPU that are in no GPU batch)."""
        gpu = {sim.run_id for sim in self.simulations if runs_on_device(sim)}
        if not on_gpu:  # a run id is 16 characters: the lookahead sees all of it (a `$` in it would see the path's end)
            return f"(?!({'|'.join(sorted(gpu))}))[0-9a-f]{{16}}" if gpu else "[0-9a-f]{16}"
        alone = sorted(gpu - {sim.run_id for batch in self.batches for sim in batch.runs})
        return f"({'|'.join(alone)})" if alone else "(?!)"

    def check_device_runs(self):
        """Raise :class:`stickslip.plugin_params.ParameterError` if this machine cannot make the study's runs on a
        device (e.g. no GPU): the solver's preflight of its first such run, per solver."""
        first = {}
        for sim in filter(runs_on_device, self.simulations):
            first.setdefault(sim.solver, sim)
        for solver, sim in first.items():
            plugin = registry.get("solver", registry.config_key(solver)[0])
            if plugin.preflight is not None:
                plugin.preflight(parse_params(plugin.params, sim.params, owner=f"solver '{solver}'"))

    def simulation(self, solver, run_id):
        """Return the :class:`SimulationJob` with this solver and run id (KeyError if none)."""
        for sim in self.simulations:
            if sim.solver == solver and sim.run_id == run_id:
                return sim
        raise KeyError(f"no simulation {solver}/{run_id} in the study")

    def run_priority(self, solver, run_id):
        """The scheduling priority of one simulation's job (rule ``simulate``; outputs do not depend on it).

        1 for a run at a finite temperature (a ``temperature`` parameter > 0), whose analyses may replay it (hold
        trials, aftershocks) for as long as the run took: its chain is the longest and starts first; 0 otherwise.
        Analyses have :data:`ANALYSIS_PRIORITY`, so that they start as soon as their run is stored.
        """
        return int(float(self.simulation(solver, run_id).params.get("temperature") or 0.0) > 0.0)

    def solver_inputs(self, solver, run_id):
        """Return the upstream files of one simulation by format (``{"mesh": Artifact}`` or ``{}``)."""
        sim = self.simulation(solver, run_id)
        return {} if sim.mesh_id is None else {"mesh": self.mesh_artifact(sim.mesh_id)}

    def analysis_job(self, analysis, solver, run_id):
        """Return the :class:`AnalysisJob` of an analysis on one simulation (KeyError if none)."""
        for job in self.analysis_jobs:
            if (job.analysis, job.simulation.solver, job.simulation.run_id) == (analysis, solver, run_id):
                return job
        raise KeyError(f"no analysis {analysis} of {solver}/{run_id} in the study")

    def outputs(self):
        """Return every output file of the study except the database (sorted)."""
        paths = [self.path("mesh", mesh_id=m) for m in self.meshes]
        paths += [sim.path for sim in self.simulations]
        paths += [job.path for job in self.analysis_jobs]
        for job in self.figures.values():
            paths += [job.path, job.path.replace(".pdf", ".png")]
        return sorted(paths)

    def records(self):
        """Return the provenance record of every job (sorted): the database rule's input."""
        paths = [self.path("mesh", mesh_id=m) for m in self.meshes]
        paths += [sim.path for sim in self.simulations]
        paths += [job.path for job in self.analysis_jobs]
        paths += [job.path for job in self.figures.values()]
        return sorted(record_path(p).as_posix() for p in paths)

    def added_records(self):
        """The records of the simulations added to the study (:meth:`stickslip.study_results.StudyResults.add`),
        sorted: the database rule ingests them too."""
        return sorted(path.as_posix() for path in Path(self.root).glob(PATHS["added"].format(solver="*", run_id="*")
                                                                          .replace(".h5", ".provenance.json")))

    @staticmethod
    def code(kind, name):
        """Return the code hash of the jobs of an analysis or figure (``kind`` "mesh": of the mesh writer's).

        A simulation's depends on its parameters: :meth:`simulation_code`.
        """
        if kind == "mesh":
            return code_hash(mesh.write_mesh.__module__)
        plugin = registry.get(kind, registry.config_key(name)[0])
        return plugin_code_hash(plugin, plugin.params())

    def simulation_code(self, solver, run_id):
        """Return the code hash of one simulation's job: its solver and the parts its parameters choose."""
        plugin = registry.get("solver", registry.config_key(solver)[0])
        params = parse_params(plugin.params, self.simulation(solver, run_id).params, owner=f"solver '{solver}'")
        return plugin_code_hash(plugin, params)

    @staticmethod
    def module(kind, name):
        """Return the module that registers a plugin (jobs import only it, :func:`stickslip.registry.get`)."""
        return registry.get(kind, registry.config_key(name)[0]).module

    @staticmethod
    def caption(figure):
        """Return the caption of a figure: its plugin's summary, name and version."""
        plugin = registry.get("figure", registry.config_key(figure)[0])
        return f"{plugin.summary} (figure plugin ``{plugin.name}`` version {plugin.version}, {plugin.module})"

    @staticmethod
    def dumps(value):
        """Return parameters or lineage (artifacts, nested in dicts and lists) as JSON, keys sorted.

        What the rules pass to the jobs; :meth:`stickslip.lineage.Artifact.from_dict` reads
        an artifact back.
        """
        return json.dumps(value, sort_keys=True, default=Artifact.to_dict)
