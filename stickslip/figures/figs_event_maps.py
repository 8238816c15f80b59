"""SI figure: event maps of two typical multi-slip events with n = 2 interfaces, stiff driving.

Every block failure of a re-run event: position r / l0 (block index) against the time since
the first failure anywhere, in units of H/c_s (H the distance between adjacent interfaces).
One panel per event, with the interfaces above each other (the highest on top); failures
in the direction of the applied shear black, backwards blue. The two fitted branches of the
ballistic front of the first slipping interface are drawn in red (a branch whose fit is
flagged, :func:`stickslip.events.fronts.analyse_event`, dashed). "Typical": the events are taken
in the order of the distance of their c_f from the median c_f of all meaningful fits of the
chosen regime and n (events without a meaningful fit last). Each panel states the event's c_f,
the median over the events, and the paper's value (c_f ~ 2 c_s at N = 1458).
"""

import dataclasses

import numpy as np

from ..events.fronts import BRANCHES
from ..plugin_params import param
from ..registry import register
from .numerical_common import read_inputs
from .style import plt, save_figure

__all__ = ["EventMapParams", "PAPER_C_F", "branch_line", "typical_events", "run"]

NAME = "figS-event-maps"

#: Failure colours of the paper's event maps: forward black, backward blue.
FORWARD_COLOR, BACKWARD_COLOR, FIT_COLOR = "k", "#2c7fb8", "#d7301f"

#: The paper's front speed (SI "Front dynamics -- numerics", N = 1458) [c_s].
PAPER_C_F = 2.0


@dataclasses.dataclass(frozen=True)
class EventMapParams:
    """Which events to draw."""

    n: int = param(2, "interfaces of the runs used (the paper: 2)", minimum=2)
    regime: str = param("stiff", "driving regime of the runs used (the paper's maps: stiff); any: both",
                        choices=("stiff", "compliant", "any"))
    N: int = param(0, "blocks per interface of the runs used (0: every N of the study)", minimum=0)
    events: tuple[int, ...] = param((0, 1), "which re-run events to draw: ranks in the list of re-run events "
                                            "(multi-slips first) ordered by how close their c_f is to the median "
                                            "of the meaningful fits (0: the most typical)", minimum=0)


def branch_line(nucleation, speed, t0, length, sign, N, points=200):
    """One branch of a front leaving block ``nucleation`` at ``speed`` for ``length`` blocks.

    Parameters
    ----------
    nucleation : int
        Block where the front starts.
    speed : float
        Front speed [blocks per time unit].
    t0 : float
        Time at which the line leaves the nucleation block.
    length : float
        Blocks the branch runs (to the block where it meets the other branch).
    sign : int
        +1: towards increasing block index, -1: back.
    N : int
        Blocks per interface (period).
    points : int, optional

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray]
        (r [points'], t [points']); NaN where the line wraps around the periodic boundary.
    """
    t = np.linspace(t0, t0 + length / speed, points)
    r = np.mod(nucleation + 0.5 + sign * speed * (t - t0), N)
    wraps = np.flatnonzero(np.abs(np.diff(r)) > N / 2) + 1
    return np.insert(r, wraps, np.nan), np.insert(t, wraps, np.nan)


def typical_events(files, n, regime, N=0):
    """Re-run events of the runs with ``n`` interfaces, ``regime`` and ``N`` blocks, the most typical first.

    Parameters
    ----------
    files : list[stickslip.events.analysis_files.AnalysisFile]
        ``front-dynamics`` files.
    n : int
    regime : str
        "stiff", "compliant" or "any".
    N : int, optional
        Blocks per interface; 0: any.

    Returns
    -------
    events : list[tuple[AnalysisFile, pandas.Series]]
        Multi-slips first; within them, events with a meaningful fit (finite ``c_f``) by the
        distance of ``c_f`` from the median, then the others; ties by (regime, N, seed, increment).
    median : float
        Median ``c_f`` [c_s] of the meaningful fits among them (NaN if none).
    count : int
        Number of meaningful fits.
    """
    chosen = []
    for item in sorted(files, key=lambda f: (f.regime, f.attrs.get("N", 0), f.attrs.get("seed", 0), f.path)):
        if item.n != n or regime not in ("any", item.regime) or N not in (0, int(item.attrs["N"])):
            continue
        for _, front in item.tables["fronts"].iterrows():
            chosen.append((item, front))
    speeds = np.array([front["c_f"] for _, front in chosen if front["s"] >= 2], dtype=float)
    speeds = speeds[np.isfinite(speeds)]
    median = float(np.median(speeds)) if speeds.size else np.nan

    def rank(event):
        c_f = event[1]["c_f"]
        return (-min(int(event[1]["s"]), 2), 0 if np.isfinite(c_f) else 1,
                abs(c_f - median) if np.isfinite(c_f) else 0.0)

    return sorted(chosen, key=rank), median, int(speeds.size)


def _front_text(front, median, count, N):
    """What the panel says about the front speed, next to the paper's value."""
    def branch(side):
        speed, quality = front[f"c_f_{side}"], front[f"quality_{side}"]
        return f"{side} {speed:.2f}" if quality == "ok" else f"{side}: {quality}"

    event = (f"$c_f = {front['c_f']:.2f}\\,c_s$" if np.isfinite(front["c_f"]) else "$c_f$: no meaningful fit")
    return (f"{event} ({branch('right')}, {branch('left')})\n"
            f"median of {count} events: {median:.2f} $c_s$ ($N = {N}$)\n"
            f"paper: $c_f \\approx {PAPER_C_F:g}\\,c_s$ ($N = 1458$)")


def _event_map(axes, item, front, median, count):
    N, spacing = int(item.attrs["N"]), float(item.attrs["interface_spacing"])
    c_s, h = float(item.attrs["c_s"]), float(item.attrs["h"])
    unit = spacing / c_s
    failures = item.tables["failures"]
    failures = failures[failures["increment"].to_numpy() == front["increment"]]
    t0 = failures["t"].min()
    for ax, a in zip(axes, range(len(axes), 0, -1)):
        sub = failures[failures["a"].to_numpy() == a]
        for direction, color in ((1, FORWARD_COLOR), (-1, BACKWARD_COLOR)):
            part = sub[sub["direction"].to_numpy() == direction]
            ax.plot(part["block"] + 0.5, (part["t"] - t0) / unit, ".", color=color, ms=1.2, rasterized=True)
        if a == front["a_first"]:
            right = np.mod(front["meeting"] - front["nucleation"], N) or N // 2
            for side, sign, length in zip(BRANCHES, (1, -1), (right, N - right)):
                speed = front[f"c_f_{side}"] * c_s / h  # blocks per time unit
                if np.isfinite(speed) and speed > 0:
                    r, t = branch_line(int(front["nucleation"]), speed, front[f"t0_{side}"], length, sign, N)
                    ax.plot(r, (t - t0) / unit, color=FIT_COLOR, lw=0.8,
                            ls="-" if front[f"quality_{side}"] == "ok" else "--")
            ax.text(0.98, 0.97, _front_text(front, median, count, N), transform=ax.transAxes, ha="right", va="top",
                    color=FIT_COLOR, fontsize=5.5, bbox={"facecolor": "white", "alpha": 0.7, "lw": 0})
        ax.set_xlim(0, N)
        ax.set_ylabel(f"$i = {a}$\n" + r"$t c_s / H$", fontsize=8)
    kind = "multi-slip" if front["s"] >= 2 else "single slip (no multi-slip re-run)"
    axes[0].set_title(f"{kind}\n{item.regime}, $N = {N}$, seed {item.attrs.get('seed', '?')}, "
                      f"increment {int(front['increment'])}", fontsize=7)
    axes[-1].set_xlabel(r"$r / \ell_0$")


@register("figure", NAME, "2", EventMapParams, inputs=("analysis:front-dynamics",))
def run(params, inputs, output):
    """SI: event maps (failure position against time) of two typical multi-slip events, n = 2, with c_f."""
    files = read_inputs(inputs, "analysis:front-dynamics", ("failures", "fronts"), NAME)
    events, median, count = typical_events(files, params.n, params.regime, params.N)
    fig = plt.figure(figsize=(3.5 * len(params.events), 4.0), constrained_layout=True)
    panels = fig.subfigures(1, len(params.events), squeeze=False)[0]
    for panel, index, letter in zip(panels, params.events, "abcdefgh"):
        axes = panel.subplots(params.n, 1, sharex=True, sharey=True)
        if index < len(events):
            _event_map(axes, *events[index], median, count)
        else:
            axes[0].set_title(f"event {index}: the inputs hold {len(events)} re-run event(s) with n = {params.n} "
                              f"({params.regime})", fontsize=7)
        panel.suptitle(f"({letter})", x=0.05, ha="left", fontweight="bold", fontsize=9)
    save_figure(fig, output)
