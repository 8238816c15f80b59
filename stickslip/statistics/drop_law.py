"""What records of drops and waiting times can tell about aging: the drop law at equal waiting time.

A record is an interface's single slips, pairs ``(dmu_a, T_a)``. Aging raises the threshold that an interface
reaches after a wait. In a record it can only show where it changes the drop *at a given waiting time*: the
conditional law ``E[dmu | T]``, the drop law. Where the interface is reloaded by a drive whose rate the threshold
does not set (a constant drive, an interface driven alone) and does not creep, the stress it regains in a wait ``T``
is the drive's, whatever its threshold, and the drop is what it regained (give or take the change of the post-slip
stress): the drop at a given ``T`` is the reload's, with or without aging. Aging then moves the slips *along* the drop
law (a stronger threshold takes longer to reach) and so does a disorder of the thresholds without aging: the two make
the same records, and no function of ``(dmu_a, T_a)`` can tell them apart. Identifying aging needs a variation of
``T`` that the threshold does not make: a hold, or another loading path of the same surfaces
(:mod:`.loading_contrast`). Where the interface creeps in the wait (thermal activation), the creep relaxes part of
the reload, and whatever slows the creep (aging, but also stronger thresholds without aging) raises the drop at a
given ``T``: the drop law then differs, and the question is whether an aging-free interface of another strength
differs in the same way (docs/numerical-analysis.md, "The calibration").

This module measures that on records:

- :func:`drop_law`: per bin of ``ln(T / t0)`` the mean drop with its standard error and the drops' slope within the
  bin (the law is a line within a bin: no bias from where in a bin a record's slips lie);
- :func:`drop_law_contrast`: a record against a reference record's drop law (e.g. an aging interface against its
  aging-free control): the excess drops ``dmu - law_ref(ln T)`` at the record's waiting times, their mean (offset)
  and their slope against ``ln T`` (the aging rate by which the record differs at equal ``T``: the difference of
  the true rates where ``T`` is set independently of the threshold, as in holds; 0 where the reload sets the drop),
  with bootstrap errors over both records' slips;
- :func:`at_equal_T`: the record's waiting times with the reference's drop law (its law at each ``T`` plus one of
  its residuals drawn at random): the paper's estimator on it reads what the waiting times alone give.
"""

import math

import numpy as np

__all__ = ["DROP_LAW_WIDTH", "CONTRAST_KEYS", "drop_law", "drop_law_contrast", "at_equal_T"]

#: Width of a bin of ``ln(T / t0)`` [e-folds]: narrow enough that the drop law is a line within a bin.
DROP_LAW_WIDTH = 0.5
#: Keys of :func:`drop_law_contrast`.
CONTRAST_KEYS = ["offset", "offset_error", "slope", "slope_error", "slips", "share", "lnT_low", "lnT_high", "reason"]


def _valid(T, dmu, t0):
    """``ln(T / t0)`` and the drops of the slips with a finite positive ``T`` and a finite drop."""
    T, dmu = np.asarray(T, dtype=float), np.asarray(dmu, dtype=float)
    ok = np.isfinite(T) & (T > 0) & np.isfinite(dmu)
    return np.log(T[ok] / t0), dmu[ok]


def drop_law(T, dmu, *, t0, width=DROP_LAW_WIDTH, min_slips=5):
    """The drop law ``E[dmu | T]`` of a record: per bin of ``ln(T / t0)``, a line through the bin's slips.

    Parameters
    ----------
    T : array_like, shape (m,)
        Waiting times [unit of ``t0``]; slips without a finite positive ``T`` or drop are left out.
    dmu : array_like, shape (m,)
        Drops [any unit of stress].
    t0 : float
        Unit of the logarithm [unit of ``T``].
    width : float
        Bin width [e-folds of ``T``]; bin ``k`` holds ``k width <= ln(T / t0) < (k + 1) width``.
    min_slips : int
        Bins with fewer slips (at least 3) are left out.

    Returns
    -------
    dict
        Arrays of shape (bins,) in increasing bin: ``bin`` (``k``), ``x`` (the mean ``ln(T / t0)`` of the bin's
        slips), ``y`` (their mean drop), ``y_error`` (its standard error: the sample standard deviation over the root
        of the slips), ``slope`` (the least-squares slope of the drops against ``ln T`` within the bin; the law there
        is ``y + slope (ln(T / t0) - x)``), ``slips``.
    """
    x, y = _valid(T, dmu, t0)
    index = np.floor(x / width).astype(np.int64)
    rows = []
    for k in np.unique(index):
        mine = index == k
        if mine.sum() >= max(min_slips, 3):
            mean, slope = _offset_and_slope(x[mine], y[mine])
            rows.append((k, x[mine].mean(), mean, y[mine].std(ddof=1) / math.sqrt(mine.sum()),
                         0.0 if math.isnan(slope) else slope, mine.sum()))
    columns = list(zip(*rows)) if rows else [()] * 6
    return {key: np.asarray(column, dtype=np.int64 if key in ("bin", "slips") else float)
            for key, column in zip(("bin", "x", "y", "y_error", "slope", "slips"), columns)}


def _excess(x, y, law, width):
    """The drops ``y`` at ``x`` minus ``law`` there, for the ``x`` in the law's bins; and which ``x`` those are."""
    index = np.floor(x / width).astype(np.int64)
    where = np.minimum(np.searchsorted(law["bin"], index), max(law["bin"].size - 1, 0))
    inside = law["bin"][where] == index if law["bin"].size else np.zeros(x.size, dtype=bool)
    k = where[inside]
    predicted = law["y"][k] + law["slope"][k] * (x[inside] - law["x"][k])
    return x[inside], y[inside] - predicted, inside


def _offset_and_slope(x, d):
    """Mean of ``d`` and the least-squares slope of ``d`` against ``x`` (NaN where ``x`` does not vary)."""
    centred = x - x.mean()
    spread = float(np.sum(centred**2))
    return float(d.mean()), float(np.sum(centred * (d - d.mean())) / spread) if spread > 0 else math.nan


def drop_law_contrast(T, dmu, T_ref, dmu_ref, *, t0, width=DROP_LAW_WIDTH, min_slips=5, resamples=400, seed=0):
    """A record's drops against a reference record's drop law at the record's waiting times.

    The record's slips that fall in the reference's bins of :func:`drop_law` give the excess drops
    ``d = dmu - law_ref(ln(T / t0))``. Their mean is the offset, their least-squares slope against ``ln(T / t0)``
    the aging rate the record shows beyond the reference at equal ``T``. Errors: the standard deviation over
    ``resamples`` bootstrap resamples of both records' slips (the reference's law made anew each time).

    Parameters
    ----------
    T, dmu : array_like, shape (m,)
        The record's waiting times [unit of ``t0``] and drops.
    T_ref, dmu_ref : array_like, shape (m_ref,)
        The reference's.
    t0 : float
    width : float
        [e-folds], as :func:`drop_law`.
    min_slips : int
        As :func:`drop_law` (the reference's bins).
    resamples : int
    seed : int
        Of the bootstrap's random generator.

    Returns
    -------
    dict
        :data:`CONTRAST_KEYS`: ``offset`` [unit of the drops], ``slope`` [per e-fold of ``T``], their errors,
        ``slips`` of the record compared, their ``share`` of the record's slips, the range of ``ln(T / t0)``
        compared (``lnT_low``, ``lnT_high``), ``reason`` ("" or why there is no contrast).
    """
    x, y = _valid(T, dmu, t0)
    x_ref, y_ref = _valid(T_ref, dmu_ref, t0)
    out = dict.fromkeys(CONTRAST_KEYS, math.nan) | {"slips": 0, "share": 0.0, "reason": ""}
    law = drop_law(np.exp(x_ref), y_ref, t0=1.0, width=width, min_slips=min_slips)
    if law["bin"].size < 2:
        return out | {"reason": "the reference has fewer than two bins of waiting times"}
    xs, d, inside = _excess(x, y, law, width)
    if xs.size < 3:
        return out | {"reason": "fewer than three of the record's slips lie within the reference's waiting times"}
    offset, slope = _offset_and_slope(xs, d)
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(resamples):
        mine, theirs = rng.integers(0, x.size, x.size), rng.integers(0, x_ref.size, x_ref.size)
        law_b = drop_law(np.exp(x_ref[theirs]), y_ref[theirs], t0=1.0, width=width, min_slips=min_slips)
        xb, db, _ = _excess(x[mine], y[mine], law_b, width)
        if xb.size >= 3:
            draws.append(_offset_and_slope(xb, db))
    draws = np.asarray(draws, dtype=float).reshape(-1, 2)
    errors = np.nanstd(draws, axis=0, ddof=1) if len(draws) > 1 else np.full(2, math.nan)
    return out | {"offset": offset, "offset_error": float(errors[0]), "slope": slope, "slope_error": float(errors[1]),
                  "slips": int(xs.size), "share": float(inside.mean()), "lnT_low": float(xs.min()),
                  "lnT_high": float(xs.max())}


def at_equal_T(T, T_ref, dmu_ref, *, t0, rng, width=DROP_LAW_WIDTH, min_slips=5):
    """The record's waiting times with the reference's drops: its drop law there plus one of its residuals.

    Parameters
    ----------
    T : array_like, shape (m,)
        The record's waiting times [unit of ``t0``].
    T_ref, dmu_ref : array_like, shape (m_ref,)
        The reference's waiting times and drops.
    t0 : float
    rng : numpy.random.Generator
        Draws the residuals.
    width : float
    min_slips : int
        As :func:`drop_law`.

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray]
        ``T`` and drops of the record's slips in the reference's bins (shape (k,)): the reference's law at
        ``ln(T / t0)`` plus a residual drawn with replacement from the reference's slips in those bins.
    """
    x_ref, y_ref = _valid(T_ref, dmu_ref, t0)
    law = drop_law(np.exp(x_ref), y_ref, t0=1.0, width=width, min_slips=min_slips)
    x = np.log(np.asarray(T, dtype=float) / t0)
    x = x[np.isfinite(x)]
    _, residuals, _ = _excess(x_ref, y_ref, law, width)
    xs, minus_law, _ = _excess(x, np.zeros(x.size), law, width)  # 0 - the law at the record's waiting times
    if residuals.size == 0 or xs.size == 0:
        return np.empty(0), np.empty(0)
    return t0 * np.exp(xs), residuals[rng.integers(0, residuals.size, xs.size)] - minus_law
