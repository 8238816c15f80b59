"""The aging estimator calibrated against the truth: the lab's eye and clock, spreads, errors over seeds.

The paper measures the aging rate from the drops ``dmu_a`` against the waiting times ``T_a`` of its slips
(:mod:`.estimator`); a model knows the true rate from paired holds. To compare them as the lab would, this
module gives:

- **the lab's clock** (:func:`lab_clock`): the paper takes ``T0 = 1 s``, and its pooled slips (Fig. 5c) have
  ``<ln(T / T0)> ~ 4.6`` (:data:`LAB_MEAN_LN`); a model's own microscopic time (``1 / nu``) puts its slips
  16-18 e-folds above ``T0``. The lab-like clock is the ``T0`` at which the slips that the lab would resolve have
  the paper's ``<ln(T / T0)>``: one model time per lab second;
- **the lab's eye** (:func:`merge_unresolved`): the lab detects a slip on positions filmed at 5 frames per second
  averaged over 5 frames (:mod:`stickslip.experiment.detection`): slips of one interface closer than that window,
  :data:`LAB_RESOLUTION` = 1 s, are one slip to it, with the drop from the first one's peak to the last one's
  post-slip stress and the waiting time from the previous resolved slip;
- **the spread of ln T** (:func:`log_spread`): its standard deviation with the normal-theory error
  ``std / sqrt(2 (m - 1))`` and a bootstrap error, and the robust spread ``IQR / 1.349`` (the standard deviation
  of a normal sample; heavy tails do not inflate it) with its bootstrap error;
- **errors over seeds** (:func:`over_seeds`): the mean of per-seed values with the standard error of their spread
  (what another seed would give), beside the typical within-seed error;
- **the calibration line** (:func:`calibration_line`): estimate against truth over settings and seeds, by
  orthogonal distance regression (both carry errors), slope and intercept with 95 % intervals.
"""

import math

import numpy as np
import pandas as pd
from scipy import stats

from .lines import fit_line

__all__ = ["LAB_MEAN_LN", "LAB_RESOLUTION", "ROBUST_SCALE", "merge_unresolved", "lab_clock", "log_spread",
           "over_seeds", "calibration_line"]

#: ``<ln(T / T0)>`` of the paper's pooled slips (its Fig. 5c: T_a of ~10-1000 s around ~100 s, T0 = 1 s).
LAB_MEAN_LN = 4.6
#: The lab's time resolution of an interface's slips [lab seconds = T0]: the detection's running average over
#: 5 frames at 5 frames per second (:data:`stickslip.experiment.detection.AVERAGE_FRAMES`).
LAB_RESOLUTION = 1.0
#: IQR of a standard normal distribution: ``IQR / ROBUST_SCALE`` estimates a normal sample's standard deviation.
ROBUST_SCALE = 2.0 * stats.norm.ppf(0.75)


def merge_unresolved(slips, resolution, *, by=("run", "interface")):
    """The slips as an eye that cannot tell slips of one interface apart within ``resolution`` sees them.

    A slip that follows the previous slip of its interface by less than ``resolution`` (``T < resolution``) is
    merged into it; chains merge into one. A merged slip has the first slip's time and peak, the last one's
    post-slip stress (drop: ``mu_before`` of the first minus ``mu_before - dmu`` of the last), the waiting time from
    the previous merged slip of its interface (the first slip of an interface in the table keeps its own: its
    previous slip is not in the table), and is a multi-slip if any of its slips is.

    Parameters
    ----------
    slips : pandas.DataFrame
        One row per slip: the columns of ``by``, ``t`` (time of the slip), ``T`` (waiting time since the previous
        slip of the interface; NaN for the first), ``dmu`` (drop), ``mu_before`` (peak), ``multi`` (bool); further
        columns are kept from the first slip of a merged one.
    resolution : float
        [unit of ``t``]; 0 keeps every slip.
    by : Sequence[str]
        Columns that tell the interfaces of the runs apart.

    Returns
    -------
    pandas.DataFrame
        The merged slips, the columns of ``slips`` plus ``merged`` (slips in it), in the order of ``by`` and ``t``.
    """
    parts = []
    for _, group in slips.sort_values([*by, "t"], kind="stable").groupby(list(by), sort=False):
        T = group["T"].to_numpy(dtype=float)
        starts = ~(T < resolution)  # NaN (no previous slip) starts a merged slip
        starts[0] = True  # its previous slip is not in the table (before the steady state): kept apart
        label = np.cumsum(starts) - 1
        first = group[starts].copy()
        after = (group["mu_before"] - group["dmu"]).to_numpy(dtype=float)
        last_after = pd.Series(after).groupby(label).last().to_numpy()
        first["merged"] = np.bincount(label)
        several = first["merged"].to_numpy() > 1
        first["dmu"] = np.where(several, first["mu_before"].to_numpy(dtype=float) - last_after, first["dmu"])
        first["multi"] = pd.Series(group["multi"].to_numpy(dtype=bool)).groupby(label).any().to_numpy()
        times = first["t"].to_numpy(dtype=float)
        first["T"] = np.concatenate([T[:1], np.diff(times)])
        parts.append(first)
    columns = [*slips.columns, "merged"]
    return pd.concat(parts, ignore_index=True)[columns] if parts else pd.DataFrame(columns=columns)


def _mean_ln(slips, T0):
    single = slips[~slips["multi"].to_numpy(dtype=bool)]
    T = single["T"].to_numpy(dtype=float)
    ok = np.isfinite(T) & (T > 0)
    return float(np.mean(np.log(T[ok] / T0))) if ok.any() else math.nan


def lab_clock(slips, *, mean_ln=LAB_MEAN_LN, resolution=LAB_RESOLUTION, merge=True, by=("run", "interface"),
              iterations=60):
    """The lab-like ``T0``: the single slips the lab resolves have ``<ln(T / T0)> = mean_ln`` (module docstring).

    With ``merge`` the slips are those of :func:`merge_unresolved` at ``resolution T0``, which depends on ``T0``:
    ``ln T0`` is found by bisection of ``<ln(T / T0)>_resolved - mean_ln`` (positive while ``T0`` is small: no slip
    merged, ``T0`` below every ``T``; negative once ``T0`` passes the longest wait).

    Parameters
    ----------
    slips : pandas.DataFrame
        As :func:`merge_unresolved` (``multi`` slips are merged but not counted in the mean).
    mean_ln : float
    resolution : float
        [T0].
    merge : bool
        False: the raw slips, ``T0 = exp(<ln T> - mean_ln)``.
    by : Sequence[str]
    iterations : int
        Bisection steps (the bracket's width halves each: 60 resolve ``ln T0`` to far below 1e-9).

    Returns
    -------
    float
        ``T0`` [unit of the slips' times]: one lab second.
    """
    raw = _mean_ln(slips, 1.0)
    if not merge or not math.isfinite(raw):
        return math.exp(raw - mean_ln)
    T = slips["T"].to_numpy(dtype=float)
    T = T[np.isfinite(T) & (T > 0)]
    low, high = math.log(T.min() / resolution) - 1.0, math.log(T.max()) + 1.0

    def excess(log_t0):
        t0 = math.exp(log_t0)
        value = _mean_ln(merge_unresolved(slips, resolution * t0, by=by), t0) - mean_ln
        return value if math.isfinite(value) else -math.inf

    for _ in range(iterations):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if excess(middle) > 0 else (low, middle)
    return math.exp(0.5 * (low + high))


def log_spread(T, *, resamples=2000, seed=0):
    """The spread of ``ln T`` of the positive finite ``T``: standard deviation and robust spread, with errors.

    Parameters
    ----------
    T : array_like
        Waiting times [any unit].
    resamples : int
        Bootstrap resamples (:func:`scipy.stats.bootstrap`, percentile method, generator seeded by ``seed``:
        the same numbers every time).
    seed : int

    Returns
    -------
    dict
        ``slips``; ``std`` (``ddof = 1``) with ``std_error`` (normal theory, ``std / sqrt(2 (m - 1))``) and
        ``std_error_bootstrap``; ``robust`` (``IQR / 1.349``) with ``robust_error_bootstrap``. NaN below 3 slips.
    """
    T = np.asarray(T, dtype=float)
    logs = np.log(T[np.isfinite(T) & (T > 0)])
    out = {"slips": int(logs.size), "std": math.nan, "std_error": math.nan, "std_error_bootstrap": math.nan,
           "robust": math.nan, "robust_error_bootstrap": math.nan}
    if logs.size < 3:
        return out

    def std(x, axis=-1):
        return np.std(x, ddof=1, axis=axis)

    def robust(x, axis=-1):
        return stats.iqr(x, axis=axis) / ROBUST_SCALE

    errors = {}
    for name, statistic in (("std", std), ("robust", robust)):
        result = stats.bootstrap((logs,), statistic, n_resamples=resamples, method="percentile", vectorized=True,
                                 random_state=np.random.default_rng(seed))
        errors[name] = float(result.standard_error)
    value = float(std(logs))
    return out | {"std": value, "std_error": value / math.sqrt(2.0 * (logs.size - 1)),
                  "std_error_bootstrap": errors["std"], "robust": float(robust(logs)),
                  "robust_error_bootstrap": errors["robust"]}


def over_seeds(values, errors=None):
    """The mean of per-seed values with the error of their spread over seeds, beside the within-seed errors.

    Parameters
    ----------
    values : array_like, shape (k,)
        One value per seed (NaN left out).
    errors : array_like, shape (k,), optional
        Each value's within-seed standard error.

    Returns
    -------
    dict
        ``seeds`` (k), ``mean``, ``sd`` (their standard deviation, ``ddof = 1``), ``error`` (``sd / sqrt(k)``: the
        between-seed standard error of the mean), ``low``, ``high`` (95 % interval, Student's t with ``k - 1``
        degrees of freedom), ``within`` (the within-seed errors' root mean square over ``sqrt(k)``: the mean's error
        if the seeds differed only by their sampling noise; NaN without ``errors``).
    """
    values = np.asarray(values, dtype=float)
    ok = np.isfinite(values)
    k = int(ok.sum())
    mean = float(values[ok].mean()) if k else math.nan
    sd = float(values[ok].std(ddof=1)) if k > 1 else math.nan
    error = sd / math.sqrt(k) if k > 1 else math.nan
    quantile = float(stats.t.ppf(0.975, k - 1)) if k > 1 else math.nan
    within = math.nan
    if errors is not None:
        errors = np.asarray(errors, dtype=float)[ok]
        within = float(np.sqrt(np.mean(errors**2)) / math.sqrt(k)) if k else math.nan
    return {"seeds": k, "mean": mean, "sd": sd, "error": error, "low": mean - quantile * error,
            "high": mean + quantile * error, "within": within}


def calibration_line(truth, truth_error, estimate, estimate_error):
    """The line ``estimate = intercept + slope truth`` through (setting, seed) points, both with errors.

    The line through points with errors on both axes (:func:`.lines.fit_line`: the scatter over seeds sets the
    errors where it exceeds the points' own); the intercept's error ``B_error sqrt(<x^2>_w)`` (the intercept is the
    line at ``x = 0``, the weighted mean of ``x`` away from the points' centre); 95 % intervals from Student's t
    with ``points - 2`` degrees of freedom. A calibrated estimator has slope 1 and intercept 0.

    Parameters
    ----------
    truth, truth_error, estimate, estimate_error : array_like, shape (m,)
        One point per setting and seed (points with a non-finite value or a non-positive error are left out).

    Returns
    -------
    dict
        ``points``, ``slope``, ``slope_error``, ``slope_low``, ``slope_high``, ``intercept``, ``intercept_error``,
        ``intercept_low``, ``intercept_high``.
    """
    x, sx, y, sy = (np.asarray(v, dtype=float) for v in (truth, truth_error, estimate, estimate_error))
    ok = np.isfinite(x) & np.isfinite(y) & np.isfinite(sx) & np.isfinite(sy) & (sx > 0) & (sy > 0)
    out = dict.fromkeys(["slope", "slope_error", "slope_low", "slope_high", "intercept", "intercept_error",
                         "intercept_low", "intercept_high"], math.nan) | {"points": int(ok.sum())}
    if ok.sum() < 3:
        return out
    line = fit_line(x[ok], sx[ok], y[ok], sy[ok])
    quantile = float(stats.t.ppf(0.975, ok.sum() - 2))
    slope, slope_error = line["B"], line["B_error"]
    intercept = line["intercepts"][None]
    intercept_error = slope_error * math.sqrt(np.average(x[ok] ** 2, weights=1.0 / (sy[ok]**2 + slope**2 * sx[ok]**2)))
    return out | {"slope": slope, "slope_error": slope_error, "slope_low": slope - quantile * slope_error,
                  "slope_high": slope + quantile * slope_error, "intercept": intercept,
                  "intercept_error": intercept_error, "intercept_low": intercept - quantile * intercept_error,
                  "intercept_high": intercept + quantile * intercept_error}
