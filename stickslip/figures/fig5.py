"""Fig. 5: disorder law of individually driven interfaces, P(T_a) of interface 1 for every n,
and the aging law dmu_a = B ln(T_a / T0) on all slips of the stacks."""

import dataclasses

import numpy as np

from .. import registry
from ..plugin_params import param
from .experimental_data import EVENTS, load_slips
from .plotting import a_style, label_panels, legend_outside, log_edges
from .experimental_panels import LABELS, aging_panel, disorder_law_lines, distributions_by_n, single_slips
from .style import plt, save_figure

VERSION = "3"  # 3: legends beside the panels; (a) every seed of the individual protocol


@dataclasses.dataclass(frozen=True)
class Fig5Params:
    """Binning and aging time scale."""

    t0: float = param(1.0, "time scale T0 of the aging law", unit="s", exclusive_minimum=0)
    bins_per_decade: int = param(10, "logarithmic bins of T_a per decade (panel b)", minimum=1)


def individual_panel(ax, slips):
    """dmu_a against T_a of the individually driven interfaces, with the disorder law."""
    alone = single_slips(slips, "individual")
    alone = alone[np.isfinite(alone["T"].to_numpy(dtype=float))]
    for a in sorted(alone["interface"].unique()):
        part = alone[alone["interface"] == a]
        ax.plot(part["T"], part["dmu"], linestyle="none", markersize=3, alpha=0.6, markeredgewidth=0, gid=f"a={a}",
                **a_style(a))
    if not alone.empty:
        disorder_law_lines(ax, slips, (0.0, alone["T"].max() * 1.05))
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.set_xlabel(LABELS["T"])
    ax.set_ylabel(LABELS["dmu"])
    legend_outside(ax, title="$n = 1$ (individual)")


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    slips = load_slips(inputs[EVENTS])
    fig, axes = plt.subplots(1, 3, figsize=(12.0, 3.3), layout="constrained")
    individual_panel(axes[0], slips)
    stack = single_slips(slips, "stack")
    distributions_by_n(axes[1], slips, 1, "T",
                       log_edges(stack.loc[stack["interface"] == 1, "T"], params.bins_per_decade),
                       individual=False, logarithmic=True)
    legend_outside(axes[1], title="$a = 1$")
    aging_panel(axes[2], stack, t0=params.t0)
    legend_outside(axes[2], fontsize=6)
    label_panels(axes)
    return fig


@registry.register("figure", "fig5", VERSION, Fig5Params, inputs=(EVENTS,),
                   summary="Fig. 5: (a) dmu_a against T_a of the interfaces driven alone (every seed), with the "
                           "disorder law; (b) P(T_a) of a = 1 for every n; (c) dmu_a against T_a of every stack "
                           "slip, the log-binned means (error bars: standard deviation in the bin), the paper's fit "
                           "through the origin (dotted) and the fit with a free intercept (dashed)")
def run(params, inputs, output):
    """Fig. 5: dmu_a(T_a) individual, P(T_a) for a = 1 and every n, dmu_a(T_a) with the aging fit."""
    save_figure(draw(params, inputs), output)
