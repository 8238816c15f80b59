"""The public API of the package, for notebooks and scripts (docs/tutorial.md).

Functions, each a thin layer over what the command line and the workflow run, so that a call
here gives what the command gives:

- :func:`simulate`: ``stickslip simulate`` (same validation and messages, resume, overwrite rule);
- :func:`open_run`: a simulation file's header, tables and states (the format's reader, the
  analysis the workflow runs on it, the solver's event replay);
- :func:`study`: a study's results tree, config and database (``stickslip db``);
- :func:`plugins` and :func:`params`: ``stickslip plugins [--params]`` as tables.

Everything else in the package stays importable, but is not the public surface.
"""

import dataclasses

import pandas as pd

from . import formats, registry
from .plugin_params import ParameterError, describe
from .runs import open_run
from .vocabulary import with_units

__all__ = ["simulate", "open_run", "study", "plugins", "params"]

#: What :func:`simulate` says about an output that holds another run.
OVERWRITE_HINT = "pass overwrite=True to replace it, or choose another output"

#: What :func:`plugins` lists: the plugin kinds and the artifact formats.
LISTED = (*registry.KINDS, "format")


def simulate(solver, output, *, threads=1, overwrite=False, **params):
    """Run one solver into ``output`` and open the run, as ``stickslip simulate`` does.

    Progress shows as a live bar on a terminal and in a notebook, as one line every 10 s
    elsewhere (:mod:`stickslip.progress`).

    Parameters
    ----------
    solver : str
        Solver plugin name: ``fem``, ``lever``, ``rate-state-lever``, ... (:func:`plugins`).
    output : str or os.PathLike
        The output file (HDF5). If it holds this run unfinished, the run is resumed (``fem``); if it
        holds this run finished, it is left as it is (``fem``) or written again; if it holds another
        run (another solver, version or parameters), it is refused unless ``overwrite``.
    threads : int, optional
        Threads of the parallel kernels (>= 1).
    overwrite : bool, optional
        Replace an output that holds another run (kept aside until the new one is complete).
    **params
        The solver's parameters (:func:`params`); the others keep their defaults.

    Returns
    -------
    stickslip.runs.FemRun or stickslip.runs.TimeseriesRun
        The run, opened for reading (:func:`open_run`).

    Raises
    ------
    stickslip.plugin_params.ParameterError
        A ``ValueError`` naming a bad parameter and what was expected (the command line's message).
    stickslip.registry.PluginError
        If there is no such solver.
    stickslip.output_safety.errors.OutputError
        An ``OSError``: the output cannot be written, or holds another run and ``overwrite`` is false.
    """
    # Imported here: stickslip.solver_run imports numba, and numba imported with the package would fix its
    # thread pool and cache directory before a workflow job sets them (workflow_api.prepare_environment;
    # every job imports this package first).
    from .solver_run import run_solver

    run_solver(solver, output, params, threads=threads, overwrite=overwrite, overwrite_hint=OVERWRITE_HINT)
    return open_run(output)


def study(name_or_path="default", *, workdir=None):
    """Open a study's results: its database, its results tree and its config.

    Parameters
    ----------
    name_or_path : str or os.PathLike, optional
        A study name (``"default"``, ``"ci"``, ...: ``results/{name}`` in the workflow directory, as
        ``snakemake`` writes it when run there), a config file (``workflow/config/ci.yaml``), or a
        results tree (``results/ci``, an absolute path).
    workdir : str or os.PathLike, optional
        The workflow directory (where Snakemake ran). Default: ``$STICKSLIP_WORKDIR``, else the nearest
        folder at or above the current one with a ``Snakefile``, so that a notebook in a subfolder of the
        repository finds its studies (:mod:`stickslip.workdir`).

    Returns
    -------
    stickslip.study_results.StudyResults
        ``runs(...)``, ``events(...)`` with keyword filters on every parameter (``plates=3, k_drive=...,
        regime="stiff"``), ``figures()``, ``sql(...)`` (typed pandas DataFrames with ``attrs["units"]``, from
        read-only connections, :mod:`stickslip.provenance.query`), ``open_run(run_id)``, ``open_runs(frame)``,
        ``find(**filters)`` (the simulations opened one at a time), ``root``, ``database``, ``config``.

    Raises
    ------
    stickslip.errors.StudyNotFoundError
        A ``FileNotFoundError`` (and a ``FileFormatError``): the study has neither results nor a config
        there; the message says where it looked.
    """
    # Imported here: the database layer (SQLAlchemy and the schema) takes 0.24 s to import, which every command
    # and workflow job would pay, since each imports this package (python -X importtime, 2026-11-26).
    from .study_results import StudyResults

    return StudyResults(name_or_path, workdir=workdir)


def plugins(kind=None):
    """The registered plugins (or the formats) as a table: what ``stickslip plugins`` prints.

    Parameters
    ----------
    kind : {None, "solver", "analysis", "figure", "format"}, optional
        Only this kind; ``"format"``: the artifact formats instead of the plugins.

    Returns
    -------
    pandas.DataFrame
        Plugins: one row each, columns ``kind``, ``name``, ``version``, ``summary``, ``consumes``,
        ``produces``, ``inputs`` (a figure's input categories), ``replay`` (a solver that replays
        events), ``module``. Formats: ``name``, ``version`` (text, as a plugin's), ``module``, ``summary``,
        ``source``, ``describe``, ``unstamped`` (:class:`stickslip.formats.Format`). ``attrs["units"]``.

    Raises
    ------
    stickslip.plugin_params.ParameterError
        A ``ValueError`` for another ``kind``.
    """
    if kind is not None and kind not in LISTED:
        raise ParameterError(f"parameter 'kind': {kind!r} is not allowed; expected one of "
                             f"{', '.join(map(repr, LISTED))}")
    if kind == "format":
        registry.available("solver")  # loads every plugin, and with them the formats they register
        table = pd.DataFrame([dataclasses.asdict(fmt) for fmt in formats.available_formats().values()])
        return with_units(table.astype({"version": str, "unstamped": "Int64"}))
    rows = [{"kind": plugin.kind, "name": plugin.name, "version": plugin.version, "summary": plugin.summary,
             "consumes": plugin.consumes, "produces": plugin.produces, "inputs": plugin.inputs,
             "replay": plugin.replay is not None, "module": plugin.module}
            for each in (registry.KINDS if kind is None else (kind,))
            for plugin in registry.available(each).values()]
    return with_units(pd.DataFrame(rows, columns=["kind", "name", "version", "summary", "consumes", "produces",
                                                  "inputs", "replay", "module"]))


def params(name, kind="solver"):
    """One plugin's parameters as a table: what ``stickslip plugins --params`` prints for it.

    Parameters
    ----------
    name : str
        The plugin (a solver: ``"fem"``; with ``kind``, an analysis or a figure).
    kind : {"solver", "analysis", "figure"}, optional

    Returns
    -------
    pandas.DataFrame
        Indexed by parameter name, in declaration order: ``type``, ``default``, ``unit`` and ``doc``
        (:func:`stickslip.plugin_params.describe`); ``attrs["units"]`` (of these columns: none; the parameters' own
        units are the column ``unit``).

    Raises
    ------
    stickslip.registry.PluginError
        If there is no such plugin; the message lists those that exist.
    """
    rows = describe(registry.get(kind, name).params)
    # dtype object: every default stays the value it is (an int among floats is not made a float)
    table = pd.DataFrame(rows, columns=["name", "type", "default", "unit", "doc"], dtype=object).set_index("name")
    return with_units(table.astype({"type": str, "unit": str, "doc": str}))
