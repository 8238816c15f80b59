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

Each warning names the unit mistakes whose factor is within half a decade of what is seen.
"""

import numpy as np

__all__ = ["travel_warning", "no_slip_warning", "FACTOR", "STICKS"]

#: Travel off by more than this factor (either way) is implausible.
FACTOR = 3.0

#: Longest possible sticks a record without a slip may last.
STICKS = 3.0

#: Unit mistakes, by the factor they multiply the travel ratio X / (v D) with.
_TRAVEL_MISTAKES = (("positions in m (not mm)", 1e-3), ("positions in cm (not mm)", 1e-1),
                    ("positions in um (not mm)", 1e3), ("times in ms (not s)", 1e-3), ("times in min (not s)", 60.0),
                    ("V in m/s (not mm/s)", 1e3), ("V in um/s (not mm/s)", 1e-3))

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
