"""The protocol of a run: what sequence of loads, kicks and relaxations makes its increments.

A protocol drives a :class:`.system.System` one stored increment at a time for the increment
loop of :mod:`.run`. Its interface:

``columns``
    dict name -> numpy dtype of the columns it adds to the increment table;
``header``
    dict of the root attributes it adds to the run file;
``initial_row()``
    its columns for increment 0;
``step(kick, margin, increment)``
    makes the next increment (number ``increment``), a load (``kick`` False) or an event (True), and returns its
    columns with ``yield_element``, or None if the run must stop at the margin;
``stored(row)``
    is told the row just appended (e.g. to start a hold after a slip).

Built in: :class:`AthermalProtocol` (the paper's event-driven quasistatic protocol) and, for
``temperature > 0``, :class:`.thermal.ThermalProtocol` (kinetic Monte Carlo with a finite drive rate).
"""

from .minimise import within_margin

__all__ = ["AthermalProtocol", "make_protocol"]


class AthermalProtocol:
    """The paper's protocol: elastic load steps to the brink of yielding alternate with kicks and minimisation.

    Parameters
    ----------
    system : System
    """

    columns = {}
    header = {}

    def __init__(self, system):
        self.system = system

    @staticmethod
    def initial_row():
        """No columns of its own."""
        return {}

    def step(self, kick, margin, increment):
        """Load to the brink (:meth:`.system.System.event_step`) or kick and minimise (:meth:`.system.System.kick`)."""
        system = self.system
        if kick:
            converged, yield_element = system.kick(margin)
            return {"yield_element": yield_element} if converged else None
        system.event_step(False)
        if not system.extend and not within_margin(system.model, system.state.idx, margin):
            return None
        return {"yield_element": False}

    def stored(self, row):
        """Nothing to remember."""


def make_protocol(system, table=None):
    """The protocol of a system's parameters: athermal, or thermal for ``temperature > 0``.

    Parameters
    ----------
    system : System
    table : Mapping[str, numpy.ndarray], optional
        The stored increment table's columns (a resumed run; None for a new one).
    """
    if system.params.temperature > 0.0:
        from .thermal import ThermalProtocol

        return ThermalProtocol(system, table)
    return AthermalProtocol(system)
