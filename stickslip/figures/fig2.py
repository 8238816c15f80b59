"""Fig. 2 (numerical results): stress against shear, rho(s) and the stress drops.

(a, b) Macroscopic stress Sigma [sig0] against lever rotation gamma [gamma0] in the steady
state of one run with ``n_trace`` interfaces, stiff (a) and compliant (b) driving:
microscopic events as black dots, single-slip stress drops in the colour of the slipping
interface, multi-slip drops black. (c) rho(s), the fraction of slip events involving s
interfaces, for every n: stiff dashed, compliant solid. (f) Density of the stress drop
Delta mu_a [sig0] of the slipping interface in single-slip events, compliant driving, every n,
with Welch's test of equal means between the smallest and the largest n and the shift it
would detect (:mod:`stickslip.statistics.mean_shift`), beside the paper's finding (no shift).
Beyond the paper's figure (:mod:`stickslip.events.periodicity`), against n, stiff dashed and
compliant solid, mean over the runs (seeds) with one standard error: (g) periodicity, the
coefficient of variation of the shear increment Delta gamma between consecutive slip events
(0: periodic, 1: Poisson) and of the stress drops Delta Sigma; (h) synchronisation, the
fraction of slip events in which all n interfaces slip and the multi-slip fraction rho(s > 1).
Runs at the paper's Phi (5e-4 stiff, 5e-7 compliant) are pooled by (regime, n) over seeds; the
panel texts give N, Phi and the number of events.
"""

import dataclasses

import numpy as np

from ..events.extraction import interfaces_in, slip_fractions
from ..events.analysis_files import group_runs, pooled
from ..statistics.mean_shift import shift_test
from ..plugin_params import param
from ..registry import register
from .numerical_common import REGIME_LINESTYLE, read_inputs, run_phi
from .periodicity_panels import MEASURE_LABEL, MEASURE_MARKER, periodicity_summary, plot_measure
from .plotting import label_panels, n_style, plot_density, range_edges
from .style import interface_color, plt, save_figure

__all__ = ["Fig2Params", "plot_stress_trace", "run"]

NAME = "fig2"


@dataclasses.dataclass(frozen=True)
class Fig2Params:
    """Parameters of Fig. 2."""

    n_trace: int = param(3, "interfaces of the run shown in panels a and b (the paper: 3)", minimum=1)
    slips_shown: int = param(15, "slip events shown in panels a and b, from the start of the steady state", minimum=1)
    bins: int = param(15, "bins of the stress-drop density (panel f)", minimum=2)


def plot_stress_trace(ax, increments, N, slips_shown):
    """Plot Sigma against gamma in the steady state, events marked as in the paper.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    increments : pandas.DataFrame
        The ``increments`` table of a numerical-events file.
    N : int
        Blocks per interface (a slipping interface has ``A_a == N``).
    slips_shown : int
        The window ends at the ``slips_shown``-th slip event of the steady state.

    Returns
    -------
    int
        Number of slip events shown.
    """
    steady = increments[increments["steady"].to_numpy(dtype=bool)]
    if steady.empty:
        ax.text(0.5, 0.5, "steady state not reached", transform=ax.transAxes, ha="center")
        ax.set_xticks([])
        ax.set_yticks([])
        return 0
    slip_rows = np.flatnonzero(steady["kind"].isin(("single", "multi")).to_numpy())
    end = slip_rows[slips_shown - 1] + 1 if slip_rows.size >= slips_shown else len(steady)
    first = increments.index.get_loc(steady.index[0])
    # start one increment early so that the first drop is drawn from its loaded state
    window = increments.iloc[max(first - 1, 0):first + end]
    gamma, sigma = window["gamma"].to_numpy(dtype=float), window["sigd"].to_numpy(dtype=float)
    kind = window["kind"].to_numpy()
    ax.plot(gamma, sigma, color="0.6", lw=0.8, zorder=1)
    micro = kind == "micro"
    ax.plot(gamma[micro], sigma[micro], "k.", ms=2.5, zorder=2)
    slipping = window[[f"A_a{a}" for a in interfaces_in(window)]].to_numpy() == N
    rows = np.flatnonzero(np.isin(kind, ("single", "multi")))
    rows = rows[rows >= 1]  # the window starts with the loaded state before the first steady increment
    for row in rows:
        color = interface_color(np.argmax(slipping[row]) + 1) if kind[row] == "single" else "k"
        ax.plot(gamma[row - 1:row + 1], sigma[row - 1:row + 1], color=color, lw=1.8, zorder=3,
                solid_capstyle="butt")
    ax.set_xlabel(r"$\gamma / \gamma_0$")
    ax.set_ylabel(r"$\Sigma / \sigma_0$")
    return int(rows.size)


def _trace_panel(ax, groups, regime, n, slips_shown):
    files = groups.get((regime, n), [])
    ax.set_title(f"{regime}, $n = {n}$", fontsize=9)
    if not files:
        ax.text(0.5, 0.5, f"no {regime} run with n = {n}", transform=ax.transAxes, ha="center")
        ax.set_xticks([])
        ax.set_yticks([])
        return
    run_file = files[0]
    increments = run_file.tables["increments"]
    plot_stress_trace(ax, increments, int(run_file.attrs["N"]), slips_shown)
    for a in range(1, n + 1):
        ax.plot([], [], color=interface_color(a), lw=1.8, label=f"$a = {a}$")
    ax.plot([], [], color="k", lw=1.8, label="multi-slip")
    ax.plot([], [], "k.", ms=3, label="microscopic")
    ax.legend(fontsize=6, loc="lower right", ncol=2, frameon=False)
    ax.text(0.98, 0.97, f"$N = {run_file.attrs['N']}$, $\\Phi = {run_phi(run_file.attrs):.1e}$, "
            f"seed {run_file.attrs.get('seed', '?')}", transform=ax.transAxes, ha="right", va="top", fontsize=7)


def _rho_panel(ax, groups):
    for (regime, n), files in groups.items():
        slips = pooled(files, "slips")
        if slips.empty:
            continue
        rho = slip_fractions(slips, n)
        ax.plot(np.arange(1, n + 1), rho, ls=REGIME_LINESTYLE[regime], markersize=4,
                markerfacecolor="white" if regime == "stiff" else None, **{**n_style(n), "label": None})
    ax.set_xlabel("$s$")
    ax.set_ylabel(r"$\rho(s)$")
    ax.set_ylim(-0.02, 1.02)
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.plot([], [], "k--", label="stiff")
    ax.plot([], [], "k-", label="compliant")
    ax.legend(fontsize=7, frameon=False, loc="upper right")


def _drop_panel(ax, groups, bins):
    samples = {}
    for (regime, n), files in groups.items():
        if regime != "compliant":
            continue
        per = pooled(files, "slip_interfaces")
        if per.empty:
            continue
        dmu = per["dmu_sig0"].to_numpy()[~per["multi"].to_numpy(dtype=bool)]
        samples[n] = dmu
        plot_density(ax, dmu, range_edges(dmu, bins), **{**n_style(n), "label": f"$n = {n}$ ({dmu.size})"})
    ax.set_xlabel(r"$\Delta\mu_a / \sigma_0$")
    ax.set_ylabel(r"$P(\Delta\mu_a)$")
    ax.set_title("compliant, single slips", fontsize=9)
    ax.legend(fontsize=7, frameon=False, title="(events)", title_fontsize=6)
    if len(samples) >= 2:
        low, high = min(samples), max(samples)
        test = shift_test(samples[low], samples[high])
        ax.text(0.98, 0.55, f"$n = {high}$ vs ${low}$: mean {100 * test['shift']:+.0f} %\n"
                f"Welch $p = {test['p_value']:.2g}$\n"
                f"detectable: {100 * test['detectable_shift']:.0f} %\n"
                "paper ($N = 1458$): no $n$ dependence", transform=ax.transAxes,
                ha="right", va="top", fontsize=6)


def _periodicity_panels(ax_periodic, ax_sync, files):
    """(g) CV of Delta gamma and of Delta Sigma, (h) system-spanning and multi-slip fractions, against n."""
    summary = periodicity_summary(files, {"regime": lambda f: f.regime, "n": lambda f: f.n})
    for ax, measures in ((ax_periodic, ("interval_cv", "drop_cv")), (ax_sync, ("spanning_fraction", "multi_fraction"))):
        for (regime,), rows in summary.groupby(["regime"]):
            rows = rows.sort_values("n")
            for measure, color in zip(measures, ("k", "0.55")):
                plot_measure(ax, rows, "n", measure, color=color, ls=REGIME_LINESTYLE[regime],
                             marker=MEASURE_MARKER[measure], markerfacecolor="white" if regime == "stiff" else color)
        for measure, color in zip(measures, ("k", "0.55")):
            ax.plot([], [], color=color, marker=MEASURE_MARKER[measure], ms=4, ls="none", label=MEASURE_LABEL[measure])
        ax.set_xlabel("$n$")
        ax.xaxis.get_major_locator().set_params(integer=True)
        ax.legend(fontsize=6, frameon=False, loc="upper right")
    runs = ", ".join(f"{regime} {int(rows['runs'].max())}" for (regime,), rows in summary.groupby(["regime"]))
    box = {"facecolor": "white", "alpha": 0.8, "lw": 0}
    ax_periodic.axhline(1.0, color="0.7", lw=0.6, ls=":")
    ax_periodic.set_ylim(bottom=0)
    ax_periodic.set_ylabel("coefficient of variation")
    ax_periodic.set_title("periodicity", fontsize=9)
    ax_periodic.text(0.02, 0.03, f"0: periodic, 1: Poisson; runs (seeds) per point: {runs}\n"
                     "paper: stiff periodic, compliant less periodic", transform=ax_periodic.transAxes, fontsize=6,
                     bbox=box)
    ax_sync.set_ylim(-0.02, 1.02)
    ax_sync.set_ylabel("fraction of slip events")
    ax_sync.set_title("synchronisation", fontsize=9)
    ax_sync.text(0.02, 0.5, "paper: stiff slips involve all layers", transform=ax_sync.transAxes, fontsize=6,
                 bbox=box)


@register("figure", NAME, "4", Fig2Params, inputs=("analysis:numerical-events",))
def run(params, inputs, output):
    """Fig. 2: Sigma(gamma) stiff and compliant, rho(s), P(Delta mu_a) compliant; periodicity and synchronisation."""
    files = read_inputs(inputs, "analysis:numerical-events", ("increments", "slips", "slip_interfaces", "periodicity"),
                        NAME)
    groups = group_runs(files)
    fig, axes = plt.subplots(3, 2, figsize=(7.0, 8.4), constrained_layout=True)
    _trace_panel(axes[0, 0], groups, "stiff", params.n_trace, params.slips_shown)
    _trace_panel(axes[0, 1], groups, "compliant", params.n_trace, params.slips_shown)
    _rho_panel(axes[1, 0], groups)
    _drop_panel(axes[1, 1], groups, params.bins)
    _periodicity_panels(axes[2, 0], axes[2, 1], files)
    label_panels(axes, "abcfgh")
    save_figure(fig, output)
