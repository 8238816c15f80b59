"""The thermal protocol: kinetic Monte Carlo on top of the event-driven protocol, with a drive rate.

Increments alternate as in the athermal protocol, a load then an event:

- **load** (odd increments, :meth:`ThermalProtocol.next_event`): from the state at rest after the
  last event, time runs on: the drive advances at ``drive_rate`` (or is held, see below) along the
  linear response, which moves every Gauss point within its well, and the protocol's event source
  (:mod:`.sources`) draws the next event exactly: a thermally activated hop of a block, or the athermal
  threshold if no hop comes first (with junction aging, a redraw of a junction, :mod:`.aging`). The
  stored load increment is the state loaded to the time of that event (for the threshold: the athermal
  load step to the brink, :meth:`..loading.Loading.step`).
- **event** (even increments, :meth:`ThermalProtocol.perform`): the hop (:meth:`ThermalProtocol.hop`)
  or the athermal kick (:meth:`..protocol.EventLoop.kick`), with the relaxation of the run.

A hop whose block falls back into its well is undone, counts as failed (column
``failed_hops`` of the next load increment) and leaves that block and direction out of the
rates until the next event; the draw goes on from the time of the failed hop. A hop goes to the host and back
once: its block's strain at the event (a read of the interface strains); the state before it, the state after
its avalanche and the return to either are checkpoints where the state is (:meth:`..stack.Stack.checkpoint`),
and whether it fell back is counted there (:meth:`..stack.Stack.changed_since`). Avalanches take no
time: the protocol keeps the physical time (its :class:`..clock.Clock`, registered with the stack; the
minimisation's time steps are not added), which assumes that the drive moves the state by much less
than a well during an avalanche.

Slide-hold-slide (:class:`.schedule.HoldSchedule`): once the drive has advanced by ``hold_delay`` since
the last slip event, it stops for the next of ``hold_times`` (cycled) while time and hops go on.

Columns added to the increment table (:data:`COLUMNS`): ``hop_block`` (interface element of the
hop, -1 for an athermal kick), ``hop_direction`` (+1 forward, -1 backward, 0 athermal), both on the
load and on the event increment; ``failed_hops`` and ``held`` (time during which the drive was held
since the previous increment) on load increments (0 on events). Root attributes: ``protocol``
("thermal"), ``temperature``, ``attempt_rate``, ``drive_rate``, ``hold_times``, ``hold_delay``, and
``energy_unit`` (``G eps0^2 h^2`` in model units, the unit of ``temperature``).

Every quantity needed to go on is in the stored increments, and the random numbers of increment
``i`` come from the pcg32 stream ``(seed, 2^32 + i)``: a run resumed from any stored increment
gives the same bytes.
"""

import math
from typing import NamedTuple

import numpy as np

from ..clock import Clock
from ..errors import SolverError
from ..protocol import EventLoop
from ..random import pcg32_seed
from .barriers import BACKWARD, FORWARD
from .hop import ShearHop, shear_modes
from .sampler import HOP, NONE, THRESHOLD
from .schedule import HoldSchedule, replay_slips

__all__ = ["ThermalProtocol", "Pending", "COLUMNS", "drive_scale", "energy_unit", "STREAM"]

#: The increment table's thermal columns and their types.
COLUMNS = {"hop_block": np.int64, "hop_direction": np.int64, "failed_hops": np.int64, "held": np.float64}

#: Offset of the thermal streams' ``initseq`` (the yield strains use 0).
STREAM = 2**32


def energy_unit(params, h):
    """The unit of ``temperature``: ``G eps0^2 h^2``, the barrier of a cusp block ``eps0`` below its yield strain [energy]."""
    return params.G * params.eps0 ** 2 * h ** 2


def drive_scale(response, eps0, mesh):
    """Imposed shear gamma, in eps0, per unit drive offset of the linear response (:meth:`..loading.Loading.load`).

    Parameters
    ----------
    response : stickslip.fem.linear_response.LinearResponse
    eps0 : float
    mesh : stickslip.mesh.LayeredMesh
    """
    return float(response.delta_target[-1] / (2.0 * eps0 * mesh.layer_mid_height[-1]))


class Pending(NamedTuple):
    """The event a load increment ended at, which the next (event) increment performs.

    Attributes
    ----------
    kind : int
        :data:`.sampler.THRESHOLD` (the athermal kick), ``HOP`` or :data:`.redraws.REDRAW`.
    block : int
        The hop's interface element, or the redrawn junction's block; -1 for the threshold.
    sign : int
        The hop's direction, +1 forward, -1 backward; 0 otherwise.
    depth : float
        A redraw's new junction depth [G eps0^2 h^2]; NaN otherwise.
    after : stickslip.fem.stack.Checkpoint or None
        A checkpoint of the state after the hop's avalanche, its windows not yet moved ahead (None: redo the hop, a
        run resumed at its load increment).
    """

    kind: int
    block: int = -1
    sign: int = 0
    depth: float = math.nan
    after: object = None


class ThermalProtocol(EventLoop):
    """Thermally activated events with a finite drive rate (module docstring): the event loop's hooks.

    Parameters
    ----------
    stack, loading, relaxation
        As :class:`..protocol.EventLoop` (the stack at the last stored increment).
    model : stickslip.fem.model.Model
        The stack's model (its interface elements).
    params : FemParams
        With ``temperature > 0``.
    mesh : stickslip.mesh.LayeredMesh
    constants : dict
        :func:`..constants.derived_constants`.
    source : stickslip.fem.thermal.sources.ArrheniusHops or stickslip.fem.thermal.sources.ArrheniusWithRedraws
        Draws the next event (:func:`.aging.thermal_protocol` composes them).
    table : Mapping[str, numpy.ndarray], optional
        The stored increment table's columns (a resumed run), None for a new run.
    stream : int, optional
        ``initseq`` of the random stream of increment 0 (increment ``i`` draws from ``stream + i``);
        other values give independent replicas (:mod:`.holds`).

    Attributes
    ----------
    clock : stickslip.fem.clock.Clock
        The physical time, registered with the stack (a clock registered already is taken over).
    schedule : stickslip.fem.thermal.schedule.HoldSchedule
    """

    columns = COLUMNS

    def __init__(self, stack, model, loading, relaxation, params, mesh, constants, source, table=None,
                 stream=STREAM):
        super().__init__(stack, loading, relaxation, table)
        p = params
        self.model, self.params, self.source = model, p, source
        self.clock = stack.clock
        if self.clock is None:
            self.clock = Clock(stack.time)
            stack.keep_time(self.clock)
        self.energy_unit = energy_unit(p, constants["h"])
        self.speed = p.drive_rate / drive_scale(loading.response, p.eps0, mesh)
        self.modes = shear_modes(mesh)
        self.overshoot = 0.5 * constants["deps"]
        self.header = {"protocol": "thermal", "temperature": p.temperature, "attempt_rate": p.attempt_rate,
                       "drive_rate": p.drive_rate, "hold_times": list(p.hold_times), "hold_delay": p.hold_delay,
                       "energy_unit": self.energy_unit}
        self.stream = int(stream)
        self.schedule = HoldSchedule(p.hold_times, p.hold_delay / p.drive_rate)
        if table is not None:
            replay_slips(table, p.N, self.schedule)
            if self.event_next:  # resumed at a load increment: its event is next
                block, sign = int(np.asarray(table["hop_block"])[-1]), int(np.asarray(table["hop_direction"])[-1])
                self.pending = Pending(THRESHOLD) if block < 0 else Pending(HOP, block, sign)

    @staticmethod
    def initial_row():
        """Columns of increment 0."""
        return {"hop_block": -1, "hop_direction": 0, "failed_hops": 0, "held": 0.0}

    def _stream(self, increment):
        return pcg32_seed(np.array([self.params.seed], dtype=np.uint64),
                          np.array([self.stream + increment], dtype=np.uint64))

    def next_event(self, margin, increment):
        """Let time run to the next event drawn by the source; the stack at it, the event :attr:`pending`.

        A hop is tried at once (:meth:`hop`): one that falls back is undone, counted (``failed_hops``) and left out
        of the draw with its direction until the next event, and the draw goes on from its time.
        """
        stream = self._stream(increment)
        allowed = np.ones((self.model.iface_dofs.shape[0], 2), dtype=bool)
        held, failed = 0.0, 0
        self.source.begin()
        while True:
            holding, until = self.schedule.stretch(self.clock.time)
            draw = self.source.draw(self.clock.time, allowed, 0.0 if holding else self.speed, until, stream)
            if holding:
                held += draw.dt
            self.source.settle(draw)
            self.clock.advance_to(draw.time)
            if draw.kind == NONE:
                continue
            row = {"yield_element": False, "hop_block": -1, "hop_direction": 0, "failed_hops": failed, "held": held,
                   **self.source.columns(draw)}
            if draw.kind != HOP:
                self.pending = Pending(draw.kind, draw.block, depth=draw.depth)
                return row
            loaded = self.stack.checkpoint()
            if self.hop(draw.block, draw.direction, margin, loaded):
                sign = 1 if draw.direction == FORWARD else -1
                self.pending = Pending(HOP, draw.block, sign, after=self.stack.checkpoint())
                self.stack.rollback(loaded)
                return {**row, "hop_block": draw.block, "hop_direction": sign}
            failed += 1
            allowed[draw.block, draw.direction] = False
            self.source.undo(loaded)

    def hop(self, block, direction, margin, loaded):
        """Carry ``block`` over its edge in ``direction`` and relax (the windows not yet moved ahead).

        Parameters
        ----------
        block : int
            Interface element.
        direction : int
            :data:`.barriers.FORWARD` or backward.
        margin : int
            See :meth:`..relaxation.DynamicRelaxation.relax`.
        loaded : stickslip.fem.stack.Checkpoint
            A checkpoint of the stack as it is, loaded to the hop.

        Returns
        -------
        bool
            True if some well index changed (the hop happened); False if the block fell back or its
            shear mode cannot carry it over: the caller then rolls the stack back.
        """
        shear = ShearHop(self.stack, self.model, self.modes, block, direction, self.overshoot, loaded)
        if math.isnan(shear.amplitude):
            return False
        self.perturb_and_relax(shear, margin, before=loaded, ahead=False)
        return self.stack.changed_since(loaded) > 0

    def perform(self, pending, margin):
        """The event ``pending`` (:class:`Pending`): the athermal kick, or the hop (its state after the avalanche,
        redone if the run was resumed at its load increment)."""
        yield_element = False
        if pending.kind == THRESHOLD:
            yield_element = self.kick(margin)[1]
        else:
            if pending.after is not None:
                self.stack.rollback(pending.after)
            elif not self.hop(pending.block, FORWARD if pending.sign > 0 else BACKWARD, margin,
                              self.stack.checkpoint()):
                raise SolverError(f"the stored hop of block {pending.block} fell back when redone")
            if self.stack.extend:
                self.stack.hold_wells_ahead()  # what the hop's relaxation left for later
        return {"yield_element": yield_element, "hop_block": pending.block, "hop_direction": pending.sign,
                "failed_hops": 0, "held": 0.0}

    def stored(self, row):
        """After an event increment: a slip (``A_a == N`` for some interface) starts a hold."""
        if row["kick"] and any(row[name] == self.params.N for name in row if name.startswith("A_a")):
            self.schedule.slip(row["t"])
