"""What the calibration of the aging estimator measures, from its studies' outputs (docs/numerical-analysis.md,
"Slip dissonance").

- :func:`load_calibration_runs`: the ``waiting-times`` outputs of several studies, one row per run (a run that two
  studies share is read once), with its ``N``, its interfaces' strengths and its ``thermal-events`` output with hold
  trials (if any);
- :func:`run_truth`: per interface, the true B of a run's paired holds: the slope of the first peak after the hold
  against the contacts' age at the peak (:func:`.dissonance_summary.peak_ages`), and against the hold time;
- :func:`run_slips`: the slips of runs in the columns that :mod:`stickslip.statistics.calibration` and
  :mod:`stickslip.statistics.estimator` read, each with its run, seed, stack and interface strength;
- :func:`post_slip_slope`: the stress a slip leaves against ``ln T`` (the paper assumes it constant).
"""

import glob
from pathlib import Path

import numpy as np
import pandas as pd

from ..events.analysis_files import read_analysis_file
from .aging_summary import first_peaks, paired_slopes
from .dissonance_summary import load_runs, peak_ages

__all__ = ["load_calibration_runs", "run_truth", "run_slips", "post_slip_slope", "strength_of"]

_HOLD_TABLES = ("slip_events", "holds", "trial_slips")


def load_calibration_runs(studies):
    """The runs of several studies (module docstring).

    Parameters
    ----------
    studies : Sequence[str or os.PathLike]
        Results directories (``results/<study>``); their ``events/waiting-times/fem`` outputs are the runs, their
        ``events/thermal-events*/fem`` outputs with hold trials in the run give ``holds``.

    Returns
    -------
    pandas.DataFrame
        :func:`.dissonance_summary.load_runs`' columns plus ``run`` (the run id), ``study`` (the first study that
        has it), ``N``, ``strength`` (tuple: one scale per interface, 1 where the run has none) and ``holds`` (the
        :class:`stickslip.events.analysis_files.AnalysisFile` of its hold trials, or None).
    """
    paths, seen = [], set()
    for study in studies:
        for path in sorted(glob.glob(str(Path(study) / "events" / "waiting-times" / "fem" / "*.h5"))):
            if Path(path).stem not in seen:
                seen.add(Path(path).stem)
                paths.append(path)
    runs = load_runs(paths)
    if runs.empty:
        return runs.assign(run=[], study=[], N=[], strength=[], holds=[])
    runs["run"] = [Path(path).stem for path in runs["file"]]
    runs["study"] = [str(Path(path).parents[3]) for path in runs["file"]]
    params = [item.attrs.get("params", {}) for item in runs["data"]]
    runs["N"] = [int(p.get("N", 1458)) for p in params]
    runs["strength"] = [strength_of(p, n) for p, n in zip(params, runs["n"])]
    runs["holds"] = [_holds(studies, run, n) for run, n in zip(runs["run"], runs["n"])]
    return runs


def strength_of(params, n):
    """The interfaces' strength scales of a fem run's parameters: a tuple of ``n`` floats (1 where none is set)."""
    values = tuple(float(v) for v in params.get("interface_strength", ()))
    return values * n if len(values) == 1 else (values or (1.0,) * n)


def _holds(studies, run, n):
    """The ``thermal-events`` output of run ``run`` that made hold trials in it (None if none did)."""
    for study in studies:
        for path in sorted(glob.glob(str(Path(study) / "events" / "thermal-events*" / "fem" / f"{run}.h5"))):
            item = read_analysis_file(path, "event-table", _HOLD_TABLES)
            if int(item.attrs["analysis_params"].get("hold_interfaces", 1)) in (0, n) and not item.tables[
                    "holds"].empty:
                return item
    return None


def run_truth(item):
    """The true B of every interface of one run's paired holds.

    Parameters
    ----------
    item : stickslip.events.analysis_files.AnalysisFile
        A ``thermal-events`` output with hold trials (tables ``slip_events``, ``holds``, ``trial_slips``).

    Returns
    -------
    pandas.DataFrame
        Per ``interface``: ``B`` and ``B_error`` (mean over states of the first peak's slope against ln(age at the
        peak), every hold time, and its standard error over the states), ``states``, ``B_hold`` and
        ``B_hold_error`` (against ln T_w over T_w >= 1e6: the reload left out) and ``failed`` (the share of the holds
        that slipped before the reload).
    """
    peaks = peak_ages(first_peaks(item), item.tables["slip_events"])
    rows = []
    for a, mine in peaks.groupby("interface"):
        B, error, states = paired_slopes(mine, t_min=0.0, time="age")
        hold, hold_error, _ = paired_slopes(mine)
        held = mine.drop_duplicates(["state", "hold_time"])
        rows.append({"interface": int(a), "B": B, "B_error": error, "states": states, "B_hold": hold,
                     "B_hold_error": hold_error, "failed": float(held["failed_in_hold"].astype(bool).mean())})
    return pd.DataFrame(rows, columns=["interface", "B", "B_error", "states", "B_hold", "B_hold_error", "failed"])


def run_slips(runs):
    """The slips of thermal runs, one frame (module docstring).

    Parameters
    ----------
    runs : pandas.DataFrame
        :func:`load_calibration_runs` rows.

    Returns
    -------
    pandas.DataFrame
        ``run``, ``seed``, ``n``, ``N``, ``phi``, ``strengthening``, ``interface``, ``strength`` (the interface's
        scale), ``t``, ``T`` (``T_fe``), ``dmu``, ``mu_before`` [sig0], ``multi``, ``recovered``, ``interrupted``
        [sig0], ``T0`` (``1 / attempt_rate``).
    """
    parts = []
    for _, run in runs[runs["thermal"]].iterrows():
        slips = run["data"].tables["slip_events"]
        T0 = 1.0 / float(run["data"].attrs["params"].get("attempt_rate", 1.0))
        strength = np.asarray(run["strength"], dtype=float)[slips["interface"].to_numpy(dtype=int) - 1]
        parts.append(pd.DataFrame({
            "run": run["run"], "seed": run["seed"], "n": run["n"], "N": run["N"], "phi": run["phi"],
            "strengthening": run["strengthening"], "interface": slips["interface"].to_numpy(), "strength": strength,
            "t": slips["t"].to_numpy(dtype=float), "T": slips["T_fe"].to_numpy(dtype=float),
            "dmu": slips["dmu_sig0"].to_numpy(dtype=float), "mu_before": slips["mu_before_sig0"].to_numpy(dtype=float),
            "multi": slips["multi"].to_numpy(dtype=bool), "recovered": slips["recovered_sig0"].to_numpy(dtype=float),
            "interrupted": slips["interrupted_sig0"].to_numpy(dtype=float), "T0": T0}))
    columns = ["run", "seed", "n", "N", "phi", "strengthening", "interface", "strength", "t", "T", "dmu", "mu_before",
               "multi", "recovered", "interrupted", "T0"]
    return pd.concat(parts, ignore_index=True)[columns] if parts else pd.DataFrame(columns=columns)


def post_slip_slope(slips, T_min):
    """The post-slip stress ``mu_before - dmu`` of the single slips with ``T >= T_min`` against ``ln T``.

    Parameters
    ----------
    slips : pandas.DataFrame
        :func:`run_slips` rows.
    T_min : float
        [time]

    Returns
    -------
    tuple[float, float, int]
        The least-squares slope [sig0 per e-fold of T], its standard error, the slips (NaN below 3).
    """
    single = slips[~slips["multi"].to_numpy(dtype=bool) & (slips["T"].to_numpy(dtype=float) >= T_min)]
    if len(single) < 3:
        return np.nan, np.nan, len(single)
    x = np.log(single["T"].to_numpy(dtype=float))
    y = (single["mu_before"] - single["dmu"]).to_numpy(dtype=float)
    fit = np.polyfit(x, y, 1, cov=True)
    return float(fit[0][0]), float(np.sqrt(fit[1][0, 0])), len(single)
