"""Aging of the interfaces from the detected slips: logarithmic aging fit, aging rate per slip,
its spread with n, slow slip, and the disorder law of individually driven interfaces.

Paper, section "Interpretation" and appendices "Aging variations", "Slow slip":

- aging law ``dmu_a = B ln(T_a / T0)``, ``T0 = 1 s``, fitted on logarithmically binned ``T_a``
  (mean and standard deviation of ``dmu_a`` per bin);
- aging rate of one slip ``B_a = dmu_a / ln(T_a / T0)``;
- slow-slip fraction ``R_slow = 1 - sum(dR_a) / R_tot`` per interface;
- a slip has no slow slip before it if its interface drifted by less than 3 um since its
  previous slip;
- individual protocol, disorder law ``dmu_a = (d mu_a / dt) T_a`` (``K T_a h gamma_dot / N``).
"""

import dataclasses

import numpy as np
import pandas as pd

__all__ = ["T0", "SLOW_SLIP_DRIFT", "AgingFit", "log_binned", "fit_aging", "aging_rate", "spread_of_aging_rate",
           "slow_slip_fraction", "without_slow_slip"]

#: Microscopic time scale of the aging law [s].
T0 = 1.0
#: Drift of an interface between two of its slips above which slow slip occurred [mm] (3 um).
SLOW_SLIP_DRIFT = 3e-3


@dataclasses.dataclass(frozen=True)
class AgingFit:
    """Result of the aging fit ``dmu = B ln(T / T0)``.

    Attributes
    ----------
    B : float
        Aging rate [-].
    B_error : float
        Its standard error [-].
    bins : pandas.DataFrame
        One row per bin used: ``T_low``, ``T_high`` [s] (edges), ``T`` [s] (geometric mean of the
        bin's ``T``), ``dmu_mean``, ``dmu_std`` [-], ``count``.
    n_slips : int
        Number of slips in the fitted bins.
    """

    B: float
    B_error: float
    bins: pd.DataFrame
    n_slips: int


def log_binned(T, values, *, bins_per_decade=4, min_count=5):
    """Mean and standard deviation of ``values`` in logarithmic bins of ``T``.

    Parameters
    ----------
    T : array_like, shape (m,)
        Waiting times [s] (> 0; NaN entries are ignored).
    values : array_like, shape (m,)
        Quantity to average, e.g. ``dmu_a``.
    bins_per_decade : int
        Bins per factor 10 of ``T``; edges at ``10**(k / bins_per_decade)`` s.
    min_count : int
        Bins with fewer entries are dropped.

    Returns
    -------
    pandas.DataFrame
        Columns ``T_low``, ``T_high``, ``T`` [s], ``dmu_mean``, ``dmu_std``, ``count``.
    """
    T = np.asarray(T, dtype=float)
    values = np.asarray(values, dtype=float)
    keep = np.isfinite(T) & np.isfinite(values) & (T > 0)
    T, values = T[keep], values[keep]
    columns = ["T_low", "T_high", "T", "dmu_mean", "dmu_std", "count"]
    if T.size == 0:
        return pd.DataFrame(columns=columns)
    index = np.floor(np.log10(T) * bins_per_decade).astype(int)
    rows = []
    for k in np.unique(index):
        member = index == k
        if member.sum() < min_count:
            continue
        rows.append((10.0 ** (k / bins_per_decade), 10.0 ** ((k + 1) / bins_per_decade),
                     float(np.exp(np.mean(np.log(T[member])))), float(values[member].mean()),
                     float(values[member].std(ddof=1)), int(member.sum())))
    return pd.DataFrame(rows, columns=columns)


def fit_aging(T, dmu, *, t0=T0, bins_per_decade=4, min_count=5):
    """Fit ``dmu = B ln(T / t0)`` on logarithmically binned waiting times.

    The bin means ``y_k`` at ``x_k = mean(ln(T / t0))`` of bin ``k`` are fitted by weighted least
    squares through the origin, weights ``w_k = count_k / std_k**2`` (inverse variance of a bin
    mean): ``B = sum(w x y) / sum(w x^2)``. The standard error is scaled by the reduced
    chi-square of the fit, ``B_error = sqrt(chi2 / (m - 1) / sum(w x^2))`` (``m`` bins), so that it
    reflects the actual scatter of the bin means around the law.

    Parameters
    ----------
    T : array_like, shape (m,)
        Waiting time since the previous slip of the same interface [s].
    dmu : array_like, shape (m,)
        Friction drop of the slip [-].
    t0 : float
        Microscopic time scale [s].
    bins_per_decade, min_count : int
        See :func:`log_binned`.

    Returns
    -------
    AgingFit

    Raises
    ------
    ValueError
        If fewer than two bins hold ``min_count`` slips.
    """
    bins = log_binned(T, dmu, bins_per_decade=bins_per_decade, min_count=min_count)
    if len(bins) < 2:
        raise ValueError(f"aging fit needs at least two bins of {min_count} slips with a waiting time; "
                         f"got {len(bins)}")
    x = np.log(bins["T"].to_numpy() / t0)  # the geometric mean: x = mean(ln(T / t0)) per bin
    y = bins["dmu_mean"].to_numpy()
    std = np.maximum(bins["dmu_std"].to_numpy(), np.finfo(float).tiny)
    w = bins["count"].to_numpy() / std ** 2
    curvature = np.sum(w * x * x)
    B = float(np.sum(w * x * y) / curvature)
    chi2 = float(np.sum(w * (y - B * x) ** 2))
    B_error = float(np.sqrt(chi2 / (len(bins) - 1) / curvature))
    return AgingFit(B=B, B_error=B_error, bins=bins, n_slips=int(bins["count"].sum()))


def aging_rate(dmu, T, *, t0=T0):
    """Aging rate of each slip, ``B_a = dmu_a / ln(T_a / t0)``.

    Parameters
    ----------
    dmu : array_like, shape (m,)
        Friction drops [-].
    T : array_like, shape (m,)
        Waiting times [s].
    t0 : float
        Microscopic time scale [s].

    Returns
    -------
    numpy.ndarray, shape (m,)
        ``B_a`` [-]; NaN where ``T <= t0`` (the law has no positive rate there) or ``T`` is NaN.
    """
    T = np.asarray(T, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = np.asarray(dmu, dtype=float) / np.log(T / t0)
    return np.where(T > t0, rate, np.nan)


def spread_of_aging_rate(slips):
    """Standard deviation of ``B_a`` per interface and ``n``, normalised by its ``n = 1`` value.

    The ``n = 1`` reference of interface ``a`` is interface ``a`` driven alone: the slips of the
    "individual" protocol for ``a``, or, if there are none, of the stack with ``n = 1``
    (the same configuration for ``a = 1``).

    Parameters
    ----------
    slips : pandas.DataFrame
        Columns ``a``, ``n``, ``protocol``, ``B_a`` (NaN entries are ignored).

    Returns
    -------
    pandas.DataFrame
        Columns ``a``, ``n``, ``std`` (of ``B_a``), ``count``, ``std_normalised``
        (``std / std`` of the reference; NaN without reference). The reference rows have
        ``n = 1``.
    """
    valid = slips[np.isfinite(slips["B_a"].to_numpy(dtype=float))]
    individual = valid[valid["protocol"] == "individual"].assign(n=1)
    stack = valid[valid["protocol"] == "stack"]
    has_individual = set(individual["a"].unique())
    stack = stack[~((stack["n"] == 1) & stack["a"].isin(has_individual))]
    table = (pd.concat([individual, stack]).groupby(["a", "n"])["B_a"]
             .agg(std=lambda b: b.std(ddof=1), count="size").reset_index())
    reference = table[table["n"] == 1].set_index("a")["std"]
    table["std_normalised"] = table["std"] / table["a"].map(reference)
    return table


def slow_slip_fraction(R_tot, dR_sum):
    """Fraction of the sliding distance covered by slow slip, ``R_slow = 1 - sum(dR_a) / R_tot``.

    Parameters
    ----------
    R_tot : array_like
        Total sliding of the interface over the analysed record [mm].
    dR_sum : array_like
        Sum of the slips detected on it [mm].

    Returns
    -------
    numpy.ndarray
        ``R_slow`` [-]; NaN where ``R_tot <= 0``.
    """
    R_tot = np.asarray(R_tot, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(R_tot > 0, 1.0 - np.asarray(dR_sum, dtype=float) / R_tot, np.nan)


def without_slow_slip(slips, *, drift=SLOW_SLIP_DRIFT):
    """The slips whose interface drifted by less than ``drift`` since its previous slip.

    Parameters
    ----------
    slips : pandas.DataFrame
        Column ``drift`` [mm]: ``R_a(t_start) - R_a(t_end of the previous slip of a)``.
    drift : float
        Threshold [mm] (3 um in the paper).

    Returns
    -------
    pandas.DataFrame
        The rows with ``drift < threshold`` (a slip without a previous one is excluded).
    """
    return slips[slips["drift"].to_numpy(dtype=float) < drift]
