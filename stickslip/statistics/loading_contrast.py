"""An aging estimator beside the paper's: the contrast of an interface's loading between stacks.

The paper's fit (:mod:`.estimator`) regresses the drops ``dmu_a`` on ``ln T_a`` of single slips. Within one loading
path the waiting time is made by the drop itself (the disorder law: a stronger threshold takes longer to reach,
``T = dmu / (d mu / dt)``), so that regression reads the disorder law; pooled over interfaces it reads their
differences in strength. Neither is aging. A variation of ``T`` that the interface's threshold does not make is
needed: in the lab, the stack. The lever loads interface ``a`` of a stack of ``n`` at ``(n + a)(n - a + 1) / 2`` times
its rate alone, and other slips interrupt it, while its thresholds stay those of the same surfaces. Then, per
interface, the mean drop of each stack follows the mean log waiting time with the aging rate,

    <dmu>_(a, n) = c_a + B <ln(T / T0)>_(a, n),

(the paper's law averaged over a stack's slips: the threshold's fluctuation averages to the same value in every
stack), with one intercept ``c_a`` per interface (its strength, which the pooled fit confounds with aging).
:func:`loading_contrast` fits that line through the stacks' means, the instrumental-variable estimate of ``B`` with
the stack as the instrument (Wald's estimate for two stacks). Nothing in it is fitted to the slips of one stack.

What it needs, and where it fails (docs/numerical-analysis.md, "Slip dissonance"): (1) at least two loading paths per
interface with different ``<ln T>``; one path (n = 1 alone) identifies nothing. (2) The loading path must change the
drop only through the contacts' age: a direct dependence of the peak on the loading rate (rate-and-state's
``a ln V``, thermally activated depinning) enters as ``B - a_direct d ln(rate) / d <ln T>``, and a post-slip level
that depends on the age enters as such (:func:`stickslip.statistics.estimator.lab_slips` with ``direct``; tested).
(3) Reach: with two paths whose ``<ln T>`` differ by ``delta`` and drops scattered by ``sd``, the estimate's error is
``sd sqrt(2 / m) / delta`` for ``m`` slips per path (:func:`slips_needed`).
"""

import math

import numpy as np
import pandas as pd

from .lines import fit_line

__all__ = ["CONTRAST_COLUMNS", "group_means", "loading_contrast", "slips_needed"]

#: Keys of :func:`loading_contrast`.
CONTRAST_COLUMNS = ["B", "B_error", "c", "interfaces", "groups", "slips", "lnT_range", "reason"]


def group_means(slips, *, t0, interface="interface", group="n", T="T", dmu="dmu", min_slips=5):
    """Mean drop and mean ``ln(T / t0)`` of the single slips of every (interface, group), with standard errors.

    Parameters
    ----------
    slips : pandas.DataFrame
        One row per slip: ``multi`` (bool; multi-slips are left out), the columns named by ``interface``, ``group``,
        ``T`` (waiting time [unit of ``t0``]) and ``dmu`` (drop).
    t0 : float
    interface, group, T, dmu : str
        Column names.
    min_slips : int
        Groups with fewer single slips with a waiting time are left out.

    Returns
    -------
    pandas.DataFrame
        ``interface``, ``group``, ``slips``, ``x`` (mean ``ln(T / t0)``), ``x_error``, ``y`` (mean drop),
        ``y_error`` (standard errors of the means).
    """
    single = slips[~slips["multi"].to_numpy(dtype=bool)]
    values = single[T].to_numpy(dtype=float)
    ok = np.isfinite(values) & (values > 0) & np.isfinite(single[dmu].to_numpy(dtype=float))
    frame = pd.DataFrame({"interface": single[interface].to_numpy()[ok], "group": single[group].to_numpy()[ok],
                          "x": np.log(values[ok] / t0), "y": single[dmu].to_numpy(dtype=float)[ok]})
    table = frame.groupby(["interface", "group"]).agg(slips=("x", "size"), x=("x", "mean"), x_sd=("x", "std"),
                                                       y=("y", "mean"), y_sd=("y", "std")).reset_index()
    table = table[table["slips"] >= min_slips]
    root = np.sqrt(table["slips"].to_numpy(dtype=float))
    return table.assign(x_error=table["x_sd"] / root, y_error=table["y_sd"] / root)[
        ["interface", "group", "slips", "x", "x_error", "y", "y_error"]].reset_index(drop=True)


def loading_contrast(slips, *, t0, interface="interface", group="n", T="T", dmu="dmu", min_slips=5):
    """The aging rate from the contrast of each interface's loading paths (module docstring).

    The means of :func:`group_means` are fitted by ``y = c_a + B x``, one intercept per interface, with their errors
    on both axes (:func:`.lines.fit_line`).

    Parameters
    ----------
    slips : pandas.DataFrame
        As :func:`group_means`.
    t0 : float
        The law's time [unit of ``T``] (the slope does not depend on it; the intercepts do).
    interface, group, T, dmu : str
    min_slips : int

    Returns
    -------
    dict
        :data:`CONTRAST_COLUMNS`: ``B``, ``B_error``, ``c`` (the mean intercept over interfaces), ``interfaces`` and
        ``groups`` (means) used, ``slips``, ``lnT_range`` (the largest range of the group means' ``ln T`` of an
        interface: the instrument's reach), ``reason`` ("" or why there is no estimate).
    """
    means = group_means(slips, t0=t0, interface=interface, group=group, T=T, dmu=dmu, min_slips=min_slips)
    counts = means.groupby("interface")["group"].transform("size")
    means = means[counts >= 2]
    out = dict.fromkeys(CONTRAST_COLUMNS, math.nan) | {"interfaces": int(means["interface"].nunique()),
                                                        "groups": len(means), "slips": int(means["slips"].sum()),
                                                        "reason": ""}
    if means.empty:
        return out | {"reason": "no interface has two loading paths with enough slips"}
    spans = means.groupby("interface")["x"].agg(np.ptp)
    out["lnT_range"] = float(spans.max())
    if not spans.max() > 0:
        return out | {"reason": "the loading paths do not differ in <ln T>"}
    line = fit_line(means["x"], means["x_error"], means["y"], means["y_error"], groups=means["interface"].to_numpy())
    return out | {"B": line["B"], "B_error": line["B_error"], "c": float(np.mean(list(line["intercepts"].values())))}


def slips_needed(drop_sd, B, lnT_shift, *, relative_error=0.25):
    """Slips per loading path that two paths need for the contrast to measure ``B`` to ``relative_error``.

    Wald's estimate ``(<dmu>_2 - <dmu>_1) / (<ln T>_2 - <ln T>_1)`` has the standard error
    ``drop_sd sqrt(2 / m) / lnT_shift`` for ``m`` slips per path (the means of ``ln T`` taken as exact); setting it
    to ``relative_error B`` gives ``m``.

    Parameters
    ----------
    drop_sd : float
        Standard deviation of an interface's drops within a path [unit of the drops].
    B : float
        The aging rate to measure [unit of the drops per e-fold of T].
    lnT_shift : float
        How far the paths' mean ``ln T`` lie apart [e-folds].
    relative_error : float
        The standard error wanted, relative to ``B``.

    Returns
    -------
    float
        ``2 (drop_sd / (relative_error B lnT_shift))^2`` (inf where the paths do not differ).
    """
    scale = relative_error * abs(B) * abs(lnT_shift)
    return 2.0 * (drop_sd / scale) ** 2 if scale > 0 else math.inf
