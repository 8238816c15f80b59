"""The thermal protocol with junction aging: junction redraws compete with the hops, every event renews junctions.

:class:`AgingProtocol` is :class:`.protocol.ThermalProtocol` (``junction_strengthening > 0``) with the
event source :class:`.sources.ArrheniusWithRedraws`, one more kind of event and one more hook:

- **load** (odd increments): the next event is drawn exactly among the hops, the athermal
  threshold and the redraws of the junctions (:func:`.redraws.sample_with_redraws`); the redraws
  before it are applied as they come (they change the yield strains the backend holds, not the
  stress) and counted (column ``redraws``); a redraw that leaves a Gauss point of its block outside
  its narrower well is the event (``redraw_block``, ``redraw_depth`` on the load increment);
- **event** (even increments, :meth:`AgingProtocol.perform`): the hop, the kick or that redraw (the
  junction set, the stack relaxed); then (:meth:`AgingProtocol.after_event`) the junctions are renewed
  (:meth:`AgingProtocol.renew`): a block whose four Gauss points now share a well other than its
  junction's gets a new junction, one whose points are split loses its own (which can release part of
  the block: the stack is relaxed again, until nothing moves).

The junctions of every increment are stored with it (``junction_depth``, ``junction_well``), the
random numbers of the renewals after event ``i`` come from that increment's stream, and a pending
redraw is in the load increment's columns: a run resumed from any stored increment gives the same
bytes. docs/fem.md, "Junction aging".
"""

import math

import numpy as np

from .junctions import STATE_FIELDS, Junctions
from .protocol import COLUMNS, STREAM, Pending, ThermalProtocol, energy_unit
from .redraws import REDRAW
from .sources import ArrheniusHops, ArrheniusWithRedraws

__all__ = ["AgingProtocol", "AGING_COLUMNS", "JunctionChange", "thermal_protocol", "stack_junctions"]

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
        token = self.stack.checkpoint()
        self.apply()
        return self.stack.changed_since(token) > 0


def stack_junctions(stack, blocks, params):
    """The junctions registered with ``stack`` as the modifier of its yield strains, registered now if none are.

    A protocol made for a stack whose junctions are registered already (a hold trial, an aftershock replay on a
    run's stack) takes those over.

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
    blocks : int
        Interface blocks.
    params : FemParams
        With ``junction_strengthening > 0``.

    Returns
    -------
    stickslip.fem.thermal.junctions.Junctions

    Raises
    ------
    ValueError
        If the stack's yield strains are modified by something else.
    """
    junctions = stack.modifier
    if junctions is None:
        junctions = Junctions(blocks, params.junction_strengthening, params.junction_glass_temperature,
                              params.junction_attempt_rate, params.eps0)
        stack.modify_yield_strains(junctions)
    elif not isinstance(junctions, Junctions):
        raise ValueError(f"the stack's yield strains are modified by {junctions!r}, not by junctions")
    return junctions


class AgingProtocol(ThermalProtocol):
    """The thermal protocol with junction aging (module docstring): its source draws the redraws too, its hooks
    perform a redraw and renew the junctions after every event.

    Parameters
    ----------
    stack, model, loading, relaxation, params, mesh, constants, table, stream
        As :class:`.protocol.ThermalProtocol`.
    source : stickslip.fem.thermal.sources.ArrheniusWithRedraws
        Its junctions those registered with the stack (:func:`stack_junctions`).

    Attributes
    ----------
    junctions : stickslip.fem.thermal.junctions.Junctions
    """

    def __init__(self, stack, model, loading, relaxation, params, mesh, constants, source, table=None,
                 stream=STREAM):
        super().__init__(stack, model, loading, relaxation, params, mesh, constants, source, table, stream)
        p = params
        self.junctions = source.junctions
        self.columns = {**COLUMNS, **AGING_COLUMNS}
        self.header = {**self.header, "junction_strengthening": p.junction_strengthening,
                       "junction_glass_temperature": p.junction_glass_temperature,
                       "junction_attempt_rate": p.junction_attempt_rate}
        self.state_fields = {name: ((model.iface_dofs.shape[0],), dtype) for name, dtype in STATE_FIELDS.items()}
        if table is None:
            self.renew(p.margin, 0)  # the junctions of a new state (a restored one keeps its own)
        else:
            kick, block, depth = (np.asarray(table[name])[-1] for name in ("kick", "redraw_block", "redraw_depth"))
            if not kick and block >= 0:
                self.pending = Pending(REDRAW, int(block), depth=float(depth))

    @staticmethod
    def initial_row():
        """Columns of increment 0."""
        return {**ThermalProtocol.initial_row(), "redraws": 0, "redraw_block": -1, "redraw_depth": math.nan}

    def perform(self, pending, margin):
        """The event ``pending``: a redraw (the junction set to its new depth, the stack relaxed), else as
        :meth:`.protocol.ThermalProtocol.perform`."""
        if pending.kind != REDRAW:
            return {**super().perform(pending, margin), "redraws": 0, "redraw_block": -1, "redraw_depth": math.nan}
        self.junctions.depth[pending.block] = pending.depth
        self.perturb_and_relax(JunctionChange(self.stack), margin)
        return {"yield_element": False, "hop_block": -1, "hop_direction": 0, "failed_hops": 0, "held": 0.0,
                "redraws": 0, "redraw_block": pending.block, "redraw_depth": pending.depth}

    def after_event(self, margin, increment):
        """Renew the junctions of the blocks the event moved (:meth:`renew`)."""
        self.renew(margin, increment)

    def renew(self, margin, increment):
        """New junctions for the blocks that changed well (:meth:`.junctions.Junctions.renew`), relaxed until nothing moves.

        The random numbers come from the stream of ``increment``; avalanches take no time.
        """
        stream = self._stream(increment)
        while self.junctions.renew(self.stack.well_index(), *stream):
            change = JunctionChange(self.stack)
            if not change.moves():
                return
            self.perturb_and_relax(change, margin)


def thermal_protocol(stack, model, loading, relaxation, params, mesh, constants, table=None, stream=STREAM):
    """The protocol of a thermal run, composed from its parameters: :class:`.protocol.ThermalProtocol` with the event
    source :class:`.sources.ArrheniusHops`, or with junction aging (``junction_strengthening > 0``)
    :class:`AgingProtocol` with :class:`.sources.ArrheniusWithRedraws`.

    Parameters as :class:`.protocol.ThermalProtocol`.
    """
    p = params
    beta = 1.0 / (p.temperature * energy_unit(p, constants["h"]))
    if p.junction_strengthening > 0.0:
        junctions = stack_junctions(stack, model.iface_dofs.shape[0], p)
        source = ArrheniusWithRedraws(stack, model, loading, beta, p.attempt_rate, junctions, p.temperature)
        return AgingProtocol(stack, model, loading, relaxation, p, mesh, constants, source, table, stream)
    source = ArrheniusHops(stack, model, loading, beta, p.attempt_rate)
    return ThermalProtocol(stack, model, loading, relaxation, p, mesh, constants, source, table, stream)
