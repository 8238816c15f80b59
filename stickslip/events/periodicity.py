"""Periodicity and synchronisation of a run's slip events, with errors from the seeds.

The paper's stiff regime is "a periodic stick-slip sequence with many slip events corresponding
to multi-slip events" and "periodic slips involving all the layers leading to narrowly
distributed force drops"; its compliant regime "a seemingly less periodic sequence of
single-slip events". These measures put numbers on those words, per run (steady-state slip
events in order, the ``slips`` table of :func:`stickslip.events.extraction.slip_events`):

``interval_cv``
    Coefficient of variation (sample standard deviation over mean) of the shear increments
    Delta gamma between consecutive slip events (any interface). A periodic sequence gives 0,
    a Poisson sequence (exponential intervals) 1. Needs three slip events.
``drop_cv``
    Coefficient of variation of the macroscopic stress drops Delta Sigma of the slip events:
    0 for identical drops ("narrowly distributed force drops"). Needs two slip events.
``multi_fraction``
    Fraction of slip events with more than one slipping interface, rho(s > 1).
``spanning_fraction``
    Fraction of slip events in which all ``n`` interfaces slip (system-spanning); 1 by
    definition for ``n = 1``.
``alternation_cv``
    Regularity of the single/multi alternation: the coefficient of variation of the number of
    single slips between consecutive multi-slips. A periodic pattern (e.g. two singles, one
    multi, repeated) gives 0; if each slip event is a multi-slip independently with probability
    p (a Bernoulli sequence) the count is geometric and the coefficient is ``1 / sqrt(1 - p)``.
    Needs three multi-slips.
``runs_z``
    Wald-Wolfowitz runs test of the single/multi order: ``(R - E[R]) / sd(R)`` with R the
    number of runs of equal kind, ``E[R] = 2 m_1 m_2 / m + 1`` and
    ``Var R = (E[R] - 1)(E[R] - 2) / (m - 1)`` for ``m_1`` singles and ``m_2`` multis. About 0
    (within +-2) for a random order, large positive for strict alternation, negative for
    clustering into long sequences. Needs both kinds.

NaN where a measure is not defined (too few events). :func:`seed_summary` averages the
per-run values over the runs (seeds) of one parameter set: mean and standard error
``std / sqrt(k)`` over the ``k`` runs, the error from the seeds that the issue asks for (the
events within a run are not independent, so their counting errors would be optimistic).
"""

import math

import numpy as np
import pandas as pd

from ..formats.event_table import PERIODICITY_COLUMNS, PERIODICITY_TABLE

__all__ = ["TABLE", "MEASURES", "COLUMNS", "coefficient_of_variation", "alternation_cv", "runs_test",
           "periodicity", "periodicity_table", "seed_summary"]

#: Name of the one-row table of an event file (:mod:`stickslip.formats.event_table`).
TABLE = PERIODICITY_TABLE

#: Columns of :func:`periodicity_table`: three counts, then :data:`MEASURES`.
COLUMNS = tuple(PERIODICITY_COLUMNS)

#: The measures of the module doc, in order.
MEASURES = COLUMNS[3:]


def coefficient_of_variation(values):
    """Sample standard deviation (``ddof = 1``) over the mean.

    Parameters
    ----------
    values : array_like, shape (m,)

    Returns
    -------
    float
        NaN with fewer than two values or a mean of 0.
    """
    values = np.asarray(values, dtype=float)
    if values.size < 2 or values.mean() == 0:
        return math.nan
    return float(values.std(ddof=1) / values.mean())


def alternation_cv(multi):
    """Coefficient of variation of the number of single slips between consecutive multi-slips.

    Parameters
    ----------
    multi : array_like of bool, shape (m,)
        Kind of every slip event in order (True: multi-slip).

    Returns
    -------
    float
        NaN with fewer than three multi-slips (fewer than two gaps) or no single slip between them.
    """
    where = np.flatnonzero(np.asarray(multi, dtype=bool))
    if where.size < 3:
        return math.nan
    return coefficient_of_variation(np.diff(where) - 1)


def runs_test(multi):
    """Wald-Wolfowitz runs test of a sequence of single and multi slips (module doc).

    Parameters
    ----------
    multi : array_like of bool, shape (m,)

    Returns
    -------
    dict[str, float]
        ``runs`` (R), ``expected`` (E[R]) and ``z``; NaN z (and expected) without both kinds
        or with fewer than three events.
    """
    multi = np.asarray(multi, dtype=bool)
    m = multi.size
    runs = float(1 + np.count_nonzero(multi[1:] != multi[:-1])) if m else 0.0
    m2 = int(multi.sum())
    m1 = m - m2
    if m < 3 or m1 == 0 or m2 == 0:
        return {"runs": runs, "expected": math.nan, "z": math.nan}
    expected = 2.0 * m1 * m2 / m + 1.0
    variance = (expected - 1.0) * (expected - 2.0) / (m - 1.0)
    z = (runs - expected) / math.sqrt(variance) if variance > 0 else math.nan
    return {"runs": runs, "expected": expected, "z": z}


def periodicity(slips, n):
    """The measures of the module doc for the slip events of one run.

    Parameters
    ----------
    slips : pandas.DataFrame
        Steady-state slip events of one run in order: columns ``gamma`` [gamma0], ``s``
        (slipping interfaces) and ``dsigma`` (macroscopic stress drop [sig0]).
    n : int
        Interfaces of the run.

    Returns
    -------
    dict[str, float]
        :data:`COLUMNS`: the counts ``n_slips`` (m), ``n_multi`` (s > 1) and ``n_spanning`` (s = n), then
        :data:`MEASURES`.
    """
    s = slips["s"].to_numpy(dtype=np.int64)
    m = s.size
    multi = s > 1
    spanning = s == n
    return {"n_slips": m, "n_multi": int(multi.sum()), "n_spanning": int(spanning.sum()),
            "interval_cv": coefficient_of_variation(np.diff(slips["gamma"].to_numpy(dtype=float)))
            if m >= 3 else math.nan,
            "drop_cv": coefficient_of_variation(slips["dsigma"].to_numpy(dtype=float)),
            "multi_fraction": float(multi.mean()) if m else math.nan,
            "spanning_fraction": float(spanning.mean()) if m else math.nan,
            "alternation_cv": alternation_cv(multi),
            "runs_z": runs_test(multi)["z"]}


def periodicity_table(slips, n):
    """:func:`periodicity` as the one-row table of an event file (:data:`TABLE`).

    Parameters
    ----------
    slips : pandas.DataFrame
    n : int

    Returns
    -------
    pandas.DataFrame
        One row, columns :data:`COLUMNS` (counts int64, measures float64).
    """
    table = pd.DataFrame([periodicity(slips, n)], columns=list(COLUMNS))
    return table.astype({c: dtype for c, (dtype, _) in PERIODICITY_COLUMNS.items()})


def seed_summary(rows, keys):
    """Mean and standard error over runs (seeds) of the measures of each parameter set.

    Parameters
    ----------
    rows : pandas.DataFrame
        One row per run: the grouping ``keys`` and :data:`COLUMNS`.
    keys : list[str]
        Columns that define a parameter set (e.g. ``["N", "phi", "n"]``).

    Returns
    -------
    pandas.DataFrame
        Per parameter set: ``keys``, ``runs`` (runs pooled), ``n_slips`` (total), then per measure
        ``<measure>`` (mean over the runs where it is defined), ``<measure>_error`` (standard error
        over them, NaN from fewer than two) and ``<measure>_runs`` (how many runs define it).
    """
    out = []
    for values, group in rows.groupby(list(keys), sort=True):
        values = values if isinstance(values, tuple) else (values,)
        row = dict(zip(keys, values), runs=len(group), n_slips=int(group["n_slips"].sum()))
        for measure in MEASURES:
            x = group[measure].to_numpy(dtype=float)
            x = x[np.isfinite(x)]
            row[measure] = float(x.mean()) if x.size else math.nan
            row[f"{measure}_error"] = float(x.std(ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan
            row[f"{measure}_runs"] = int(x.size)
        out.append(row)
    return pd.DataFrame(out)
