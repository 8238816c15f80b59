"""The Omori-Utsu law of aftershock rates, fitted by maximum likelihood, with a bootstrap over mainshocks.

After each of ``M`` mainshocks the events of a sequence come at the rate ``lambda(t) = K (t + c)^-p``
(Utsu 1961; Ogata 1983) over the observed window ``[t_start, t_end]`` of time since the mainshock.
The log-likelihood of the pooled event times ``t_i`` is

``ln L = sum_i ln lambda(t_i) - M int_(t_start)^(t_end) lambda(t) dt``;

``K`` maximises it in closed form for given ``(c, p)`` (``K = n / (M I(c, p))``, ``I`` the integral of
``(t + c)^-p``), so the fit is a two-parameter maximisation over ``ln c`` and ``p``
(:func:`scipy.optimize.minimize`, Nelder-Mead from a grid of starts). The errors are the spread of the
fits over bootstrap samples of the mainshocks (each mainshock's events kept together).
"""

import math
from collections import namedtuple

import numpy as np
from scipy import optimize

__all__ = ["OmoriFit", "omori_rate_integral", "fit_omori", "bootstrap_omori", "MIN_EVENTS"]

#: Fewer pooled events than this give no fit (NaN).
MIN_EVENTS = 8

#: A fit: ``K`` [events per unit time^(1-p)], ``c`` [time], ``p``, their bootstrap standard errors
#: (NaN without bootstrap), ``n_events``, ``n_mainshocks``.
OmoriFit = namedtuple("OmoriFit", "K c p K_error c_error p_error n_events n_mainshocks")


def omori_rate_integral(c, p, t_start, t_end):
    """``int_(t_start)^(t_end) (t + c)^-p dt`` (stable at ``p = 1``)."""
    a, b = math.log(t_start + c), math.log(t_end + c)
    q = 1.0 - p
    if abs(q) * max(abs(a), abs(b)) < 1e-8:
        return (b - a) * (1.0 + 0.5 * q * (a + b))
    return (math.exp(q * b) - math.exp(q * a)) / q


def _negative_log_likelihood(x, times, M, t_start, t_end):
    c, p = math.exp(x[0]), x[1]
    integral = omori_rate_integral(c, p, t_start, t_end)
    if not integral > 0.0 or not math.isfinite(integral):
        return math.inf
    n = times.size
    K = n / (M * integral)
    return -(n * math.log(K) - p * np.sum(np.log(times + c)) - n)


def fit_omori(sequences, t_start, t_end):
    """Maximum-likelihood Omori-Utsu fit of pooled aftershock sequences (module docstring).

    Parameters
    ----------
    sequences : Sequence[numpy.ndarray]
        Event times since the mainshock [time], one array per mainshock (empty arrays count).
    t_start, t_end : float
        The observed window (``t_end > t_start >= 0``) [time]; events outside it are left out.

    Returns
    -------
    OmoriFit
        Errors NaN; all NaN with fewer than :data:`MIN_EVENTS` events.
    """
    M = len(sequences)
    times = np.concatenate([np.asarray(s, dtype=float) for s in sequences]) if M else np.zeros(0)
    times = times[(times >= t_start) & (times <= t_end)]
    if times.size < MIN_EVENTS:
        return OmoriFit(*([math.nan] * 6), times.size, M)
    best = None
    span = math.log(t_end + 1.0)
    for log_c in np.linspace(math.log(max(t_start, 1e-3) + 1e-3), span, 4):
        for p in (0.7, 1.3):
            result = optimize.minimize(_negative_log_likelihood, [log_c, p], args=(times, M, t_start, t_end),
                                       method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-9, "maxiter": 4000})
            if best is None or result.fun < best.fun:
                best = result
    c, p = math.exp(best.x[0]), float(best.x[1])
    K = times.size / (M * omori_rate_integral(c, p, t_start, t_end))
    return OmoriFit(K, c, p, math.nan, math.nan, math.nan, times.size, M)


def bootstrap_omori(sequences, t_start, t_end, samples=200, seed=0):
    """:func:`fit_omori` with standard errors from ``samples`` bootstrap resamples of the mainshocks.

    Parameters
    ----------
    sequences, t_start, t_end
        As :func:`fit_omori`.
    samples : int, optional
    seed : int, optional
        Seed of the resampling (numpy's default generator).

    Returns
    -------
    OmoriFit
    """
    fit = fit_omori(sequences, t_start, t_end)
    if math.isnan(fit.p):
        return fit
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(samples):
        pick = rng.integers(0, len(sequences), len(sequences))
        again = fit_omori([sequences[i] for i in pick], t_start, t_end)
        if not math.isnan(again.p):
            draws.append((math.log(again.K), math.log(again.c), again.p))
    if len(draws) < 2:
        return fit
    log_K, log_c, p = np.asarray(draws).T
    return fit._replace(K_error=fit.K * float(np.std(log_K, ddof=1)), c_error=fit.c * float(np.std(log_c, ddof=1)),
                        p_error=float(np.std(p, ddof=1)))
