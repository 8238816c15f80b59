"""The paper's numerical findings against the system size N and the time step (issue 23).

Reads the analysis files of a study with several N (and ``dt_scale``) and gives, per
(N, dt_scale, regime, n), the quantities the paper states numerically, each with an error from
the seeds (the events of one run are not independent):

- :func:`periodicity_by_size`: the periodicity and synchronisation measures of
  :mod:`stickslip.events.periodicity` (multi-slip and system-spanning fractions, CV of the shear
  increment between slip events and of the stress drops, alternation), mean and standard error
  over the runs;
- :func:`drop_shift_by_size`: the n-dependence of the stress drop Delta mu_a of compliant single
  slips (the paper's Fig. 2f: none), n against n = 1: Welch's test on the pooled events with the
  shift it resolves (:func:`stickslip.statistics.mean_shift.shift_test`) and Welch's test on the run
  means (one value per seed);
- :func:`front_speed_by_size`: the front speed c_f of the re-run multi-slips (the paper: ~2 c_s),
  meaningful fits only (:func:`stickslip.events.fronts.analyse_event`), and the delay tau.

Files are grouped by what they say about themselves (attributes ``N``, ``regime``,
``n_interfaces``, ``seed`` and the run's ``params``), never by file names.
"""

import math

import numpy as np
import pandas as pd
from scipy import stats

from ..events import periodicity
from ..statistics.mean_shift import shift_test

__all__ = ["GROUP", "run_key", "periodicity_by_size", "drop_shift_by_size", "front_speed_by_size"]

#: What a parameter set is made of (seeds are pooled within it).
GROUP = ("N", "dt_scale", "regime", "n")


def run_key(item):
    """(N, dt_scale, regime, n) and the seed of an analysis file, from its attributes.

    Parameters
    ----------
    item : stickslip.events.analysis_files.AnalysisFile

    Returns
    -------
    dict
        ``N`` (int), ``dt_scale`` (float, 1 if the run's parameters do not name it), ``regime``,
        ``n`` (int), ``seed``.
    """
    params = item.attrs.get("params", {})
    return {"N": int(item.attrs["N"]), "dt_scale": float(params.get("dt_scale", 1.0)) if isinstance(params, dict)
            else 1.0, "regime": item.regime, "n": item.n, "seed": item.attrs.get("seed")}


def periodicity_by_size(files):
    """Periodicity and synchronisation per (N, dt_scale, regime, n): mean and standard error over the seeds.

    Parameters
    ----------
    files : Iterable[stickslip.events.analysis_files.AnalysisFile]
        ``numerical-events`` files read with the table ``periodicity``.

    Returns
    -------
    pandas.DataFrame
        :func:`stickslip.events.periodicity.seed_summary` grouped by :data:`GROUP`.
    """
    rows = pd.DataFrame([{**run_key(item), **item.tables[periodicity.TABLE].iloc[0].to_dict()} for item in files])
    return periodicity.seed_summary(rows, list(GROUP)) if len(rows) else pd.DataFrame()


def drop_shift_by_size(files, reference=1):
    """The n-dependence of Delta mu_a of compliant single slips, per (N, dt_scale), against n = ``reference``.

    Parameters
    ----------
    files : Iterable[stickslip.events.analysis_files.AnalysisFile]
        ``numerical-events`` files read with the table ``slip_interfaces``.
    reference : int, optional
        The n the others are compared with.

    Returns
    -------
    pandas.DataFrame
        One row per (N, dt_scale, n) of the compliant runs: ``seeds``, ``count`` (single slips),
        ``mean`` [sig0], ``run_mean_error`` (standard error of the mean over the runs), and for
        n != ``reference`` (NaN where there is no reference): ``shift`` (relative difference of the
        pooled means), ``p_value`` (Welch, pooled events), ``detectable_shift`` (80 % power at 5 %)
        and ``p_runs`` (Welch on the run means).
    """
    pooled, run_means = {}, {}
    for item in files:
        key = run_key(item)
        if key["regime"] != "compliant":
            continue
        per = item.tables["slip_interfaces"]
        drops = per["dmu_sig0"].to_numpy(dtype=float)[~per["multi"].to_numpy(dtype=bool)]
        group = (key["N"], key["dt_scale"], key["n"])
        pooled.setdefault(group, []).append(drops)
        if drops.size:
            run_means.setdefault(group, []).append(drops.mean())
    rows = []
    for (N, dt_scale, n), parts in sorted(pooled.items()):
        sample = np.concatenate(parts)
        means = np.asarray(run_means.get((N, dt_scale, n), []))
        row = {"N": N, "dt_scale": dt_scale, "n": n, "seeds": len(parts), "count": sample.size,
               "mean": float(sample.mean()) if sample.size else math.nan,
               "run_mean_error": float(means.std(ddof=1) / math.sqrt(means.size)) if means.size > 1 else math.nan,
               "shift": math.nan, "p_value": math.nan, "detectable_shift": math.nan, "p_runs": math.nan}
        base = (N, dt_scale, reference)
        if n != reference and base in pooled:
            test = shift_test(np.concatenate(pooled[base]), sample)
            row.update(shift=test["shift"], p_value=test["p_value"], detectable_shift=test["detectable_shift"])
            base_means = np.asarray(run_means.get(base, []))
            if base_means.size > 1 and means.size > 1:
                row["p_runs"] = float(stats.ttest_ind(base_means, means, equal_var=False).pvalue)
        rows.append(row)
    return pd.DataFrame(rows)


def front_speed_by_size(files):
    """Front speed and delay of the re-run multi-slips per (N, dt_scale, regime, n).

    Parameters
    ----------
    files : Iterable[stickslip.events.analysis_files.AnalysisFile]
        ``front-dynamics`` files read with the table ``fronts``.

    Returns
    -------
    pandas.DataFrame
        ``events`` (re-run events with at least two slipping interfaces), ``ok`` (meaningful
        fits, finite ``c_f``), ``flagged``, ``c_f_median``, ``c_f_mean``, ``c_f_error`` (standard
        error of the mean over the meaningful fits) [c_s], ``tau_median``, ``tau_mean`` [H/c_s].
    """
    groups = {}
    for item in files:
        key = run_key(item)
        fronts = item.tables["fronts"]
        groups.setdefault(tuple(key[k] for k in GROUP), []).append(fronts[fronts["s"].to_numpy() >= 2])
    rows = []
    for key, parts in sorted(groups.items()):
        table = pd.concat(parts, ignore_index=True)
        speed = table["c_f"].to_numpy(dtype=float)
        ok = speed[np.isfinite(speed)]
        tau = table["tau"].to_numpy(dtype=float)
        tau = tau[np.isfinite(tau)]
        rows.append({**dict(zip(GROUP, key)), "events": len(table), "ok": ok.size, "flagged": len(table) - ok.size,
                     "c_f_median": float(np.median(ok)) if ok.size else math.nan,
                     "c_f_mean": float(ok.mean()) if ok.size else math.nan,
                     "c_f_error": float(ok.std(ddof=1) / math.sqrt(ok.size)) if ok.size > 1 else math.nan,
                     "tau_median": float(np.median(tau)) if tau.size else math.nan,
                     "tau_mean": float(tau.mean()) if tau.size else math.nan})
    return pd.DataFrame(rows)
