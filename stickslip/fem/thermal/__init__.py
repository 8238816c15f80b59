"""Finite temperature: thermally activated hops of the interface blocks, with a finite drive rate.

The protocol of a ``temperature > 0`` run (:class:`.protocol.ThermalProtocol`): kinetic Monte
Carlo on the event-driven loop, its events drawn by a composed event source (:mod:`.sources`). Every block hops over the barrier of its well
(:mod:`.barriers`, from the law) at an Arrhenius rate; the next hop is drawn exactly from the
time-dependent total rate while the drive advances (:mod:`.sampler`); a hop carries the block over
its barrier (:mod:`.hop`) and the stack relaxes; the athermal threshold, if it comes first, is the usual
kick. docs/fem.md, "Finite temperature". With junction aging (:mod:`.junctions`) the current contact of
every block strengthens at rest and is renewed by a change of well (:mod:`.aging`, the protocol; :mod:`.redraws`,
the exact sampling of the junctions' redraws with the hops); docs/fem.md, "Junction aging".
"""

from .aging import AGING_COLUMNS, AgingProtocol, thermal_protocol
from .barriers import BACKWARD, FORWARD, barrier_bounds, block_barrier, block_barriers
from .hop import ShearHop, hop_step, shear_modes
from .holds import hold_trial
from .junctions import Junctions
from .protocol import COLUMNS, ThermalProtocol, drive_scale, energy_unit
from .redraws import REDRAW, sample_with_redraws
from .sampler import HOP, NONE, THRESHOLD, sample_event
from .schedule import HoldSchedule
from .sources import ArrheniusHops, ArrheniusWithRedraws

__all__ = ["ThermalProtocol", "HoldSchedule", "COLUMNS", "drive_scale", "energy_unit", "FORWARD", "BACKWARD",
           "block_barrier", "block_barriers", "barrier_bounds", "sample_event", "NONE", "HOP", "THRESHOLD", "ShearHop",
           "hop_step", "shear_modes", "hold_trial", "AgingProtocol", "AGING_COLUMNS", "thermal_protocol", "Junctions",
           "REDRAW", "sample_with_redraws", "ArrheniusHops", "ArrheniusWithRedraws"]
