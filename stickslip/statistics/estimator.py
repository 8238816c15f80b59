"""The paper's aging estimator, applied as to recordings, and what it needs to measure a known aging rate.

The paper (its Fig. 5c) pools every single slip of every interface and stack, bins ``T_a`` logarithmically
and fits ``dmu_a = B ln(T_a / T0)`` through the bins' means (:func:`stickslip.experiment.aging.fit_aging`:
four bins per decade, five slips per bin, inverse-variance weights, errors scaled by the reduced chi-square;
``fit="intercept"`` frees ``dmu_a = c + B ln(T_a / T0)``). This module applies that fit unchanged:

- :func:`estimate`: one fit with its slope and intercept, their standard errors and 95 % confidence
  intervals (Student's t with ``bins - parameters`` degrees of freedom), the slips and bins behind it and the
  spread of ``ln T`` it was made on; NaN with the reason where the bins do not allow the fit;
- :func:`estimator_table`: both fits per group of slips (per interface, per (interface, n), pooled);
- :func:`synthetic_slips`: slips whose aging rate is known, made the way a stick-slip cycle makes them: the
  drop is a strength offset ``gap`` (the drop however short the stick) plus ``B ln(T / T0)`` plus the
  quenched threshold's fluctuation (relative ``disorder``), and ``T`` is the time the loading takes to reach
  it: proportional to the drop (the disorder law, the paper's Eq. 4: a stronger threshold takes longer) times
  a factor of the loading path (log-normal, ``std(ln)`` = ``path_spread``: the interruptions by other
  interfaces' slips and the rate's dependence on ``n``), so that without aging the drop still correlates
  with ``T``;
- :func:`biases`: what that construction predicts for the two fits: the origin fit reads the gap as aging
  (``+ gap <x> / <x^2>``, ``x = ln(T / T0)``: ``gap / <x>`` for narrow ``T``); the free intercept reads the disorder
  law (``+ drop CV^2 / var(ln T)``, ``CV`` the thresholds' relative spread).

The binned fit's standard error is that of a straight line, ``residual / (sqrt(m) std(ln T))`` for ``m`` slips
scattered by ``residual`` about the law (tested), so the slips a measurement needs for a relative error ``p`` scale
from a fit's as ``m (B_error / (p B))^2``.
"""

import math

import numpy as np
import pandas as pd
from scipy import stats

from ..experiment.aging import FITS, fit_aging

__all__ = ["ESTIMATE_COLUMNS", "LAB_LOADING_RATE", "estimate", "estimator_table", "synthetic_slips", "lab_rate",
           "lab_slips", "biases"]

#: The lab's loading rate of an interface driven alone, ``K h gamma_dot / N`` [1/s]: K = 55 N/mm, h = 10 mm,
#: gamma_dot = 1e-4 /s, N = 49 N (the ``lever`` solver's defaults); a drop of 0.2 takes ~180 s to load.
LAB_LOADING_RATE = 55.0 * 10.0 * 1e-4 / 49.0

#: Columns of :func:`estimate` (and of every row of :func:`estimator_table` after its group keys).
ESTIMATE_COLUMNS = ["fit", "B", "B_error", "B_low", "B_high", "c", "c_error", "c_low", "c_high", "slips", "bins",
                    "std_lnT", "decades", "reason"]


def estimate(T, dmu, *, t0, fit):
    """The paper's fit (module docstring) of drops ``dmu`` against waiting times ``T``, with confidence intervals.

    Parameters
    ----------
    T : array_like, shape (m,)
        Waiting times [any unit of time, that of ``t0``]; NaN entries are left out.
    dmu : array_like, shape (m,)
        Drops [any unit of stress; the results carry it].
    t0 : float
        The law's microscopic time [unit of ``T``].
    fit : {"origin", "intercept"}

    Returns
    -------
    dict
        :data:`ESTIMATE_COLUMNS`: ``B``, ``B_error`` and the 95 % interval ``B_low``, ``B_high``; ``c``,
        ``c_error``, ``c_low``, ``c_high`` (0 through the origin); ``slips`` and ``bins`` fitted; ``std_lnT``
        and ``decades`` (5-95 % range of ``T``) of the slips given; ``reason`` ("" or why there is no fit).
    """
    T, dmu = np.asarray(T, dtype=float), np.asarray(dmu, dtype=float)
    ok = np.isfinite(T) & np.isfinite(dmu) & (T > 0)
    logs = np.log(T[ok])
    spread = float(logs.std(ddof=1)) if logs.size > 1 else math.nan
    decades = float(np.diff(np.percentile(logs, [5, 95]))[0] / math.log(10)) if logs.size else math.nan
    out = dict.fromkeys(ESTIMATE_COLUMNS, math.nan) | {"fit": fit, "slips": int(ok.sum()), "bins": 0,
                                                        "std_lnT": spread, "decades": decades, "reason": ""}
    try:
        result = fit_aging(T[ok], dmu[ok], t0=t0, fit=fit)
    except ValueError as error:
        return out | {"reason": str(error)}
    dof = len(result.bins) - FITS.index(fit) - 1
    quantile = float(stats.t.ppf(0.975, dof))
    return out | {"B": result.B, "B_error": result.B_error, "B_low": result.B - quantile * result.B_error,
                  "B_high": result.B + quantile * result.B_error, "c": result.c, "c_error": result.c_error,
                  "c_low": result.c - quantile * result.c_error, "c_high": result.c + quantile * result.c_error,
                  "slips": result.n_slips, "bins": len(result.bins)}


def estimator_table(slips, *, t0, by=(), T="T", dmu="dmu"):
    """Both fits of :func:`estimate` on the single slips of every group.

    Parameters
    ----------
    slips : pandas.DataFrame
        One row per slip: ``multi`` (bool; multi-slips are left out, as in the paper), the waiting time and the
        drop (columns named by ``T`` and ``dmu``), and the columns of ``by``.
    t0 : float
        [unit of the waiting times].
    by : Sequence[str]
        Group keys (empty: every slip pooled).
    T, dmu : str
        Column names (``T_fe``, ``dmu_sig0`` for the fem model's tables).

    Returns
    -------
    pandas.DataFrame
        One row per group and fit: the keys, then :data:`ESTIMATE_COLUMNS`.
    """
    single = slips[~slips["multi"].to_numpy(dtype=bool)]
    groups = single.groupby(list(by), sort=True) if by else [((), single)]
    rows = []
    for key, group in groups:
        keys = dict(zip(by, key if isinstance(key, tuple) else (key,)))
        for fit in FITS:
            rows.append(keys | estimate(group[T], group[dmu], t0=t0, fit=fit))
    return pd.DataFrame(rows, columns=[*by, *ESTIMATE_COLUMNS])


def synthetic_slips(rng, count, *, B, gap, drop, disorder, path_spread, T_typical, t0=1.0, iterations=50):
    """Slips with a known aging rate, as a stick-slip cycle makes them (module docstring).

    Per slip, with ``z1``, ``z2`` standard normal: the loading path's factor ``P = exp(path_spread z2)``, the
    quenched threshold's fluctuation ``delta = disorder drop z1``; then the drop and the waiting time solve

        dmu = gap + B ln(T / t0) + delta,    T = T_typical P dmu / drop

    (fixed point; it converges for ``B < drop``). ``gap`` is chosen by the caller; ``gap = drop - B
    ln(T_typical / t0)`` makes the typical drop ``drop``.

    Parameters
    ----------
    rng : numpy.random.Generator
    count : int
    B : float
        The true aging rate [unit of the drops per e-fold of T].
    gap, drop : float
        The strength offset and the typical drop [unit of the drops].
    disorder : float
        Relative standard deviation of the thresholds (the paper's n = 1 widths).
    path_spread : float
        ``std(ln P)`` of the loading path's factor.
    T_typical : float
        The waiting time of a typical drop on a typical path [unit of ``t0``].
    t0 : float
    iterations : int

    Returns
    -------
    pandas.DataFrame
        ``T``, ``dmu``, ``multi`` (False), ``path`` (P), ``threshold`` (``gap + delta``, the drop without
        aging).
    """
    z1, z2 = rng.standard_normal(count), rng.standard_normal(count)
    path = np.exp(path_spread * z2)
    threshold = gap + disorder * drop * z1
    dmu = np.full(count, float(drop))
    for _ in range(iterations):
        T = T_typical * path * np.maximum(dmu, 1e-12 * drop) / drop
        dmu = threshold + B * np.log(T / t0)
    T = T_typical * path * np.maximum(dmu, 1e-12 * drop) / drop
    return pd.DataFrame({"T": T, "dmu": dmu, "multi": np.zeros(count, dtype=bool), "path": path,
                         "threshold": threshold})


def lab_rate(a, n):
    """The lab's loading rate of interface ``a`` of a stack of ``n`` relative to ``a`` driven alone,
    ``(n + a)(n - a + 1) / 2`` (the paper's section "Complex loading path")."""
    return (n + a) * (n - a + 1) / 2.0


def lab_slips(rng, count, *, B, strengths, disorder, path_spread, stacks=(1, 2, 3, 4, 5), direct=0.0, t0=1.0,
              loading_rate=LAB_LOADING_RATE):
    """Slips of known aging rate pooled as the paper's Fig. 5c pools them: every interface ``a`` of every stack ``n``.

    Interface ``a`` has its own strength (its typical drop driven alone, ``strengths[a - 1]``: the paper's 0.15-0.3;
    the strength offset ``gap`` of :func:`synthetic_slips` is the interface's) and is loaded at ``loading_rate lab_rate(a, n)``; its slips are :func:`synthetic_slips` with the disorder
    law at that rate (``T = P dmu / rate``), the aging rate ``B``, and the loading path's factor ``P`` log-normal with
    ``std(ln P) = path_spread`` in stacks (1 alone: nothing interrupts an interface driven alone). ``direct`` adds a
    dependence of the peak on the loading rate, ``direct ln(lab_rate)`` (rate-and-state's ``a ln V``), which the
    aging does not make.

    Parameters
    ----------
    rng : numpy.random.Generator
    count : int
        Slips per (interface, stack).
    B : float
        The true aging rate [per e-fold of T].
    strengths : Sequence[float]
        The mean drop of each interface driven alone (interfaces 1, 2, ... from the bottom).
    disorder : float
        Relative spread of the thresholds.
    path_spread : float
        ``std(ln P)`` in stacks of ``n > 1``.
    stacks : Sequence[int]
        The values of ``n``; interface ``a`` slips in every stack with ``n >= a``.
    direct : float
        The peak's rise per e-fold of the loading rate.
    t0 : float
        [s]
    loading_rate : float
        [1/s]

    Returns
    -------
    pandas.DataFrame
        :func:`synthetic_slips`' columns with ``interface`` and ``n``.
    """
    parts = []
    for n in stacks:
        for a in range(1, n + 1):
            drop = float(strengths[a - 1])
            rate = lab_rate(a, n)
            typical = drop / (loading_rate * rate)
            gap = drop - B * math.log(drop / (loading_rate * t0)) + direct * math.log(rate)  # drop alone: strength
            part = synthetic_slips(rng, count, B=B, gap=gap, drop=drop, disorder=disorder,
                                   path_spread=path_spread if n > 1 else 0.0, T_typical=typical, t0=t0)
            parts.append(part.assign(interface=a, n=n))
    return pd.concat(parts, ignore_index=True)


def biases(*, gap, drop, disorder, std_lnT, mean_ln):
    """The two fits' biases that :func:`synthetic_slips`' construction predicts (first order in ``disorder``).

    Parameters
    ----------
    gap, drop : float
        [unit of the drops].
    disorder : float
        Relative spread of the thresholds (``CV``).
    std_lnT : float
        ``std(ln T)`` of the slips fitted.
    mean_ln : float
        ``<ln(T / t0)>`` of the slips fitted.

    Returns
    -------
    dict
        ``origin``: ``gap <x> / <x^2>`` with ``x = ln(T / t0)`` (the gap read as aging by a line through the origin;
        ``gap / <x>`` for narrow ``T``); ``intercept``: ``drop CV^2 / std_lnT^2`` (the disorder law:
        ``cov(dmu, ln T) / var(ln T)`` without aging, where ``ln T`` carries ``ln(threshold)``).
    """
    return {"origin": gap * mean_ln / (mean_ln**2 + std_lnT**2), "intercept": drop * disorder**2 / std_lnT**2}
