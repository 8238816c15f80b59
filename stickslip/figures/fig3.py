"""Fig. 3: lever force and slab positions of one run, P(dF) of interface 1 for every n, and the
measured slip against the slip predicted from the force drop."""

import dataclasses

import numpy as np
from matplotlib.ticker import NullFormatter

from .. import registry
from ..plugin_params import param
from .experimental_data import EVENTS, example_run, excerpt, load_slips
from .plotting import a_style, hollow, label_panels, legend_outside, linear_edges
from .experimental_panels import LABELS, distributions_by_n, positions_panel, single_slips
from .style import interface_color, plt, save_figure

VERSION = "2"  # 2: legends beside the panels, open markers of distinct shapes and sizes in (c)


@dataclasses.dataclass(frozen=True)
class Fig3Params:
    """Which run and which stretch of time panel (a) shows."""

    n_example: int = param(4, "driven slabs of the run shown in panel (a)", minimum=1)
    t_from: float = param(5400.0, "start t_0 of the excerpt (the run's last stretch if it is shorter)", unit="s",
                          minimum=0)
    duration: float = param(400.0, "length of the excerpt", unit="s", exclusive_minimum=0)


def force_panel(ax, record, slips, t_range):
    """``F(t)`` in grey with every force drop drawn in the colour of its interface (black if multi)."""
    window = (record.t_F >= t_range[0]) & (record.t_F <= t_range[1])
    ax.plot(record.t_F[window], record.F[window], color="0.6", linewidth=0.6)
    shown = slips[(slips["t_start"] >= t_range[0]) & (slips["t_end"] <= t_range[1])].drop_duplicates("event")
    for _, slip in shown.iterrows():
        before = np.searchsorted(record.t_F, slip["t_start"], side="right") - 1
        colour = "black" if slip["multi"] else interface_color(slip["interface"])
        ax.plot([slip["time"], slip["time"]], [record.F[before], record.F[before] - slip["dF"]], color=colour,
                linewidth=2.0, solid_capstyle="butt")
    for a in sorted(shown["interface"].unique()):
        ax.plot([], [], color=interface_color(a), linewidth=2.0, label=f"$a = {a}$")
    ax.set_ylabel("$F$ (N)")
    legend_outside(ax, handlelength=1.0)


#: Marker size [pt] of interface a = 1 in panel (c); each next interface is smaller by MARKER_STEP.
MARKER_SIZE, MARKER_STEP = 4.5, 0.5


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    slips = load_slips(inputs[EVENTS])
    record, run_slips = example_run(slips, inputs[EVENTS], n=params.n_example)
    fig = plt.figure(figsize=(9.5, 5.0), layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(1.5, 1.0))
    ax_F = fig.add_subplot(grid[0, 0])
    ax_R = fig.add_subplot(grid[1, 0], sharex=ax_F)
    ax_dF = fig.add_subplot(grid[0, 1])
    ax_dR = fig.add_subplot(grid[1, 1])
    t_range = excerpt(record, params.t_from, params.duration)
    force_panel(ax_F, record, run_slips, t_range)
    ax_F.set_title(f"$n = {record.n}$", loc="right", fontsize=9)
    ax_F.tick_params(labelbottom=False)
    positions_panel(ax_R, record, range(1, record.n_slabs + 1), t_range)
    legend_outside(ax_R, handlelength=1.0)

    stack = single_slips(slips, "stack")
    one = stack[stack["interface"] == 1]
    distributions_by_n(ax_dF, slips, 1, "dF", linear_edges(one["dF"], 30), individual=False)
    legend_outside(ax_dF, title="$a = 1$")

    # Open markers, a shape and a size per interface, translucent, the most numerous drawn first: overlaps stay
    # legible.
    for a in stack["interface"].value_counts().index:
        part = stack[stack["interface"] == a]
        ax_dR.plot(part["slip_from_dF"], part["slip"], linestyle="none", gid=f"a={a}", alpha=0.6,
                   **{**hollow(a_style(a), MARKER_SIZE - MARKER_STEP * (a - 1)), "markeredgewidth": 0.6})
    both = stack[["slip", "slip_from_dF"]].to_numpy()
    limits = np.array([np.nanmin(both), np.nanmax(both)])
    limits = np.array([max(limits[0], 1e-3) / 1.2, limits[1] * 1.2])
    ax_dR.plot(limits, limits, color="black", linewidth=0.8, linestyle="--", label=r"$y = x$")
    ax_dR.set_xscale("log")
    ax_dR.set_yscale("log")
    for axis in (ax_dR.xaxis, ax_dR.yaxis):
        axis.set_minor_formatter(NullFormatter())
    ax_dR.set_xlim(limits)
    ax_dR.set_ylim(limits)
    ax_dR.set_xlabel(LABELS["slip_from_dF"])
    ax_dR.set_ylabel(r"$\Delta R_a$ measured (mm)")
    entries = sorted(zip(*ax_dR.get_legend_handles_labels()), key=lambda entry: (entry[1] == r"$y = x$", entry[1]))
    legend_outside(ax_dR, handles=[handle for handle, _ in entries], labels=[label for _, label in entries])
    label_panels([ax_F, ax_dF, ax_dR])
    return fig


@registry.register("figure", "fig3", VERSION, Fig3Params, inputs=(EVENTS,),
                   summary="Fig. 3: (a) F(t) with the force drops coloured by interface, and R_i(t), of the first "
                           "stack run of n_example; (b) P(dF) of a = 1 for every n; (c) dR_a measured against dR_a "
                           "from dF, every stack slip (open markers, one shape and size per interface)")
def run(params, inputs, output):
    """Fig. 3: F(t) and R_i(t) excerpt, P(dF) for a = 1 and every n, dR_a measured vs from dF."""
    save_figure(draw(params, inputs), output)
