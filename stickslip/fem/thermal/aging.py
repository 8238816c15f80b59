"""The thermal protocol with junction aging: junction redraws compete with the hops, every event renews junctions.

:class:`AgingProtocol` is :class:`.protocol.ThermalProtocol` (``junction_strengthening > 0``) with
its own load and one more kind of event:

- **load** (odd increments): the next event is drawn exactly among the hops, the athermal
  threshold and the redraws of the junctions (:func:`.redraws.sample_with_redraws`); the redraws
  before it are applied as they come (they change the yield strains the backend holds, not the
  stress) and counted (column ``redraws``); a redraw that leaves a Gauss point of its block outside
  its narrower well is the event (``redraw_block``, ``redraw_depth`` on the load increment);
- **event** (even increments): the hop, the kick or that redraw (the junction set, the stack
  relaxed), then the junctions are renewed (:meth:`AgingProtocol.renew`): a block whose four Gauss
  points now share a well other than its junction's gets a new junction, one whose points are split
  loses its own (which can release part of the block: the stack is relaxed again, until nothing moves).

The junctions of every increment are stored with it (``junction_depth``, ``junction_well``), the
random numbers of the renewals after event ``i`` come from that increment's stream, and a pending
redraw is in the load increment's columns: a run resumed from any stored increment gives the same
bytes. docs/fem.md, "Junction aging".
"""

import math

import numpy as np

from ..errors import SolverError
from .barriers import FORWARD
from .junctions import STATE_FIELDS, Junctions
from .protocol import COLUMNS, STREAM, ThermalProtocol
from .redraws import REDRAW, sample_with_redraws
from .sampler import HOP, NONE, THRESHOLD

__all__ = ["AgingProtocol", "AGING_COLUMNS", "JunctionChange", "thermal_protocol"]

#: The increment table's columns of junction aging (beside :data:`.protocol.COLUMNS`).
AGING_COLUMNS = {"redraws": np.int64, "redraw_block": np.int64, "redraw_depth": np.float64}


class JunctionChange:
    """A perturbation: the yield strains of the junctions as they are now given to the backend (a Gauss point may move).

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
        With junctions.
    """

    def __init__(self, stack):
        self.stack = stack

    def apply(self):
        """Push the junctions' yield strains (:meth:`..stack.Stack.push_yield_strains`)."""
        self.stack.push_yield_strains()

    def moves(self):
        """:meth:`apply`, and whether a Gauss point changed well (its stress changed: the stack must relax)."""
        token = self.stack.watch()
        self.apply()
        return self.stack.moved(token)


class AgingProtocol(ThermalProtocol):
    """The thermal protocol with junction aging (module docstring); parameters as :class:`.protocol.ThermalProtocol`.

    Its junctions (:class:`.junctions.Junctions`) are registered with the stack as the modifier of its yield strains
    (:meth:`..stack.Stack.modify_yield_strains`): a stored state includes them. A protocol made for a stack whose
    junctions are registered already (a hold trial, an aftershock replay on a run's stack) takes those over.

    Attributes
    ----------
    junctions : stickslip.fem.thermal.junctions.Junctions
    """

    def __init__(self, stack, model, loading, relaxation, params, mesh, constants, table=None, stream=STREAM):
        super().__init__(stack, model, loading, relaxation, params, mesh, constants, table, stream)
        p = params
        blocks = model.epsy.shape[0]
        self.junctions = stack.modifier
        if self.junctions is None:
            self.junctions = Junctions(blocks, p.junction_strengthening, p.junction_glass_temperature,
                                       p.junction_attempt_rate, p.eps0)
            stack.modify_yield_strains(self.junctions)
        elif not isinstance(self.junctions, Junctions):
            raise ValueError(f"the stack's yield strains are modified by {self.junctions!r}, not by junctions")
        self.columns = {**COLUMNS, **AGING_COLUMNS}
        self.header = {**self.header, "junction_strengthening": p.junction_strengthening,
                       "junction_glass_temperature": p.junction_glass_temperature,
                       "junction_attempt_rate": p.junction_attempt_rate}
        self.state_fields = {name: ((blocks,), dtype) for name, dtype in STATE_FIELDS.items()}
        self.redraw = None
        if table is None:
            self.renew(p.margin, 0)  # the junctions of a new state (a restored one keeps its own)
        else:
            kick, block, depth = (np.asarray(table[name])[-1] for name in ("kick", "redraw_block", "redraw_depth"))
            self.redraw = None if kick or block < 0 else (int(block), float(depth))

    @staticmethod
    def initial_row():
        """Columns of increment 0."""
        return {**ThermalProtocol.initial_row(), "redraws": 0, "redraw_block": -1, "redraw_depth": math.nan}

    def step(self, event, margin, increment):
        """A load to the next event, or that event followed by the renewal of the junctions (module docstring)."""
        if not event:
            return self._load(margin, increment)
        if self.redraw is None:
            row = {**self._event(margin), "redraws": 0, "redraw_block": -1, "redraw_depth": math.nan}
        else:
            row = self._redrawn(margin)
        self.renew(margin, increment)
        return row

    def renew(self, margin, increment):
        """New junctions for the blocks that changed well (:meth:`.junctions.Junctions.renew`), relaxed until nothing moves.

        The random numbers come from the stream of ``increment``; avalanches take no time.
        """
        stack, t = self.stack, self.stack.time
        stream = self._stream(increment)
        while self.junctions.renew(stack.well_index(), *stream):
            change = JunctionChange(stack)
            if not change.moves():
                return
            self.perturb_and_relax(change, margin)
            stack.set_time(t)

    def _redrawn(self, margin):
        """The event of a pending redraw: the junction set to its new depth, the stack relaxed."""
        stack, (block, depth) = self.stack, self.redraw
        t = stack.time
        self.junctions.depth[block] = depth
        self.perturb_and_relax(JunctionChange(stack), margin)
        stack.set_time(t)
        self.redraw, self.pending = None, None
        return {"yield_element": False, "hop_block": -1, "hop_direction": 0, "failed_hops": 0, "held": 0.0,
                "redraws": 0, "redraw_block": block, "redraw_depth": depth}

    def _settle(self, ds, redraws):
        """Give the backend the junctions redrawn meanwhile and bring the stack to drive offset ``ds``.

        The yield strains go first: the load re-evaluates every Gauss point's well at the new offset,
        where the sampling found each of them in its well.
        """
        token = self.stack.watch()
        if redraws:
            self.stack.push_yield_strains()
        if ds != 0.0:
            self.loading.load(ds)
        if self.stack.moved(token):
            raise SolverError(f"the load to the next event (drive offset {ds:.6e}, {redraws} junctions redrawn "
                              "meanwhile) moved a Gauss point out of its well (round-off at a yield strain)")

    def _load(self, margin, increment):
        stack, model, junctions, wells = self.stack, self.model, self.junctions, self.stack.wells
        stream = self._stream(increment)
        allowed = np.ones((model.epsy.shape[0], 2), dtype=bool)
        held, failed, redraws = 0.0, 0, 0
        while True:
            t = stack.time
            holding, until = self.schedule.stretch(t)
            speed = 0.0 if holding else self.speed
            idx, eps = stack.read("idx", "eps")
            kind, block, direction, dt, ds, count, depth = sample_with_redraws(
                model.law, stack.yield_strains.copy(), wells.epsy, wells.offset, junctions.well, junctions.depth,
                junctions.scale, junctions.glass_temperature, junctions.attempt_rate, 1.0 / self.params.temperature,
                idx, eps, self.loading.response.delta_eps, model.iface_dV, allowed, self.beta,
                self.params.attempt_rate, speed, until - t, *stream)
            redraws += count
            if holding:
                held += dt
            row = {"yield_element": False, "hop_block": -1, "hop_direction": 0, "failed_hops": failed, "held": held,
                   "redraws": redraws, "redraw_block": -1, "redraw_depth": math.nan}
            if kind == THRESHOLD:
                self._settle(ds, count)  # the offset of the last redraw: the load step to the brink from there
                self.loading.step(False)
                stack.set_time(t + dt)
                self.pending = (-1, 0)
                return row
            self._settle(ds, count)
            stack.set_time(t + dt)
            if kind == NONE:
                continue
            if kind == REDRAW:
                self.redraw = (block, depth)
                return {**row, "redraw_block": block, "redraw_depth": depth}
            assert kind == HOP
            loaded = stack.stored()
            if self.hop(block, direction, margin):
                stack.set_time(t + dt)
                self._after = stack.stored()
                stack.restore(*loaded)
                self.pending = (block, 1 if direction == FORWARD else -1)
                return {**row, "hop_block": block, "hop_direction": self.pending[1]}
            failed += 1
            allowed[block, direction] = False
            stack.restore(*loaded)


def thermal_protocol(stack, model, loading, relaxation, params, mesh, constants, table=None, stream=STREAM):
    """The protocol of a thermal run: :class:`AgingProtocol` if ``junction_strengthening > 0``, else
    :class:`.protocol.ThermalProtocol`.

    Parameters as :class:`.protocol.ThermalProtocol`.
    """
    cls = AgingProtocol if params.junction_strengthening > 0.0 else ThermalProtocol
    return cls(stack, model, loading, relaxation, params, mesh, constants, table, stream)
