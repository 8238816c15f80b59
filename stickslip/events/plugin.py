"""The ``numerical-events`` analysis plugin: one ``fem`` run in, its event tables out.

Output file (HDF5, tables as in :func:`stickslip.h5io.write_table`):

``increments``
    every stored increment, classified (:func:`~stickslip.events.extraction.classify_increments`);
``slips``
    one row per steady-state slip event (:func:`~stickslip.events.extraction.slip_events`);
``slip_interfaces``
    one row per (slip event, slipping interface) (:func:`~stickslip.events.extraction.slip_interfaces`);
``sequences``
    runs of consecutive single- or multi-slip events (:func:`~stickslip.events.extraction.slip_sequences`).

Root attributes: every attribute of the run (N, plates, n_interfaces, k_drive, seed, ...),
plus ``phi`` (the rigidity ratio Phi, :func:`~stickslip.fem.stiffness.stiffness_ratio`),
``regime`` ("stiff" or "compliant", from ``phi``), ``steady_state`` (first steady-state increment,
-1 if not reached), ``analysis`` and ``analysis_version``.
"""

import dataclasses
import json

from .. import h5io
from ..fem.stiffness import driving_regime, stiffness_ratio
from ..h5io import FileFormatError
from ..registry import register
from . import extraction

__all__ = ["EventParams", "VERSION", "event_tables", "event_attrs", "write_event_file", "run"]

VERSION = "1"


@dataclasses.dataclass(frozen=True)
class EventParams:
    """The event extraction has no parameter: its definitions are the paper's."""


def event_tables(increments, N, *, source="increment table"):
    """Return the four event tables of one run.

    Parameters
    ----------
    increments : pandas.DataFrame
        The solver's increment table (see :func:`stickslip.fem.output.read_increments`).
    N : int
        Blocks per interface.
    source : str, optional
        Origin of the table, for error messages.

    Returns
    -------
    dict[str, pandas.DataFrame]
        ``increments``, ``slips``, ``slip_interfaces``, ``sequences``.
    """
    classified = extraction.classify_increments(increments, N, source=source)
    slips = extraction.slip_events(classified, N)
    return {
        "increments": classified,
        "slips": slips,
        "slip_interfaces": extraction.slip_interfaces(classified, N),
        "sequences": extraction.slip_sequences(slips),
    }


def event_attrs(run_attrs, classified, *, source="run"):
    """Return the attributes of an event file: the run's, plus regime and steady state.

    Parameters
    ----------
    run_attrs : Mapping[str, object]
        Attributes of the run (see :func:`stickslip.fem.output.read_run_attrs`); must
        hold ``N``, ``plates`` and ``k_drive``.
    classified : pandas.DataFrame
        Output of :func:`~stickslip.events.extraction.classify_increments`.
    source : str, optional
        Origin of the attributes, for error messages.

    Returns
    -------
    dict[str, object]
    """
    missing = [key for key in ("N", "plates", "k_drive") if key not in run_attrs]
    if missing:
        raise FileFormatError(f"{source}: run attributes lack {', '.join(missing)}")
    attrs = dict(run_attrs)
    attrs["n_interfaces"] = int(run_attrs["plates"]) - 1
    params = run_attrs.get("params", {})
    G = (json.loads(params) if isinstance(params, str) else params).get("G", 1.0)
    attrs["phi"] = stiffness_ratio(run_attrs["k_drive"], run_attrs["N"], G)
    attrs["regime"] = driving_regime(attrs["phi"])
    steady = classified["increment"][classified["steady"]]
    attrs["steady_state"] = int(steady.iloc[0]) if steady.size else -1
    return attrs


def write_event_file(tables, attrs, output):
    """Write the event tables and attributes to ``output`` (atomically).

    Parameters
    ----------
    tables : Mapping[str, pandas.DataFrame]
        Output of :func:`event_tables`.
    attrs : Mapping[str, object]
        Output of :func:`event_attrs`.
    output : str or pathlib.Path
    """
    with h5io.atomic_output(output) as tmp, h5io.open_file(tmp, "w") as file:
        h5io.write_attrs(file, {**attrs, "analysis": "numerical-events", "analysis_version": VERSION})
        for name, table in tables.items():
            h5io.write_table(file, name, table)


@register("analysis", "numerical-events", VERSION, EventParams, inputs=("fem",))
def run(params, input, output):
    """Slip and microscopic events of a quasistatic fem run (steady state, rho(s), sequences)."""
    from ..fem.output import read_increments, read_run_attrs  # the solver loads numba kernels

    run_attrs = read_run_attrs(input)
    if "N" not in run_attrs:
        raise FileFormatError(f"{input}: run attributes lack N")
    tables = event_tables(read_increments(input), int(run_attrs["N"]), source=str(input))
    write_event_file(tables, event_attrs(run_attrs, tables["increments"], source=str(input)), output)
