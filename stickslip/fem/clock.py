"""The physical time of a thermal run, kept by its protocol: avalanches take no time.

A backend counts the time of the dynamics it integrates (its ``t``, advanced by ``dt`` per time step). For the
athermal protocol that is the run's physical time. A thermal protocol keeps its own: the time drawn by the
kinetic Monte Carlo, which the relaxations do not advance (an avalanche is instantaneous on the thermal scale).
It registers a :class:`Clock` with the stack (:meth:`.stack.Stack.keep_time`); the stack's time, its stored
states and :meth:`.stack.Stack.restore` are then the clock's.
"""

__all__ = ["Clock"]


class Clock:
    """Physical time owned by a protocol [time]: only the protocol advances it.

    Parameters
    ----------
    t : float
        The time now [time].

    Attributes
    ----------
    time : float
        The time now [time].
    """

    def __init__(self, t):
        self.time = float(t)

    def advance_to(self, t):
        """Advance to time ``t`` [time], not earlier than now.

        Raises
        ------
        ValueError
            If ``t`` is earlier than the time now.
        """
        if t < self.time:
            raise ValueError(f"the clock cannot go back from {self.time!r} to {t!r}")
        self.time = float(t)

    def restore(self, t):
        """Set the time of a stored state (a restore, not an advance) [time]."""
        self.time = float(t)
