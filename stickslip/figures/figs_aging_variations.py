"""SI figure "Aging variations": dmu_a against T_a coloured by interface and by n, with the
individually driven interfaces and the disorder law, and without the slips after slow slip."""

import dataclasses

from .. import registry
from ..experiment.aging import without_slow_slip
from ..plugin_params import param
from .experimental_data import EVENTS, load_slips
from .plotting import individual_style, label_panels, legend_outside
from .experimental_panels import aging_panel, disorder_law_lines, single_slips
from .style import plt, save_figure

VERSION = "3"  # 3: legends beside the panels


@dataclasses.dataclass(frozen=True)
class FigsAgingVariationsParams:
    """Aging time scale."""

    t0: float = param(1.0, "time scale T0 of the aging law", unit="s", exclusive_minimum=0)


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes."""
    slips = load_slips(inputs[EVENTS])
    stack = single_slips(slips, "stack")
    alone = single_slips(slips, "individual")
    fig, axes = plt.subplots(2, 2, figsize=(10.0, 6.4), layout="constrained")
    aging_panel(axes[0, 0], stack, color_by="interface", t0=params.t0)
    aging_panel(axes[0, 1], stack, color_by="n", t0=params.t0)
    fit = aging_panel(axes[1, 0], stack, color_by="n", t0=params.t0)
    axes[1, 0].plot(alone["T"], alone["dmu"], linestyle="none", markersize=3, alpha=0.7, markeredgewidth=0,
                    zorder=4, **individual_style())
    if not alone.empty:  # the disorder law over the narrow range of T_a the individual slips explore
        disorder_law_lines(axes[1, 0], slips, (0.8 * alone["T"].min(), 1.2 * alone["T"].max()))
    quiet = without_slow_slip(stack)
    aging_panel(axes[1, 1], quiet, color_by="interface", t0=params.t0)
    axes[1, 1].text(0.97, 0.03, f"no slow slip: {len(quiet)} of {len(stack)} slips", transform=axes[1, 1].transAxes,
                    ha="right", va="bottom", fontsize=7)
    if fit is not None:
        for ax in axes.ravel():
            ax.set_ylim(bottom=0)
    for ax in axes.ravel():
        legend_outside(ax, fontsize=5.5)
    label_panels(axes)
    return fig


@registry.register("figure", "figS-aging-variations", VERSION, FigsAgingVariationsParams, inputs=(EVENTS,),
                   summary="SI aging variations: dmu_a against T_a of every stack slip (a) by interface, (b) by n, "
                           "(c) with the slips of the interfaces driven alone (black, every seed) and the disorder "
                           "law, (d) without the slips after slow slip; log-binned means (error bars: standard "
                           "deviation in the bin), fits through the origin (dotted) and with an intercept (dashed)")
def run(params, inputs, output):
    """SI aging variations: dmu_a(T_a) by interface, by n, with individual slips, without slow slip."""
    save_figure(draw(params, inputs), output)
