"""SI figure: delay tau between activity on the first and the second slipping interface.

Density of tau [H/c_s, H the distance between adjacent interfaces] over every re-run
multi-slip event of the runs with ``n`` interfaces (the paper: n = 2), both driving regimes
pooled; the dashed line is the mean, stated beside the paper's finding (tau of the order of the
time a shear wave takes to cross a layer, i.e. of order 1 in these units).
"""

import dataclasses

import numpy as np

from ..events.analysis_files import pooled
from ..plugin_params import param
from ..registry import register
from .numerical_common import read_inputs
from .style import interface_color, plt, save_figure

__all__ = ["TauParams", "run"]

NAME = "figS-tau"


@dataclasses.dataclass(frozen=True)
class TauParams:
    """Parameters of the tau figure."""

    n: int = param(2, "interfaces of the runs used (the paper: 2)", minimum=2)
    bins: int = param(12, "bins of the density", minimum=2)


@register("figure", NAME, "2", TauParams, inputs=("analysis:front-dynamics",))
def run(params, inputs, output):
    """SI: P(tau), the delay between the first failures of the first two slipping interfaces."""
    files = [f for f in read_inputs(inputs, "analysis:front-dynamics", ("fronts",), NAME) if f.n == params.n]
    fronts = pooled(files, "fronts")
    tau = fronts["tau"].to_numpy(dtype=float) if not fronts.empty else np.zeros(0)
    tau = tau[np.isfinite(tau)]
    fig, ax = plt.subplots(figsize=(3.6, 2.8), constrained_layout=True)
    if tau.size:
        ax.hist(tau, bins=params.bins, density=True, histtype="stepfilled", color=interface_color(2), alpha=0.6)
    if tau.size:
        ax.axvline(tau.mean(), color="k", ls="--", lw=0.8)
    ax.set_xlabel(r"$\tau c_s / H$")
    ax.set_ylabel(r"$P(\tau)$")
    runs = len({(f.attrs.get("regime"), f.attrs.get("seed"), f.attrs.get("N")) for f in files})
    mean = f", mean {tau.mean():.2f}" if tau.size else ""
    ax.set_title(f"$n = {params.n}$: {tau.size} events, {runs} runs{mean}\npaper: $\\tau$ of order $H / c_s$",
                 fontsize=8)
    save_figure(fig, output)
