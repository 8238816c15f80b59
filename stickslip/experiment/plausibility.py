"""Is a recording plausible for the apparatus it claims? A unit mistake shows as orders of magnitude.

A lab export in the wrong unit (positions in m labelled mm, times in ms labelled s) passes every
check of the format and gives a silent wrong result: no slip is detected, or slips a thousand
times too small. Two facts of the lever apparatus (docs/experiment-model.md) expose it:

- **Travel.** The spring of driven slab ``d`` (``d = n`` in the stack protocol, the top driven slab;
  ``d = a`` alone) is pulled at ``v = d h V / H`` [mm/s]. Over a record of duration ``D`` the slab
  follows it to within the change of the spring's extension, at most ``N / K`` per spring (no
  friction coefficient exceeds 1): its travel ``X`` is ``v D`` within ``n N / K``. A record whose
  travel differs from ``v D`` by more than that and by a factor of more than :data:`FACTOR` is
  implausible (:func:`travel_warning`).
- **Sticks end.** A stick cannot outlast the time the spring takes to load by the normal force,
  ``N / (K v)``. A record longer than :data:`STICKS` such times without one detected slip is
  implausible (:func:`no_slip_warning`).
- **The force loads at the drive's rate.** While the slabs stick, every driven spring ``j`` stretches
  at ``v_j = j h V / H`` and acts on the lever with the arm ``j h / H``: the lever force rises at
  ``sum_j K v_j j h / H`` [N/s]. The force record alone, against its own time axis, shows this rate as
  the upper decile of its slopes over 1/200 of the record (sticks fill most of a record; measured on
  virtual runs of both protocols, n = 1 ... 5: 0.9-1.3 times the rate). A rate off by more than
  :data:`FORCE_FACTOR` is implausible (:func:`force_rate_warning`): a force file in ms labelled s, with
  a correct positions file, passes the travel check.
- **The springs hold at most the friction of every interface.** A driven spring cannot pull harder than the
  friction of all ``n_slabs`` interfaces at the normal force (no friction coefficient exceeds 1), and acts on
  the lever with its arm ``j h / H``: a force record beyond :data:`FORCE_FACTOR` times the sum of these is
  implausible (:func:`force_range_warning`; a force of 1e308 N is a broken export, not a measurement).
- **Every slip has its drop.** The force drop of a slip is read from the force record around the
  slip's time, found in the positions: slips whose drop could not be measured (the two records
  do not cover the same times) make the analysis fail (:func:`missing_drop_error`).

Each warning names the unit mistakes whose factor is within half a decade of what is seen.
"""

import numpy as np

__all__ = ["travel_warning", "no_slip_warning", "force_rate_warning", "force_range_warning", "measured_loading_rate",
           "missing_drop_error", "FACTOR", "STICKS", "FORCE_FACTOR"]

#: Travel off by more than this factor (either way) is implausible.
FACTOR = 3.0

#: Longest possible sticks a record without a slip may last.
STICKS = 3.0

#: The force's loading rate off by more than this factor (either way) is implausible.
FORCE_FACTOR = 10.0

#: Unit mistakes, by the factor they multiply the travel ratio X / (v D) with.
_TRAVEL_MISTAKES = (("positions in m (not mm)", 1e-3), ("positions in cm (not mm)", 1e-1),
                    ("positions in um (not mm)", 1e3), ("times in ms (not s)", 1e-3), ("times in min (not s)", 60.0),
                    ("V in m/s (not mm/s)", 1e3), ("V in um/s (not mm/s)", 1e-3))

#: Unit mistakes of a force file, by the factor they multiply its loading rate with.
_FORCE_MISTAKES = (("times in ms (not s)", 1e-3), ("times in min (not s)", 60.0), ("times in h (not s)", 3600.0),
                   ("force in kN (not N)", 1e-3), ("force in mN (not N)", 1e3), ("V in m/s (not mm/s)", 1e3),
                   ("V in um/s (not mm/s)", 1e-3))

#: Unit mistakes of a force file, by the factor they multiply its largest force with.
_FORCE_RANGE_MISTAKES = (("force in mN (not N)", 1e3),)

#: Unit mistakes of one file's times, by the factor they multiply the force record's span over the positions' with.
_SPAN_MISTAKES = (("times in ms (not s) in the force file", 1e3), ("times in ms (not s) in the positions file", 1e-3),
                  ("times in min (not s) in the force file", 1 / 60.0),
                  ("times in min (not s) in the positions file", 60.0))

#: Windows over which the force's slopes are taken.
_WINDOWS = 200


def _driven(record):
    """The driven slab whose spring moves fastest and the speed of that spring [mm/s]."""
    slab = record.n if record.protocol == "stack" else record.a
    return slab, slab * record.h * record.V / record.H


def _likely(ratio, mistakes):
    """The mistakes whose factor is within half a decade of ``ratio``, as one phrase."""
    close = [name for name, factor in mistakes if abs(np.log10(ratio / factor)) <= 0.5]
    if not close:
        return "check the units and the apparatus attributes"
    return "likely a unit mistake: " + (", ".join(close[:-1]) + " or " if len(close) > 1 else "") + close[-1]


def travel_warning(record, source):
    """A one-line warning if the driven slab's travel does not fit the lever's drive, else None.

    Parameters
    ----------
    record : stickslip.experiment.timeseries.ExperimentRecord
    source : str
        The file, named in the message.

    Returns
    -------
    str or None
    """
    slab, speed = _driven(record)
    duration = record.t_x[-1] - record.t_x[0]
    expected = speed * duration
    travel = record.x[-1, slab - 1] - record.x[0, slab - 1]
    slack = record.n * record.normal_force / record.k_spring
    ratio = abs(travel) / expected
    if abs(travel - expected) <= slack or 1 / FACTOR <= ratio <= FACTOR:
        return None
    return (f"{source}: slab {slab} moved {travel:.3g} mm in {duration:.4g} s, {ratio:.2g} times the "
            f"{expected:.3g} mm its spring was pulled (V = {record.V:g} mm/s at H = {record.H:g} mm, spring at "
            f"{slab} h = {slab * record.h:g} mm); {_likely(max(ratio, 1e-12), _TRAVEL_MISTAKES)}")


def _loading_rate(record):
    """The lever force's rate while every driven slab sticks [N/s] (module docstring)."""
    slabs = range(1, record.n + 1) if record.protocol == "stack" else [record.a]
    _, speed = _driven(record)
    fastest = max(slabs)
    return sum(record.k_spring * speed * slab / fastest * slab * record.h / record.H for slab in slabs)


def _largest_force(record):
    """The largest lever force the springs can hold [N] (module docstring)."""
    slabs = range(1, record.n + 1) if record.protocol == "stack" else [record.a]
    return sum(record.n_slabs * record.normal_force * slab * record.h / record.H for slab in slabs)


def force_range_warning(record, source):
    """A one-line warning if the force record exceeds what the springs can hold, else None (``record``, and the force
    file ``source`` named in the message, as :func:`force_rate_warning`'s)."""
    largest = _largest_force(record)
    found = float(np.max(np.abs(record.F)))
    if found <= FORCE_FACTOR * largest:
        return None
    return (f"{source}: the lever force reaches {found:.3g} N, {found / largest:.2g} times the {largest:.3g} N its "
            f"springs can hold (each at most the friction of the {record.n_slabs} interfaces at N = "
            f"{record.normal_force:g} N, on its arm j h / H); {_likely(found / largest, _FORCE_RANGE_MISTAKES)}")


def measured_loading_rate(t, F):
    """Upper decile of the force's slopes over :data:`_WINDOWS` windows of the record [N / time unit].

    Parameters
    ----------
    t, F : numpy.ndarray
        float64 [n]: sample times and forces.

    Returns
    -------
    float
    """
    edges = np.unique(np.clip(np.searchsorted(t, np.linspace(t[0], t[-1], _WINDOWS + 1)), 0, t.size - 1))
    with np.errstate(over="ignore", invalid="ignore"):  # forces near the largest double: not a finite rate
        return float(np.percentile(np.diff(F[edges]) / np.diff(t[edges]), 90)) if edges.size > 2 else float("nan")


def force_rate_warning(record, source):
    """A one-line warning if the force record does not load at the drive's rate, else None.

    Parameters
    ----------
    record : stickslip.experiment.timeseries.ExperimentRecord
    source : str
        The force file, named in the message.

    Returns
    -------
    str or None
    """
    expected = _loading_rate(record)
    measured = measured_loading_rate(record.t_F, record.F)
    ratio = measured / expected
    if not np.isfinite(ratio) or 1 / FORCE_FACTOR <= ratio <= FORCE_FACTOR:
        return None
    return (f"{source}: the lever force rises at {measured:.3g} N/s while the slabs stick, {ratio:.2g} times the "
            f"{expected:.3g} N/s of its springs (K = {record.k_spring:g} N/mm, V = {record.V:g} mm/s); "
            f"{_likely(max(ratio, 1e-12), _FORCE_MISTAKES)}")


def missing_drop_error(record, slips, source):
    """A one-line message if most slips of a record have no measured force drop, else None.

    Parameters
    ----------
    record : stickslip.experiment.timeseries.ExperimentRecord
    slips : pandas.DataFrame
        Its slips (:func:`stickslip.experiment.analysis.analyse_record`; column ``dF``).
    source : str

    Returns
    -------
    str or None
    """
    missing = int(slips["dF"].isna().sum())
    if not len(slips) or missing <= len(slips) // 2:
        return None
    span_F, span_x = record.t_F[-1] - record.t_F[0], record.t_x[-1] - record.t_x[0]
    ratio = span_F / span_x if span_x > 0 else float("nan")
    likely = (_likely(ratio, _SPAN_MISTAKES) if np.isfinite(ratio) and not 1 / FACTOR <= ratio <= FACTOR
              else "check the two files' times")
    return (f"{source}: {missing} of {len(slips)} slips have no measured force drop: the force record spans "
            f"{record.t_F[0]:.4g} ... {record.t_F[-1]:.4g} s, the positions {record.t_x[0]:.4g} ... "
            f"{record.t_x[-1]:.4g} s; {likely}")


def no_slip_warning(record, slips, source):
    """A one-line warning if a record many stick times long has no slip, else None.

    Parameters
    ----------
    record : stickslip.experiment.timeseries.ExperimentRecord
    slips : int
        Slips detected in it.
    source : str

    Returns
    -------
    str or None
    """
    _, speed = _driven(record)
    longest = record.normal_force / (record.k_spring * speed)
    duration = record.t_x[-1] - record.t_x[0]
    if slips or duration <= STICKS * longest:
        return None
    return (f"{source}: no slip in {duration:.4g} s, {duration / longest:.2g} times the longest possible stick "
            f"({longest:.3g} s for the spring to load by N = {record.normal_force:g} N); likely a unit mistake: "
            f"positions in m or cm (not mm: slips too small to see), times in ms (not s) or V in m/s (not mm/s)")
