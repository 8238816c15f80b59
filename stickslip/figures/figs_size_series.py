"""Figure beyond the paper: the paper's numerical findings against the system size N.

Runs at the paper's two Phi, grouped by (N, dt_scale, regime, n) with the seeds pooled
(:mod:`stickslip.summaries.size_series`); filled markers dt_scale 4 (or the study's only time step),
open markers (shifted right by 5 %) the paper's time step dt_scale 1 where the study has it.
(a) Synchronisation, stiff driving: multi-slip fraction (solid) and fraction of slip events in
which all n interfaces slip (dashed), mean over the seeds with one standard error; the paper's
stiff runs (N = 1458) are "periodic multi-slips" involving all layers. (b) Periodicity: the
coefficient of variation of the shear increment between consecutive slip events, stiff (solid)
and compliant (dashed): 0 is periodic, 1 Poisson. (c) Front speed c_f of the re-run multi-slips
(n = 2, meaningful fits only; median with the standard error of the mean), against the paper's
~2 c_s at N = 1458 (star); dotted: c_s, sqrt(2) c_s and the P-wave speed c_d. (d) Relative shift of
the mean Delta mu_a of compliant single slips of n interfaces against n = 1, with its standard
error (the paper: no shift at N = 1458, star).
"""

import dataclasses
import math

import numpy as np

from ..summaries.size_series import drop_shift_by_size, front_speed_by_size, periodicity_by_size
from ..registry import register
from .numerical_common import read_inputs
from .plotting import label_panels, n_style
from .style import plt, save_figure

__all__ = ["SizeSeriesParams", "run"]

NAME = "figS-size-series"

#: The paper's system size, and its front speed [c_s].
PAPER_N, PAPER_C_F = 1458, 2.0

#: Standard errors in the detectable shift of :func:`stickslip.statistics.mean_shift.detectable_shift`
#: (z_0.975 + z_0.8): the shift's standard error is the detectable shift over this.
DETECTABLE_IN_ERRORS = 2.8016


@dataclasses.dataclass(frozen=True)
class SizeSeriesParams:
    """The size-series figure has no parameter."""


def _x(rows):
    """N, shifted right by 5 % for the paper's time step (dt_scale 1) when other steps are drawn too."""
    return rows["N"].to_numpy(dtype=float) * np.where(rows["dt_scale"].to_numpy(dtype=float) == 1.0, 1.05, 1.0)


def _series(ax, rows, y, error, style, dashed=False):
    for dt_scale, part in rows.groupby("dt_scale"):
        part = part.sort_values("N")
        open_marker = dt_scale == 1.0 and rows["dt_scale"].nunique() > 1
        ax.errorbar(_x(part), part[y].to_numpy(dtype=float), yerr=np.nan_to_num(part[error].to_numpy(dtype=float)),
                    capsize=2, markersize=4, ls="--" if dashed else "-",
                    **{**style, "markerfacecolor": "white" if open_marker else style["color"],
                       "label": style["label"] if not open_marker and not dashed else None})


@register("figure", NAME, "1", SizeSeriesParams, inputs=("analysis:numerical-events", "analysis:front-dynamics"))
def run(params, inputs, output):
    """Beyond the paper: synchronisation, periodicity, front speed and the n-dependence of Delta mu_a against N."""
    events = read_inputs(inputs, "analysis:numerical-events", ("slip_interfaces", "periodicity"), NAME)
    fronts = read_inputs(inputs, "analysis:front-dynamics", ("fronts",), NAME)
    summary = periodicity_by_size(events)
    fig, axes = plt.subplots(2, 2, figsize=(7.0, 5.6), constrained_layout=True)
    (sync, periodic), (speed, shift) = axes
    for n in sorted(summary["n"].unique()):
        if n < 2:
            continue
        style = n_style(n)
        stiff = summary[(summary["n"] == n) & (summary["regime"] == "stiff")]
        _series(sync, stiff, "multi_fraction", "multi_fraction_error", style)
        _series(sync, stiff, "spanning_fraction", "spanning_fraction_error", style, dashed=True)
        _series(periodic, stiff, "interval_cv", "interval_cv_error", style)
        compliant = summary[(summary["n"] == n) & (summary["regime"] == "compliant")]
        _series(periodic, compliant, "interval_cv", "interval_cv_error", style, dashed=True)
    sync.set_ylim(-0.02, 1.02)
    sync.set_ylabel("fraction of slip events (stiff)")
    sync.set_title("solid: multi-slips; dashed: all interfaces", fontsize=6, loc="right")
    sync.text(0.02, 0.93, "paper (N = 1458): periodic multi-slips of all layers", transform=sync.transAxes,
              fontsize=6)
    periodic.axhline(1.0, color="0.7", lw=0.6, ls=":")
    periodic.set_ylim(bottom=0)
    periodic.set_ylabel(r"CV of $\Delta\gamma$ between slips")
    periodic.set_title("solid: stiff; dashed: compliant (0: periodic, 1: Poisson)", fontsize=6, loc="right")
    periodic.text(0.02, 0.04, "paper: stiff periodic, compliant less periodic", transform=periodic.transAxes,
                  fontsize=6)
    table = front_speed_by_size(fronts)
    table = table[(table["n"] == 2) & (table["ok"] > 0)]
    if not table.empty:
        for regime, marker in (("stiff", "o"), ("compliant", "s")):
            rows = table[table["regime"] == regime]
            style = {"color": "k" if regime == "stiff" else "0.5", "marker": marker,
                     "label": f"{regime} (fits: {int(rows['ok'].sum())} of {int(rows['events'].sum())})"}
            _series(speed, rows, "c_f_median", "c_f_error", style)
    c_d = math.sqrt(1 + 4.5)  # the P-wave speed of the plane model with K = 4.5 G, in c_s
    for value in (1.0, math.sqrt(2.0), c_d):
        speed.axhline(value, color="0.7", lw=0.6, ls=":")
    speed.plot([PAPER_N], [PAPER_C_F], "*", color="#d7301f", ms=9, label=r"paper: $c_f \approx 2 c_s$")
    speed.set_ylabel(r"$c_f / c_s$ ($n = 2$)")
    speed.legend(fontsize=6, frameon=False, loc="lower right")
    drops = drop_shift_by_size(events)
    drops = drops[np.isfinite(drops["shift"].to_numpy(dtype=float))]
    for n in sorted(drops["n"].unique()):
        rows = drops[drops["n"] == n].assign(shift=lambda t: 100 * t["shift"],
                                             error=lambda t: 100 * t["detectable_shift"] / DETECTABLE_IN_ERRORS)
        _series(shift, rows, "shift", "error", {**n_style(n), "label": f"$n = {n}$ vs 1"})
    shift.axhline(0.0, color="0.7", lw=0.6)
    shift.plot([PAPER_N], [0.0], "*", color="#d7301f", ms=9, label="paper: no $n$ dependence")
    shift.set_ylabel(r"shift of $\langle\Delta\mu_a\rangle$ [%] (compliant, single)")
    shift.legend(fontsize=6, frameon=False)
    for ax in axes.ravel():
        ax.set_xscale("log")
        ax.set_xlabel("$N$")
        ax.axvline(PAPER_N, color="0.8", lw=0.6, ls="--")
    sync.legend(fontsize=6, frameon=False, loc="best")
    label_panels(axes, "abcd")
    save_figure(fig, output)
