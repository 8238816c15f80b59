"""The event sources of a thermal run: what draws the next event and brings the stack to it.

The thermal protocol (:class:`.protocol.ThermalProtocol`) asks its source, stretch by stretch of the
hold schedule, for the next event after the time now (:meth:`ArrheniusHops.draw`), then to bring the
stack to the drive offset of that event (:meth:`ArrheniusHops.settle`), and after a hop that fell back,
to undo it (:meth:`ArrheniusHops.undo`: a rollback to a checkpoint, :meth:`..stack.Stack.rollback`). A draw reads
the wells and strains of the interfaces (what the kinetic Monte Carlo needs to choose); a state returned to is
not read again (:class:`..host_copies.HostCopies`), and the load to an event keeps every Gauss point in its well
(counted where the state is, :func:`load_keeping_wells`), so the wells of the draw are those of the event. Two
sources, composed into the protocol rather than inherited:

- :class:`ArrheniusHops`: the blocks hop over their barriers at Arrhenius rates while the drive
  advances, or the athermal threshold comes first (:func:`.sampler.sample_event`). The offsets are
  counted from the state at the start of the load increment, which stays where it is until the event.
- :class:`ArrheniusWithRedraws`: the same with the redraws of the junctions among the events
  (:func:`.redraws.sample_with_redraws`): the redraws before the event are applied as they come, so the
  stack is settled at every stretch's end and the offsets are counted from there.

A draw (:class:`Draw`) has the kind of event (:data:`.sampler.NONE`: the stretch ended; ``HOP``,
``THRESHOLD``, :data:`.redraws.REDRAW`) and its time; the protocol keeps the clock.
"""

import math
from typing import NamedTuple

from ..errors import SolverError
from .redraws import REDRAW, sample_with_redraws
from .sampler import NONE, THRESHOLD, sample_event

__all__ = ["Draw", "ArrheniusHops", "ArrheniusWithRedraws", "load_keeping_wells"]


def load_keeping_wells(stack, loading, offset, since, redraws=0):
    """Load ``stack`` by ``offset`` (a draw's drive offset), which keeps every Gauss point in its well.

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
    loading : stickslip.fem.loading.Loading
    offset : float
        [response units].
    since : stickslip.fem.stack.Checkpoint
        The state whose wells the stack must keep (the draw's).
    redraws : int, optional
        Junctions redrawn since (for the message).

    Raises
    ------
    SolverError
        If a Gauss point left its well on the way (round-off at a yield strain).
    """
    if offset != 0.0:
        loading.load(offset)
    if stack.changed_since(since):
        raise SolverError(f"the load to the next event (drive offset {offset:.6e}, {redraws} junctions redrawn "
                          "meanwhile) moved a Gauss point out of its well (round-off at a yield strain)")


class Draw(NamedTuple):
    """The next event drawn by a source.

    Attributes
    ----------
    kind : int
        :data:`.sampler.NONE`, ``HOP``, ``THRESHOLD`` or :data:`.redraws.REDRAW`.
    block, direction : int
        A hop's interface element and :data:`.barriers.FORWARD` or backward; a redraw's block (direction -1);
        -1 otherwise.
    dt : float
        Time from the draw's start to the event (to the stretch's end for ``NONE``) [time].
    time : float
        Time of the event [time].
    offset : float
        Drive offset of the event [response units], counted as the source counts it (from the load increment's
        start, or from the stack's state at the draw's start; for ``THRESHOLD`` with redraws, that of the last
        redraw before it).
    redraws : int
        Junction redraws applied before the event within this draw.
    depth : float
        A redraw's new junction depth [G eps0^2 h^2] (not applied), else NaN.
    """

    kind: int
    block: int
    direction: int
    dt: float
    time: float
    offset: float
    redraws: int = 0
    depth: float = math.nan


class ArrheniusHops:
    """Hops at Arrhenius rates while the drive advances, and the athermal threshold (module docstring).

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
    model : stickslip.fem.model.Model
        The stack's model (its law and interface elements).
    loading : stickslip.fem.loading.Loading
    beta : float
        ``1 / T`` [1 / energy].
    attempt_rate : float
        ``nu`` [1 / time].
    """

    def __init__(self, stack, model, loading, beta, attempt_rate):
        self.stack, self.model, self.loading = stack, model, loading
        self.beta, self.attempt_rate = beta, attempt_rate
        self.start = None
        self.offset = self.threshold = 0.0

    def begin(self):
        """Start a load increment from the state now (a checkpoint: the stack stays there until the event)."""
        self.start = self.stack.checkpoint()
        self.threshold = self.loading.step_size(False)
        self.offset = 0.0

    def columns(self, draw=None):
        """No columns of its own in the increment table."""
        return {}

    def draw(self, t, allowed, speed, until, stream):
        """The next event after time ``t`` within the stretch that ends at ``until``.

        Parameters
        ----------
        t, until : float
            The time now and the stretch's end [time].
        allowed : numpy.ndarray
            bool [ni, 2]: the blocks and directions that may hop (failed hops are left out).
        speed : float
            Drive offset per unit time (0 while the drive is held).
        stream : tuple
            The pcg32 state and increment of the load increment's random stream.

        Returns
        -------
        Draw
        """
        m = self.model
        idx, eps = self.stack.read("idx", "eps")  # the start's, read once (a failed hop rolls back to it)
        kind, block, direction, dt = sample_event(
            m.law, self.stack.yield_strains, idx, eps, self.loading.response.delta_eps, m.iface_dV, allowed,
            self.beta, self.attempt_rate, self.offset, speed, until - t, self.threshold, *stream)
        if speed > 0.0:
            self.offset += speed * dt
        return Draw(kind, block, direction, dt, until if kind == NONE else t + dt, self.offset)

    def settle(self, draw):
        """Bring the stack to the event: to the brink for the threshold, along the drive to a hop's offset
        (:func:`load_keeping_wells`)."""
        if draw.kind == THRESHOLD:
            self.loading.step(False)
        elif draw.kind != NONE:
            load_keeping_wells(self.stack, self.loading, draw.offset, self.start)

    def undo(self, loaded):
        """A hop fell back: the stack back to the increment's start (the clock goes on from the hop's time;
        ``loaded``, the checkpoint at the hop, is not needed)."""
        self.stack.rollback(self.start)


class ArrheniusWithRedraws:
    """Hops, the athermal threshold and the redraws of the junctions (module docstring).

    Parameters
    ----------
    stack, model, loading, beta, attempt_rate
        As :class:`ArrheniusHops`.
    junctions : stickslip.fem.thermal.junctions.Junctions
        Registered with the stack as the modifier of its yield strains.
    temperature : float
        ``T`` [G eps0^2 h^2].

    Attributes
    ----------
    redraws : int
        Redraws applied since the start of the load increment.
    """

    def __init__(self, stack, model, loading, beta, attempt_rate, junctions, temperature):
        self.stack, self.model, self.loading = stack, model, loading
        self.beta, self.attempt_rate = beta, attempt_rate
        self.junctions, self.temperature = junctions, temperature
        self.redraws = 0

    def begin(self):
        """Start a load increment (no redraw yet)."""
        self.redraws = 0

    def columns(self, draw=None):
        """The increment's aging columns: redraws so far and, for a redraw event ``draw``, its block and depth."""
        if draw is not None and draw.kind == REDRAW:
            return {"redraws": self.redraws, "redraw_block": draw.block, "redraw_depth": draw.depth}
        return {"redraws": self.redraws, "redraw_block": -1, "redraw_depth": math.nan}

    def draw(self, t, allowed, speed, until, stream):
        """The next event after time ``t`` within the stretch that ends at ``until``, the redraws before it applied
        to the junctions (parameters as :meth:`ArrheniusHops.draw`)."""
        m, j, wells = self.model, self.junctions, self.stack.wells
        idx, eps = self.stack.read("idx", "eps")
        kind, block, direction, dt, offset, count, depth = sample_with_redraws(
            m.law, self.stack.yield_strains.copy(), wells.epsy, wells.offset, j.well, j.depth, j.scale,
            j.glass_temperature, j.attempt_rate, 1.0 / self.temperature, idx, eps, self.loading.response.delta_eps,
            m.iface_dV, allowed, self.beta, self.attempt_rate, speed, until - t, *stream)
        self.redraws += count
        return Draw(kind, block, direction, dt, t + dt, offset, count, depth)

    def settle(self, draw):
        """Give the backend the junctions redrawn meanwhile and bring the stack to the draw's drive offset (to the
        brink for the threshold, from the offset of the last redraw before it).

        The yield strains go first: the load re-evaluates every Gauss point's well at the new offset, where the
        sampling found each of them in its well.

        Raises
        ------
        SolverError
            If a Gauss point left its well on the way (round-off at a yield strain).
        """
        token = self.stack.checkpoint()
        if draw.redraws:
            self.stack.push_yield_strains()
        load_keeping_wells(self.stack, self.loading, draw.offset, token, draw.redraws)
        if draw.kind == THRESHOLD:
            self.loading.step(False)

    def undo(self, loaded):
        """A hop fell back: the stack back to ``loaded``, the checkpoint at the hop."""
        self.stack.rollback(loaded)
