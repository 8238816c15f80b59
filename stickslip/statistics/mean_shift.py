"""Does the stress drop depend on n? A two-sample test with its resolution.

The paper's Fig. 2f claims that, with compliant driving, the stress drop Delta mu_a of
the slipping interface does not depend on the number of interfaces n. A claim of "no
dependence" needs two numbers: the test (is the measured shift compatible with zero?)
and its resolution (which shift would the same samples have detected?).

The test is Welch's two-sample t-test on the means (unequal variances; the stress drops
are skewed, but the means of tens of events are close to normal). Its resolution is the
smallest relative shift of the mean that the test detects at level ``alpha`` with
probability ``power``, from the normal approximation of the Welch statistic:
``(z_{1 - alpha/2} + z_power) sqrt(s_1^2 / m_1 + s_2^2 / m_2) / mean_1``.
"""

import math

import numpy as np
from scipy import stats

__all__ = ["SHIFT_COLUMNS", "detectable_shift", "shift_test"]

#: Keys of the dict returned by :func:`shift_test`.
SHIFT_COLUMNS = ("count_1", "count_2", "mean_1", "mean_2", "shift", "p_value", "detectable_shift")


def detectable_shift(sample_1, sample_2, alpha=0.05, power=0.8):
    """Smallest relative shift of the mean that Welch's test detects (module doc).

    Parameters
    ----------
    sample_1, sample_2 : array_like, shape (m_1,), (m_2,)
        The two samples (e.g. Delta mu_a [sig0] at two values of n), each with m >= 2.
    alpha : float
        Two-sided significance level.
    power : float
        Probability of detecting the shift.

    Returns
    -------
    float
        The shift as a fraction of the mean of ``sample_1`` (0.1: a 10 % shift); nan if a
        sample has fewer than two values.
    """
    a, b = np.asarray(sample_1, dtype=float), np.asarray(sample_2, dtype=float)
    if a.size < 2 or b.size < 2:
        return math.nan
    error = math.sqrt(a.var(ddof=1) / a.size + b.var(ddof=1) / b.size)
    z = stats.norm.ppf(1 - alpha / 2) + stats.norm.ppf(power)
    return float(z * error / abs(a.mean()))


def shift_test(sample_1, sample_2, alpha=0.05, power=0.8):
    """Welch's test of equal means and its resolution (module doc).

    Parameters
    ----------
    sample_1, sample_2 : array_like, shape (m_1,), (m_2,)
        The two samples.
    alpha, power : float
        As in :func:`detectable_shift`.

    Returns
    -------
    dict
        :data:`SHIFT_COLUMNS`: the sample sizes and means, the measured relative shift
        ``mean_2 / mean_1 - 1``, the two-sided p-value of equal means and the detectable
        relative shift; nan where a sample has fewer than two values.
    """
    a, b = np.asarray(sample_1, dtype=float), np.asarray(sample_2, dtype=float)
    enough = a.size >= 2 and b.size >= 2
    mean_1 = float(a.mean()) if a.size else math.nan
    mean_2 = float(b.mean()) if b.size else math.nan
    return {"count_1": int(a.size), "count_2": int(b.size), "mean_1": mean_1, "mean_2": mean_2,
            "shift": mean_2 / mean_1 - 1 if a.size and b.size else math.nan,
            "p_value": float(stats.ttest_ind(a, b, equal_var=False).pvalue) if enough else math.nan,
            "detectable_shift": detectable_shift(a, b, alpha, power)}
