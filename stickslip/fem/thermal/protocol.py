"""The thermal protocol: kinetic Monte Carlo on top of the event-driven protocol, with a drive rate.

Increments alternate as in the athermal protocol, a load then an event:

- **load** (odd increments): from the state at rest after the last event, time runs on: the
  drive advances at ``drive_rate`` (or is held, see below) along the linear response, which moves
  every Gauss point within its well, and the next event is drawn exactly
  (:func:`.sampler.sample_event`): a thermally activated hop of a block, or the athermal threshold
  if no hop comes first. The stored load increment is the state loaded to the time of that event
  (for the threshold: the athermal load step to the brink, :meth:`..loading.Loading.step`).
- **event** (even increments): the hop (:meth:`ThermalProtocol.hop`) or the athermal kick
  (:meth:`..protocol.AthermalProtocol.kick`), with the relaxation of the run.

A hop whose block falls back into its well restores the state, counts as failed (column
``failed_hops`` of the next load increment) and leaves that block and direction out of the
rates until the next event; the draw goes on from the time of the failed hop. Avalanches take no
time: the state's ``t`` is the thermal clock (the minimisation's time steps are not added), which
assumes that the drive moves the state by much less than a well during an avalanche.

Slide-hold-slide (:class:`HoldSchedule`): once the drive has advanced by ``hold_delay`` since the
last slip event (an event in which every block of some interface changed well), it stops for the
next of ``hold_times`` (cycled) while time and hops go on; a slip during the hold ends it, a slip
before it starts postpones it to the next cycle.

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

import numpy as np

from ..errors import SolverError
from ..protocol import AthermalProtocol
from ..random import pcg32_seed
from .barriers import BACKWARD, FORWARD
from .hop import ShearHop, shear_modes
from .sampler import HOP, NONE, sample_event

__all__ = ["ThermalProtocol", "HoldSchedule", "COLUMNS", "drive_scale", "energy_unit", "STREAM"]

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


def _resumed(table, N, schedule):
    """Replay the slips of a stored table into ``schedule``; return the hop pending after its last increment.

    Returns
    -------
    tuple or None
        ``(hop_block, hop_direction)`` of a last stored load increment (its event is next), else None.
    """
    table = {name: np.asarray(table[name]) for name in table}
    for t in _slips(table, N):
        schedule.slip(t)
    if table["kick"][-1]:
        return None
    return int(table["hop_block"][-1]), int(table["hop_direction"][-1])


class ThermalProtocol(AthermalProtocol):
    """Thermally activated hops with a finite drive rate (module docstring): the athermal protocol with its own steps.

    Parameters
    ----------
    stack, loading, relaxation
        As :class:`..protocol.AthermalProtocol` (the stack at the last stored increment).
    model : stickslip.fem.model.Model
        The stack's model (its law and interface elements).
    params : FemParams
        With ``temperature > 0``.
    mesh : stickslip.mesh.LayeredMesh
    constants : dict
        :func:`..constants.derived_constants`.
    table : Mapping[str, numpy.ndarray], optional
        The stored increment table's columns (a resumed run), None for a new run.
    stream : int, optional
        ``initseq`` of the random stream of increment 0 (increment ``i`` draws from ``stream + i``);
        other values give independent replicas (:mod:`.holds`).
    """

    columns = COLUMNS

    def __init__(self, stack, model, loading, relaxation, params, mesh, constants, table=None, stream=STREAM):
        super().__init__(stack, loading, relaxation)
        p = params
        self.model = model
        self.params = p
        self.energy_unit = energy_unit(p, constants["h"])
        self.beta = 1.0 / (p.temperature * self.energy_unit)
        self.speed = p.drive_rate / drive_scale(loading.response, p.eps0, mesh)
        self.modes = shear_modes(mesh)
        self.overshoot = 0.5 * constants["deps"]
        self.header = {"protocol": "thermal", "temperature": p.temperature, "attempt_rate": p.attempt_rate,
                       "drive_rate": p.drive_rate, "hold_times": list(p.hold_times), "hold_delay": p.hold_delay,
                       "energy_unit": self.energy_unit}
        self.stream = int(stream)
        self.schedule = HoldSchedule(p.hold_times, p.hold_delay / p.drive_rate)
        self.pending = None if table is None else _resumed(table, p.N, self.schedule)
        self._after = None

    @staticmethod
    def initial_row():
        """Columns of increment 0."""
        return {"hop_block": -1, "hop_direction": 0, "failed_hops": 0, "held": 0.0}

    def _stream(self, increment):
        state, inc = pcg32_seed(np.array([self.params.seed], dtype=np.uint64),
                                np.array([self.stream + increment], dtype=np.uint64))
        return state, inc

    def step(self, event, margin, increment):
        """The next increment: a load to the next event (``event`` False) or that event; see the module docstring."""
        if event:
            return self._event(margin)
        return self._load(margin, increment)

    def hop(self, block, direction, margin):
        """Carry ``block`` over its edge in ``direction`` and relax; restore the state if it falls back.

        Parameters
        ----------
        block : int
            Interface element.
        direction : int
            :data:`.barriers.FORWARD` or backward.
        margin : int
            See :meth:`..relaxation.DynamicRelaxation.relax`.

        Returns
        -------
        bool
            True if some well index changed (the hop happened); False if the block fell back or its
            shear mode cannot carry it over (the state is then as before).
        """
        stack = self.stack
        shear = ShearHop(stack, self.model, self.modes, block, direction, self.overshoot)
        if math.isnan(shear.step()):
            return False
        before = stack.stored()
        token = stack.watch()
        self.perturb_and_relax(shear, margin)
        if not stack.moved(token):
            stack.restore(*before)
            return False
        return True

    def _load(self, margin, increment):
        stack = self.stack
        start = stack.stored()
        t = start[3]
        stream = self._stream(increment)
        ds_c = self.loading.step_size(False)
        model = self.model
        allowed = np.ones((model.epsy.shape[0], 2), dtype=bool)
        ds, held, failed = 0.0, 0.0, 0
        while True:
            holding, until = self.schedule.stretch(t)
            speed = 0.0 if holding else self.speed
            idx, eps = stack.read("idx", "eps")  # a failed hop may have moved the held wells: read them anew
            kind, block, direction, dt = sample_event(
                model.law, stack.yield_strains, idx, eps, self.loading.response.delta_eps, model.iface_dV, allowed,
                self.beta, self.params.attempt_rate, ds, speed, until - t, ds_c, *stream)
            if holding:
                held += dt
            else:
                ds += speed * dt
            if kind == NONE:
                t = until
                continue
            t += dt
            sign = 1 if direction == FORWARD else -1
            if kind != HOP:
                self.loading.step(False)
                stack.set_time(t)
                self.pending = (-1, 0)
                return {"yield_element": False, "hop_block": -1, "hop_direction": 0, "failed_hops": failed,
                        "held": held}
            self.loading.load(ds)
            stack.set_time(t)
            loaded = stack.stored()
            if self.hop(block, direction, margin):
                stack.set_time(t)  # avalanches take no time
                self._after = stack.stored()
                stack.restore(*loaded)
                self.pending = (block, sign)
                return {"yield_element": False, "hop_block": block, "hop_direction": sign, "failed_hops": failed,
                        "held": held}
            failed += 1
            allowed[block, direction] = False
            stack.restore(*start)

    def _event(self, margin):
        stack = self.stack
        block, sign = self.pending
        t = stack.time
        yield_element = False
        if block < 0:
            converged, yield_element = self.kick(margin)
            stack.set_time(t)
        else:
            if self._after is None:  # resumed at the load increment: redo the hop drawn there
                if not self.hop(block, FORWARD if sign > 0 else BACKWARD, margin):
                    raise SolverError(f"the stored hop of block {block} fell back when redone")
                stack.set_time(t)
                self._after = stack.stored()
            stack.restore(*self._after)
        self.pending, self._after = None, None
        return {"yield_element": yield_element, "hop_block": block, "hop_direction": sign, "failed_hops": 0,
                "held": 0.0}

    def stored(self, row):
        """After an event increment: a slip (``A_a == N`` for some interface) starts a hold."""
        if row["kick"] and any(row[name] == self.params.N for name in row if name.startswith("A_a")):
            self.schedule.slip(row["t"])
