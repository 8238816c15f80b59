"""Slide-hold-slide: when a thermal run's drive is held (the schedule of :class:`.protocol.ThermalProtocol`).

Once the drive has advanced by ``hold_delay`` since the last slip event (an event in which every block of
some interface changed well), it stops for the next of ``hold_times`` (cycled) while time and hops go on; a
slip during the hold ends it, a slip before it starts postpones it to the next cycle. A resumed run replays
its stored slips into the schedule (:func:`replay_slips`).
"""

import math

import numpy as np

__all__ = ["HoldSchedule", "replay_slips"]


class HoldSchedule:
    """When the drive is held: the slide-hold-slide protocol of the module docstring.

    Parameters
    ----------
    hold_times : Sequence[float]
        Hold durations, cycled [time]; empty: the drive never stops.
    delay : float
        Time of driving after a slip before the hold starts [time].

    Attributes
    ----------
    started : int
        Holds started so far (the next one lasts ``hold_times[started % len(hold_times)]``).
    """

    def __init__(self, hold_times, delay):
        self.hold_times = tuple(hold_times)
        self.delay = float(delay)
        self.started = 0
        self.start = self.end = math.inf

    def hold_now(self, t, duration):
        """Hold the drive from time ``t`` for ``duration`` (then drive on; no further holds)."""
        self.hold_times = ()
        self.start, self.end = t, t + duration

    def slip(self, t):
        """A slip at time ``t``: a hold that had started is over; the next one is scheduled."""
        if t > self.start:
            self.started += 1
        if self.hold_times:
            self.start = t + self.delay
            self.end = self.start + self.hold_times[self.started % len(self.hold_times)]
        else:
            self.start = self.end = math.inf

    def stretch(self, t):
        """``(holding, until)``: whether the drive is held at time ``t``, and until when that lasts (``inf``: on)."""
        if t < self.start:
            return False, self.start
        if t < self.end:
            return True, self.end
        return False, math.inf


def _slips(table, N):
    """Times of the stored slip events (event increments in which every block of an interface changed well)."""
    kick = np.asarray(table["kick"], dtype=bool)
    full = np.zeros(kick.size, dtype=bool)
    for name in table:
        if name.startswith("A_a"):
            full |= np.asarray(table[name]) == N
    return np.asarray(table["t"], dtype=np.float64)[kick & full]


def replay_slips(table, N, schedule):
    """Replay the slips of a stored increment table (columns ``kick``, ``t``, ``A_a*``) into ``schedule``."""
    for t in _slips(table, N):
        schedule.slip(t)
