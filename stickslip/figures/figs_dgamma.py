"""SI figure: shear increment Delta gamma_1 between slip events of the first interface.

Density of Delta gamma_a for a = 1 [gamma0], every slip event involving interface 1 (single
or multi), for every number of interfaces n; (a) stiff, (b) compliant driving. Runs are
pooled by (regime, n) over seeds.
"""

import dataclasses

import numpy as np

from ..events.analysis_files import group_runs, pooled
from ..plugin_params import param
from ..registry import register
from .numerical_common import REGIME_LABEL, read_inputs
from .plotting import label_panels, n_style, plot_density, range_edges
from .style import plt, save_figure

__all__ = ["DgammaParams", "run"]

NAME = "figS-dgamma"


@dataclasses.dataclass(frozen=True)
class DgammaParams:
    """Parameters of the Delta gamma figure."""

    interface: int = param(1, "interface a whose slip-to-slip shear increments are shown (the paper: 1)", minimum=1)
    bins: int = param(15, "bins of each density", minimum=2)


@register("figure", NAME, "1", DgammaParams, inputs=("analysis:numerical-events",))
def run(params, inputs, output):
    """SI: P(Delta gamma_a) between slips of interface a = 1, for every n, stiff and compliant."""
    groups = group_runs(read_inputs(inputs, "analysis:numerical-events", ("slip_interfaces",), NAME))
    fig, axes = plt.subplots(1, 2, figsize=(7.0, 2.8), constrained_layout=True)
    for ax, regime in zip(axes, ("stiff", "compliant")):
        for (group_regime, n), files in groups.items():
            per = pooled(files, "slip_interfaces")
            if group_regime != regime or per.empty or n < params.interface:
                continue
            dgamma = per["dgamma"].to_numpy()[per["interface"].to_numpy() == params.interface]
            dgamma = dgamma[np.isfinite(dgamma)]  # the first slip of each run has no predecessor (NaN)
            plot_density(ax, dgamma, range_edges(dgamma, params.bins),
                         **{**n_style(n), "label": f"$n = {n}$ ({dgamma.size})"})
        ax.set_xlabel(rf"$\Delta\gamma_{{{params.interface}}} / \gamma_0$")
        ax.set_ylabel(rf"$P(\Delta\gamma_{{{params.interface}}})$")
        ax.set_title(REGIME_LABEL[regime], fontsize=9)
        ax.legend(fontsize=7, frameon=False, title="(intervals)", title_fontsize=6)
    label_panels(axes)
    save_figure(fig, output)
