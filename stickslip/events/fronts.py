"""Time-resolved multi-slip events: rupture-front velocity and the delay between interfaces.

A stored kick increment of a ``fem-run`` file is replayed by the solver that wrote it (its
``replay`` capability, :mod:`stickslip.fem.replay` for ``fem``) while every block failure is recorded
(interface ``a``, ``block``, time ``t`` since the kick, ``direction``), as the paper does
for its event maps (appendix "Front dynamics -- numerics"). From the failures of one event:

- the *slipping* interfaces are those on which every block fails at least once (the
  paper's definition), ordered by their first failure;
- the front velocity ``c_f`` of the first slipping interface: the first failure time of
  each block against its periodic distance from the nucleation block (the first block to
  fail) is a straight line in the ballistic part of the rupture; ``c_f`` is the inverse slope
  of a least-squares fit over distances ``fit_from ... fit_to`` times half the interface
  length, in units of the shear-wave speed c_s;
- the delay ``tau`` between the first failure on the first and on the second slipping
  interface, in units of H/c_s with H the distance between the mid-lines of two adjacent
  interfaces (one plate plus one block layer).

The ``front-dynamics`` analysis plugin applies this to the first ``max_events``
steady-state multi-slip increments of a run (or every slip event, ``events = "slip"``).
"""

import dataclasses

import numpy as np
import pandas as pd

from .. import h5io, registry
from ..formats.analysis_file import write_analysis_file
from ..formats.fem_run import RunFile, read_increments, read_run_attrs
from ..formats.front_table import FAILURE_DTYPES, FORMAT, FRONT_DTYPES
from ..h5io import FileFormatError
from ..lineage import Artifact
from ..mesh import interface_layer
from ..params import ParameterError, param
from ..progress import iterate
from ..registry import register
from . import extraction
from .plugin import event_attrs

__all__ = ["FrontParams", "VERSION", "slipping_interfaces", "front_fit", "analyse_event", "multi_slip_increments",
           "interface_spacing", "front_tables", "write_front_file", "solver_replay", "run"]

NAME = "front-dynamics"
VERSION = "1"

#: Columns of a replay's failure table (:meth:`stickslip.fem.replay.EventReplay.failures`).
FAILURE_COLUMNS = ("a", "block", "t", "direction")


def _check_failures(failures, source):
    missing = [c for c in FAILURE_COLUMNS if c not in failures.columns]
    if missing:
        raise FileFormatError(f"{source}: failure table lacks column(s) {', '.join(missing)}")


def _first_failures(failures, a):
    """First failure time of every block of interface ``a`` (Series indexed by block, sorted)."""
    sub = failures[failures["a"].to_numpy() == a]
    return sub.groupby("block", sort=True)["t"].min()


def slipping_interfaces(failures, N):
    """Interfaces on which every block failed at least once, ordered by their first failure.

    Parameters
    ----------
    failures : pandas.DataFrame
        Columns ``a``, ``block`` (0 ... N-1), ``t`` [FE time], ``direction``.
    N : int
        Blocks per interface.

    Returns
    -------
    list[tuple[int, float]]
        (interface, time of its first failure), earliest first (ties: lower interface first).
    """
    found = []
    for a, sub in failures.groupby("a", sort=True):
        if sub["block"].nunique() == N:
            found.append((int(a), float(sub["t"].min())))
    return sorted(found, key=lambda item: (item[1], item[0]))


def front_fit(failures, a, N, *, fit_from=0.3, fit_to=0.9):
    """Fit the ballistic rupture front on interface ``a``.

    Parameters
    ----------
    failures : pandas.DataFrame
        Columns ``a``, ``block``, ``t`` [FE time].
    a : int
        Interface.
    N : int
        Blocks per interface (periodic: the largest distance is N/2 blocks).
    fit_from, fit_to : float
        Fitted distances from the nucleation block, as fractions of N/2.

    Returns
    -------
    dict[str, float]
        ``nucleation`` (block of the first failure; lowest index on ties), ``speed``
        (front speed [blocks per FE time unit]; NaN with fewer than 3 fitted blocks),
        ``t0`` (time at which the fitted front leaves the nucleation block [FE time]) and
        ``points`` (number of fitted blocks).
    """
    first = _first_failures(failures, a)
    blocks = first.index.to_numpy(dtype=np.int64)
    times = first.to_numpy(dtype=float)
    nucleation = int(blocks[np.argmin(times)])
    offset = np.abs(blocks - nucleation)
    distance = np.minimum(offset, N - offset).astype(float)
    fitted = (distance >= fit_from * N / 2) & (distance <= fit_to * N / 2)
    result = {"nucleation": nucleation, "speed": np.nan, "t0": np.nan, "points": int(fitted.sum())}
    if fitted.sum() >= 3 and np.ptp(distance[fitted]) > 0:
        slope, intercept = np.polyfit(distance[fitted], times[fitted], 1)
        if slope > 0:
            result.update(speed=1.0 / slope, t0=intercept)
    return result


def analyse_event(failures, N, *, h, c_s, spacing, fit_from=0.3, fit_to=0.9):
    """Front velocity and inter-interface delay of one re-run event.

    Parameters
    ----------
    failures : pandas.DataFrame
        Columns ``a``, ``block``, ``t`` [FE time], ``direction``.
    N : int
        Blocks per interface.
    h : float
        Block size l0 [FE length].
    c_s : float
        Shear-wave speed [FE length / FE time].
    spacing : float
        Distance H between the mid-lines of adjacent interfaces [FE length].
    fit_from, fit_to : float
        See :func:`front_fit`.

    Returns
    -------
    dict[str, float]
        ``s`` (number of slipping interfaces), ``a_first``, ``a_second`` (0 if fewer than
        two slip), ``nucleation`` (block), ``c_f`` (front speed of the first slipping
        interface [c_s]), ``fit_t0`` [FE time], ``fit_points``, ``t_first`` (first failure
        [FE time]) and ``tau`` (delay between the first failures of the first two slipping
        interfaces [H/c_s]; NaN if fewer than two slip).
    """
    _check_failures(failures, "failure table")
    order = slipping_interfaces(failures, N)
    row = {"s": len(order), "a_first": 0, "a_second": 0, "nucleation": -1, "c_f": np.nan, "fit_t0": np.nan,
           "fit_points": 0, "t_first": float(failures["t"].min()) if len(failures) else np.nan, "tau": np.nan}
    if not order:
        return row
    fit = front_fit(failures, order[0][0], N, fit_from=fit_from, fit_to=fit_to)
    row.update(a_first=order[0][0], nucleation=fit["nucleation"], c_f=fit["speed"] * h / c_s, fit_t0=fit["t0"],
               fit_points=fit["points"])
    if len(order) > 1:
        row.update(a_second=order[1][0], tau=(order[1][1] - order[0][1]) * c_s / spacing)
    return row


def multi_slip_increments(classified, max_events, kinds=("multi",)):
    """The first ``max_events`` steady-state slip increments of the given kinds.

    Parameters
    ----------
    classified : pandas.DataFrame
        Output of :func:`stickslip.events.extraction.classify_increments`.
    max_events : int
    kinds : tuple[str, ...], optional
        Event kinds: ("multi",) (default) or ("single", "multi").

    Returns
    -------
    numpy.ndarray
        Increment numbers, ascending.
    """
    chosen = classified["steady"].to_numpy(dtype=bool) & classified["kind"].isin(kinds).to_numpy()
    return classified["increment"].to_numpy()[chosen][:max_events]


def interface_spacing(interface_heights):
    """Distance H between the mid-lines of adjacent interfaces.

    Parameters
    ----------
    interface_heights : array_like
        Mid-height of every interface a = 1 ... n, shape [n] [FE length] (the run's layer
        heights at :func:`stickslip.mesh.interface_layer`).

    Returns
    -------
    float
        ``interface_heights[1] - interface_heights[0]`` [FE length]; NaN with a single interface.
    """
    heights = np.asarray(interface_heights, dtype=float)
    return float(heights[1] - heights[0]) if heights.size >= 2 else np.nan


@dataclasses.dataclass(frozen=True)
class FrontParams:
    """Parameters of the front-dynamics analysis."""

    max_events: int = param(10, "steady-state multi-slip increments re-run per fem run (the first ones)", minimum=1)
    events: str = param("multi", "which steady-state slip events are re-run: multi-slips (the paper) or every "
                                 "slip (front speed from single slips too)", choices=("multi", "slip"))
    interfaces: int = param(2, "re-run events only in runs with this many interfaces (the paper: 2; 0: every "
                               "run); the output of other runs has empty tables", minimum=0)
    fit_from: float = param(0.3, "front fit: smallest distance from the nucleation block, fraction of half the "
                                 "interface length", minimum=0.0, maximum=1.0)
    fit_to: float = param(0.9, "front fit: largest distance from the nucleation block, fraction of half the "
                               "interface length", minimum=0.0, maximum=1.0)

    def check(self):
        """The fit window must not be empty."""
        if self.fit_from >= self.fit_to:
            raise ParameterError(f"parameters 'fit_from' ({self.fit_from}) and 'fit_to' ({self.fit_to}): "
                                 "expected fit_from < fit_to")


def front_tables(classified, rerun, *, N, h, c_s, spacing, params):
    """Re-run the chosen multi-slip events and analyse each.

    Parameters
    ----------
    classified : pandas.DataFrame
        Output of :func:`stickslip.events.extraction.classify_increments`.
    rerun : Callable[[int], pandas.DataFrame]
        Returns the failures (``a``, ``block``, ``t`` [FE time], ``direction``) of one increment.
    N, h, c_s, spacing
        See :func:`analyse_event`.
    params : FrontParams
        ``max_events``, ``events`` ("multi" or "slip"), ``interfaces`` (runs with another
        number of interfaces give empty tables), ``fit_from``, ``fit_to``.

    Returns
    -------
    tuple[pandas.DataFrame, pandas.DataFrame]
        ``failures`` (columns of :data:`FAILURE_DTYPES`, ordered by increment, time,
        interface, block) and ``fronts`` (columns of :data:`FRONT_DTYPES`, one row per event).
    """
    failures, fronts = [], []
    n = len(extraction.interfaces_in(classified))
    kinds = ("multi",) if params.events == "multi" else ("single", "multi")
    chosen = multi_slip_increments(classified, params.max_events, kinds) if params.interfaces in (0, n) else []
    for increment in iterate(chosen, desc="front-dynamics events", unit="event"):
        events = rerun(int(increment))
        _check_failures(events, f"re-run of increment {increment}")
        events = events[list(FAILURE_COLUMNS)].sort_values(["t", "a", "block"], kind="stable")
        failures.append(events.assign(increment=int(increment)))
        row = analyse_event(events, N, h=h, c_s=c_s, spacing=spacing, fit_from=params.fit_from, fit_to=params.fit_to)
        fronts.append({"increment": int(increment), **row})
    failure_table = pd.concat(failures, ignore_index=True) if failures else pd.DataFrame(columns=list(FAILURE_DTYPES))
    front_table = pd.DataFrame(fronts, columns=list(FRONT_DTYPES))
    return failure_table[list(FAILURE_DTYPES)].astype(FAILURE_DTYPES), front_table.astype(FRONT_DTYPES)


def write_front_file(failures, fronts, attrs, output, *, input, params=FrontParams()):
    """Write the tables ``failures`` and ``fronts`` and the attributes to ``output`` (atomically).

    Parameters
    ----------
    failures, fronts : pandas.DataFrame
        Output of :func:`front_tables`.
    attrs : Mapping[str, object]
        Run attributes as :func:`stickslip.events.plugin.event_attrs` gives them, plus
        ``interface_spacing`` [FE length].
    output : str or pathlib.Path
    input : str or os.PathLike
        The analysed run file (its checksum goes into the header).
    params : FrontParams, optional
    """
    write_analysis_file(output, FORMAT, analysis=NAME, version=VERSION, params=params, input=input,
                        attrs=attrs, tables={"failures": failures, "fronts": fronts})


def solver_replay(input, analysis=NAME):
    """The replay of the solver that wrote ``input`` (from its lineage), for the analysis ``analysis``."""
    if not isinstance(input, Artifact):
        raise FileFormatError(f"{input}: {analysis} needs the lineage of its input (a "
                              "stickslip.lineage.Artifact naming the solver that wrote it)")
    solver = registry.get("solver", input.plugin)
    if solver.replay is None:
        raise FileFormatError(f"{input}: solver {solver.name!r} that wrote it cannot replay events")
    return solver.replay(input.path)


@register("analysis", NAME, VERSION, FrontParams, consumes=("fem-run",), produces="front-table")
def run(params, input, output):
    """Re-run multi-slip events of a fem run recording every block failure; front speed and delay."""
    replay = solver_replay(input)
    run_attrs = read_run_attrs(input)
    N = int(run_attrs["N"])
    with h5io.open_file(input) as file:
        heights = RunFile(file).mesh.layer_mid_height
    spacing = interface_spacing([heights[interface_layer(a)] for a in range(1, int(run_attrs["n_interfaces"]) + 1)])
    classified = extraction.classify_increments(read_increments(input), N, source=str(input))
    failures, fronts = front_tables(classified, replay.failures, N=N, h=float(run_attrs["h"]),
                                    c_s=float(run_attrs["c_s"]), spacing=spacing, params=params)
    attrs = {**event_attrs(run_attrs, classified, source=str(input)), "interface_spacing": spacing}
    write_front_file(failures, fronts, attrs, output, input=input, params=params)
