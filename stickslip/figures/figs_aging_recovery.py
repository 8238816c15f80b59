"""SI figure "Aging recovery": what the aging estimators return on rate-and-state twins whose
interfaces' aging rate b is known, and how the mean B_a changes with n.

Input: the ``experiment-events`` files of ``rate-state-lever`` stack runs with several pairs
(``rs_a``, ``rs_b``) (workflow/config/rate-state-aging-scan.yaml, or benchmarks/aging_scan.py); a
pair is read from the run's parameters (one value for every interface, or their mean). Two series:
``b`` varied at fixed ``b - a`` and at fixed ``a`` (pairs on neither are drawn grey); the pair on
both belongs to both.

(a) The paper's fit through the origin, ``dmu = B ln(T/T0)``, and the fit with a free intercept,
``dmu = c + B ln(T/T0)``, on every single stack slip of a pair (all n, all seeds), against the b put
in, with the line ``B = b``; error bars: the fits' standard errors.
(b) The mean of ``B_a = dmu_a / ln(T_a/T0)`` of interface 1 against n, relative to n = 1, for the pairs
at fixed ``b - a`` (colour: ``a``); error bars: standard error over the runs (seeds) of that mean.
"""

import dataclasses
import json

import numpy as np
import pandas as pd

from .. import h5io, registry
from ..experiment import aging
from ..formats import event_table
from ..formats.analysis_file import open_analysis_file
from ..plugin_params import param
from .experimental_data import EVENTS, load_slips
from .experimental_panels import single_slips
from .plotting import label_panels, legend_outside, plot_against_n
from .style import plt, save_figure

__all__ = ["run_pairs", "recovery", "draw", "run"]

VERSION = "1"


@dataclasses.dataclass(frozen=True)
class FigsAgingRecoveryParams:
    """Which pairs form the two series, and the aging time scale."""

    b_minus_a: float = param(0.006, "b - a of the series at fixed b - a", exclusive_minimum=0)
    fixed_a: float = param(0.013, "a of the series at fixed a", exclusive_minimum=0)
    t0: float = param(aging.T0, "time scale T0 of the aging law", unit="s", exclusive_minimum=0)


def run_pairs(paths):
    """The rate-and-state pair of every run: ``file``, ``rs_a``, ``rs_b`` (means over the interfaces)
    from the ``params`` attribute the events files copy from their runs."""
    rows = []
    for path in sorted(map(str, paths)):
        with open_analysis_file(path, event_table.FORMAT) as f:
            text = f.attrs.get("params")
        values = json.loads(text) if text is not None else {}
        if "rs_a" not in values or "rs_b" not in values:
            raise h5io.FileFormatError(f"{path}: no rate-and-state parameters (rs_a, rs_b) among its run's params "
                                       f"(not a rate-state-lever run?)")
        rows.append((path, float(np.mean(values["rs_a"])), float(np.mean(values["rs_b"]))))
    return pd.DataFrame(rows, columns=["file", "rs_a", "rs_b"])


def recovery(slips, pairs, t0=aging.T0):
    """Aging fits and the mean B_a of interface 1 per n, for every pair.

    Parameters
    ----------
    slips : pandas.DataFrame
        :func:`~stickslip.figures.experimental_data.load_slips` of the runs.
    pairs : pandas.DataFrame
        :func:`run_pairs` of the same files.
    t0 : float
        [s].

    Returns
    -------
    fits : pandas.DataFrame
        One row per pair: ``rs_a``, ``rs_b``, ``B_origin``, ``B_origin_error``, ``B_intercept``,
        ``B_intercept_error``, ``c``, ``c_error``, ``slips``.
    rates : pandas.DataFrame
        One row per pair and n: ``rs_a``, ``rs_b``, ``n``, ``mean`` (of B_a of a = 1), ``sem`` (over the
        runs), ``relative`` and ``relative_error`` (divided by the pair's n = 1 mean).
    """
    stack = single_slips(slips, "stack").merge(pairs, on="file")
    stack = stack[np.isfinite(stack["T"].to_numpy(dtype=float))]
    fits, rates = [], []
    for (rs_a, rs_b), part in stack.groupby(["rs_a", "rs_b"]):
        origin = aging.fit_aging(part["T"], part["dmu"], t0=t0, fit="origin")
        free = aging.fit_aging(part["T"], part["dmu"], t0=t0, fit="intercept")
        fits.append((rs_a, rs_b, origin.B, origin.B_error, free.B, free.B_error, free.c, free.c_error, len(part)))
        first = part[part["interface"] == 1]
        per_run = first.groupby(["n", "file"])["B_a"].mean().groupby("n")
        table = per_run.agg(["mean", "sem"]).reset_index()
        reference = table.loc[table["n"] == table["n"].min(), "mean"].iloc[0]
        rates.append(table.assign(rs_a=rs_a, rs_b=rs_b, relative=table["mean"] / reference,
                                  relative_error=table["sem"] / reference))
    fits = pd.DataFrame(fits, columns=["rs_a", "rs_b", "B_origin", "B_origin_error", "B_intercept",
                                       "B_intercept_error", "c", "c_error", "slips"])
    return fits, pd.concat(rates, ignore_index=True)


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    events = inputs[EVENTS]
    fits, rates = recovery(load_slips(events), run_pairs(events), params.t0)
    at_difference = np.isclose(fits["rs_b"] - fits["rs_a"], params.b_minus_a)
    at_a = np.isclose(fits["rs_a"], params.fixed_a)
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 3.6), layout="constrained")
    ax = axes[0]
    groups = (("difference", at_difference, "o", True, 0.0, f"$b - a = {params.b_minus_a:g}$"),
              ("a", at_a, "s", False, 0.0003, f"$a = {params.fixed_a:g}$"),    # shifted right: the shared pair
              ("other", ~at_difference & ~at_a, "x", True, 0.0, "other pairs"))
    for fit, colour, name in (("B_origin", "black", "through the origin"), ("B_intercept", "tab:red", "free intercept")):
        for key, chosen, marker, filled, shift, label in groups:
            if not chosen.any():
                continue
            part = fits[chosen].sort_values("rs_b")
            ax.errorbar(part["rs_b"] + shift, part[fit], yerr=part[fit + "_error"], linestyle="none", marker=marker,
                        markersize=5, capsize=2, color=colour, markerfacecolor=colour if filled else "none",
                        gid=f"{fit}:{key}", label=f"{name}, {label}")
    b = np.linspace(0.0, fits["rs_b"].max() * 1.1, 2)
    ax.plot(b, b, color="grey", linestyle="--", linewidth=0.8, label="$B = b$")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.set_xlabel("$b$ put in (mean over the interfaces)")
    ax.set_ylabel("$B$ recovered")
    legend_outside(ax)
    ax = axes[1]
    chosen = fits[at_difference].sort_values("rs_a")
    colours = plt.get_cmap("plasma")(np.linspace(0.0, 0.85, max(len(chosen), 1)))
    for colour, pair in zip(colours, chosen.itertuples()):
        part = rates[(rates["rs_a"] == pair.rs_a) & (rates["rs_b"] == pair.rs_b)].sort_values("n")
        plot_against_n(ax, part["n"], part["relative"], part["relative_error"].fillna(0.0), color=colour,
                       marker="o", markersize=4, gid=f"a={pair.rs_a:g}",
                       label=f"$a = {pair.rs_a:g}$, $b = {pair.rs_b:g}$")
    ax.axhline(1.0, color="grey", linewidth=0.5)
    ax.set_xlabel("$n$")
    ax.set_ylabel(r"mean $B_1$ / mean $B_1$ at $n = 1$")
    legend_outside(ax, title=f"$b - a = {params.b_minus_a:g}$")
    label_panels(axes)
    return fig


@registry.register("figure", "figS-aging-recovery", VERSION, FigsAgingRecoveryParams, inputs=(EVENTS,),
                   summary="SI aging recovery (rate-and-state twins of known b): (a) B from the fit through the "
                           "origin (black) and with a free intercept (red) on every stack slip, against the b put "
                           "in, at fixed b - a (filled) and at fixed a (open); error bars: the fits' standard "
                           "errors; (b) mean B_a of interface 1 against n relative to n = 1 at fixed b - a; error "
                           "bars: standard error over the runs (seeds)")
def run(params, inputs, output):
    """SI aging recovery: B recovered against b put in; mean B_1 against n at fixed b - a."""
    save_figure(draw(params, inputs), output)
