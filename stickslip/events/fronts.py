"""Time-resolved multi-slip events: rupture-front velocity and the delay between interfaces.

A stored kick increment of a ``fem-run`` file is replayed by the solver that wrote it (its
``replay`` capability, :mod:`stickslip.fem.replay` for ``fem``) while every block failure is recorded
(interface ``a``, ``block``, time ``t`` since the kick, ``direction``), as the paper does
for its event maps (appendix "Front dynamics -- numerics"). From the failures of one event:

- the *slipping* interfaces are those on which every block fails at least once (the
  paper's definition), ordered by their first failure;
- the front velocity ``c_f`` of the first slipping interface: the front leaves the nucleation
  block (the first block to fail) in both directions, and each branch's first failure time of
  each block against its distance from the nucleation block is a straight line in the ballistic
  part of the rupture; each branch is fitted by a robust (Theil-Sen) line over distances
  ``fit_from ... fit_to`` times its length (to the block both branches reach last), and ``c_f``
  [c_s] is the mean of the inverse slopes of the branches whose fit is meaningful: at least
  ``min_points`` blocks, a positive slope, a speed below the P-wave speed (no causal front is
  faster) and a straight line (coefficient of determination >= :data:`MIN_R2`); the others are
  flagged with the reason, never averaged;
- the delay ``tau`` between the first failure on the first and on the second slipping
  interface, in units of H/c_s with H the distance between the mid-lines of two adjacent
  interfaces (one plate plus one block layer).

The ``front-dynamics`` analysis plugin applies this to the first ``max_events``
steady-state multi-slip increments of a run (or every slip event, ``events = "slip"``).
"""

import dataclasses
import json
import math

import numpy as np
import pandas as pd
from scipy import stats

from .. import h5io, registry
from ..formats.analysis_file import write_analysis_file
from ..formats.fem_run import RunFile, read_increments, read_run_attrs
from ..formats.front_table import FAILURE_DTYPES, FORMAT, FRONT_DTYPES
from ..h5io import FileFormatError
from ..lineage import Artifact
from ..mesh import interface_layer
from ..plugin_params import ParameterError, param
from ..progress import iterate
from ..registry import register
from . import extraction
from .plugin import event_attrs

__all__ = ["FrontParams", "VERSION", "BRANCHES", "MIN_R2", "slipping_interfaces", "p_wave_speed", "front_fit",
           "analyse_event", "multi_slip_increments", "interface_spacing", "front_tables", "write_front_file",
           "solver_replay", "run"]

NAME = "front-dynamics"
VERSION = "2"  # 2: the two branches fitted separately (Theil-Sen), fits flagged by quality

#: The two branches of a front: towards increasing block index, and back.
BRANCHES = ("right", "left")

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


def p_wave_speed(K, G, rho):
    """Dilatational (P) wave speed of the plane model [FE length / FE time].

    The plates' stress ``K eps_m I + G eps_d`` (``eps_m = tr(eps) / 2``) gives ``sig_xx = (K + G) / 2 eps_xx``
    in uniaxial strain, so ``c_d = sqrt((K + G) / (2 rho))``; with ``c_s = sqrt(G / (2 rho))``,
    ``c_d / c_s = sqrt(1 + K / G)`` (2.35 for the paper's K = 4.5 G). No causal rupture front is faster.
    """
    return math.sqrt((K + G) / (2.0 * rho))


def _meeting_block(blocks, times, N, window=5):
    """The block the two branches of a front reach last: the latest first failure, smoothed.

    A running median over ``window`` neighbouring blocks (periodic) keeps one late block (a block
    the front passed that failed only later) from being taken for the meeting point.
    """
    full = np.full(N, np.nan)
    full[blocks] = times
    half = window // 2
    stacked = np.stack([np.roll(full, shift) for shift in range(-half, half + 1)])
    return int(np.nanargmax(np.nanmedian(stacked, axis=0)))


#: Smallest coefficient of determination of a branch fit that counts as a ballistic front.
MIN_R2 = 0.8


def _branch(distance, times, length, *, fit_from, fit_to, min_points, c_max):
    """Theil-Sen fit ``t = t0 + d / speed`` of one branch over ``fit_from ... fit_to`` of its length; its quality."""
    fitted = (distance >= fit_from * length) & (distance <= fit_to * length)
    d, t = distance[fitted], times[fitted]
    out = {"speed": math.nan, "t0": math.nan, "points": int(fitted.sum()), "r2": math.nan, "quality": "few points"}
    if d.size < max(min_points, 3) or np.ptp(d) == 0:
        return out
    slope, intercept = stats.theilslopes(t, d)[:2]
    residual = t - (intercept + slope * d)
    spread = np.sum((t - t.mean()) ** 2)
    out.update(t0=float(intercept), r2=float(1.0 - np.sum(residual ** 2) / spread) if spread > 0 else math.nan)
    if slope <= 0:
        out["quality"] = "no front"
        return out
    out["speed"] = 1.0 / slope
    out["quality"] = "faster than P waves" if out["speed"] > c_max else (
        "not ballistic" if not out["r2"] >= MIN_R2 else "ok")
    return out


def front_fit(failures, a, N, *, fit_from=0.3, fit_to=0.9, min_points=8, c_max=np.inf):
    """Fit the two branches of the rupture front on interface ``a`` (the paper's ballistic front).

    The front leaves the nucleation block (the first to fail) in both directions and its two
    branches meet at the block reached last (:func:`_meeting_block`). Each branch is fitted
    separately, first failure time against distance from the nucleation block, by the robust
    Theil-Sen line over ``fit_from ... fit_to`` of the branch's length: the slow, fractal
    nucleation near the nucleation block and the meeting region are left out, and blocks that fail
    early by themselves (ahead of the front) do not tilt the line.

    Parameters
    ----------
    failures : pandas.DataFrame
        Columns ``a``, ``block``, ``t`` [FE time].
    a : int
        Interface.
    N : int
        Blocks per interface (periodic).
    fit_from, fit_to : float
        Fitted distances from the nucleation block, as fractions of the branch's length.
    min_points : int
        Fewer fitted blocks: quality "few points".
    c_max : float
        Largest speed of a front [blocks per FE time]: the P-wave speed; a faster fit (blocks that
        fail at once, not one after the other) has quality "faster than P waves".

    Returns
    -------
    dict
        ``nucleation`` (block), ``meeting`` (block), and per branch ``right`` (increasing block
        index) and ``left``: a dict with ``speed`` [blocks per FE time] (NaN if the slope is not
        positive or there are too few blocks), ``t0`` (time at which the fitted line leaves the
        nucleation block [FE time]), ``points``, ``r2`` (coefficient of determination of the line)
        and ``quality``: "ok", "few points", "no front" (slope not positive), "faster than P waves",
        or "not ballistic" (``r2`` below :data:`MIN_R2`).
    """
    first = _first_failures(failures, a)
    blocks = first.index.to_numpy(dtype=np.int64)
    times = first.to_numpy(dtype=float)
    nucleation = int(blocks[np.argmin(times)])
    meeting = _meeting_block(blocks, times, N)
    offset = np.mod(blocks - nucleation, N)
    right_length = int(np.mod(meeting - nucleation, N)) or N // 2
    result = {"nucleation": nucleation, "meeting": meeting}
    for side, inside, distance, length in (
            ("right", (offset > 0) & (offset <= right_length), offset, right_length),
            ("left", (offset >= right_length) | (offset == 0), np.mod(N - offset, N), N - right_length)):
        result[side] = _branch(distance[inside].astype(float), times[inside], length, fit_from=fit_from,
                               fit_to=fit_to, min_points=min_points, c_max=c_max)
    return result


def analyse_event(failures, N, *, h, c_s, spacing, c_d=np.inf, fit_from=0.3, fit_to=0.9, min_points=8):
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
    c_d : float, optional
        P-wave speed [FE length / FE time] (:func:`p_wave_speed`): faster fits are flagged.
    fit_from, fit_to, min_points
        See :func:`front_fit`.

    Returns
    -------
    dict[str, float]
        ``s`` (number of slipping interfaces), ``a_first``, ``a_second`` (0 if fewer than
        two slip), ``nucleation`` and ``meeting`` (blocks, -1 without a slipping interface), per branch
        ``c_f_right``, ``c_f_left`` (front speed [c_s], NaN if no positive slope), ``t0_right``,
        ``t0_left`` [FE time], ``points_right``, ``points_left``, ``r2_right``, ``r2_left``,
        ``quality_right``, ``quality_left`` (see :func:`front_fit`); ``c_f`` (the mean of the
        branches whose quality is "ok" [c_s]; NaN if neither is: such fits are flagged, never
        averaged), ``fit`` ("ok" if ``c_f`` is finite, else the branches' qualities), ``t_first``
        (first failure [FE time]) and ``tau`` (delay between the first failures of the first two
        slipping interfaces [H/c_s]; NaN if fewer than two slip).
    """
    _check_failures(failures, "failure table")
    order = slipping_interfaces(failures, N)
    row = {"s": len(order), "a_first": 0, "a_second": 0, "nucleation": -1, "meeting": -1, "c_f": np.nan,
           "fit": "no slipping interface", "t_first": float(failures["t"].min()) if len(failures) else np.nan,
           "tau": np.nan}
    for side in BRANCHES:
        row.update({f"c_f_{side}": np.nan, f"t0_{side}": np.nan, f"points_{side}": 0, f"r2_{side}": np.nan,
                    f"quality_{side}": ""})
    if not order:
        return row
    fit = front_fit(failures, order[0][0], N, fit_from=fit_from, fit_to=fit_to, min_points=min_points,
                    c_max=c_d / h)
    row.update(a_first=order[0][0], nucleation=fit["nucleation"], meeting=fit["meeting"])
    good = []
    for side in BRANCHES:
        branch = fit[side]
        row.update({f"c_f_{side}": branch["speed"] * h / c_s, f"t0_{side}": branch["t0"],
                    f"points_{side}": branch["points"], f"r2_{side}": branch["r2"],
                    f"quality_{side}": branch["quality"]})
        if branch["quality"] == "ok":
            good.append(branch["speed"] * h / c_s)
    row["c_f"] = float(np.mean(good)) if good else np.nan
    row["fit"] = "ok" if good else "; ".join(f"{side}: {fit[side]['quality']}" for side in BRANCHES)
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
    fit_from: float = param(0.3, "front fit: smallest distance from the nucleation block, fraction of the "
                                 "branch's length (nucleation block to meeting block)", minimum=0.0, maximum=1.0)
    fit_to: float = param(0.9, "front fit: largest distance from the nucleation block, fraction of the branch's "
                               "length", minimum=0.0, maximum=1.0)
    min_points: int = param(8, "front fit: fewer fitted blocks in a branch flag it 'few points'", minimum=3)

    def check(self):
        """The fit window must not be empty."""
        if self.fit_from >= self.fit_to:
            raise ParameterError(f"parameters 'fit_from' ({self.fit_from}) and 'fit_to' ({self.fit_to}): "
                                 "expected fit_from < fit_to")


def front_tables(classified, rerun, *, N, h, c_s, spacing, params, c_d=np.inf):
    """Re-run the chosen multi-slip events and analyse each.

    Parameters
    ----------
    classified : pandas.DataFrame
        Output of :func:`stickslip.events.extraction.classify_increments`.
    rerun : Callable[[int], pandas.DataFrame]
        Returns the failures (``a``, ``block``, ``t`` [FE time], ``direction``) of one increment.
    N, h, c_s, spacing, c_d
        See :func:`analyse_event`.
    params : FrontParams
        ``max_events``, ``events`` ("multi" or "slip"), ``interfaces`` (runs with another
        number of interfaces give empty tables), ``fit_from``, ``fit_to``, ``min_points``.

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
        row = analyse_event(events, N, h=h, c_s=c_s, spacing=spacing, c_d=c_d, fit_from=params.fit_from,
                            fit_to=params.fit_to, min_points=params.min_points)
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
    return registry.replay(input.plugin, input.path)


@register("analysis", NAME, VERSION, FrontParams, consumes=("fem-run",), produces="front-table")
def run(params, input, output):
    """Re-run multi-slip events of a fem run recording every block failure; front speed and delay."""
    replay = solver_replay(input)
    run_attrs = read_run_attrs(input)
    N = int(run_attrs["N"])
    with h5io.open_file(input) as file:
        heights = RunFile(file).mesh.layer_mid_height
    spacing = interface_spacing([heights[interface_layer(a)] for a in range(1, int(run_attrs["n_interfaces"]) + 1)])
    material = run_attrs.get("params", {})
    material = json.loads(material) if isinstance(material, str) else material
    c_d = p_wave_speed(float(material.get("K", 4.5)), float(material.get("G", 1.0)), float(material.get("rho", 1.0)))
    classified = extraction.classify_increments(read_increments(input), N, source=str(input))
    failures, fronts = front_tables(classified, replay.failures, N=N, h=float(run_attrs["h"]),
                                    c_s=float(run_attrs["c_s"]), spacing=spacing, params=params, c_d=c_d)
    attrs = {**event_attrs(run_attrs, classified, source=str(input)), "interface_spacing": spacing, "c_d": c_d}
    write_front_file(failures, fronts, attrs, output, input=input, params=params)
