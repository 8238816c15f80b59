"""The ``experiment-events`` analysis: every slip of one experimental recording, with its
interface, force drop, friction drop, waiting time, aging rate and slow slip.

Input: one ``timeseries`` file (:mod:`stickslip.experiment.timeseries`; lab recording or ``lever``
run). Output: one ``event-table`` file (header of :mod:`stickslip.formats.analysis_file`) with three
tables (:func:`stickslip.h5io.write_table`) and the run's attributes copied to the root:

``slip_events``: the normalised slip table that the database ingests
(:mod:`stickslip.formats.event_table`): ``event``, ``interface``, ``multi``, ``slip`` (dR),
``dmu``, ``time``.
``slips``: one row per slip of one interface, sorted by time (see :func:`analyse_record`).
``interfaces``: one row per ``interface`` a: ``driven`` (it can slip: ``a <= n`` in the stack,
``a`` the driven slab in the individual protocol), ``R_tot`` [mm] (total sliding over the analysed
record), ``dR_sum`` [mm] (sum of its detected slips), ``R_slow`` (``1 - dR_sum / R_tot``),
``n_slips``, ``n_multi``.

The first ``t_exclude`` seconds of the record (the paper's 300 s transient) are excluded from
both tables; slips there still count as the previous slip of an interface for ``T`` and the
drift.
"""

import dataclasses

import numpy as np
import pandas as pd

from .. import h5io, registry
from ..formats.analysis_file import write_analysis_file
from ..formats.event_table import slip_events_table
from ..plugin_params import ParameterError, param
from . import aging, detection, kinematics
from .timeseries import read_timeseries

__all__ = ["ExperimentEventsParams", "analyse_record", "experimental_slip_events", "run", "NAME", "VERSION"]

NAME = "experiment-events"
VERSION = "3"  # 3: the package's vocabulary (interface, time, slip, slip_from_dF; event-table 2)

SLIP_COLUMNS = ["event", "time", "interface", "n", "protocol", "multi", "t_start", "t_end", "dF", "dmu", "T", "slip",
                "slip_from_dF", "B_a", "drift", "slow_slip_before"]

#: The names of :func:`stickslip.experiment.detection.detect_slips` and of the paper in the vocabulary's words.
_VOCABULARY = {"a": "interface", "t": "time", "dR": "slip", "dR_from_dF": "slip_from_dF"}


@dataclasses.dataclass(frozen=True)
class ExperimentEventsParams:
    """Parameters of the slip detection and of the per-slip quantities."""

    threshold: float = param(detection.VELOCITY_THRESHOLD, "smoothed interface velocity above which a frame "
                             "belongs to a slip", unit="mm/s", exclusive_minimum=0)
    average_frames: int = param(detection.AVERAGE_FRAMES, "running-average width of the velocity (odd)",
                                unit="frames", minimum=1)
    min_frames: int = param(detection.MIN_FRAMES, "minimum number of consecutive fast frames of a slip",
                            unit="frames", minimum=1)
    force_window: float = param(1.0, "length of the force fits before and after a force drop", unit="s",
                                exclusive_minimum=0)
    t_exclude: float = param(300.0, "initial transient excluded from the tables (from the first frame)",
                             unit="s", minimum=0)
    t0: float = param(aging.T0, "time scale T0 of the aging law dmu = B ln(T/T0)", unit="s", exclusive_minimum=0)
    position_frames: int = param(detection.POSITION_FRAMES, "frames averaged for the position of an interface "
                                 "before and after a slip", unit="frames", minimum=1)
    slow_slip_drift: float = param(aging.SLOW_SLIP_DRIFT, "drift of an interface between two of its slips "
                                   "above which slow slip occurred", unit="mm", minimum=0)

    def check(self):
        """Raise ParameterError if the running-average width is even."""
        if self.average_frames % 2 == 0:
            raise ParameterError(f"parameter 'average_frames': expected an odd number, got {self.average_frames}")


def _event_windows(slips):
    """Bracket of each event and the bracket ends of its neighbours (force fits stop there)."""
    events = slips.groupby("event").agg(t_start=("t_start", "min"), t_end=("t_end", "max"))
    previous = np.concatenate([[-np.inf], events["t_end"].to_numpy()[:-1]])
    following = np.concatenate([events["t_start"].to_numpy()[1:], [np.inf]])
    return events["t_start"].to_numpy(), events["t_end"].to_numpy(), previous, following


def analyse_record(record, params=ExperimentEventsParams()):
    """Detect the slips of one recording and measure them.

    Parameters
    ----------
    record : stickslip.experiment.timeseries.ExperimentRecord
        Force ``F(t_F)`` [N], slab positions ``x(t_x)`` [mm] and the apparatus attributes.
    params : ExperimentEventsParams

    Returns
    -------
    slips : pandas.DataFrame
        One row per slip of one interface, columns :data:`SLIP_COLUMNS`:
        ``event`` (slips with overlapping brackets share it), ``time`` [s] (time of the slip),
        ``interface`` (a, 1 = lowest), ``n``, ``protocol``, ``multi`` (bool: more than one interface
        slipped in the event; ``dmu``, ``slip_from_dF``, ``B_a`` are then NaN since the lever
        kinematics of a single slip does not apply), ``t_start``, ``t_end`` [s] (frames that
        bracket the slip), ``dF`` [N] (force drop of the event), ``dmu`` [-]
        (:func:`~stickslip.experiment.kinematics.dmu_from_dF`), ``T`` [s] (since the previous slip
        of interface ``a``; NaN for its first), ``slip`` [mm] (dR, measured, see
        :func:`~stickslip.experiment.detection.detect_slips`), ``slip_from_dF`` [mm]
        (:func:`~stickslip.experiment.kinematics.dR_from_dF`), ``B_a``
        (``dmu / ln(T / T0)``), ``drift`` [mm] (``R_a`` just before the slip minus ``R_a`` just
        after the previous slip of ``a``, both averaged over ``position_frames`` frames), ``slow_slip_before`` (``drift >= slow_slip_drift``).
    interfaces : pandas.DataFrame
        Columns ``interface``, ``driven``, ``R_tot``, ``dR_sum`` [mm], ``R_slow`` [-], ``n_slips``, ``n_multi``.
    """
    R = record.R
    slips = detection.detect_slips(record.t_x, R, threshold=params.threshold, width=params.average_frames,
                                   min_frames=params.min_frames, position_frames=params.position_frames)
    t_start, t_end, previous, following = _event_windows(slips)
    event_dF = detection.force_drop(record.t_F, record.F, t_start, t_end, window=params.force_window,
                                    t_previous=previous, t_next=following)
    slips["dF"] = event_dF[slips["event"].to_numpy()]
    single = ~slips["multi"].to_numpy()
    geometry = dict(h=record.h, H=record.H)
    a = slips["a"].to_numpy()
    slips["dmu"] = np.where(single, kinematics.dmu_from_dF(slips["dF"], a, record.n, record.protocol,
                                                           normal_force=record.normal_force, **geometry), np.nan)
    slips["dR_from_dF"] = np.where(single, kinematics.dR_from_dF(slips["dF"], a, record.n, record.protocol,
                                                                 k_spring=record.k_spring, **geometry), np.nan)
    # Per interface, in time order: waiting time and drift since the previous slip.
    slips = slips.sort_values(["a", "t"], kind="stable")
    by_interface = slips.groupby("a")
    slips["T"] = slips["t"] - by_interface["t"].shift()
    slips["drift"] = slips["R_before"] - by_interface["R_after"].shift()
    slips["slow_slip_before"] = slips["drift"].to_numpy() >= params.slow_slip_drift
    slips["B_a"] = aging.aging_rate(slips["dmu"], slips["T"], t0=params.t0)
    slips["n"] = int(record.n)
    slips["protocol"] = str(record.protocol)

    first_frame = int(np.searchsorted(record.t_x, record.t_x[0] + params.t_exclude, side="left"))
    first_frame = min(first_frame, len(record.t_x) - 1)
    slips = slips[slips["i_start"].to_numpy() >= first_frame].sort_values(["t", "a"], kind="stable")
    slips = slips.rename(columns=_VOCABULARY)[SLIP_COLUMNS].reset_index(drop=True)

    index = np.arange(1, R.shape[1] + 1)
    driven = index <= record.n if record.protocol == "stack" else index == record.a
    interfaces = pd.DataFrame({"interface": index, "driven": driven})
    interfaces["R_tot"] = R[-1] - R[first_frame]
    grouped = slips.groupby("interface")
    interfaces["dR_sum"] = interfaces["interface"].map(grouped["slip"].sum()).fillna(0.0)
    interfaces["R_slow"] = aging.slow_slip_fraction(interfaces["R_tot"], interfaces["dR_sum"])
    interfaces["n_slips"] = interfaces["interface"].map(grouped.size()).fillna(0).astype(np.int64)
    interfaces["n_multi"] = interfaces["interface"].map(grouped["multi"].sum()).fillna(0).astype(np.int64)
    return slips, interfaces


def experimental_slip_events(slips):
    """The normalised slip table (format ``event-table``) of :func:`analyse_record`'s ``slips``.

    Returns
    -------
    pandas.DataFrame
        ``event``, ``interface`` (a), ``multi``, ``slip`` (dR) [mm], ``dmu`` [-], ``time`` [s], then
        the other numeric columns of ``slips`` (``dF``, ``T``, ``B_a``, ``slip_from_dF``, ``drift``, ...).
    """
    return slip_events_table(slips[[c for c in slips.columns if slips[c].dtype.kind in "biuf" and c != "n"]])


@registry.register("analysis", NAME, VERSION, ExperimentEventsParams, consumes=("timeseries",),
                   produces="event-table")
def run(params, input, output):
    """Detect and measure every slip of one experimental time series (lab or lever run)."""
    record = read_timeseries(input)
    slips, interfaces = analyse_record(record, params)
    with h5io.open_file(input) as source:
        run_attrs = dict(source.attrs)
    write_analysis_file(output, "event-table", analysis=NAME, version=VERSION, params=params, input=input,
                        attrs=run_attrs, tables={"slip_events": experimental_slip_events(slips), "slips": slips,
                                                 "interfaces": interfaces})
