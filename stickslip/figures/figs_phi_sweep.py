"""Figure beyond the paper: slip synchronisation and stress drops against the rigidity ratio Phi.

(a) Fraction of steady-state slip events that are multi-slips (rho(s > 1)) against Phi, for
each n, with the Wilson counting interval (one standard deviation); the crossover Phi where
it passes 0.5 is marked and given in the legend. (b) Mean stress drop Delta mu_a [sig0] of the
slipping interfaces (every slip event) with its standard error, and (c) the width (standard
deviation) of its distribution with its error, against Phi. Dotted verticals: the paper's two
runs (Phi = 5e-4 stiff, 5e-7 compliant). Runs pooled over seeds at each (n, Phi); every run of
the study counts, at any N (panel a states which N).
"""

import dataclasses
import math

import numpy as np

from ..events.phi_sweep import crossover, sweep_table
from ..fem.stiffness import PAPER_PHI
from ..registry import register
from .numerical_common import read_inputs, run_phi
from .plotting import label_panels, n_style
from .style import plt, save_figure

__all__ = ["PhiSweepParams", "run"]

NAME = "figS-phi-sweep"


@dataclasses.dataclass(frozen=True)
class PhiSweepParams:
    """The Phi-sweep figure has no parameter."""


def _errorbars(ax, rows, value, low, high, n, label):
    x = rows["phi"].to_numpy(dtype=float)
    y = rows[value].to_numpy(dtype=float)
    yerr = np.vstack([y - rows[low].to_numpy(dtype=float), rows[high].to_numpy(dtype=float) - y])
    ax.errorbar(x, y, yerr=yerr, capsize=2, markersize=4, **{**n_style(n), "label": label})


@register("figure", NAME, "1", PhiSweepParams, inputs=("analysis:numerical-events",))
def run(params, inputs, output):
    """Multi-slip fraction and stress drops against the rigidity ratio Phi, for each n (a Phi sweep)."""
    files = read_inputs(inputs, "analysis:numerical-events", ("slips", "slip_interfaces"), NAME, paper_phi=False)
    table = sweep_table(files, run_phi)
    table["dmu_mean_low"] = table["dmu_mean"] - table["dmu_mean_error"]
    table["dmu_mean_high"] = table["dmu_mean"] + table["dmu_mean_error"]
    table["dmu_width_low"] = table["dmu_width"] - table["dmu_width_error"]
    table["dmu_width_high"] = table["dmu_width"] + table["dmu_width_error"]
    fig, axes = plt.subplots(1, 3, figsize=(9.0, 3.0), constrained_layout=True)
    for n in sorted(table["n"].unique()):
        rows = table[table["n"] == n]
        cross = crossover(table, n)
        text = f"$\\Phi_c = {cross:.1e}$" if math.isfinite(cross) else "no crossing"
        _errorbars(axes[0], rows, "multi_fraction", "multi_low", "multi_high", n, f"$n = {n}$: {text}")
        if math.isfinite(cross):
            axes[0].axvline(cross, color=n_style(n)["color"], lw=0.6, ls="-.")
        _errorbars(axes[1], rows, "dmu_mean", "dmu_mean_low", "dmu_mean_high", n, None)
        _errorbars(axes[2], rows, "dmu_width", "dmu_width_low", "dmu_width_high", n, None)
    sizes = ", ".join(sorted(set(",".join(table["N"]).split(","))))
    axes[0].axhline(0.5, color="0.5", lw=0.6)
    axes[0].set_ylim(-0.02, 1.02)
    axes[0].set_ylabel(r"$\rho(s > 1)$")
    axes[0].set_title(f"$N = {sizes}$", fontsize=8)
    axes[0].legend(fontsize=6, frameon=False)
    axes[1].set_ylabel(r"$\langle \Delta\mu_a \rangle / \sigma_0$")
    axes[2].set_ylabel(r"std$(\Delta\mu_a) / \sigma_0$")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xlabel(r"$\Phi = K / K_s$")
        for phi in PAPER_PHI.values():
            ax.axvline(phi, color="k", lw=0.5, ls=":")
    label_panels(axes, "abc")
    save_figure(fig, output)
