"""Plugin registry: solvers, analyses and figures, chosen by name in the config.

A plugin is one function plus its identity: name (a path component of its
outputs), version (part of the run id: a new version reruns what it produced),
a parameter dataclass (see :mod:`stickslip.plugin_params`) and its contract: the
artifact formats it consumes and produces (:mod:`stickslip.formats`); a figure
declares the input categories it reads. The study wires stages by format, never
by plugin name: an analysis that consumes ``fem-run`` runs on the output of every
solver that produces ``fem-run``.

Built-in plugins register with a decorator in the modules of the packages
:data:`BUILTIN_PACKAGES` (every module there is imported: a new module is found
without editing a list); third-party packages add an entry point in the group
of the plugin's kind (:data:`ENTRY_POINT_GROUPS`) that names the module to import
(importing it runs its decorators), e.g. in their ``pyproject.toml``::

    [project.entry-points."stickslip.solvers"]
    mysolver = "mypackage.mysolver"

(:mod:`stickslip.discovery`; docs/writing-a-plugin.md). The parts a solver's run chooses by name with a
parameter (the ``fem`` solver's interface laws and backends, with their own entry-point groups) are declared
as its :class:`Choice` s, so that a run's code hash covers the part it chooses and no other.

Call signatures by kind (checked when a plugin registers):

- ``solver``: ``run(params, output, *, threads, inputs)``: write one file of the
  format it produces, ``output`` (:class:`pathlib.Path`, HDF5), using at most
  ``threads`` threads; ``inputs`` maps each consumed format (e.g. ``"mesh"``) to
  a file made by an upstream stage, and may be empty (the solver then makes what
  it needs itself). A solver may offer ``replay(path)``: an object whose
  ``failures(increment)`` re-runs one stored event of a file it wrote.
- ``analysis``: ``run(params, input, output)``: read one simulation (a
  :class:`stickslip.lineage.Artifact`: path-like, with the run id and the solver
  that wrote it), write one file of the format it produces.
- ``figure``: ``run(params, inputs, output)``: ``inputs`` maps each declared input
  category (``"analysis:<name>"``: every output of that analysis, each with its
  simulation as ``parent``; ``"format:<name>"``: every simulation or mesh of that
  format) to a list of artifacts; write ``output`` (PDF) and the PNG beside it.
"""

import dataclasses
import importlib
import inspect
import re
from collections.abc import Callable, Mapping

from . import formats
from .discovery import PluginError, import_modules, load_entry_points
from .h5io import FileFormatError
from .hashing import short_hash
from .plugin_params import params_to_dict

__all__ = [
    "KINDS",
    "ENTRY_POINT_GROUPS",
    "BUILTIN_PACKAGES",
    "Plugin",
    "DeviceBatching",
    "Choice",
    "NoParameters",
    "PluginError",
    "register",
    "get",
    "available",
    "run_id",
    "derived_run_id",
    "config_key",
    "replay",
]

KINDS = ("solver", "analysis", "figure")

ENTRY_POINT_GROUPS = {"solver": "stickslip.solvers", "analysis": "stickslip.analyses", "figure": "stickslip.figures"}

#: Packages whose modules hold the built-in plugins: importing each module registers them.
BUILTIN_PACKAGES = ("stickslip.solvers", "stickslip.events", "stickslip.experiment", "stickslip.figures")

_RUN_SIGNATURES = {
    "solver": (["params", "output"], ["threads", "inputs"]),
    "analysis": (["params", "input", "output"], []),
    "figure": (["params", "inputs", "output"], []),
}

_NAME = re.compile(r"^[a-z0-9][A-Za-z0-9_-]*$")
_LABEL = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*$")

_plugins = {kind: {} for kind in KINDS}
_loaded = False


@dataclasses.dataclass(frozen=True)
class DeviceBatching:
    """How a solver's runs share one device in batches: a capability a solver declares (``device_batch``).

    The study plans a batch of the runs that :attr:`on_device` picks and that agree on :attr:`shared`
    (:func:`stickslip.study_plan.device_batches`); one workflow job runs them with :attr:`run`
    (:func:`stickslip.workflow_api.run_simulation_batch`). Neither names a solver or a backend.

    Attributes
    ----------
    on_device : Callable[[Mapping[str, object]], bool]
        Whether a run of these parameters (defaults filled, :func:`stickslip.plugin_params.params_to_dict`) runs on
        the device.
    shared : tuple[str, ...]
        The parameters that the runs of one batch share (what the device holds once for all of them).
    run : Callable[[Sequence[Callable]], list]
        ``run(members)`` runs a batch: every member is ``member(backend)``, one run on the backend it is given,
        all at once; returns what each returned, in order, after all ended (raises the first error).
    """

    on_device: Callable
    shared: tuple
    run: Callable


@dataclasses.dataclass(frozen=True)
class Choice:
    """A part of a solver's runs chosen by name with one of its parameters (``fem``: the interface law, the backend).

    The parts register themselves in :attr:`registered` (built-in ones: every module of their package;
    other packages' through an entry-point group, :mod:`stickslip.discovery`). A run's code hash covers the
    part it chooses and no other (:func:`stickslip.provenance.code.plugin_code_hash`).

    Attributes
    ----------
    parameter : str
        The solver's parameter whose value names the part (e.g. ``"interface_law"``).
    registered : Mapping[str, type]
        The live registry of the parts by name: each value is the class of a part, defined in the module that
        registers it (its ``__module__``).
    """

    parameter: str
    registered: Mapping

    def module(self, params):
        """The module of the part that ``params`` (an instance of the solver's parameters) chooses."""
        return self.registered[getattr(params, self.parameter)].__module__

    def modules(self):
        """The modules of every registered part (a frozenset of dotted names)."""
        return frozenset(part.__module__ for part in self.registered.values())


@dataclasses.dataclass(frozen=True)
class NoParameters:
    """The parameters of a plugin that has none (``register(..., params=None)``)."""


@dataclasses.dataclass(frozen=True)
class Plugin:
    """One registered plugin.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    name : str
        Unique within its kind; starts with a lowercase letter or digit, then
        letters, digits, ``-`` and ``_`` (e.g. ``fem``, ``figS-mesh``).
    version : str
        Version of the plugin's algorithm; part of every run id it produces.
    params : type
        Parameter dataclass (all fields with defaults).
    run : Callable
        The plugin function, with the signature of its kind.
    summary : str
        One line for ``stickslip plugins``.
    consumes : tuple[str, ...]
        Formats read. Solvers: optional upstream files (``"mesh"``); analyses:
        exactly one, the format of the simulations it analyses.
    produces : str or None
        Format of the output (solvers and analyses).
    inputs : tuple[str, ...]
        Figures: the input categories, each ``"analysis:<name>"`` or ``"format:<name>"``.
    replay : Callable or None
        Solvers: ``replay(path)`` re-runs stored events of a file the solver wrote.
    preflight : Callable or None
        Solvers: ``preflight(params)`` raises :class:`stickslip.plugin_params.ParameterError` if this machine cannot
        make the run (e.g. a GPU backend without a GPU); called before any output is claimed or written.
    device_batch : DeviceBatching or None
        Solvers: how runs share a device in batches (None: every run is one job).
    choices : tuple[Choice, ...]
        Solvers: the parts of a run chosen by name with a parameter (an interface law, a backend).
    module : str
        Module that defined it.
    """

    kind: str
    name: str
    version: str
    params: type
    run: Callable
    summary: str
    consumes: tuple = ()
    produces: str | None = None
    inputs: tuple = ()
    replay: Callable | None = None
    preflight: Callable | None = None
    device_batch: DeviceBatching | None = None
    choices: tuple = ()
    module: str = ""


def _check_shape(plugin):
    if plugin.kind not in KINDS:
        raise PluginError(f"plugin kind must be one of {', '.join(KINDS)}, got {plugin.kind!r}")
    if not _NAME.match(plugin.name):
        raise PluginError(f"{plugin.kind} name {plugin.name!r} must match {_NAME.pattern} (it is a path component)")
    if not isinstance(plugin.version, str) or not plugin.version:
        raise PluginError(f"{plugin.kind} {plugin.name!r}: version must be a non-empty string")
    if not (isinstance(plugin.params, type) and dataclasses.is_dataclass(plugin.params)):
        raise PluginError(f"{plugin.kind} {plugin.name!r}: params must be a dataclass type")
    missing = [f.name for f in dataclasses.fields(plugin.params)
               if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    if missing:
        raise PluginError(f"{plugin.kind} {plugin.name!r}: parameters without a default: {', '.join(missing)}")
    if not callable(plugin.run):
        raise PluginError(f"{plugin.kind} {plugin.name!r}: run must be callable")
    positional, keyword = _RUN_SIGNATURES[plugin.kind]
    signature = inspect.signature(plugin.run)
    names = [p.name for p in signature.parameters.values()
             if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    keywords = [p.name for p in signature.parameters.values() if p.kind == p.KEYWORD_ONLY]
    if names != positional or any(k not in keywords for k in keyword):
        expected = ", ".join(positional + [f"*, {k}" for k in keyword])
        raise PluginError(f"{plugin.kind} {plugin.name!r}: run must have the signature ({expected}), got {signature}")
    _check_contract(plugin)


def _check_contract(plugin):
    where = f"{plugin.kind} {plugin.name!r}"
    for name in plugin.consumes + ((plugin.produces,) if plugin.produces else ()):
        try:
            formats.get_format(name)
        except formats.FormatError as error:
            raise PluginError(f"{where}: {error}") from None
    if plugin.kind in ("solver", "analysis") and not plugin.produces:
        raise PluginError(f"{where}: declare the format it produces (produces=...)")
    if plugin.kind == "analysis" and len(plugin.consumes) != 1:
        raise PluginError(f"{where}: declare the one format it consumes (consumes=(...,)), got {plugin.consumes}")
    if plugin.kind == "figure":
        if plugin.consumes or plugin.produces:
            raise PluginError(f"{where}: a figure declares inputs=(...) categories, not formats")
        for category in plugin.inputs:
            kind, _, name = category.partition(":")
            if kind not in ("analysis", "format") or not name:
                raise PluginError(f"{where}: input category {category!r}: expected 'analysis:<name>' or "
                                  "'format:<name>'")
    elif plugin.inputs:
        raise PluginError(f"{where}: only figures declare inputs=(...); solvers and analyses declare consumes")
    if plugin.replay is not None and (plugin.kind != "solver" or not callable(plugin.replay)):
        raise PluginError(f"{where}: replay must be a callable of a solver")
    if plugin.device_batch is not None:
        batching = plugin.device_batch
        if plugin.kind != "solver" or not isinstance(batching, DeviceBatching):
            raise PluginError(f"{where}: device_batch must be a DeviceBatching of a solver")
        fields = {f.name for f in dataclasses.fields(plugin.params)}
        unknown = [name for name in batching.shared if name not in fields]
        if unknown:
            raise PluginError(f"{where}: device_batch shares parameters it does not have: {', '.join(unknown)}")
    if plugin.choices:
        fields = {f.name for f in dataclasses.fields(plugin.params)}
        if plugin.kind != "solver" or not all(isinstance(choice, Choice) for choice in plugin.choices):
            raise PluginError(f"{where}: choices must be Choice objects of a solver")
        unknown = [choice.parameter for choice in plugin.choices if choice.parameter not in fields]
        if unknown:
            raise PluginError(f"{where}: choices name parameters it does not have: {', '.join(unknown)}")


def register(kind, name, version, params=None, *, summary="", consumes=(), produces=None, inputs=(), replay=None,
             preflight=None, device_batch=None, choices=()):
    """Decorator that registers a plugin function.

    Parameters
    ----------
    kind : {"solver", "analysis", "figure"}
    name : str
        Plugin name, unique within ``kind``.
    version : str
        Algorithm version.
    params : type, optional
        Parameter dataclass; None (default): the plugin has no parameters (:class:`NoParameters`).
    summary : str, optional
        One line for listings; defaults to the first line of the docstring.
    consumes, produces, inputs, replay, preflight, device_batch, choices
        The plugin's contract (see :class:`Plugin`).

    Returns
    -------
    Callable
        The decorator; it returns the function unchanged.

    Raises
    ------
    PluginError
        If the plugin is malformed or the name is taken by another function.
    """

    def decorator(function):
        doc = (inspect.getdoc(function) or "").strip().splitlines()
        plugin = Plugin(kind=kind, name=name, version=version, params=NoParameters if params is None else params,
                        run=function, summary=summary or (doc[0] if doc else ""), consumes=tuple(consumes),
                        produces=produces, inputs=tuple(inputs), replay=replay, preflight=preflight,
                        device_batch=device_batch, choices=tuple(choices), module=function.__module__)
        _check_shape(plugin)
        existing = _plugins[kind].get(name)
        if existing is not None and (existing.module, existing.run.__qualname__) != (
                plugin.module, function.__qualname__):
            raise PluginError(f"{kind} {name!r} is already registered by {existing.module}")
        _plugins[kind][name] = plugin
        return function

    return decorator


def _load():
    global _loaded
    if _loaded:
        return
    _loaded = True
    for name in BUILTIN_PACKAGES:
        import_modules(name)
    for group in ENTRY_POINT_GROUPS.values():
        load_entry_points(group)


def available(kind):
    """Return the registered plugins of one kind.

    Parameters
    ----------
    kind : {"solver", "analysis", "figure"}

    Returns
    -------
    dict[str, Plugin]
        By name, sorted.
    """
    if kind not in KINDS:
        raise PluginError(f"plugin kind must be one of {', '.join(KINDS)}, got {kind!r}")
    _load()
    return dict(sorted(_plugins[kind].items()))


def get(kind, name, module=None):
    """Return one plugin by kind and name.

    Parameters
    ----------
    kind : {"solver", "analysis", "figure"}
    name : str
    module : str, optional
        The module that registers the plugin (its :attr:`Plugin.module`, which the
        workflow passes to each job): imported alone, so that a job does not import
        every plugin (and their libraries: matplotlib, scipy, ...). Without it, or if it
        does not register ``name``, every plugin is loaded. Name clashes between plugins
        are found by the full load, which the workflow makes before any job.

    Raises
    ------
    PluginError
        If there is none; the message lists the names that exist.
    """
    if module is not None and kind in KINDS and name not in _plugins[kind]:
        importlib.import_module(module)
    if module is not None and name in _plugins.get(kind, {}) and _plugins[kind][name].module == module:
        return _plugins[kind][name]
    plugins = available(kind)
    if name not in plugins:
        raise PluginError(f"unknown {kind} {name!r}; available: {', '.join(plugins) or '(none)'}")
    return plugins[name]


def replay(solver, path):
    """The event replay of a file that the solver ``solver`` wrote (its ``replay`` capability).

    Parameters
    ----------
    solver : str
        The solver plugin that wrote the file (from the file's lineage or header).
    path : str or os.PathLike

    Returns
    -------
    object
        ``solver.replay(path)``: its ``failures(increment)`` re-runs one stored event.

    Raises
    ------
    PluginError
        If there is no such solver.
    stickslip.h5io.FileFormatError
        If the solver cannot replay events; the message names the file.
    """
    plugin = get("solver", solver)
    if plugin.replay is None:
        raise FileFormatError(f"{path}: solver {plugin.name!r} that wrote it cannot replay events")
    return plugin.replay(path)


def run_id(plugin, params):
    """Return the id of a run: a hash of plugin identity and defaults-filled parameters.

    Parameters
    ----------
    plugin : Plugin
    params : object
        An instance of ``plugin.params``.

    Returns
    -------
    str
        16 hexadecimal characters; equal inputs give equal ids.
    """
    return short_hash({"kind": plugin.kind, "name": plugin.name, "version": plugin.version,
                       "params": params_to_dict(params)})


def derived_run_id(plugin, params, input_run_ids):
    """Return the id of an analysis or figure run: its plugin, parameters and the run ids it reads.

    The inputs enter through their lineage (run ids), not their bytes, so the study knows
    every id before any job runs.

    Parameters
    ----------
    plugin : Plugin
    params : object
        An instance of ``plugin.params``.
    input_run_ids : Iterable[str]
        Run ids of the files it reads (order does not matter).

    Returns
    -------
    str
        16 hexadecimal characters.
    """
    return short_hash({"run": run_id(plugin, params), "inputs": sorted(input_run_ids)})


def config_key(key):
    """Split a config key of an analysis or figure into the plugin name and its label.

    ``name@label`` names one more parameterisation of the plugin ``name``: its outputs
    go under ``name@label`` (``events/front-dynamics@all/...``, ``figures/figS-tau@all.pdf``),
    so one study can hold several. A plain ``name`` has no label.

    Parameters
    ----------
    key : str

    Returns
    -------
    tuple[str, str]
        ``(name, label)``; ``label`` is ``""`` for a plain name.

    Raises
    ------
    PluginError
        If the label is empty or not letters, digits, ``-`` and ``_``.
    """
    name, at, label = key.partition("@")
    if at and not _LABEL.match(label):
        raise PluginError(f"{key!r}: the label after '@' must match {_LABEL.pattern}")
    return name, label
