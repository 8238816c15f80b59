"""Figure beyond the paper: slip synchronisation and stress drops against the rigidity ratio Phi.

(a) Fraction of steady-state slip events that are multi-slips (rho(s > 1)) against Phi, for
each n, with the Wilson counting interval (one standard deviation); the crossover Phi where
it passes 0.5 is marked and given in the legend, beside the paper's statement (synchronised
for Phi >~ 1e-3 at N = 1458). (b) Mean stress drop Delta mu_a [sig0] of the
slipping interfaces (every slip event) with its standard error, and (c) the width (standard
deviation) of its distribution with its error, against Phi. Periodicity and synchronisation
(:mod:`stickslip.events.periodicity`; mean over the runs at each point, error bars one standard
error over them, i.e. from the seeds): (d) coefficient of variation of the shear increment
between consecutive slip events (filled, 0: periodic, 1: Poisson) and of the stress drops Delta
Sigma (open); (e) fraction of slip events in which all n interfaces slip; (f) the runs test of
the order of single and multi slips (about 0 for a random order, dotted band +-2). Dotted
verticals: the paper's two runs (Phi = 5e-4 stiff, 5e-7 compliant). Runs pooled over seeds at
each (n, Phi); every run of the study counts, at any N (panel a states which N).
"""

import dataclasses
import math

import numpy as np

from ..summaries.phi_sweep import crossover, sweep_table
from ..fem.stiffness import PAPER_PHI
from ..registry import register
from .numerical_common import read_inputs, run_phi
from .periodicity_panels import MEASURE_LABEL, periodicity_summary, plot_measure
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


def _periodicity_panels(axes, files):
    """(d) CV of Delta gamma and Delta Sigma, (e) system-spanning fraction, (f) runs test, against Phi."""
    summary = periodicity_summary(files, {"n": lambda f: f.n, "phi": lambda f: float(f"{run_phi(f.attrs):.3g}")})
    for (n,), rows in summary.groupby(["n"]):
        rows = rows.sort_values("phi")
        style = n_style(n)
        plot_measure(axes[0], rows, "phi", "interval_cv", **style)
        plot_measure(axes[0], rows, "phi", "drop_cv", **{**style, "label": None, "markerfacecolor": "white", "ls": "--"})
        if n > 1:
            plot_measure(axes[1], rows, "phi", "spanning_fraction", **style)
            plot_measure(axes[2], rows, "phi", "runs_z", **style)
    axes[0].axhline(1.0, color="0.7", lw=0.6, ls=":")
    axes[0].set_ylim(bottom=0)
    axes[0].set_ylabel("CV of $\\Delta\\gamma$ (filled), $\\Delta\\Sigma$ (open)")
    axes[0].text(0.02, 0.03, "0: periodic, 1: Poisson; paper: stiff periodic", transform=axes[0].transAxes, fontsize=6)
    axes[1].set_ylim(-0.02, 1.02)
    axes[1].set_ylabel(MEASURE_LABEL["spanning_fraction"])
    axes[1].text(0.02, 0.93, "paper: stiff slips involve all layers", transform=axes[1].transAxes, fontsize=6)
    axes[2].axhspan(-2.0, 2.0, color="0.9", lw=0)
    axes[2].set_ylabel(MEASURE_LABEL["runs_z"])
    axes[2].text(0.02, 0.03, "> 2: alternating, < -2: clustered", transform=axes[2].transAxes, fontsize=6)


@register("figure", NAME, "2", PhiSweepParams, inputs=("analysis:numerical-events",))
def run(params, inputs, output):
    """Multi-slip fraction, stress drops, periodicity and synchronisation against the rigidity ratio Phi, each n."""
    files = read_inputs(inputs, "analysis:numerical-events", ("slips", "slip_interfaces", "periodicity"), NAME,
                        paper_phi=False)
    table = sweep_table(files, run_phi)
    table["dmu_mean_low"] = table["dmu_mean"] - table["dmu_mean_error"]
    table["dmu_mean_high"] = table["dmu_mean"] + table["dmu_mean_error"]
    table["dmu_width_low"] = table["dmu_width"] - table["dmu_width_error"]
    table["dmu_width_high"] = table["dmu_width"] + table["dmu_width_error"]
    fig, grid = plt.subplots(2, 3, figsize=(9.0, 6.0), constrained_layout=True)
    axes = grid.ravel()
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
    axes[0].set_title(f"$N = {sizes}$; paper: synchronised for $\\Phi \\gtrsim 10^{{-3}}$ ($N = 1458$)",
                      fontsize=7, loc="right")
    axes[0].legend(fontsize=6, frameon=False)
    _periodicity_panels(axes[3:], files)
    axes[1].set_ylabel(r"$\langle \Delta\mu_a \rangle / \sigma_0$")
    axes[2].set_ylabel(r"std$(\Delta\mu_a) / \sigma_0$")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xlabel(r"$\Phi = K / K_s$")
        for phi in PAPER_PHI.values():
            ax.axvline(phi, color="k", lw=0.5, ls=":")
    label_panels(axes, "abcdef")
    save_figure(fig, output)
