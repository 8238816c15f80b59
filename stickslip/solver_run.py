"""One solver run under the command line's rules: ``stickslip simulate`` and :func:`stickslip.simulate`.

The parameters are validated with the plugin's dataclass (the message names the parameter and what
was expected), the output is checked writable before any work, and an existing output is claimed
by the one rule of every command that writes a file (:func:`stickslip.output_safety.overwrite.claimed_output`):
the same run is resumed (``fem``) or written again, another run is refused unless ``overwrite``.
A run that succeeds gets its provenance record beside it (``<stem>.provenance.json``,
:mod:`stickslip.provenance.record`: run id, plugin, code hash, commit, parameters, host, times, the output's
sha256), as a workflow job's: the run object's ``run_id`` and ``provenance``, and what
:meth:`stickslip.study_results.StudyResults.add` puts into a study.
"""

import numbers

import numpy as np

from . import registry
from .numba_options import set_num_threads
from .output_safety.atomic import check_output
from .output_safety.overwrite import OVERWRITE_HINT, claimed_output
from .plugin_params import ParameterError, params_to_dict, parse_params
from .provenance.code import code_hash
from .provenance.record import record_path, recording

__all__ = ["run_identity", "run_solver"]


def run_identity(plugin, params):
    """What a solver's output file stores about its run (root attributes): format, solver, version, parameters."""
    return {"format": plugin.produces, "solver": plugin.name, "solver_version": plugin.version,
            "params": params_to_dict(params)}


def run_solver(solver, output, values, *, threads=1, overwrite=False, overwrite_hint=OVERWRITE_HINT):
    """Validate the parameters and the output, then run one solver into ``output``.

    Parameters
    ----------
    solver : str
        Solver plugin name (``stickslip plugins``).
    output : str or pathlib.Path
        The output file (HDF5): written, or resumed if it holds this run unfinished (``fem``).
    values : Mapping[str, object]
        Parameters by name, as values or as the command line's strings; the others keep their defaults.
    threads : int, optional
        Threads of the parallel kernels (>= 1; at most what numba was started with).
    overwrite : bool, optional
        Replace an output that holds another run (kept aside until the new one is complete).
    overwrite_hint : str, optional
        The end of the message that refuses another run's output: how to overwrite it (the command
        line's ``--overwrite`` by default).

    Returns
    -------
    registry.Plugin, object
        The solver and its validated parameters. The output's provenance record is written beside it
        (:func:`stickslip.provenance.record.record_path`; the times, wall time and memory are this call's: a
        resumed run's, or nothing but the check of a completed one).

    Raises
    ------
    stickslip.registry.PluginError
        If there is no such solver.
    stickslip.plugin_params.ParameterError
        For an unknown parameter or a bad value (a ``ValueError`` naming the parameter; ``threads`` and
        ``overwrite`` of another type too), or parameters this machine cannot run (the solver's ``preflight``: a
        GPU backend without a GPU), before any file is touched.
    stickslip.output_safety.errors.OutputError
        If ``output`` cannot be written, or holds another run and ``overwrite`` is false.
    """
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral) or threads < 1:
        raise ParameterError(f"parameter 'threads': expected an integer >= 1, got {threads!r}")
    if not isinstance(overwrite, (bool, np.bool_)):
        raise ParameterError(f"parameter 'overwrite': expected True or False, got {overwrite!r}")
    plugin = registry.get("solver", solver)
    params = parse_params(plugin.params, values, owner=f"solver '{plugin.name}'")
    if plugin.preflight is not None:
        plugin.preflight(params)
    used = set_num_threads(threads)
    check_output(output)
    record = record_path(output)
    with claimed_output(output, run_identity(plugin, params), overwrite=overwrite, hint=overwrite_hint):
        record.unlink(missing_ok=True)  # an earlier call's: the record is written again when this one succeeds
        with recording(record, [("output", output, plugin.produces)], run_id=registry.run_id(plugin, params),
                       kind="solver", plugin=plugin.name, plugin_version=plugin.version,
                       code_hash=code_hash(plugin.module), params=params_to_dict(params), threads=used):
            plugin.run(params, output, threads=used, inputs={})
    return plugin, params
