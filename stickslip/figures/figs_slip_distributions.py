"""SI figure "Slip distributions": P(dmu_a), P(T_a) and P(B_a) for interfaces a = 1..4 and every n."""

import dataclasses

from .. import registry
from ..plugin_params import param
from .experimental_data import EVENTS, load_slips
from .experimental_panels import distributions_by_n, single_slips
from .plotting import legend_outside, linear_edges, log_edges
from .style import plt, save_figure

VERSION = "2"  # 2: legends beside the panels


@dataclasses.dataclass(frozen=True)
class FigsSlipDistributionsParams:
    """Interfaces shown and binning."""

    interfaces: int = param(4, "interfaces a = 1..interfaces, one column each (the paper: 4)", minimum=1)
    bins: int = param(25, "bins of P(dmu_a) and P(B_a)", minimum=2)
    bins_per_decade: int = param(10, "logarithmic bins of T_a per decade", minimum=1)


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    slips = load_slips(inputs[EVENTS])
    single = single_slips(slips)
    fig, axes = plt.subplots(3, params.interfaces, figsize=(2.6 * params.interfaces + 1.2, 7.2), layout="constrained",
                             squeeze=False)
    for column, a in enumerate(range(1, params.interfaces + 1)):
        own = single[single["interface"] == a]
        distributions_by_n(axes[0, column], slips, a, "dmu", linear_edges(own["dmu"], params.bins))
        distributions_by_n(axes[1, column], slips, a, "T", log_edges(own["T"], params.bins_per_decade),
                           logarithmic=True)
        distributions_by_n(axes[2, column], slips, a, "B_a", linear_edges(own["B_a"], params.bins))
        for row, letter in enumerate("abc"):
            axes[row, column].set_title(f"({letter}.{a})  $a = {a}$", loc="left", fontsize=9)
    legend_outside(axes[0, -1], fontsize=6)
    return fig


@registry.register("figure", "figS-slip-distributions", VERSION, FigsSlipDistributionsParams, inputs=(EVENTS,),
                   summary="SI slip distributions: P(dmu_a), P(T_a) and P(B_a) of interfaces a = 1..4 for every n "
                           "of the stack; black: the interface driven alone (n = 1, every seed pooled)")
def run(params, inputs, output):
    """SI slip distributions: P(dmu_a), P(T_a), P(B_a) per interface a = 1..4, every n."""
    save_figure(draw(params, inputs), output)
