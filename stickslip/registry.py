"""Plugin registry: solvers, analyses and figures, chosen by name in the config.

A plugin is one function plus its identity: name (a path component of its
outputs), version (part of the run id: a new version reruns what it produced),
a parameter dataclass (see :mod:`stickslip.params`) and, for analyses and
figures, the categories of input it reads.

Built-in plugins register with a decorator in the modules listed in
:data:`BUILTIN_MODULES`; third-party packages add an entry point in the group
of the plugin's kind (:data:`ENTRY_POINT_GROUPS`) that names the module to import
(importing it runs its decorators), e.g. in their ``pyproject.toml``::

    [project.entry-points."stickslip.solvers"]
    mysolver = "mypackage.mysolver"

Call signatures by kind (checked when a plugin registers):

- ``solver``: ``run(params, output, *, threads, inputs)``: write one simulation
  file ``output`` (:class:`pathlib.Path`, HDF5) using at most ``threads``
  threads; ``inputs`` maps each declared input category (e.g. ``"mesh"``) to a
  path made by an upstream stage, and may be empty (the solver then makes what
  it needs itself).
- ``analysis``: ``run(params, input, output)``: read one solver output, write one
  HDF5 table file.
- ``figure``: ``run(params, inputs, output)``: ``inputs`` maps each declared input
  category to a list of paths; write ``output`` (PDF) and the PNG beside it.
"""

import dataclasses
import hashlib
import importlib
import inspect
import json
import re
from collections.abc import Callable
from importlib.metadata import entry_points

from .params import params_to_dict

__all__ = [
    "KINDS",
    "ENTRY_POINT_GROUPS",
    "BUILTIN_MODULES",
    "Plugin",
    "PluginError",
    "register",
    "get",
    "available",
    "run_id",
]

KINDS = ("solver", "analysis", "figure")

ENTRY_POINT_GROUPS = {"solver": "stickslip.solvers", "analysis": "stickslip.analyses", "figure": "stickslip.figures"}

#: Modules whose import registers the built-in plugins.
BUILTIN_MODULES = ("stickslip.events.plugin", "stickslip.events.fronts", "stickslip.experiment.analysis",
                   "stickslip.figures.mesh", "stickslip.solvers.lever", "stickslip.solvers.rate_state_lever", "stickslip.figures.fig2",
                   "stickslip.figures.figs_dgamma", "stickslip.figures.figs_sequences",
                   "stickslip.figures.figs_phi_sweep", "stickslip.figures.figs_event_maps", "stickslip.figures.figs_tau",
                   "stickslip.figures.fig3", "stickslip.figures.fig4", "stickslip.figures.fig5",
                   "stickslip.figures.fig6", "stickslip.figures.figs_individual",
                   "stickslip.figures.figs_slip_distributions", "stickslip.figures.figs_aging_variations",
                   "stickslip.figures.figs_slow_slip", "stickslip.solvers.fem")

_RUN_SIGNATURES = {
    "solver": (["params", "output"], ["threads", "inputs"]),
    "analysis": (["params", "input", "output"], []),
    "figure": (["params", "inputs", "output"], []),
}

_NAME = re.compile(r"^[a-z0-9][A-Za-z0-9_-]*$")

_plugins = {kind: {} for kind in KINDS}
_loaded = False


class PluginError(LookupError):
    """A plugin is malformed, registered twice, or not found."""


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
    inputs : tuple[str, ...]
        Input categories. Solvers: optional upstream files (``"mesh"``).
        Analyses: the solver names whose outputs it accepts. Figures: what it
        reads, each ``"solver:<name>"`` (all outputs of that solver in the
        study), ``"analysis:<name>"`` (all outputs of that analysis) or
        ``"mesh"`` (all mesh files).
    module : str
        Module that defined it.
    """

    kind: str
    name: str
    version: str
    params: type
    run: Callable
    summary: str
    inputs: tuple = ()
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


def register(kind, name, version, params, *, summary="", inputs=()):
    """Decorator that registers a plugin function.

    Parameters
    ----------
    kind : {"solver", "analysis", "figure"}
    name : str
        Plugin name, unique within ``kind``.
    version : str
        Algorithm version.
    params : type
        Parameter dataclass.
    summary : str, optional
        One line for listings; defaults to the first line of the docstring.
    inputs : tuple[str, ...], optional
        Input categories (see :class:`Plugin`).

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
        plugin = Plugin(kind=kind, name=name, version=version, params=params, run=function,
                        summary=summary or (doc[0] if doc else ""), inputs=tuple(inputs),
                        module=function.__module__)
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
    for module in BUILTIN_MODULES:
        importlib.import_module(module)
    for kind, group in ENTRY_POINT_GROUPS.items():
        for entry in entry_points(group=group):
            try:
                entry.load()
            except Exception as error:  # a broken third-party plugin must say so, not vanish
                raise PluginError(f"entry point {entry.name!r} in group {group!r} failed to load: {error}") from error


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


def get(kind, name):
    """Return one plugin by kind and name.

    Raises
    ------
    PluginError
        If there is none; the message lists the names that exist.
    """
    plugins = available(kind)
    if name not in plugins:
        raise PluginError(f"unknown {kind} {name!r}; available: {', '.join(plugins) or '(none)'}")
    return plugins[name]


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
    payload = {"kind": plugin.kind, "name": plugin.name, "version": plugin.version,
               "params": params_to_dict(params)}
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]
