"""SI figure: event maps of two multi-slip events with n = 2 interfaces.

Every block failure of a re-run event: position r / l0 (block index) against the time since
the first failure anywhere, in units of H/c_s (H the distance between adjacent interfaces).
One panel per event, with the interfaces above each other (the highest on top); failures
in the direction of the applied shear black, backwards blue. The fitted ballistic front of
the first slipping interface (speed c_f, in the text) is drawn in red.
"""

import dataclasses

import numpy as np

from ..params import param
from ..registry import register
from .numerical_common import read_inputs
from .style import plt, save_figure

__all__ = ["EventMapParams", "front_lines", "run"]

NAME = "figS-event-maps"

#: Failure colours of the paper's event maps: forward black, backward blue.
FORWARD_COLOR, BACKWARD_COLOR, FIT_COLOR = "k", "#2c7fb8", "#d7301f"


@dataclasses.dataclass(frozen=True)
class EventMapParams:
    """Which events to draw."""

    n: int = param(2, "interfaces of the runs used (the paper: 2)", minimum=2)
    events: tuple[int, ...] = param((0, 1), "which re-run events to draw: indices in the list of re-run events "
                                            "of the runs with n interfaces, multi-slips first, then by (regime, "
                                            "N, seed, increment)", minimum=0)


def front_lines(nucleation, speed, t0, t_end, N, points=200):
    """The two branches of a front leaving block ``nucleation`` at ``speed``, until they meet.

    Parameters
    ----------
    nucleation : int
        Block where the front starts.
    speed : float
        Front speed [blocks per time unit].
    t0, t_end : float
        Start time of the line, and the latest end time (the branches end earlier if they
        meet, after N/2 blocks).
    N : int
        Blocks per interface (period).
    points : int, optional

    Returns
    -------
    list[tuple[numpy.ndarray, numpy.ndarray]]
        Two (r [points'], t [points']) polylines; NaN where the line wraps around.
    """
    t = np.linspace(t0, min(t_end, t0 + N / 2 / speed), points)
    distance = speed * (t - t0)
    lines = []
    for sign in (+1, -1):
        r = np.mod(nucleation + 0.5 + sign * distance, N)
        wraps = np.flatnonzero(np.abs(np.diff(r)) > N / 2) + 1
        lines.append((np.insert(r, wraps, np.nan), np.insert(t, wraps, np.nan)))
    return lines


def _events(files, n):
    """Re-run events of the runs with ``n`` interfaces: multi-slips first (the paper's), then single slips."""
    chosen = []
    for item in sorted(files, key=lambda f: (f.regime, f.attrs.get("N", 0), f.attrs.get("seed", 0), f.path)):
        if item.n != n:
            continue
        for _, front in item.tables["fronts"].iterrows():
            chosen.append((item, front))
    return sorted(chosen, key=lambda event: -int(event[1]["s"]))


def _event_map(axes, item, front):
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
        if a == front["a_first"] and np.isfinite(front["c_f"]):
            speed = front["c_f"] * c_s / h  # blocks per time unit
            t_end = failures["t"].max()
            for r, t in front_lines(int(front["nucleation"]), speed, front["fit_t0"], t_end, N):
                ax.plot(r, (t - t0) / unit, color=FIT_COLOR, lw=0.8)
            ax.text(0.98, 0.95, f"$c_f = {front['c_f']:.2f}\\,c_s$", transform=ax.transAxes, ha="right",
                    va="top", color=FIT_COLOR, fontsize=7)
        ax.set_xlim(0, N)
        ax.set_ylabel(f"$i = {a}$\n" + r"$t c_s / H$", fontsize=8)
    kind = "multi-slip" if front["s"] >= 2 else "single slip (no multi-slip re-run)"
    axes[0].set_title(f"{kind}\n{item.regime}, $N = {N}$, seed {item.attrs.get('seed', '?')}, "
                      f"increment {int(front['increment'])}", fontsize=7)
    axes[-1].set_xlabel(r"$r / \ell_0$")


@register("figure", NAME, "1", EventMapParams, inputs=("analysis:front-dynamics",))
def run(params, inputs, output):
    """SI: event maps (failure position against time) of two multi-slip events, n = 2."""
    events = _events(read_inputs(inputs, "analysis:front-dynamics", ("failures", "fronts"), NAME), params.n)
    fig = plt.figure(figsize=(3.5 * len(params.events), 4.0), constrained_layout=True)
    panels = fig.subfigures(1, len(params.events), squeeze=False)[0]
    for panel, index, letter in zip(panels, params.events, "abcdefgh"):
        axes = panel.subplots(params.n, 1, sharex=True, sharey=True)
        if index < len(events):
            _event_map(axes, *events[index])
        else:
            axes[0].set_title(f"event {index}: the inputs hold {len(events)} re-run event(s) with n = {params.n}",
                              fontsize=7)
        panel.suptitle(f"({letter})", x=0.05, ha="left", fontweight="bold", fontsize=9)
    save_figure(fig, output)
