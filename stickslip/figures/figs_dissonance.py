"""Beyond the paper: its test of aging replayed in the fem model (docs/numerical-analysis.md, "Slip dissonance").

Reads the ``waiting-times`` outputs of a study's fem runs (:func:`stickslip.summaries.dissonance_summary.load_runs`)
and, if the study has them, its ``thermal-events`` outputs with hold trials:

(a) P(T_1) of interface 1 against n (the paper's Fig. 5b) for the athermal drive setting with the broadest waiting
    times pooled over n (solid) and for the paper's compliant Phi = 5e-7 (dashed); T in the drive since the previous
    slip [eps0] (the waiting time in units of 1 / drive rate).
(b) std(ln T_a) per interface pooled over n against Phi, every athermal setting (free levers open), with the
    target 0.7 and the paper's ~1.3.
(c) The loading rate of interface 1 against n while nothing yields, relative to n = 1, per Phi, with the lab's
    n (n + 1) / 2.
(d) The paper's estimator on the thermal runs: Delta mu against ln(T_fe / T0), log-binned means of the single
    slips of every setting (aging on and off), with the fits through the origin (dashed) and with an intercept
    (solid).
(e) The true B (paired holds, first peak against the contacts' age at the peak, n = 1, each hold load) against
    lambda, with the fits through the origin and with an intercept of (d) at the same lambda.
"""

import dataclasses

import numpy as np

from .. import registry
from ..summaries.aging_summary import load_aging_runs, paired_slopes
from ..summaries.dissonance_summary import (estimator_runs, hold_peaks, load_runs, loading_rates, scan_table,
                                         setting_of)
from ..statistics.estimator import estimate
from ..experiment.aging import log_binned
from ..h5io import FileFormatError
from ..plugin_params import param
from .plotting import label_panels, legend_outside, log_edges, plot_density
from .style import n_color, plt, save_figure

__all__ = ["FigsDissonanceParams", "WAITS", "THERMAL", "draw", "run"]

VERSION = "1"

#: Input categories: the waiting times of every fem run, and the hold trials of the thermal ones.
WAITS = "analysis:waiting-times"
THERMAL = "analysis:thermal-events"

#: The paper's compliant Phi (the reference of panel (a)).
PAPER_PHI = 5e-7


@dataclasses.dataclass(frozen=True)
class FigsDissonanceParams:
    """Which lines the panels mark."""

    target: float = param(0.7, "the go/no-go target of std(ln T_a) per interface", minimum=0.0)
    paper_spread: float = param(1.3, "the paper's std(ln T_a) (two decades of T_a)", minimum=0.0)


def _athermal(runs):
    chosen = runs[~runs["thermal"]].copy()
    chosen["setting"] = [setting_of(row) for _, row in chosen.iterrows()]
    return chosen


def _waits_panel(ax, runs, pooled):
    """(a) P(T_1) per n for the broadest setting and for the paper's Phi."""
    if runs.empty:
        ax.text(0.5, 0.5, "no athermal runs", ha="center", transform=ax.transAxes)
        return
    first = pooled[pooled["interface"] == 1]
    broadest = first.loc[first["std_lnT"].idxmax(), "setting"] if len(first) else None
    paper = runs.loc[np.isclose(runs["phi"], PAPER_PHI, rtol=0.3) & (runs["drive"] == "fixed-lever"), "setting"]
    for setting, dashes in ((broadest, "-"), (paper.iloc[0] if len(paper) else None, "--")):
        if setting is None:
            continue
        for _, run in runs[runs["setting"] == setting].sort_values("n").iterrows():
            slips = run["data"].tables["slip_events"]
            T = slips.loc[slips["interface"] == 1, "wait_drive"].to_numpy(dtype=float)
            T = T[np.isfinite(T) & (T > 0)]
            if T.size > 2:
                plot_density(ax, T, log_edges(T, 6), logarithmic=True, color=n_color(run["n"]), linestyle=dashes,
                             label=f"n = {run['n']}, {setting}")
    ax.set_xscale("log")
    ax.set_xlabel(r"$T_1$: drive since the previous slip [$\epsilon_0$]")
    ax.set_ylabel(r"$P(T_1)$")
    ax.set_title("waiting times of interface 1 against n", fontsize=8)
    legend_outside(ax)


def _spread_panel(ax, runs, pooled, params):
    """(b) std(ln T_a) pooled over n against Phi."""
    phi = runs.drop_duplicates("setting").set_index("setting")["phi"]
    free = runs.drop_duplicates("setting").set_index("setting")["drive"] == "free-lever"
    for a, group in pooled.groupby("interface"):
        x = phi.reindex(group["setting"]).to_numpy()
        hollow = free.reindex(group["setting"]).to_numpy(dtype=bool)
        for mask, face in ((~hollow, None), (hollow, "none")):
            if mask.any():
                ax.errorbar(x[mask] * (1 + 0.08 * (a - 1)), group["std_lnT"].to_numpy()[mask],
                            yerr=group["std_lnT_error"].to_numpy()[mask], marker="o", linestyle="none", capsize=2,
                            color=plt.get_cmap("tab10")(a - 1), mfc=face,
                            label=f"a = {a}" if face is None else None)
    ax.axhline(params.target, color="k", linestyle=":", label=f"target {params.target:g}")
    ax.axhline(params.paper_spread, color="0.5", linestyle="--", label=f"paper ~{params.paper_spread:g}")
    ax.set_xscale("log")
    ax.set_xlabel(r"$\Phi$ (free lever: open)")
    ax.set_ylabel(r"std$(\ln T_a)$, pooled over n")
    ax.set_title("the go/no-go scan", fontsize=8)
    legend_outside(ax)


def _rates_panel(ax, runs, study_of):
    """(c) loading rate of interface 1 against n relative to n = 1, per Phi (fixed lever)."""
    fixed = runs[runs["drive"] == "fixed-lever"]
    for setting, group in fixed.groupby("setting"):
        rows = []
        for _, run in group.sort_values("n").iterrows():
            path = study_of(run["file"])
            if path is not None:
                rows.append((run["n"], loading_rates(path)[0]))
        rows = np.asarray(rows)
        if len(rows) and 1 in rows[:, 0]:
            ax.plot(rows[:, 0], rows[:, 1] / rows[rows[:, 0] == 1, 1][0], marker="o", label=setting.split(" ", 1)[1])
    n = np.arange(1, 6)
    ax.plot(n, n * (n + 1) / 2, "k:", label="lab n (n + 1) / 2")
    ax.set_xlabel("n")
    ax.set_ylabel(r"loading rate of $a = 1$ / at n = 1")
    ax.set_title("loading rate while nothing yields", fontsize=8)
    legend_outside(ax)


def _estimator_panel(ax, slips):
    """(d) binned Delta mu against ln(T / T0) with both fits, every thermal setting."""
    if slips.empty:
        ax.text(0.5, 0.5, "no thermal runs", ha="center", transform=ax.transAxes)
        return
    for k, (setting, group) in enumerate(slips.groupby("setting")):
        single = group[~group["multi"].astype(bool)]
        T0 = float(group["T0"].iloc[0])
        bins = log_binned(single["T_fe"], single["dmu_sig0"])
        color = plt.get_cmap("tab10")(k)
        if bins.empty:
            continue
        ax.errorbar(bins["T"] / T0, bins["dmu_mean"], yerr=bins["dmu_std"] / np.sqrt(bins["count"]), marker="o",
                    linestyle="none", color=color, capsize=2, label=setting.split(", ", 1)[-1])
        x = np.geomspace(bins["T_low"].min(), bins["T_high"].max(), 20) / T0
        for fit, style in (("origin", "--"), ("intercept", "-")):
            result = estimate(single["T_fe"], single["dmu_sig0"], t0=T0, fit=fit)
            if np.isfinite(result["B"]):
                ax.plot(x, result["c"] + result["B"] * np.log(x), style, color=color, linewidth=0.8)
    ax.set_xscale("log")
    ax.set_xlabel(r"$T_a / T_0$")
    ax.set_ylabel(r"$\Delta\mu_a$ [$\sigma_0$]")
    ax.set_title("estimator: dashed origin, solid intercept", fontsize=8)
    legend_outside(ax)


def _truth_panel(ax, thermal, estimates):
    """(e) the true B of the paired holds against lambda, n = 1, with the estimator beside it."""
    if thermal.empty:
        ax.text(0.5, 0.5, "no hold trials", ha="center", transform=ax.transAxes)
        return
    runs = thermal[(thermal["n"] == 1) & (thermal["trials"] == 1)]
    curves = {}  # (T, below) -> [(lambda, B, error)]
    for (T, lam), group in runs.groupby(["temperature", "strengthening"]):
        peaks = hold_peaks(group["data"])
        if peaks.empty:
            continue
        for below, held in peaks.groupby("below"):
            slope, error, states = paired_slopes(held, t_min=0.0, time="age")
            if states:
                curves.setdefault((T, below), []).append((lam, slope, error))
    for ((T, below), rows), marker in zip(sorted(curves.items()), "osD^v<>"):
        rows = np.asarray(rows)
        ax.errorbar(rows[:, 0], rows[:, 1], yerr=rows[:, 2], marker=marker, capsize=2,
                    label=f"true B, T {T:g}, below {below:g}")
    labelled = set()
    for (T, lam, fit), value in sorted(estimates.items()):
        ax.plot([lam], [value], marker="x" if fit == "origin" else "+", color="k", linestyle="none",
                label=None if fit in labelled else f"estimator ({fit}), n = 1")
        labelled.add(fit)
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    ax.set_xlabel(r"$\lambda$ [$\epsilon_0$ per $G\epsilon_0^2h^2$]")
    ax.set_ylabel(r"$B$ [$\sigma_0$ per e-fold]")
    ax.set_title("true B against the estimator", fontsize=8)
    legend_outside(ax)


def draw(params, inputs):
    """The figure (module docstring) from the inputs of :func:`run`."""
    runs = load_runs(item.path for item in inputs[WAITS])
    if runs.empty:
        raise FileFormatError(f"figure 'figS-dissonance': no fem run among the {WAITS} inputs")
    parents = {str(item.path): getattr(item, "parent", None) for item in inputs[WAITS]}

    def study_of(path):
        parent = parents.get(str(path))
        return getattr(parent, "path", None)

    athermal = _athermal(runs)
    _, pooled = scan_table(athermal)
    thermal = load_aging_runs(item.path for item in inputs.get(THERMAL, []))
    slips = estimator_runs(runs)
    estimates = {}  # (temperature, lambda, fit) -> B of the runs n = 1
    for (T, lam), group in slips[slips["n"] == 1].groupby(["temperature", "strengthening"]):
        single = group[~group["multi"].astype(bool)]
        for fit in ("origin", "intercept"):
            value = estimate(single["T_fe"], single["dmu_sig0"], t0=float(group["T0"].iloc[0]), fit=fit)["B"]
            if np.isfinite(value):
                estimates[(T, lam, fit)] = value
    fig, axes = plt.subplots(2, 3, figsize=(15.0, 7.4), layout="constrained")
    ax = axes.ravel()
    _waits_panel(ax[0], athermal, pooled)
    _spread_panel(ax[1], athermal, pooled, params)
    _rates_panel(ax[2], athermal, study_of)
    _estimator_panel(ax[3], slips)
    _truth_panel(ax[4], thermal, estimates)
    ax[5].axis("off")
    label_panels(ax[:5])
    return fig


@registry.register("figure", "figS-dissonance", VERSION, FigsDissonanceParams, inputs=(WAITS, THERMAL),
                   summary="beyond the paper: the paper's test of aging replayed in the fem model")
def run(params, inputs, output):
    """Draw figS-dissonance (module docstring)."""
    save_figure(draw(params, inputs), output)
