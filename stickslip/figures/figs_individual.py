"""SI figure "Individual sliding": dR_a measured against dR_a from dF, P(dF) and P(dmu_a) of each
interface driven alone."""

import dataclasses

import numpy as np
from matplotlib.ticker import NullFormatter

from .. import registry
from ..plugin_params import param
from .experimental_data import EVENTS, load_slips
from .plotting import a_style, label_panels, legend_outside, linear_edges, plot_density
from .experimental_panels import LABELS, single_slips
from .style import plt, save_figure

VERSION = "2"  # 2: legends beside the panels; every seed of the individual protocol


@dataclasses.dataclass(frozen=True)
class FigsIndividualParams:
    """Binning of the distributions."""

    bins: int = param(30, "bins of P(dF) and P(dmu_a), from 0 to the 99.5th percentile", minimum=2)


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    alone = single_slips(load_slips(inputs[EVENTS]), "individual")
    fig, axes = plt.subplots(1, 3, figsize=(11.0, 3.2), layout="constrained")
    interfaces = sorted(alone["interface"].unique())
    for a in interfaces:
        part = alone[alone["interface"] == a]
        axes[0].plot(part["slip_from_dF"], part["slip"], linestyle="none", markersize=3, alpha=0.6,
                     markeredgewidth=0, **a_style(a))
    if not alone.empty:
        values = alone[["slip", "slip_from_dF"]].to_numpy(dtype=float)
        limits = np.array([np.nanmin(values) / 1.1, np.nanmax(values) * 1.1])
        axes[0].plot(limits, limits, color="black", linestyle="--", linewidth=0.8, label="$y = x$")
        axes[0].set_xlim(limits)
        axes[0].set_ylim(limits)
    axes[0].set_xlabel(LABELS["slip_from_dF"])
    axes[0].set_ylabel(r"$\Delta R_a$ measured (mm)")
    for column, ax in zip(("dF", "dmu"), axes[1:]):
        edges = linear_edges(alone[column], params.bins)
        for a in interfaces:
            plot_density(ax, alone.loc[alone["interface"] == a, column], edges, gid=f"a={a}", **a_style(a))
        ax.set_xlabel(LABELS[column])
        ax.set_ylabel(f"$P$({LABELS[column].split(' (')[0]})")
    for ax in axes:
        ax.xaxis.set_minor_formatter(NullFormatter())
    legend_outside(axes[-1], title="$n = 1$ (individual)")
    label_panels(axes)
    return fig


@registry.register("figure", "figS-individual", VERSION, FigsIndividualParams, inputs=(EVENTS,),
                   summary="SI individual sliding: (a) dR_a measured against dR_a from dF, (b) P(dF) and (c) "
                           "P(dmu_a) of each interface driven alone (every seed pooled)")
def run(params, inputs, output):
    """SI individual sliding: dR_a vs dR_a(dF), P(dF) and P(dmu_a) per interface driven alone."""
    save_figure(draw(params, inputs), output)
