"""Waiting times between the slips of an interface of a fem run, and what makes them broad or narrow.

The paper's test of aging (its Fig. 5b, c) needs waiting times T_a that spread over decades: in the lab the
lever loads interface ``a`` of a stack of ``n`` at a rate that grows with ``n`` and slips elsewhere unload it,
so that T_a is "broadly distributed". This module measures that spread on a fem run:

- **The clocks** (:func:`drive_clock`): a thermal run's time ``t``, and in every run the imposed drive [eps0]:
  the shear ``gamma`` of a fixed lever (its top plate's target over twice its mid-height), the drive target
  ``x_target`` of a free lever (whose rotation follows the lever, not the drive), the quantities that the
  thermal protocol advances at ``drive_rate`` per unit time. An athermal run has no clock (its ``t`` counts
  minimisation steps), but its drive advances only in the elastic load steps, so the drive since the previous
  slip is its waiting time in units of ``1 / drive_rate``.
- **Waiting times** (:func:`waiting_times`): for every steady-state slip of interface ``a`` (``A_a == N``,
  single or in a multi-slip), since the previous slip of ``a`` (any slip of ``a``, before the steady state
  too; NaN for the first): ``T_fe`` (thermal runs), ``wait_drive``, the drop ``dmu_sig0``, the peak
  ``mu_before_sig0``, and the loading path between the two slips: ``rise_sig0`` (the increase of ``a``'s
  stress over the elastic load steps in between, proportional to ``wait_drive`` along the linear response),
  ``recovered_sig0`` (its own part, the peak minus the stress the previous slip left) and
  ``interrupted_sig0`` (what ``a`` lost in the events of other interfaces and in its own microscopic events
  in between: ``rise = recovered + interrupted``).
- **The spread** (:func:`spread_table`): per group of slips ``std(ln T)`` with its standard error
  (``std / sqrt(2 (m - 1))``), the 5-95 % range of ``T`` in decades, the spread of ``ln recovered`` (what the
  thresholds alone would give) and the mean share of the rise lost to interruptions (what the loading path
  adds).

The analysis plugin ``waiting-times`` writes the slips (format ``event-table``, table ``slip_events``) with
these columns, and the table ``spread`` per interface (:func:`spread_table` of ``T_fe`` in a thermal run, of
``wait_drive`` in an athermal one).
"""

import dataclasses
import math

import numpy as np
import pandas as pd

from ..formats.analysis_file import write_analysis_file
from ..formats.event_table import slip_events_table
from ..h5io import FileFormatError
from ..registry import register
from . import extraction
from .plugin import event_attrs

__all__ = ["NAME", "VERSION", "WaitingTimeParams", "drive_clock", "waiting_times", "spread", "spread_table", "run"]

NAME = "waiting-times"
VERSION = "1"


@dataclasses.dataclass(frozen=True)
class WaitingTimeParams:
    """The waiting times have no parameter: the slips are the paper's (``A_a == N``), the clocks the run's."""


def drive_clock(increments, top_height, eps0):
    """The imposed drive per increment [eps0] (module docstring).

    Parameters
    ----------
    increments : pandas.DataFrame
        The run's increment table (:func:`stickslip.formats.fem_run.read_increments`): ``lever_target`` (free
        lever) or the top layer's ``fxdrive_<l>`` and ``ubar_<l>`` (fixed lever; ``l`` the last layer).
    top_height : float
        Mid-height of the top plate [length].
    eps0 : float

    Returns
    -------
    numpy.ndarray
        float64 [ninc].
    """
    if "lever_target" in increments:
        return increments["lever_target"].to_numpy(dtype=float) / eps0
    top = max(int(name.split("_")[1]) for name in increments if name.startswith("fxdrive_"))
    target = increments[f"fxdrive_{top}"].to_numpy(dtype=float) + increments[f"ubar_{top}"].to_numpy(dtype=float)
    return target / (2.0 * top_height * eps0)


def waiting_times(increments, N, drive, *, t=None, classified=None):
    """Every steady-state slip of every interface with its waiting time and loading path (module docstring).

    Parameters
    ----------
    increments : pandas.DataFrame
        The run's increment table.
    N : int
        Blocks per interface.
    drive : numpy.ndarray
        :func:`drive_clock` of the table [eps0].
    t : numpy.ndarray, optional
        A thermal run's clock per increment [time]; None: no ``T_fe`` (an athermal run).
    classified : pandas.DataFrame, optional
        :func:`.extraction.classify_increments` of the table (computed if not given).

    Returns
    -------
    pandas.DataFrame
        The normalised slip table (:func:`stickslip.formats.event_table.slip_events_table`: ``event``,
        ``interface``, ``multi``, ``dmu_sig0``, ``t`` (thermal), ``increment``), then ``T_fe`` (thermal),
        ``wait_drive``, ``mu_before_sig0``, ``rise_sig0``, ``recovered_sig0``, ``interrupted_sig0``; one row per
        (steady-state slip, interface), sorted by increment and interface.
    """
    if classified is None:
        classified = extraction.classify_increments(increments, N)
    kick = classified["kick"].to_numpy(dtype=bool)
    steady = classified["steady"].to_numpy(dtype=bool)
    parts = []
    for a in extraction.interfaces_in(classified):
        mu = classified[f"mu_a{a}"].to_numpy(dtype=float)
        change = np.diff(mu, prepend=mu[0])
        cum_gain, cum_loss = np.cumsum(np.where(~kick, change, 0.0)), np.cumsum(np.where(kick, -change, 0.0))
        slipped = np.flatnonzero(kick & (classified[f"A_a{a}"].to_numpy() == N))
        rows = slipped[steady[slipped]]
        previous = np.searchsorted(slipped, rows) - 1
        has = previous >= 0
        before = np.where(has, slipped[np.maximum(previous, 0)], 0)

        def since(values):  # over the increments after the previous slip, up to the one before this kick
            return np.where(has, values[rows - 1] - values[before], np.nan)

        part = {"increment": classified["increment"].to_numpy()[rows], "interface": np.full(rows.size, a, np.int64),
                "multi": classified["s"].to_numpy()[rows] > 1, "dmu_sig0": mu[rows - 1] - mu[rows]}
        if t is not None:
            part |= {"t": t[rows], "T_fe": np.where(has, t[rows] - t[before], np.nan)}
        parts.append(pd.DataFrame(part | {
            "wait_drive": np.where(has, drive[rows] - drive[before], np.nan), "mu_before_sig0": mu[rows - 1],
            "rise_sig0": since(cum_gain), "recovered_sig0": since(mu), "interrupted_sig0": since(cum_loss)}))
    table = pd.concat(parts, ignore_index=True).sort_values(["increment", "interface"], kind="stable")
    table.insert(0, "event", np.unique(table["increment"].to_numpy(), return_inverse=True)[1].reshape(-1))
    return slip_events_table(table.reset_index(drop=True))


def spread(values):
    """``std(ln values)`` of the positive finite values, its standard error ``std / sqrt(2 (m - 1))`` and ``m``."""
    values = np.asarray(values, dtype=float)
    logs = np.log(values[np.isfinite(values) & (values > 0)])
    if logs.size < 2:
        return math.nan, math.nan, int(logs.size)
    std = float(logs.std(ddof=1))
    return std, std / math.sqrt(2.0 * (logs.size - 1)), int(logs.size)


def spread_table(slips, by=("interface",), T="wait_drive"):
    """The spread of the waiting times per group of slips (module docstring).

    Parameters
    ----------
    slips : pandas.DataFrame
        :func:`waiting_times` rows (of one or several runs; further columns such as ``n`` may be grouped by).
    by : Sequence[str]
        Columns to group by (empty: all slips).
    T : str
        The waiting time: ``wait_drive`` or ``T_fe``.

    Returns
    -------
    pandas.DataFrame
        Per group: ``n_slips`` (with a waiting time), ``std_lnT`` and ``std_lnT_error``, ``decades`` (the 5-95 %
        range of ``T``), ``std_ln_recovered`` (the spread the thresholds alone give), ``interrupted_share``
        (mean ``interrupted / rise``), ``median_T``.
    """
    rows = []
    groups = slips.groupby(list(by), sort=True) if by else [((), slips)]
    for key, group in groups:
        values = group[T].to_numpy(dtype=float)
        ok = np.isfinite(values) & (values > 0)
        std, error, count = spread(values)
        low, high = np.percentile(values[ok], [5, 95]) if ok.any() else (math.nan, math.nan)
        with np.errstate(divide="ignore", invalid="ignore"):
            share = group["interrupted_sig0"].to_numpy(dtype=float) / group["rise_sig0"].to_numpy(dtype=float)
        rows.append({**dict(zip(by, key if isinstance(key, tuple) else (key,))), "n_slips": count, "std_lnT": std,
                     "std_lnT_error": error, "decades": math.log10(high / low) if ok.any() else math.nan,
                     "std_ln_recovered": spread(group["recovered_sig0"])[0],
                     "interrupted_share": float(np.nanmean(share)) if np.isfinite(share).any() else math.nan,
                     "median_T": float(np.median(values[ok])) if ok.any() else math.nan})
    return pd.DataFrame(rows, columns=[*by, "n_slips", "std_lnT", "std_lnT_error", "decades", "std_ln_recovered",
                                       "interrupted_share", "median_T"])


@register("analysis", NAME, VERSION, WaitingTimeParams, consumes=("fem-run",), produces="event-table")
def run(params, input, output):
    """Waiting times of every slip of a fem run, with the loading path between slips, and their spread."""
    import h5py

    from ..formats.fem_run import read_increments, read_run_attrs
    from ..mesh import load_mesh

    attrs = read_run_attrs(input)
    if "N" not in attrs:
        raise FileFormatError(f"{input}: run attributes lack N")
    with h5py.File(input, "r") as file:
        top_height = float(load_mesh(file["mesh"]).layer_mid_height[-1])
    increments = read_increments(input)
    N = int(attrs["N"])
    classified = extraction.classify_increments(increments, N, source=str(input))
    thermal = float(attrs.get("temperature", 0.0)) > 0.0
    slips = waiting_times(increments, N, drive_clock(increments, top_height, float(attrs["eps0"])),
                          t=increments["t"].to_numpy(dtype=float) if thermal else None, classified=classified)
    table = spread_table(slips, T="T_fe" if thermal else "wait_drive")
    write_analysis_file(output, "event-table", analysis=NAME, version=VERSION, params=params, input=input,
                        attrs={**event_attrs(attrs, classified, source=str(input)), "thermal": thermal},
                        tables={"slip_events": slips, "spread": table})
