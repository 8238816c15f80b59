"""Fig. 4: P(dmu_a) of interfaces a = 1..4 for every n, with the interface driven alone in black."""

import dataclasses

from .. import registry
from ..plugin_params import param
from .experimental_data import EVENTS, load_slips
from .plotting import label_panels, legend_outside, linear_edges
from .experimental_panels import distributions_by_n, single_slips
from .style import plt, save_figure

VERSION = "2"  # 2: legends beside the panels


@dataclasses.dataclass(frozen=True)
class Fig4Params:
    """Binning of the distributions."""

    interfaces: int = param(4, "interfaces a = 1..interfaces shown, one panel each (the paper: 4)", minimum=1)
    bins: int = param(25, "bins of each density, from 0 to the 99.5th percentile of dmu_a", minimum=2)


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    slips = load_slips(inputs[EVENTS])
    single = single_slips(slips)
    columns = 2 if params.interfaces > 1 else 1
    rows = -(-params.interfaces // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 2.7 * rows), layout="constrained", squeeze=False)
    for a, ax in zip(range(1, params.interfaces + 1), axes.ravel()):
        edges = linear_edges(single.loc[single["interface"] == a, "dmu"], params.bins)
        distributions_by_n(ax, slips, a, "dmu", edges)
        ax.set_title(f"$a = {a}$", loc="right", fontsize=9)
        legend_outside(ax)
    for ax in axes.ravel()[params.interfaces:]:
        ax.set_visible(False)
    label_panels(axes.ravel()[:params.interfaces])
    return fig


@registry.register("figure", "fig4", VERSION, Fig4Params, inputs=(EVENTS,),
                   summary="Fig. 4: P(dmu_a) of interfaces a = 1..4 for every n of the stack; black: the interface "
                           "driven alone (n = 1, the slips of every seed pooled)")
def run(params, inputs, output):
    """Fig. 4: P(dmu_a) for a = 1..4 and every n; n = 1 individual in black."""
    save_figure(draw(params, inputs), output)
