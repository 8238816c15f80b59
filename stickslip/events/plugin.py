"""The ``numerical-events`` analysis plugin: one ``fem-run`` file in, an ``event-table`` file out.

Output file (format ``event-table``, header of :mod:`stickslip.formats.analysis_file`;
tables as in :func:`stickslip.h5io.write_table`):

``slip_events``
    the normalised slip table that the database ingests (:mod:`stickslip.formats.event_table`):
    ``event`` (index of the steady-state slip event), ``interface``, ``multi``, ``dmu_sig0``, ``increment``;
``increments``
    every stored increment, classified (:func:`~stickslip.events.extraction.classify_increments`);
``slips``
    one row per steady-state slip event (:func:`~stickslip.events.extraction.steady_slips`);
``slip_interfaces``
    one row per (slip event, slipping interface) (:func:`~stickslip.events.extraction.slip_interfaces`);
``sequences``
    runs of consecutive single- or multi-slip events (:func:`~stickslip.events.extraction.slip_sequences`);
``periodicity``
    one row: the run's periodicity and synchronisation measures (:mod:`stickslip.events.periodicity`).

Root attributes: every attribute of the run (N, plates, n_interfaces, k_drive, seed, ...),
with the run's ``phi`` (the rigidity ratio Phi) and ``regime`` ("stiff" or "compliant") as the run file
states them, ``steady_state`` (first steady-state increment,
-1 if not reached) and the analysis header.
"""

import dataclasses

import numpy as np
import pandas as pd

from ..formats.analysis_file import write_analysis_file
from ..formats.event_table import slip_events_table
from ..formats.fem_run import read_increments, read_run_attrs
from ..h5io import FileFormatError
from ..registry import register
from . import extraction, periodicity

__all__ = ["EventParams", "NAME", "VERSION", "event_tables", "numerical_slip_events", "event_attrs", "write_event_file", "run"]

NAME = "numerical-events"
VERSION = "3"  # 2: the table "periodicity"; 3: the package's vocabulary (interface, multi, dmu_sig0, n_slips, ...)


@dataclasses.dataclass(frozen=True)
class EventParams:
    """The event extraction has no parameter: its definitions are the paper's."""


def event_tables(increments, N, *, source="increment table"):
    """Return the event tables of one run.

    Parameters
    ----------
    increments : pandas.DataFrame
        The solver's increment table (see :func:`stickslip.formats.fem_run.read_increments`).
    N : int
        Blocks per interface.
    source : str, optional
        Origin of the table, for error messages.

    Returns
    -------
    dict[str, pandas.DataFrame]
        ``increments``, ``slips``, ``slip_interfaces``, ``sequences``, ``slip_events``,
        ``periodicity`` (:func:`stickslip.events.periodicity.periodicity_table`).
    """
    classified = extraction.classify_increments(increments, N, source=source)
    slips = extraction.steady_slips(classified, N)
    per_interface = extraction.slip_interfaces(classified, N)
    return {
        "increments": classified,
        "slips": slips,
        "slip_interfaces": per_interface,
        "sequences": extraction.slip_sequences(slips),
        "slip_events": numerical_slip_events(per_interface),
        periodicity.TABLE: periodicity.periodicity_table(slips, len(extraction.interfaces_in(classified))),
    }


def numerical_slip_events(per_interface):
    """The normalised slip table (format ``event-table``) of a run's ``slip_interfaces`` table.

    Parameters
    ----------
    per_interface : pandas.DataFrame
        Output of :func:`~stickslip.events.extraction.slip_interfaces`.

    Returns
    -------
    pandas.DataFrame
        ``event`` (steady-state slip events numbered from 0 in increment order), ``interface``,
        ``multi``, ``dmu_sig0`` [sig0], ``increment``, then ``dgamma`` [gamma0].
    """
    increment = per_interface["increment"].to_numpy()
    return slip_events_table(pd.DataFrame({
        "event": np.unique(increment, return_inverse=True)[1].reshape(-1), "interface": per_interface["interface"],
        "multi": per_interface["multi"], "dmu_sig0": per_interface["dmu_sig0"], "increment": increment,
        "dgamma": per_interface["dgamma"]}))


def event_attrs(run_attrs, classified, *, source="run"):
    """Return the attributes of an event file: the run's (with its ``phi`` and ``regime``), plus the steady state.

    Parameters
    ----------
    run_attrs : Mapping[str, object]
        Attributes of the run (see :func:`stickslip.formats.fem_run.read_run_attrs`); must
        hold ``N``, ``plates``, ``phi`` and ``regime``.
    classified : pandas.DataFrame
        Output of :func:`~stickslip.events.extraction.classify_increments`.
    source : str, optional
        Origin of the attributes, for error messages.

    Returns
    -------
    dict[str, object]
    """
    missing = [key for key in ("N", "plates", "phi", "regime") if key not in run_attrs]
    if missing:
        raise FileFormatError(f"{source}: run attributes lack {', '.join(missing)}")
    attrs = dict(run_attrs)
    attrs["n_interfaces"] = int(run_attrs["plates"]) - 1
    steady = classified["increment"][classified["steady"]]
    attrs["steady_state"] = int(steady.iloc[0]) if steady.size else -1
    return attrs


def write_event_file(tables, attrs, output, *, input, params=EventParams()):
    """Write the event tables and attributes to ``output`` (atomically, format ``event-table``).

    Parameters
    ----------
    tables : Mapping[str, pandas.DataFrame]
        Output of :func:`event_tables`.
    attrs : Mapping[str, object]
        Output of :func:`event_attrs`.
    output : str or pathlib.Path
    input : str or os.PathLike
        The analysed run file (its checksum goes into the header).
    params : EventParams, optional
    """
    write_analysis_file(output, "event-table", analysis=NAME, version=VERSION, params=params, input=input,
                        attrs=attrs, tables=tables)


@register("analysis", NAME, VERSION, EventParams, consumes=("fem-run",), produces="event-table")
def run(params, input, output):
    """Slip and microscopic events of a quasistatic fem run (steady state, rho(s), sequences)."""
    run_attrs = read_run_attrs(input)
    tables = event_tables(read_increments(input), int(run_attrs["N"]), source=str(input))
    write_event_file(tables, event_attrs(run_attrs, tables["increments"], source=str(input)), output, input=input,
                     params=params)
