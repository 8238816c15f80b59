"""Do two runs have the same slip statistics? Two-sample tests with their resolution.

Used to compare two ways of computing the same model (e.g. ``relaxation = dynamic``
against ``exact``, or two time steps; ``benchmarks/fem_relaxation_fidelity.py``). Each
run gives a :class:`SlipSample`: the counts of its steady-state slip events by the number
of slipping interfaces ``s`` (rho(s)), the stress drops Delta mu_a of its slipping
interfaces, and the sizes of all its steady-state events (kicks).

The tests, each with the difference the same samples would detect, because "cannot tell
apart" means little without it:

- rho(s): chi-square test of the two count vectors (a contingency table; ``s`` values
  that neither run has are dropped); resolution: the difference of the multi-slip fraction
  rho(s > 1) that a two-proportion test detects at level ``alpha`` with probability
  ``power`` (normal approximation at the pooled fraction, floored at 1 / m so that a
  sample without multi-slips still gets a finite figure).
- P(Delta mu_a) and P(event size): two-sample Kolmogorov-Smirnov (statistic ``D`` and
  p-value) and Anderson-Darling (p-value by permutation, valid with ties); resolution of KS:
  the distance ``D`` that is significant at ``alpha`` (asymptotic, ``sqrt(-ln(alpha / 2) / 2)
  sqrt((m_1 + m_2) / (m_1 m_2))``). Delta mu_a also gets Welch's test of the means and its
  detectable relative shift (:func:`stickslip.statistics.mean_shift.shift_test`).
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from .mean_shift import shift_test

__all__ = ["SlipSample", "multi_slip_resolution", "ks_resolution", "compare_distributions", "compare_slip_samples"]


@dataclass(frozen=True)
class SlipSample:
    """The slip statistics of one run (steady state only).

    Attributes
    ----------
    counts : numpy.ndarray, shape (n,)
        Slip events with ``s = 1 ... n`` slipping interfaces.
    drops : numpy.ndarray, shape (m,)
        Delta mu_a of every slipping interface of every slip event [sig0].
    sizes : numpy.ndarray, shape (k,)
        Size of every event (kick), e.g. the number of well changes of all interfaces.
    """

    counts: np.ndarray
    drops: np.ndarray
    sizes: np.ndarray


def multi_slip_resolution(counts_1, counts_2, alpha=0.05, power=0.8):
    """Smallest difference of the multi-slip fraction rho(s > 1) that the samples detect (module doc).

    Parameters
    ----------
    counts_1, counts_2 : array_like, shape (n,)
        Slip events by ``s = 1 ... n``.
    alpha, power : float
        Two-sided level and power.

    Returns
    -------
    float
        Absolute difference of rho(s > 1) (0.1: ten percentage points); nan if a run has no
        slip event.
    """
    c1, c2 = np.asarray(counts_1), np.asarray(counts_2)
    m1, m2 = int(c1.sum()), int(c2.sum())
    if m1 == 0 or m2 == 0:
        return math.nan
    pooled = (c1[1:].sum() + c2[1:].sum()) / (m1 + m2)
    pooled = min(max(pooled, 1.0 / (m1 + m2)), 1.0 - 1.0 / (m1 + m2))
    z = stats.norm.ppf(1 - alpha / 2) + stats.norm.ppf(power)
    return float(z * math.sqrt(pooled * (1 - pooled) * (1 / m1 + 1 / m2)))


def ks_resolution(m_1, m_2, alpha=0.05):
    """The Kolmogorov-Smirnov distance that is significant at ``alpha`` for samples of ``m_1``, ``m_2``."""
    if m_1 == 0 or m_2 == 0:
        return math.nan
    return math.sqrt(-math.log(alpha / 2) / 2) * math.sqrt((m_1 + m_2) / (m_1 * m_2))


def compare_distributions(sample_1, sample_2, alpha=0.05, n_resamples=2000, seed=0):
    """KS and Anderson-Darling tests of two samples of a continuous or discrete quantity.

    Parameters
    ----------
    sample_1, sample_2 : array_like, shape (m_1,), (m_2,)
    alpha : float
        Level of the KS resolution.
    n_resamples : int
        Permutations of the Anderson-Darling p-value.
    seed : int
        Seed of the permutations (the result is deterministic).

    Returns
    -------
    dict
        ``count_1``, ``count_2``, ``ks`` (statistic D), ``ks_p``, ``ks_resolution``, ``ad_p``;
        nan where a sample has fewer than two values.
    """
    a, b = np.asarray(sample_1, dtype=float), np.asarray(sample_2, dtype=float)
    out = {"count_1": int(a.size), "count_2": int(b.size), "ks": math.nan, "ks_p": math.nan,
           "ks_resolution": ks_resolution(a.size, b.size, alpha), "ad_p": math.nan}
    if a.size < 2 or b.size < 2:
        return out
    ks = stats.ks_2samp(a, b)
    if np.unique(np.concatenate([a, b])).size < 2:
        ad_p = 1.0  # every value equal: the samples cannot differ
    else:
        permutations = stats.PermutationMethod(n_resamples=n_resamples, random_state=seed)
        ad_p = stats.anderson_ksamp([a, b], variant="midrank", method=permutations).pvalue
    out.update(ks=float(ks.statistic), ks_p=float(ks.pvalue), ad_p=float(ad_p))
    return out


def compare_slip_samples(first, second, alpha=0.05, power=0.8, n_resamples=2000, seed=0):
    """All tests of the module doc for two runs.

    Parameters
    ----------
    first, second : SlipSample
    alpha, power : float
        Level and power of the resolutions.
    n_resamples, seed : int
        Anderson-Darling permutations (:func:`compare_distributions`).

    Returns
    -------
    dict
        ``rho_1``, ``rho_2`` (rho(s) of each, fractions), ``rho_chi2``, ``rho_p`` (1.0 if fewer
        than two ``s`` values occur), ``multi_1``, ``multi_2`` (rho(s > 1)), ``multi_resolution``;
        ``dmu``: :func:`compare_distributions` of the drops plus Welch's ``shift``,
        ``shift_p``, ``detectable_shift``; ``size``: :func:`compare_distributions` of the sizes.
    """
    c1, c2 = np.asarray(first.counts), np.asarray(second.counts)
    used = (c1 + c2) > 0
    if used.sum() > 1 and c1.sum() > 0 and c2.sum() > 0:
        chi2, rho_p = stats.chi2_contingency(np.array([c1[used], c2[used]]))[:2]
    else:
        chi2, rho_p = 0.0, 1.0
    welch = shift_test(first.drops, second.drops, alpha, power)
    dmu = compare_distributions(first.drops, second.drops, alpha, n_resamples, seed)
    dmu.update(shift=welch["shift"], shift_p=welch["p_value"], detectable_shift=welch["detectable_shift"])

    def fraction(c, part):
        return float(part / c.sum()) if c.sum() else math.nan

    return {"rho_1": [fraction(c1, k) for k in c1], "rho_2": [fraction(c2, k) for k in c2],
            "rho_chi2": float(chi2), "rho_p": float(rho_p),
            "multi_1": fraction(c1, c1[1:].sum()), "multi_2": fraction(c2, c2[1:].sum()),
            "multi_resolution": multi_slip_resolution(c1, c2, alpha, power),
            "dmu": dmu, "size": compare_distributions(first.sizes, second.sizes, alpha, n_resamples, seed)}
