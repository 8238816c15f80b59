"""What the aging study measures, from the ``thermal-events`` outputs of its runs (docs/numerical-analysis.md, "Junction aging").

Every function takes tables of the analysis (:mod:`.thermal`, :mod:`.aging_trials`) and returns numbers with
their standard errors and the counts behind them; :func:`load_aging_runs` groups a study's files by what they
say (``n_interfaces``, ``temperature``, ``drive_rate``, ``junction_strengthening``, ``seed``).

- **The aging rate of the paired holds** (:func:`paired_slopes`): every state's first-slip peak of an
  interface against ``ln T_w`` (the trials of one state are paired: same state, same random numbers),
  a least-squares line per state over the hold times ``>= t_min``; the mean of the states' slopes and its
  standard error over the states (trials that failed during the hold are left out; a state needs three
  points). The same for the second slip after the hold (memory erased?), per load ``below``, and for the
  mean widening of the interface's junctions at the peak (one block's strengthening, [eps0] = [sig0]).
- **Linearity in ln T_w** (:func:`curvature`): the quadratic term of the states' pooled paired
  differences against ``ln T_w``, with its standard error.
- **The steady-state peak against the drive rate** (:func:`rate_slope`): the mean peak stress of the
  steady-state slips per run, a weighted line against ``ln(drive_rate)`` over the runs.
- **The paper's estimator** (:func:`estimator`): Delta mu_a against the waiting time T_a of the slips of
  the runs, the project's aging fits through the origin and with an intercept (:func:`stickslip.experiment.aging.fit_aging`).
- **Aftershocks** (:func:`aftershock_pairs`): per pair (mainshock interface ``a``, responding interface
  ``b``) the events of the post-slip holds and of the controls, their mean number per hold, and the
  Omori-Utsu fit with a bootstrap over the mainshocks (:mod:`.omori`).
- **The clock of the driven aftershocks** (:func:`driven_aftershocks`): in the runs themselves, the
  time (and the drive, ``rate x time``) from every steady-state slip of ``a`` to the next event on ``b``.
"""

import math

import numpy as np
import pandas as pd

from ..experiment.aging import fit_aging
from ..formats.analysis_file import open_analysis_file
from ..events.analysis_files import read_analysis_file
from ..statistics.omori import bootstrap_omori

__all__ = ["TABLES", "load_aging_runs", "select_runs", "first_peaks", "trial_peaks", "paired_slopes", "curvature", "ratio", "rate_slope",
           "estimator", "aftershock_pairs", "driven_aftershocks", "mean_sem"]

#: Tables of a ``thermal-events`` output that the summary reads (those absent are empty).
TABLES = ("slip_events", "interfaces", "holds", "trial_slips", "aftershock_trials", "aftershocks")


def mean_sem(values):
    """Mean, standard error and count of the finite values (NaN error below two)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return math.nan, math.nan, 0
    sem = values.std(ddof=1) / math.sqrt(values.size) if values.size > 1 else math.nan
    return float(values.mean()), float(sem), int(values.size)


def load_aging_runs(paths):
    """The ``thermal-events`` files of a study, one row per run.

    Returns
    -------
    pandas.DataFrame
        ``file``, ``trials`` (the analysis's ``hold_interfaces``: the runs it made trials in; a study may
        analyse its runs with several parameterisations), ``n``, ``seed``, ``temperature``, ``drive_rate``, ``strengthening`` (0 without aging), ``T0`` and
        ``data`` (:class:`.analysis_files.AnalysisFile`); only thermal runs.
    """
    rows = []
    for path in sorted(map(str, paths)):
        with open_analysis_file(path, "event-table") as file:
            present = [name for name in TABLES if name in file]
        item = read_analysis_file(path, "event-table", present)
        if not item.attrs.get("thermal", False):
            continue
        rows.append({"file": path, "trials": int(item.attrs["analysis_params"].get("hold_interfaces", 1)),
                     "n": item.n, "seed": int(item.attrs["seed"]),
                     "temperature": float(item.attrs["temperature"]), "drive_rate": float(item.attrs["drive_rate"]),
                     "strengthening": float(item.attrs.get("junction_strengthening", 0.0)),
                     "T0": float(item.attrs["T0"]), "data": item})
    return pd.DataFrame(rows, columns=["file", "trials", "n", "seed", "temperature", "drive_rate", "strengthening",
                                       "T0", "data"])


def select_runs(runs, **where):
    """The rows of :func:`load_aging_runs` whose columns equal the given values (floats to 1e-9 relative)."""
    chosen = np.ones(len(runs), dtype=bool)
    for key, value in where.items():
        chosen &= np.isclose(runs[key].to_numpy(dtype=float), value, rtol=1e-9, atol=0)
    return runs[chosen]


def trial_peaks(runs, slip=1):
    """:func:`first_peaks` of several runs, with a column ``run`` (the row's position) keeping their states apart."""
    parts = [first_peaks(item, slip).assign(run=k) for k, item in enumerate(runs["data"])]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()


def first_peaks(item, slip=1):
    """The ``slip``-th slip of every interface after every hold trial of one run, with the trial's setting.

    Returns
    -------
    pandas.DataFrame
        ``state``, ``hold_time``, ``below``, ``held_below`` (the load reached, [eps0] under the threshold: ``below``
        where the file predates the column), ``interface``, ``peak`` [sig0], ``widening`` [eps0], ``precursors``,
        ``mu_start`` (the trial's held stress of its first slipping interface), ``failed_in_hold``.
    """
    holds, slips = item.tables["holds"], item.tables.get("trial_slips")
    if slips is None or holds.empty:
        return pd.DataFrame(columns=["state", "hold_time", "below", "held_below", "interface", "peak", "widening",
                                     "precursors", "mu_start", "failed_in_hold"])
    holds = holds if "below" in holds else holds.assign(below=float(item.attrs["analysis_params"].get("below", 0.02)))
    holds = holds if "held_below" in holds else holds.assign(held_below=holds["below"])
    chosen = slips[slips["slip"] == slip]
    return chosen.merge(holds[["trial", "state", "hold_time", "below", "held_below", "mu_start", "failed_in_hold"]],
                        on="trial")


def paired_slopes(peaks, column="peak", t_min=1e6, min_points=3, time="hold_time"):
    """Per state (and load, interface), the least-squares slope of ``column`` against ``ln(time)``; their mean.

    Parameters
    ----------
    peaks : pandas.DataFrame
        :func:`first_peaks` of one or more runs (a column ``run`` keeps states of different runs apart).
    column : str
    t_min : float
        Smallest hold time fitted [time] (shorter holds are shorter than the reload to the peak).
    min_points : int
        Holds a state's slope needs at least (all the hold times of ``peaks`` where there are fewer: a study that
        holds each state twice gets a slope from both).
    time : str
        The time of the logarithm: ``hold_time`` (T_w), or a column of the contacts' age at the peak
        (:func:`stickslip.summaries.dissonance_summary.peak_ages`).

    Returns
    -------
    tuple[float, float, int]
        Mean slope [unit of ``column`` per e-fold of the time], its standard error over the states, states.
    """
    chosen = peaks[(peaks["hold_time"] >= t_min) & ~peaks["failed_in_hold"].astype(bool)]
    keys = [key for key in ("run", "state", "below", "interface") if key in chosen]
    needed = min(min_points, chosen["hold_time"].nunique())
    slopes = []
    for _, group in chosen.groupby(keys):
        values = group[column].to_numpy(dtype=float)
        x = np.log(group[time].to_numpy(dtype=float))
        ok = np.isfinite(values)
        if ok.sum() >= needed and np.ptp(x[ok]) > 0:
            slopes.append(np.polyfit(x[ok], values[ok], 1)[0])
    return mean_sem(slopes)


def curvature(peaks, column="peak", t_min=1e6):
    """Quadratic coefficient of the paired differences (each state minus its mean) against ``ln T_w``, with its error.

    Returns
    -------
    tuple[float, float]
        [unit per e-fold squared]; 0 within the error: linear in ``ln T_w``.
    """
    chosen = peaks[(peaks["hold_time"] >= t_min) & ~peaks["failed_in_hold"].astype(bool)].copy()
    keys = [key for key in ("run", "state", "below", "interface") if key in chosen]
    chosen["y"] = chosen[column] - chosen.groupby(keys)[column].transform("mean")
    x = np.log(chosen["hold_time"].to_numpy(dtype=float))
    x = x - x.mean()
    y = chosen["y"].to_numpy(dtype=float)
    design = np.column_stack([x * x, x, np.ones_like(x)])
    coef, residual, *_ = np.linalg.lstsq(design, y, rcond=None)
    dof = max(y.size - 3, 1)
    sigma2 = float(np.sum((y - design @ coef) ** 2)) / dof
    cov = sigma2 * np.linalg.inv(design.T @ design)
    return float(coef[0]), float(math.sqrt(cov[0, 0]))


def ratio(a, a_error, b, b_error):
    """``a / b`` with its propagated standard error (independent errors)."""
    value = a / b
    return value, abs(value) * math.hypot(a_error / a, b_error / b)


def rate_slope(runs):
    """The steady-state peak stress against the drive rate.

    Parameters
    ----------
    runs : pandas.DataFrame
        :func:`load_aging_runs` rows (n = 1) at several drive rates.

    Returns
    -------
    tuple[pandas.DataFrame, float, float]
        Per drive rate: ``drive_rate``, ``peak``, ``sem``, ``slips`` (pooled over the runs); the slope of the
        peak against ``ln(drive_rate)`` [sig0 per e-fold] and its error (weighted least squares).
    """
    rows = []
    for rate, group in runs.groupby("drive_rate"):
        peaks = np.concatenate([item.tables["slip_events"]["mu_before_sig0"].to_numpy(dtype=float)
                                for item in group["data"]])
        mean, sem, count = mean_sem(peaks)
        rows.append({"drive_rate": rate, "peak": mean, "sem": sem, "slips": count})
    table = pd.DataFrame(rows, columns=["drive_rate", "peak", "sem", "slips"])
    ok = np.isfinite(table["sem"]) & (table["sem"] > 0)
    if ok.sum() < 2:
        return table, math.nan, math.nan
    x, y, w = np.log(table["drive_rate"][ok]), table["peak"][ok], 1.0 / table["sem"][ok] ** 2
    design = np.column_stack([x, np.ones_like(x)])
    cov = np.linalg.inv(design.T @ (w.to_numpy()[:, None] * design))
    coef = cov @ design.T @ (w * y)
    return table, float(coef[0]), float(math.sqrt(cov[0, 0]))


def estimator(slips, T0, fit):
    """The paper's aging fit of Delta mu against the waiting time of single slips (``fit``: "origin" or "intercept").

    Parameters
    ----------
    slips : pandas.DataFrame
        A ``thermal-events`` slip table: ``multi``, ``T_fe`` [time], ``dmu_sig0`` [sig0].
    T0 : float
        The time scale of the fit [time].
    fit : {"origin", "intercept"}

    Returns
    -------
    dict
        ``B``, ``B_error``, ``c``, ``c_error`` [sig0], ``slips``, ``bins``; NaN where the fit cannot be made.
    """
    single = slips[~slips["multi"].astype(bool) & np.isfinite(slips["T_fe"])]
    try:
        result = fit_aging(single["T_fe"].to_numpy(), single["dmu_sig0"].to_numpy(), t0=T0, fit=fit)
    except ValueError:
        return {"B": math.nan, "B_error": math.nan, "c": math.nan, "c_error": math.nan, "slips": len(single),
                "bins": 0}
    return {"B": result.B, "B_error": result.B_error, "c": result.c, "c_error": result.c_error,
            "slips": result.n_slips, "bins": len(result.bins)}


def aftershock_pairs(items, n, samples=200):
    """Events on interface ``b`` in the holds after slips of ``a`` (post-slip) and in their controls, per pair.

    Parameters
    ----------
    items : Sequence[stickslip.events.analysis_files.AnalysisFile]
        Runs with ``n`` interfaces and aftershock trials.
    n : int
    samples : int
        Bootstrap samples of the Omori-Utsu fits.

    Returns
    -------
    pandas.DataFrame
        One row per (a, b, kind): ``holds``, ``complete`` (share), ``events`` (mean per hold and its standard
        error over the holds, ``events_sem``), ``K``, ``c``, ``p`` and their errors (NaN with too few events).
    """
    rows = []
    for a in range(1, n + 1):
        for b in range(1, n + 1):
            for kind, name in enumerate(("post-slip", "control")):
                sequences, complete, hold_time = [], [], math.nan
                for item in items:
                    trials = item.tables.get("aftershock_trials")
                    if trials is None:
                        continue
                    events = item.tables["aftershocks"]
                    hold_time = float(item.attrs["analysis_params"]["aftershock_time"]) * float(item.attrs["T0"])
                    for _, trial in trials[(trials["a"] == a) & (trials["kind"] == kind)].iterrows():
                        mine = events[(events["trial"] == trial["trial"]) & (events[f"A_{b}"] > 0)]
                        sequences.append(mine["t"].to_numpy(dtype=float))
                        complete.append(bool(trial["complete"]))
                if not sequences:
                    continue
                mean, sem, _ = mean_sem([s.size for s in sequences])
                fit = bootstrap_omori(sequences, 0.0, hold_time, samples=samples)
                rows.append({"a": a, "b": b, "kind": name, "holds": len(sequences), "complete": float(np.mean(complete)),
                             "events": mean, "events_sem": sem, **fit._asdict()})
    return pd.DataFrame(rows)


def driven_aftershocks(increments, N, rate):
    """In a driven run: from every steady-state slip of ``a``, the time and the drive to the next event on ``b``.

    Parameters
    ----------
    increments : pandas.DataFrame
        The run's increment table (``t``, ``kick``, ``A_a<b>``).
    N : int
    rate : float
        Its drive rate [eps0 per unit time].

    Returns
    -------
    pandas.DataFrame
        One row per (mainshock, b): ``a``, ``b``, ``t`` (time to the next event that moves a block of ``b``,
        before the next slip of ``a``; NaN if none), ``drive`` (``rate t`` [eps0]).
    """
    t = increments["t"].to_numpy(dtype=float)
    kick = increments["kick"].to_numpy(dtype=bool)
    names = sorted(name for name in increments if name.startswith("A_a"))
    moved = np.column_stack([increments[name].to_numpy() for name in names])
    slipped = kick[:, None] & (moved == N)
    rows = []
    for a in range(len(names)):
        shocks = np.flatnonzero(slipped[:, a])
        for shock, following in zip(shocks[:-1], shocks[1:]):
            for b in range(len(names)):
                later = np.flatnonzero(kick[shock + 1:following + 1] & (moved[shock + 1:following + 1, b] > 0))
                dt = t[shock + 1 + later[0]] - t[shock] if later.size else math.nan
                rows.append({"a": a + 1, "b": b + 1, "t": dt, "drive": rate * dt})
    return pd.DataFrame(rows, columns=["a", "b", "t", "drive"])
