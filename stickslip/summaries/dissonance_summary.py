"""What the slip-dissonance study measures, from its ``waiting-times`` outputs (docs/numerical-analysis.md, "Slip
dissonance").

- :func:`load_runs`: a study's ``waiting-times`` files, one row per run, with the drive they were made at (``drive``,
  ``lever_height``, ``k_drive``, ``phi``), ``n``, ``seed``, ``temperature``, ``drive_rate``, ``strengthening``.
- :func:`setting_of`: the drive setting of a run as one label (runs of one setting differ in ``n`` and ``seed``).
- :func:`scan_table`: per setting, ``n`` and interface the spread of ``ln T`` (:func:`stickslip.events.waiting_times.spread_table`),
  and per setting and interface the same pooled over ``n`` (the paper's Fig. 5b pools P(T_a) of one interface over
  the stacks; with one clock for every ``n`` the shift of T with ``n`` broadens the pool).
- :func:`loading_rates`: the rate at which the drive loads every interface of a run while nothing yields (its
  linear response), [sig0 per eps0 of drive]: in the lab ``K h gamma_dot (n + a)(n - a + 1) / (2 N)``.
- :func:`peak_ages`: the hold trials' peaks (:func:`.aging_summary.first_peaks`) with the age of the slipping
  interface's contacts at its peak: the time since the hold's start (hold and reload) plus the time between the
  interface's last slip and the state held (0 for the interface whose slip the state is); :func:`hold_peaks`: the
  same for several runs.
- :func:`estimator_runs`: the single slips of thermal runs with their waiting time ``T_fe`` and drop, ready for
  :func:`stickslip.statistics.estimator.estimator_table`.
"""

import h5py
import numpy as np
import pandas as pd

from ..formats.analysis_file import open_analysis_file
from ..events.analysis_files import read_analysis_file
from ..events.waiting_times import spread_table
from .aging_summary import first_peaks

__all__ = ["load_runs", "setting_of", "scan_table", "interface_rates", "loading_rates", "peak_ages", "hold_peaks", "estimator_runs", "SETTING_KEYS"]

#: Columns of :func:`load_runs` that make a drive setting.
SETTING_KEYS = ("drive", "lever_height", "k_drive", "temperature", "drive_rate", "strengthening")


def load_runs(paths):
    """The ``waiting-times`` files of a study, one row per run (module docstring).

    Returns
    -------
    pandas.DataFrame
        ``file``, ``n``, ``seed``, ``phi``, :data:`SETTING_KEYS`, ``thermal`` and ``data``
        (:class:`stickslip.events.analysis_files.AnalysisFile` with the tables ``slip_events`` and ``spread``).
    """
    rows = []
    for path in sorted(map(str, paths)):
        with open_analysis_file(path, "event-table") as file:
            if "spread" not in file:
                continue
        item = read_analysis_file(path, "event-table", ("slip_events", "spread"))
        params = item.attrs.get("params", {})
        thermal = bool(item.attrs.get("thermal", False))
        rows.append({"file": path, "n": item.n, "seed": int(item.attrs["seed"]), "phi": float(item.attrs["phi"]),
                     "drive": str(params.get("drive", "fixed-lever")),
                     "lever_height": float(params.get("lever_height", 10.0)) if params.get("drive") == "free-lever"
                     else np.nan,
                     "k_drive": float(item.attrs["k_drive"]),
                     "temperature": float(params.get("temperature", 0.0)),
                     "drive_rate": float(params["drive_rate"]) if thermal else np.nan,
                     "strengthening": float(params.get("junction_strengthening", 0.0)),
                     "thermal": thermal, "data": item})
    return pd.DataFrame(rows, columns=["file", "n", "seed", "phi", *SETTING_KEYS, "thermal", "data"])


def setting_of(row):
    """A drive setting as one label, e.g. ``"fixed-lever Phi 5e-07"`` or ``"free-lever H 2 Phi 5e-07, T 0.001 rate
    2e-08 lambda 5"``."""
    label = f"{row['drive']}" + (f" H {row['lever_height']:g}" if row["drive"] == "free-lever" else "") + \
        f" Phi {row['phi']:.1g}"
    if row["thermal"]:
        label += f", T {row['temperature']:g} rate {row['drive_rate']:g} lambda {row['strengthening']:g}"
    return label


def scan_table(runs):
    """The spread of the waiting times per setting, ``n`` and interface, and per setting and interface over ``n``.

    Parameters
    ----------
    runs : pandas.DataFrame
        :func:`load_runs`.

    Returns
    -------
    tuple[pandas.DataFrame, pandas.DataFrame]
        Per (``setting``, ``n``, ``interface``) and per (``setting``, ``interface``) pooled over ``n`` and seeds:
        :func:`stickslip.events.waiting_times.spread_table`'s columns (of ``T_fe`` in thermal runs, ``wait_drive`` else),
        then ``median_dmu_sig0`` (the median drop) and ``std_peak_sig0`` (the standard deviation of the peaks) [sig0].
    """
    parts = []
    for _, run in runs.iterrows():
        slips = run["data"].tables["slip_events"]
        parts.append(slips.assign(setting=setting_of(run), n=run["n"], seed=run["seed"],
                                  T=slips["T_fe"] if run["thermal"] else slips["wait_drive"]))
    if not parts:
        parts = [pd.DataFrame(columns=["setting", "n", "interface", "T", "rise_sig0", "recovered_sig0",
                                       "interrupted_sig0", "dmu_sig0", "mu_before_sig0"])]
    slips = pd.concat(parts, ignore_index=True)
    return tuple(_with_drops(spread_table(slips, by, T="T"), slips, by)
                 for by in (("setting", "n", "interface"), ("setting", "interface")))


def _with_drops(table, slips, by):
    """``table`` with the median drop ``median_dmu_sig0`` and the peaks' spread ``std_peak_sig0`` per group."""
    drops = slips.groupby(list(by)).agg(median_dmu_sig0=("dmu_sig0", "median"), std_peak_sig0=("mu_before_sig0", "std"))
    return table.merge(drops.reset_index(), on=list(by), how="left")


def interface_rates(delta_eps, delta_target, delta_lever, top_height, eps0, free_lever):
    """The loading rate of every interface along a linear response [sig0 per eps0 of drive].

    Parameters
    ----------
    delta_eps : numpy.ndarray
        [n N, 4, 3] the interface strains per step (:class:`stickslip.fem.linear_response.LinearResponse`).
    delta_target : numpy.ndarray
        [nlayer] the drive targets per step [length].
    delta_lever : float
        The free lever's drive target per step [length].
    top_height : float
        Mid-height of the top plate [length].
    eps0 : float
    free_lever : bool

    Returns
    -------
    numpy.ndarray
        float64 [n]: the interface's mean shear strain ``eps_xy`` per step (its stress ``G eps_xy``, the equivalent
        stress ``2 G eps_xy`` in units of ``sig0 = 2 G eps0``) over the drive per step (``gamma / eps0`` of a fixed
        lever, ``x_target / eps0`` of a free lever), interfaces bottom to top.
    """
    drive = delta_lever / eps0 if free_lever else delta_target[-1] / (2.0 * top_height * eps0)
    n = int(np.rint((delta_target.size - 1) / 2))
    return delta_eps[:, :, 2].reshape(n, -1).mean(axis=1) / eps0 / drive


def loading_rates(path):
    """:func:`interface_rates` of a fem run, from its stored linear response (``/event``).

    Parameters
    ----------
    path : str or os.PathLike
        A ``fem-run`` file.

    Returns
    -------
    numpy.ndarray
        float64 [n] [sig0 per eps0 of drive].
    """
    from ..formats.fem_run import read_run_attrs
    from ..mesh import load_mesh

    attrs = read_run_attrs(path)
    with h5py.File(path, "r") as file:
        delta_eps, delta_target = file["event/delta_eps"][...], file["event/delta_target"][...]
        delta_lever = float(np.ravel(file["event/delta_lever"][...])[0])
        top = float(load_mesh(file["mesh"]).layer_mid_height[-1])
    return interface_rates(delta_eps, delta_target, delta_lever, top, float(attrs["eps0"]),
                           attrs.get("drive") == "free-lever")


def peak_ages(peaks, slips):
    """The contacts' age at every peak of the hold trials of one run (module docstring).

    Parameters
    ----------
    peaks : pandas.DataFrame
        :func:`.aging_summary.first_peaks` of the run (``state``, ``interface``, ``t`` since the hold's start).
    slips : pandas.DataFrame
        The run's slips with their times: ``increment``, ``interface``, ``t`` (the ``thermal-events`` table
        ``slip_events``).

    Returns
    -------
    pandas.DataFrame
        ``peaks`` with ``age_start`` (the interface's age when the hold started [time]; NaN if it has not slipped
        before the state) and ``age`` (``age_start + t``).
    """
    start = np.full(len(peaks), np.nan)
    for k, (state, interface) in enumerate(zip(peaks["state"].to_numpy(), peaks["interface"].to_numpy())):
        mine = slips[(slips["interface"] == interface) & (slips["increment"] <= state)]
        if len(mine):
            last = mine.loc[mine["increment"].idxmax()]
            now = slips.loc[slips["increment"] == state, "t"]
            start[k] = float(now.iloc[0]) - float(last["t"]) if len(now) else np.nan
    return peaks.assign(age_start=start, age=start + peaks["t"].to_numpy(dtype=float))


def hold_peaks(items):
    """:func:`peak_ages` of the first peaks after every hold of several runs, one frame.

    Parameters
    ----------
    items : Iterable[stickslip.events.analysis_files.AnalysisFile]
        ``thermal-events`` outputs with the tables ``slip_events``, ``holds`` and ``trial_slips``.

    Returns
    -------
    pandas.DataFrame
        :func:`peak_ages` rows of every run with hold trials, with ``run`` (the run's index in ``items``); empty if
        none has any.
    """
    parts = []
    for k, item in enumerate(items):
        peaks = first_peaks(item)
        if len(peaks):
            parts.append(peak_ages(peaks, item.tables["slip_events"]).assign(run=k))
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()


def estimator_runs(runs):
    """The slips of the thermal runs with the columns the estimator reads, one frame.

    Returns
    -------
    pandas.DataFrame
        ``setting``, ``temperature``, ``strengthening``, ``n``, ``seed``, ``interface``, ``multi``, ``T_fe`` [time],
        ``dmu_sig0`` [sig0], ``T0`` (``1 / attempt_rate`` [time]).
    """
    parts = []
    for _, run in runs[runs["thermal"]].iterrows():
        slips = run["data"].tables["slip_events"]
        T0 = 1.0 / float(run["data"].attrs["params"].get("attempt_rate", 1.0))
        parts.append(slips[["interface", "multi", "T_fe", "dmu_sig0"]].assign(
            setting=setting_of(run), temperature=run["temperature"], strengthening=run["strengthening"], n=run["n"],
            seed=run["seed"], T0=T0))
    columns = ["setting", "temperature", "strengthening", "n", "seed", "interface", "multi", "T_fe", "dmu_sig0", "T0"]
    return pd.concat(parts, ignore_index=True)[columns] if parts else pd.DataFrame(columns=columns)
