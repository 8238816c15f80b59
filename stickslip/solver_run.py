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
import warnings

import numpy as np

from . import registry
from .errors import SolverError
from .numba_options import set_num_threads
from .output_safety.atomic import check_output
from .output_safety.overwrite import OVERWRITE_HINT, claimed_output
from .plugin_params import ParameterError, ParameterWarning, params_to_dict, parse_params
from .provenance.code import plugin_code_hash
from .provenance.record import record_path, recording

__all__ = ["run_identity", "run_solver", "invalid_params"]


def run_identity(plugin, params):
    """What a solver's output file stores about its run (root attributes): format, solver, version, parameters."""
    return {"format": plugin.produces, "solver": plugin.name, "solver_version": plugin.version,
            "params": params_to_dict(params)}


def invalid_params(plugin, stored):
    """Why a file of ``plugin``'s run holds parameters that no run of it has (a damaged file), or None.

    Parameters
    ----------
    plugin : registry.Plugin
    stored : Mapping[str, object]
        The file's root attributes (``solver``, ``solver_version``, ``params`` decoded).

    Returns
    -------
    str or None
        None also for a file of another solver or version (another run, not damage).
    """
    if (stored.get("solver"), stored.get("solver_version")) != (plugin.name, plugin.version):
        return None
    if not isinstance(stored.get("params"), dict):
        return f"its attribute 'params' is not a JSON object of parameters ({str(stored.get('params'))[:80]!r})"
    try:
        with warnings.catch_warnings():  # a valid run's warning is not the damage
            warnings.simplefilter("ignore", ParameterWarning)
            parse_params(plugin.params, stored["params"], owner=f"solver '{plugin.name}'")
    except ParameterError as error:
        return f"its stored parameters are not valid ({error})"
    return None


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
        GPU backend without a GPU, a run that needs more memory than the machine has), before any file is touched
        (an output that cannot be written is said first).
    stickslip.output_safety.errors.OutputError
        If ``output`` cannot be written, or holds another run and ``overwrite`` is false.
    stickslip.errors.SolverError
        If the solver cannot make the run (naming ``output`` and the solver; what a ``fem`` run stored is kept).
    """
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral) or threads < 1:
        raise ParameterError(f"parameter 'threads': expected an integer >= 1, got {threads!r}")
    if not isinstance(overwrite, (bool, np.bool_)):
        raise ParameterError(f"parameter 'overwrite': expected True or False, got {overwrite!r}")
    plugin = registry.get("solver", solver)
    params = parse_params(plugin.params, values, owner=f"solver '{plugin.name}'")
    check_output(output)
    if plugin.preflight is not None:
        plugin.preflight(params)
    used = set_num_threads(threads)
    record = record_path(output)
    with claimed_output(output, run_identity(plugin, params), overwrite=overwrite, hint=overwrite_hint,
                        damage=lambda stored: invalid_params(plugin, stored)):
        record.unlink(missing_ok=True)  # an earlier call's: the record is written again when this one succeeds
        with recording(record, [("output", output, plugin.produces)], run_id=registry.run_id(plugin, params),
                       kind="solver", plugin=plugin.name, plugin_version=plugin.version,
                       code_hash=plugin_code_hash(plugin, params), params=params_to_dict(params), threads=used):
            try:
                plugin.run(params, output, threads=used, inputs={})
            except SolverError as error:
                raise SolverError(f"{output}: solver '{plugin.name}' cannot make this run: {error}") from None
    return plugin, params
