"""Beyond the paper: junction aging in the fem model (docs/numerical-analysis.md, "Junction aging").

Reads the ``thermal-events`` outputs of an aging study (:func:`stickslip.summaries.aging_summary.load_aging_runs`)
and groups the runs by what the files say (``n_interfaces``, ``temperature``, ``drive_rate``,
``junction_strengthening``):

(a) Paired holds (n = 1 at ``drive_rate``, hold load ``below``): the first-slip peak after a hold of T_w
    minus the mean over the hold times of its state, mean and standard error over the states of the
    runs of each setting (``lambda``, T, aging off), with the mean of the states' slopes in ln T_w.
(b) The same for the second slip after the hold (the memory of the hold erased?), base setting.
(c) One block's strengthening: the mean widening of the slipping interface's junctions at the peak
    against T_w (base), beside the peak (collective factor: the ratio of the slopes).
(d) Aging against the hold load: the slope of (a) for every ``below`` against the held stress, and the
    share of the interface's blocks that precursors moved before the peak.
(e) The steady-state peak stress against the drive rate (n = 1, base with and without aging).
(f) The paper's estimator on the stacks with aging: Delta mu_a against ln(T_a / T0), log-binned means per
    n, the fit through the origin (dashed) and with an intercept (solid) of the pooled single slips.
(g) Aftershocks: mean cumulative number of events per hold moving blocks of interface b after slips of
    a (post-slip) and in the controls, every pair of the stacks with aging at ``drive_rate``.
"""

import dataclasses

import numpy as np
import pandas as pd

from .. import registry
from ..summaries.aging_summary import estimator, load_aging_runs, mean_sem, paired_slopes, select_runs, trial_peaks
from ..experiment.aging import log_binned
from ..h5io import FileFormatError
from ..plugin_params import param
from .plotting import label_panels, n_style
from .style import interface_color, plt, save_figure

__all__ = ["FigsAgingParams", "THERMAL", "centred", "draw", "run"]

VERSION = "1"

#: Input category: the ``thermal-events`` outputs of the study's fem runs.
THERMAL = "analysis:thermal-events"


@dataclasses.dataclass(frozen=True)
class FigsAgingParams:
    """Which runs the panels show."""

    drive_rate: float = param(2e-8, "drive rate of the runs of panels (a)-(d), (f), (g)", unit="eps0/time",
                              exclusive_minimum=0.0)
    temperature: float = param(1e-3, "temperature of the base runs", unit="G eps0^2 h^2", exclusive_minimum=0.0)
    strengthening: float = param(5.0, "junction_strengthening of the base runs", unit="eps0 / (G eps0^2 h^2)",
                                 exclusive_minimum=0.0)
    below: float = param(0.02, "hold load of panels (a)-(c)", unit="eps0", minimum=0.0)


def centred(peaks, column="peak"):
    """Per hold time: mean and standard error over the states of ``column`` minus its state's mean (hold times > 0).

    Returns
    -------
    pandas.DataFrame
        ``hold_time``, ``mean``, ``sem``, ``count``.
    """
    chosen = peaks[(peaks["hold_time"] > 0) & ~peaks["failed_in_hold"].astype(bool)].copy()
    keys = [key for key in ("run", "state", "below", "interface") if key in chosen]
    chosen["y"] = chosen[column] - chosen.groupby(keys)[column].transform("mean")
    rows = [(t, *mean_sem(group["y"])) for t, group in chosen.groupby("hold_time")]
    return pd.DataFrame(rows, columns=["hold_time", "mean", "sem", "count"])


def _holds_panel(ax, peaks, label, style, column="peak"):
    if peaks.empty:
        return
    table = centred(peaks, column)
    slope, error, states = paired_slopes(peaks, column)
    ax.errorbar(table["hold_time"], table["mean"], yerr=table["sem"], capsize=2,
                label=f"{label}: {slope:.4f} ± {error:.4f} per e-fold ({states})", **style)


def _legend(ax, size):
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=size)


def _base(runs, params):
    return select_runs(runs, n=1, drive_rate=params.drive_rate, temperature=params.temperature,
                   strengthening=params.strengthening)


def draw(params, inputs):
    """The figure (module docstring) from the inputs of :func:`run`."""
    runs = load_aging_runs(item.path for item in inputs[THERMAL])
    if runs.empty:
        raise FileFormatError(f"figure 'figS-aging': no thermal run among the {THERMAL} inputs")
    fig, axes = plt.subplots(2, 4, figsize=(17.0, 7.6), layout="constrained")
    ax = axes.ravel()
    at = dict(n=1, drive_rate=params.drive_rate)
    settings = [("base", dict(temperature=params.temperature, strengthening=params.strengthening), "C0"),
                ("lambda x 2", dict(temperature=params.temperature, strengthening=2 * params.strengthening), "C1"),
                ("T x 2", dict(temperature=2 * params.temperature, strengthening=params.strengthening), "C2"),
                ("no aging", dict(temperature=params.temperature, strengthening=0.0), "0.4")]
    for label, where, color in settings:
        peaks = trial_peaks(select_runs(runs, **at, **where))
        peaks = peaks[np.isclose(peaks["below"], params.below)] if not peaks.empty else peaks
        _holds_panel(ax[0], peaks, label, {"color": color, "marker": "o"})
    base = trial_peaks(_base(runs, params))
    base_below = base[np.isclose(base["below"], params.below)] if not base.empty else base
    second = trial_peaks(_base(runs, params), slip=2)
    second = second[np.isclose(second["below"], params.below)] if not second.empty else second
    _holds_panel(ax[1], base_below, "first slip", {"color": "C0", "marker": "o"})
    _holds_panel(ax[1], second, "second slip", {"color": "C3", "marker": "s"})
    _holds_panel(ax[2], base_below, "peak [sig0]", {"color": "C0", "marker": "o"})
    _holds_panel(ax[2], base_below, "widening [eps0]", {"color": "C4", "marker": "^"}, column="widening")
    for axis, title in zip(ax[:3], ("(peak - state mean) [sig0]", "(peak - state mean) [sig0]",
                                    "(value - state mean)")):
        axis.set_xscale("log")
        axis.set_xlabel(r"hold $T_w$ [$1/\nu$]")
        axis.set_ylabel(title)
        _legend(axis, 6)
    ax[0].set_title("paired holds, n = 1", fontsize=8)
    ax[1].set_title("memory of the hold, base", fontsize=8)
    ax[2].set_title("one block's strengthening and the peak", fontsize=8)
    if not base.empty:
        rows = []
        for below, part in base.groupby("below"):
            slope, error, _ = paired_slopes(part)
            stress = mean_sem(part.drop_duplicates(["run", "state"])["mu_start"])
            rows.append((stress[0], stress[1], slope, error, mean_sem(part["precursors"])[0]))
        rows = np.asarray(rows)
        ax[3].errorbar(rows[:, 0], rows[:, 2], xerr=rows[:, 1], yerr=rows[:, 3], marker="o", capsize=2, color="C0")
        for x, y, share in zip(rows[:, 0], rows[:, 2], rows[:, 4]):
            ax[3].annotate(f"precursors {share:.2f}", (x, y), fontsize=6, xytext=(3, 3), textcoords="offset points")
    ax[3].set_xlabel(r"held stress $\mu_{start}$ [$\sigma_0$]")
    ax[3].set_ylabel(r"$B$ of the paired holds [$\sigma_0$ per e-fold]")
    ax[3].set_title("aging against the hold load", fontsize=8)
    for strengthening, color in ((params.strengthening, "C0"), (0.0, "0.4")):
        chosen = select_runs(runs, n=1, temperature=params.temperature, strengthening=strengthening)
        for rate, group in chosen.groupby("drive_rate"):
            peaks = np.concatenate([item.tables["slip_events"]["mu_before_sig0"].to_numpy() for item in group["data"]])
            mean, sem, _ = mean_sem(peaks)
            ax[4].errorbar([rate], [mean], yerr=[sem], marker="o", color=color, capsize=2)
        ax[4].plot([], [], "o", color=color, label=f"lambda = {strengthening:g}")
    ax[4].set_xscale("log")
    ax[4].set_xlabel("drive rate [eps0 per unit time]")
    ax[4].set_ylabel(r"steady-state peak [$\sigma_0$]")
    _legend(ax[4], 6)
    for n in (1, 2, 3):
        chosen = select_runs(runs, n=n, drive_rate=params.drive_rate, temperature=params.temperature,
                         strengthening=params.strengthening)
        if chosen.empty:
            continue
        slips = pd.concat([item.tables["slip_events"] for item in chosen["data"]], ignore_index=True)
        single = slips[~slips["multi"].astype(bool) & np.isfinite(slips["T_fe"])]
        T0 = float(chosen["T0"].iloc[0])
        bins = log_binned(single["T_fe"], single["dmu_sig0"])
        style = n_style(n)
        ax[5].errorbar(bins["T"] / T0, bins["dmu_mean"], yerr=bins["dmu_std"] / np.sqrt(bins["count"]), capsize=2,
                       **style)
        x = np.geomspace(max(single["T_fe"].min(), T0), single["T_fe"].max(), 20)
        for kind, line in (("origin", "--"), ("intercept", "-")):
            fit = estimator(single, T0, kind)
            if np.isfinite(fit["B"]):
                ax[5].plot(x / T0, fit["c"] + fit["B"] * np.log(x / T0), line, color=style.get("color"), lw=0.8)
    ax[5].set_xscale("log")
    ax[5].set_xlabel(r"$T_a$ [$1/\nu$]")
    ax[5].set_ylabel(r"$\Delta\mu_a$ [$\sigma_0$]")
    ax[5].set_title("the paper's estimator (aging on)", fontsize=8)
    _legend(ax[5], 6)
    stacks = runs[(runs["n"] > 1) & np.isclose(runs["drive_rate"], params.drive_rate)
                  & np.isclose(runs["strengthening"], params.strengthening)]
    times = np.geomspace(1.0, 1e12, 60)
    for item in stacks["data"]:
        trials, events = item.tables.get("aftershock_trials"), item.tables.get("aftershocks")
        if trials is None or trials.empty:
            continue
        for (a, kind), group in trials.groupby(["a", "kind"]):
            for b in range(1, item.n + 1):
                counts = [np.searchsorted(np.sort(events.loc[(events["trial"] == trial) & (events[f"A_{b}"] > 0),
                                                              "t"].to_numpy()), times, side="right")
                          for trial in group["trial"]]
                ax[6].plot(times, np.mean(counts, axis=0), "-" if kind == 0 else ":", color=interface_color(b),
                           label=f"n = {item.n}, {a} -> {b}, {('post-slip', 'control')[kind]}")
    ax[6].set_xscale("log")
    ax[6].set_xlabel(r"time since the hold's start [$1/\nu$]")
    ax[6].set_ylabel("events per hold")
    ax[6].set_title("aftershocks (solid) and controls (dotted)", fontsize=8)
    _legend(ax[6], 5)
    ax[7].axis("off")
    label_panels(ax[:7])
    return fig


@registry.register("figure", "figS-aging", VERSION, FigsAgingParams, inputs=(THERMAL,),
                   summary="beyond the paper: junction aging in the fem model")
def run(params, inputs, output):
    """Draw figS-aging (module docstring)."""
    save_figure(draw(params, inputs), output)
