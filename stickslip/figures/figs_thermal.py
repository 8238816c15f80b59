"""Beyond the paper: finite temperature in the fem model (docs/numerical-analysis.md, "Finite temperature").

Reads the ``thermal-events`` outputs of the fem runs of a study (thermal and athermal) and the
``experiment-events`` outputs of its virtual experiment, and groups the runs by what the files say
(``protocol``, ``n_interfaces``, ``drive_rate``, ``hold_times``):

(a) Slide-hold-slide in one run (the thermal n = 1 run with ``hold_times``): Delta mu against the
    waiting time T since the previous slip, which the holds spread over decades; log-binned means
    (standard error) and the project's aging fits through the origin and with an intercept, with
    ``T0 = 1 / attempt_rate``.
(b) Paired hold trials (the thermal n = 1 run at ``drive_rate`` without holds): the peak stress
    after a hold of T_w minus the peak after none, from the same state, mean and standard error
    over the states; the weighted line in ln T_w with its slope.
(c) The mechanism: the number of blocks with a forward barrier below E (in units of T), per state,
    at the start of the holds and at their end, for every T_w; dotted lines at E = T ln(nu T_w), the
    barrier that a hold of T_w crosses.
(d) Creep at the held load: slip of the interface during the longest holds against the time since
    the hold's start, in units of the mean slip of a slip event; mean over the states (a trial ends
    at its slip).
(e) Delta mu_a against T_a, numerics (the thermal stacks at ``drive_rate``, n = 1, 2, 3) and the
    virtual experiment (its stacks, n <= 3) on one axis: each scaled by its own n = 1 means; single
    slips, log-binned means and the intercept fit of each.
(f) The drive rate: mean peak stress and stress drop of the thermal n = 1 runs without holds against
    their drive rate, the athermal run (T = 0) as lines.
(g) Slow slip R_slow = 1 - sum(dR_slips) / R_tot per interface against n: thermal stacks, athermal
    stacks, virtual experiment (mean and standard error over seeds).
"""

import dataclasses

import numpy as np
import pandas as pd

from .. import registry
from ..events.analysis_files import read_analysis_file
from ..experiment.aging import fit_aging, log_binned
from ..h5io import FileFormatError
from ..plugin_params import param
from .experimental_data import EVENTS, load_interfaces, load_slips
from .plotting import a_style, hollow, label_panels, legend_outside, n_style, plot_against_n
from .style import plt, save_figure

__all__ = ["FigsThermalParams", "THERMAL", "load_runs", "hold_differences", "hold_slope", "barrier_counts",
           "creep_curves",
           "creep_curve", "creep_rate",
           "scaled_slips", "rate_table", "slow_slip_table", "draw", "run"]

VERSION = "1"

#: Input category of the fem runs' analyses.
THERMAL = "analysis:thermal-events"

_TABLES = ("slip_events", "interfaces", "holds", "creep", "barriers")


@dataclasses.dataclass(frozen=True)
class FigsThermalParams:
    """Which thermal runs the panels show."""

    drive_rate: float = param(2e-8, "drive rate of the thermal runs of panels (b)-(e) and (g)", unit="eps0/time",
                              exclusive_minimum=0.0)
    bins_per_decade: int = param(4, "log bins of the waiting times per decade (panels a, e; the aging fits' default)",
                                 minimum=1)


def load_runs(paths):
    """The ``thermal-events`` files of a study, one row per run.

    Returns
    -------
    pandas.DataFrame
        ``file``, ``thermal`` (bool), ``n``, ``drive_rate`` (NaN athermal), ``holds`` (bool: the run has
        hold cycles of its own), ``T0``, ``temperature``, and ``data`` (the
        :class:`stickslip.events.analysis_files.AnalysisFile`).
    """
    rows = []
    for path in sorted(map(str, paths)):
        item = read_analysis_file(path, "event-table", _TABLES)
        thermal = bool(item.attrs.get("thermal", False))
        params = item.attrs.get("params", {})
        rows.append({"file": path, "thermal": thermal, "n": item.n,
                     "drive_rate": float(item.attrs["drive_rate"]) if thermal else np.nan,
                     "holds": bool(params.get("hold_times")), "T0": float(item.attrs.get("T0", np.nan)),
                     "temperature": float(item.attrs.get("temperature", 0.0)), "data": item})
    if not rows:
        raise FileFormatError(f"figure 'figS-thermal': no input file of category '{THERMAL}'")
    return pd.DataFrame(rows)


def _one(runs, where, what):
    chosen = runs[where]
    if chosen.empty:
        raise FileFormatError(f"figure 'figS-thermal': no {what} among the {THERMAL} inputs")
    return chosen.iloc[0]


def _at_rate(runs, params):
    return runs["thermal"] & ~runs["holds"] & np.isclose(runs["drive_rate"], params.drive_rate, rtol=1e-9, atol=0)


def hold_differences(holds):
    """Peak after each hold minus the peak after no hold from the same state.

    Returns
    -------
    pandas.DataFrame
        One row per hold time > 0: ``hold_time``, ``mean``, ``sem``, ``count`` (states with both a
        finite peak), ``failed`` (fraction of trials that slipped during the hold).
    """
    peaks = holds.pivot_table(index="state", columns="hold_time", values="peak")
    failed = holds.groupby("hold_time")["failed_in_hold"].mean()
    rows = []
    for hold_time in peaks.columns[peaks.columns > 0]:
        diff = (peaks[hold_time] - peaks[0.0]).dropna()
        rows.append({"hold_time": hold_time, "mean": diff.mean(),
                     "sem": diff.std(ddof=1) / np.sqrt(diff.size) if diff.size > 1 else np.nan,
                     "count": diff.size, "failed": failed[hold_time]})
    return pd.DataFrame(rows, columns=["hold_time", "mean", "sem", "count", "failed"])


def hold_slope(table):
    """Weighted least-squares line of :func:`hold_differences` against ``ln(hold_time)`` (weights 1 / sem^2).

    Returns
    -------
    tuple[float, float, float]
        Slope [sig0 per e-fold of T_w], its standard error, intercept; NaN with fewer than two hold times.
    """
    sem = table["sem"].to_numpy(dtype=float)
    ok = np.isfinite(sem) & (sem > 0)
    if ok.sum() < 2:
        return np.nan, np.nan, np.nan
    x, y, w = np.log(table["hold_time"].to_numpy()[ok]), table["mean"].to_numpy()[ok], 1.0 / sem[ok] ** 2
    design = np.column_stack([x, np.ones_like(x)])
    cov = np.linalg.inv(design.T @ (w[:, None] * design))
    coef = cov @ design.T @ (w * y)
    return float(coef[0]), float(np.sqrt(cov[0, 0])), float(coef[1])


def barrier_counts(holds, barriers, grid):
    """Mean number of blocks per state with a barrier below each value of ``grid`` [T].

    Returns
    -------
    dict
        ``"start"``: array [len(grid)] at the start of the holds (every trial of a state starts alike);
        ``hold_time -> array`` at the end of the holds of that time.
    """
    joined = barriers.merge(holds[["trial", "state", "hold_time"]], on="trial")

    def counts(frame, column):
        per_trial = [np.searchsorted(np.sort(group[column].to_numpy()), grid, side="right")
                     for _, group in frame.groupby("trial")]
        return np.mean(per_trial, axis=0) if per_trial else np.full(len(grid), np.nan)

    first = joined[joined["hold_time"] == joined["hold_time"].min()]
    out = {"start": counts(first, "start")}
    for hold_time, frame in joined.groupby("hold_time"):
        if hold_time > 0:
            out[hold_time] = counts(frame, "end")
    return out


def creep_curves(holds, creep, times, interface=1):
    """Slip of ``interface`` since the start of each of the longest holds, at ``times`` after it.

    A trial contributes until it slips (its slip event ends it) or its hold ends (NaN after). The
    shorter holds of a state follow the same path as its longest one up to their end (paired trials
    draw the same numbers), so only the longest holds are used.

    Returns
    -------
    numpy.ndarray
        [trials, len(times)] [well hops of the interface's blocks].
    """
    longest = holds[holds["hold_time"] == holds["hold_time"].max()]
    curves = []
    for _, trial in longest.iterrows():
        steps = creep[creep["trial"] == trial["trial"]].sort_values("t")
        end = trial["t_slip"] if trial["failed_in_hold"] else trial["hold_time"]
        values = np.concatenate([[0.0], steps[f"R_{interface}"].to_numpy()])
        curve = values[np.searchsorted(steps["t"].to_numpy(), times, side="right")]
        curves.append(np.where(times <= end, curve, np.nan))
    return np.asarray(curves, dtype=float).reshape(-1, len(times))


def creep_curve(holds, creep, times, interface=1):
    """Mean of :func:`creep_curves` over the trials that have not slipped yet (NaN where none)."""
    curves = creep_curves(holds, creep, times, interface)
    counts = np.sum(np.isfinite(curves), axis=0)
    return np.where(counts > 0, np.nansum(curves, axis=0) / np.maximum(counts, 1), np.nan)


def creep_rate(holds, creep, times, interface=1):
    """Slope of the mean creep against ``ln t`` (least squares over ``times``), with its jackknife error over the trials.

    Returns
    -------
    tuple[float, float, float]
        Slip per e-fold of time [well hops], its standard error (NaN with fewer than 3 trials), and the
        line's value at ``ln t = 0``.
    """
    curves = creep_curves(holds, creep, times, interface)

    def line(rows):
        counts = np.sum(np.isfinite(rows), axis=0)
        mean = np.nansum(rows, axis=0) / np.maximum(counts, 1)
        keep = counts > 0
        return np.polyfit(np.log(times[keep]), mean[keep], 1) if keep.sum() >= 2 else np.full(2, np.nan)

    value, intercept = line(curves)
    k = len(curves)
    if k < 3:
        return value, np.nan, intercept
    left_out = np.array([line(np.delete(curves, i, axis=0))[0] for i in range(k)])
    return value, float(np.sqrt((k - 1) / k * np.sum((left_out - left_out.mean()) ** 2))), intercept


def scaled_slips(runs, params, experiment):
    """Single slips of the numerical stacks (at ``drive_rate``) and of the virtual experiment's stacks (n <= 3),
    each with ``T`` and ``dmu`` scaled by the means of its own n = 1 slips.

    Returns
    -------
    pandas.DataFrame
        ``source`` ("numerics" or "experiment"), ``n``, ``a``, ``T``, ``dmu``, ``T_scaled``, ``dmu_scaled``.
    """
    parts = []
    stacks = runs[_at_rate(runs, params)]
    for _, row in stacks.iterrows():
        slips = row["data"].tables["slip_events"]
        slips = slips[~slips["multi"].to_numpy(dtype=bool) & np.isfinite(slips["T_fe"].to_numpy(dtype=float))]
        parts.append(pd.DataFrame({"source": "numerics", "n": row["n"], "a": slips["interface"].to_numpy(),
                                   "T": slips["T_fe"].to_numpy(dtype=float),
                                   "dmu": slips["dmu_sig0"].to_numpy(dtype=float)}))
    if experiment is not None:
        exp = experiment[(experiment["protocol"] == "stack") & (experiment["n"] <= 3)
                         & ~experiment["multi"].to_numpy(dtype=bool) & np.isfinite(experiment["T"].to_numpy(dtype=float))]
        parts.append(pd.DataFrame({"source": "experiment", "n": exp["n"].to_numpy(), "a": exp["interface"].to_numpy(),
                                   "T": exp["T"].to_numpy(dtype=float), "dmu": exp["dmu"].to_numpy(dtype=float)}))
    table = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=["source", "n", "a", "T", "dmu"])
    for source, group in table.groupby("source"):
        reference = group[group["n"] == 1]
        if reference.empty:
            raise FileFormatError(f"figure 'figS-thermal': no n = 1 slips of the {source} to scale by")
        table.loc[group.index, "T_scaled"] = group["T"] / reference["T"].mean()
        table.loc[group.index, "dmu_scaled"] = group["dmu"] / reference["dmu"].mean()
    return table


def rate_table(runs):
    """Mean peak stress and stress drop (single slips, standard errors) of the n = 1 runs without holds.

    Returns
    -------
    pandas.DataFrame
        ``drive_rate`` (NaN: the athermal run), ``peak``, ``peak_sem``, ``dmu``, ``dmu_sem``, ``slips``.
    """
    rows = []
    for _, row in runs[(runs["n"] == 1) & ~runs["holds"]].iterrows():
        slips = row["data"].tables["slip_events"]
        slips = slips[~slips["multi"].to_numpy(dtype=bool)]
        count = len(slips)
        rows.append({"drive_rate": row["drive_rate"], "peak": slips["mu_before_sig0"].mean(),
                     "peak_sem": slips["mu_before_sig0"].std(ddof=1) / np.sqrt(count),
                     "dmu": slips["dmu_sig0"].mean(), "dmu_sem": slips["dmu_sig0"].std(ddof=1) / np.sqrt(count),
                     "slips": count})
    return pd.DataFrame(rows).sort_values("drive_rate", na_position="last").reset_index(drop=True)


def slow_slip_table(runs, params, experiment_interfaces):
    """``R_slow`` per interface and n: thermal stacks at ``drive_rate``, athermal stacks, virtual experiment.

    Returns
    -------
    pandas.DataFrame
        ``source`` ("thermal", "athermal", "experiment"), ``n``, ``a``, ``R_slow``, ``sem`` (over seeds; NaN for
        one run).
    """
    parts = []
    for source, where in (("thermal", _at_rate(runs, params)), ("athermal", ~runs["thermal"])):
        for _, row in runs[where].iterrows():
            table = row["data"].tables["interfaces"]
            parts.append(pd.DataFrame({"source": source, "n": row["n"], "a": table["interface"].to_numpy(),
                                       "R_slow": table["R_slow"].to_numpy(dtype=float)}))
    if experiment_interfaces is not None:
        exp = experiment_interfaces[(experiment_interfaces["protocol"] == "stack") & (experiment_interfaces["n"] <= 3)
                                    & experiment_interfaces["driven"].to_numpy(dtype=bool)]
        parts.append(pd.DataFrame({"source": "experiment", "n": exp["n"].to_numpy(), "a": exp["interface"].to_numpy(),
                                   "R_slow": exp["R_slow"].to_numpy(dtype=float)}))
    table = pd.concat(parts, ignore_index=True)
    grouped = table.groupby(["source", "n", "a"])["R_slow"]
    out = grouped.mean().rename("R_slow").to_frame()
    out["sem"] = grouped.std(ddof=1) / np.sqrt(grouped.size())
    return out.reset_index()


def _aging_fits(T, dmu, t0, bins_per_decade):
    fits = {}
    for kind in ("origin", "intercept"):
        try:
            fits[kind] = fit_aging(T, dmu, t0=t0, fit=kind, bins_per_decade=bins_per_decade)
        except ValueError:
            fits[kind] = None
    return fits


def _fit_label(fit, scale=1.0):
    if fit is None:
        return "too few bins"
    text = f"B = {fit.B / scale:.3g} ± {fit.B_error / scale:.2g}"
    return text + (f", c = {fit.c / scale:.3g} ± {fit.c_error / scale:.2g}" if fit.kind == "intercept" else "")


def _panel_shs(ax, runs, params):
    row = _one(runs, runs["thermal"] & runs["holds"] & (runs["n"] == 1), "thermal n = 1 run with hold cycles")
    slips = row["data"].tables["slip_events"]
    slips = slips[~slips["multi"].to_numpy(dtype=bool) & np.isfinite(slips["T_fe"].to_numpy(dtype=float))]
    T, dmu, t0 = slips["T_fe"].to_numpy(float), slips["dmu_sig0"].to_numpy(float), row["T0"]
    ax.plot(T / t0, dmu, "o", color="0.6", markersize=2.5, markeredgewidth=0, label=f"{len(slips)} slips")
    bins = log_binned(T / t0, dmu, bins_per_decade=params.bins_per_decade)
    ax.errorbar(bins["T"], bins["dmu_mean"], yerr=bins["dmu_std"] / np.sqrt(bins["count"]), fmt="s", color="black",
                markersize=3.5, capsize=2, label="binned mean (s.e.)")
    fits = _aging_fits(T / t0, dmu, 1.0, params.bins_per_decade)
    grid = np.geomspace(T.min() / t0, T.max() / t0, 50)
    for kind, style in (("origin", ":"), ("intercept", "--")):
        if fits[kind] is not None:
            ax.plot(grid, fits[kind](grid), style, color="C3", label=f"{kind}: {_fit_label(fits[kind])}")
    ax.set_xscale("log")
    ax.set_xlabel(r"$\nu T$ (waiting time since the previous slip)")
    ax.set_ylabel(r"$\Delta\mu_1$ ($\sigma_0$)")
    ax.set_title("slide-hold-slide, one run, n = 1", fontsize=8)
    return fits


def _panel_holds(ax, holds, t0):
    table = hold_differences(holds)
    x = table["hold_time"].to_numpy() / t0
    ax.errorbar(x, table["mean"], yerr=table["sem"], fmt="o", color="black", capsize=2,
                label=f"{int(table['count'].max()) if len(table) else 0} states, paired")
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    slope, error, intercept = hold_slope(table)
    if np.isfinite(slope):
        times = table["hold_time"].to_numpy()
        ax.plot(x, slope * np.log(times) + intercept, "--", color="C3",
                label=rf"slope {slope:.2g} ± {error:.1g} $\sigma_0$ per e-fold")
    for xi, fraction in zip(x, table["failed"]):
        ax.annotate(f"{fraction:.0%}", (xi, 0), textcoords="offset points", xytext=(0, -12), ha="center", fontsize=5.5,
                    color="C0")
    ax.set_xscale("log")
    ax.set_xlabel(r"$\nu T_w$ (hold; % slipped during it)")
    ax.set_ylabel(r"peak$(T_w)$ $-$ peak$(0)$ ($\sigma_0$)")
    ax.set_title("paired holds below the athermal threshold", fontsize=8)
    return table


def _panel_barriers(ax, holds, barriers, t0):
    grid = np.linspace(0.0, 40.0, 161)
    counts = barrier_counts(holds, barriers, grid)
    ax.plot(grid, counts["start"], color="black", linewidth=1.5, label="hold start")
    hold_times = sorted(k for k in counts if k != "start")
    for k, hold_time in enumerate(hold_times):
        color = plt.cm.viridis(k / max(1, len(hold_times) - 1))
        ax.plot(grid, counts[hold_time], color=color, linewidth=1.0, label=rf"after $\nu T_w$ = {hold_time / t0:.0e}")
        ax.axvline(np.log(hold_time / t0), color=color, linestyle=":", linewidth=0.8)
    ax.set_xlabel(r"forward barrier $E$ ($T$)")
    ax.set_ylabel(r"blocks with a barrier $< E$ (mean per state)")
    ax.set_title(r"mechanism: depletion below $T\ln(\nu T_w)$ (dotted)", fontsize=8)
    return counts


def _panel_creep(ax, holds, creep, t0, slip_size):
    longest = holds["hold_time"].max()
    times = np.geomspace(1.0 * t0, longest, 60)
    curve = creep_curve(holds, creep, times)
    trials = holds[holds["hold_time"] == longest]
    ax.plot(times / t0, curve / slip_size, color="black",
            label=f"{len(trials)} holds of {longest / t0:.0e}, {int(trials['failed_in_hold'].sum())} ended by a slip")
    rate, error, intercept = creep_rate(holds, creep, times)
    ax.plot(times / t0, (rate * np.log(times) + intercept) / slip_size, "--", color="C3",
            label=f"{rate / slip_size:.3g} ± {error / slip_size:.2g} per e-fold of t")
    ax.set_xscale("log")
    ax.set_xlabel(r"$\nu t$ since the hold's start")
    ax.set_ylabel("slip / mean slip of a slip event")
    ax.set_title("creep at the held load", fontsize=8)
    return times, curve


def _panel_scaled(ax, table, params):
    fits = {}
    for source, filled in (("numerics", True), ("experiment", False)):
        part = table[table["source"] == source]
        for n in sorted(part["n"].unique()):
            mine = part[part["n"] == n]
            style = n_style(n)
            style = style if filled else hollow(style, 3.0)
            ax.plot(mine["T_scaled"], mine["dmu_scaled"], linestyle="none",
                    **{**style, "markersize": style.get("markersize", 2.5), "alpha": 0.6,
                       "label": f"{source} {style['label']} ({len(mine)})"})
        if part.empty:
            continue
        fit = _aging_fits(part["T_scaled"].to_numpy(float), part["dmu_scaled"].to_numpy(float), 1.0,
                          params.bins_per_decade)["intercept"]
        fits[source] = fit
        if fit is not None:
            grid = np.geomspace(part["T_scaled"].min(), part["T_scaled"].max(), 40)
            ax.plot(grid, fit(grid), "-" if filled else "--", color="black",
                    label=f"{source}, intercept fit: slope {fit.B:.2f} ± {fit.B_error:.2f}")
    ax.set_xscale("log")
    ax.set_xlabel(r"$T_a / \langle T_a \rangle_{n=1}$")
    ax.set_ylabel(r"$\Delta\mu_a / \langle \Delta\mu_a \rangle_{n=1}$")
    ax.set_title("stacks: numerics (T > 0) and virtual experiment", fontsize=8)
    return fits


def _panel_rate(ax, table):
    thermal = table[np.isfinite(table["drive_rate"])]
    athermal = table[~np.isfinite(table["drive_rate"])]
    for column, color, label in (("peak", "C0", "peak stress"), ("dmu", "C1", r"stress drop $\Delta\mu_1$")):
        ax.errorbar(thermal["drive_rate"], thermal[column], yerr=thermal[f"{column}_sem"], fmt="o-", color=color,
                    capsize=2, label=f"{label}, T > 0")
        for _, row in athermal.iterrows():
            ax.axhline(row[column], color=color, linestyle="--", linewidth=0.9, label=f"{label}, T = 0")
    ax.set_xscale("log")
    ax.set_xlabel(r"drive rate $\dot\gamma$ ($\epsilon_0$ per unit time)")
    ax.set_ylabel(r"$\sigma_0$")
    ax.set_title("n = 1: the drive rate (single slips, s.e.)", fontsize=8)


def _panel_slow(ax, table):
    offsets = {"thermal": 0.0, "athermal": -0.2, "experiment": 0.2}
    for (source, a), part in table.groupby(["source", "a"]):
        style = a_style(a)
        if source == "athermal":
            style = hollow(style, 4.0)
        elif source == "experiment":
            style = {**hollow(style, 3.0), "marker": "x" if a % 2 else "+"}
        part = part.sort_values("n")
        errors = part["sem"].to_numpy(float) if np.any(np.isfinite(part["sem"])) else None
        plot_against_n(ax, part["n"].to_numpy() + offsets[source], part["R_slow"].to_numpy(), errors,
                       **{**style, "label": f"{source} {style['label']}"})
    ax.set_xticks([1, 2, 3])
    ax.set_xlabel(r"$n$ (athermal left, thermal centre, virtual experiment right)")
    ax.set_ylabel(r"$R_\mathrm{slow}$")
    ax.set_title("slow slip", fontsize=8)


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes."""
    runs = load_runs(inputs[THERMAL])
    experiment = load_slips(inputs[EVENTS]) if inputs.get(EVENTS) else None
    experiment_interfaces = load_interfaces(inputs[EVENTS]) if inputs.get(EVENTS) else None
    fig, axes = plt.subplots(2, 4, figsize=(17.0, 7.6), layout="constrained")
    _panel_shs(axes[0, 0], runs, params)
    held = _one(runs, _at_rate(runs, params) & (runs["n"] == 1), f"thermal n = 1 run at drive_rate {params.drive_rate:g}")
    tables = held["data"].tables
    if tables["holds"].empty:
        raise FileFormatError(f"figure 'figS-thermal': {held['file']} has no hold trials")
    _panel_holds(axes[0, 1], tables["holds"], held["T0"])
    _panel_barriers(axes[0, 2], tables["holds"], tables["barriers"], held["T0"])
    interface = tables["interfaces"].set_index("interface").loc[1]
    _panel_creep(axes[0, 3], tables["holds"], tables["creep"], held["T0"], interface["dR_sum"] / interface["n_slips"])
    _panel_scaled(axes[1, 0], scaled_slips(runs, params, experiment), params)
    _panel_rate(axes[1, 1], rate_table(runs))
    _panel_slow(axes[1, 2], slow_slip_table(runs, params, experiment_interfaces))
    axes[1, 3].axis("off")
    first = runs[runs["thermal"]].iloc[0]
    axes[1, 3].text(0.0, 1.0, "\n".join([
        "fem, finite temperature (kinetic Monte Carlo)",
        f"N = {first['data'].attrs['N']}, Phi = {first['data'].attrs['phi']:.1e} ({first['data'].attrs['regime']})",
        f"T = {first['temperature']:g} G eps0^2 h^2, nu = 1 / T0 = {1 / first['T0']:g}",
        f"drive rate (b-e, g): {params.drive_rate:g} eps0 per unit time",
        "holds (b-d): 0.02 eps0 below the athermal threshold",
        "docs/numerical-analysis.md, 'Finite temperature'"]), va="top", fontsize=7, transform=axes[1, 3].transAxes)
    for ax in axes.ravel()[:-1]:
        legend_outside(ax, fontsize=5.0) if ax in (axes[1, 0], axes[1, 2]) else ax.legend(fontsize=5.0, frameon=False)
    label_panels(axes.ravel()[:-1])
    return fig


@registry.register("figure", "figS-thermal", VERSION, FigsThermalParams, inputs=(THERMAL, EVENTS),
                   summary="beyond the paper, finite temperature in the fem model: (a) slide-hold-slide in one run, "
                           "dmu against the waiting time with the aging fits; (b) paired holds, peak(T_w) - peak(0); "
                           "(c) barrier depletion during holds; (d) creep at the held load; (e) dmu_a against T_a of "
                           "numerical and virtual stacks on one axis; (f) peak and drop against the drive rate; "
                           "(g) R_slow thermal, athermal, virtual experiment")
def run(params, inputs, output):
    """Finite temperature in the fem model: aging, holds, barriers, creep, stacks, drive rate, slow slip."""
    save_figure(draw(params, inputs), output)
