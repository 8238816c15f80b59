"""Solver ``lever``: a virtual experiment of the paper's apparatus, written as a lab recording.

Rigid slabs on a fixed base, springs to a lever driven at constant speed, interfaces with
logarithmic aging, threshold disorder, optional creep and triggered simultaneous slips
(model and equations: docs/experiment-model.md; code: :mod:`stickslip.experiment.virtual`,
assembled from the parameters in :mod:`stickslip.experiment.virtual.model`; this module is the
plugin's adapter: parameters in, time-series file out).
The output is the experimental time-series file (:mod:`stickslip.experiment.timeseries`)
with the parameters (JSON) and seed as attributes and two ground-truth tables:

``truth``: one row per interface per slip, columns ``event``, ``t_start``, ``t_end`` [s],
``a``, ``dR`` [mm], ``dF`` [N], ``dmu``, ``mu_before``, ``mu_after``, ``T`` [s], ``age`` [s],
``excess``, ``multi``, ``triggered``, ``creep_before`` [mm] (see
:func:`stickslip.experiment.virtual.integrate`).

``interfaces``: one row per interface ``a`` = 1..n_slabs: ``slippable`` (can slip in this
protocol), ``mu_d``, ``B``, ``creep_velocity`` [mm/s] (effective, after the scaling with n),
``n_slips``, ``slip_total`` [mm] (sum of dR), ``creep_total`` [mm] (slow slip over the run),
``R_total`` [mm] (R_a at the end minus at the start, noise-free; equals slip_total +
creep_total except for a slip still running at the end).
"""

import dataclasses
import typing

import numpy as np

from .. import registry
from ..experiment.timeseries import PROTOCOLS, write_timeseries
from ..experiment.virtual.model import apparatus, per_interface, simulate
from ..experiment.virtual.sensors import recording_bytes
from ..machine_memory import process_memory, size_text
from ..plugin_params import ParameterError, param, params_to_dict

__all__ = ["LeverParams", "run", "check_protocol", "check_sampling", "check_memory", "VERSION"]

VERSION = "2"  # 2: coupling products and solves in a fixed order (host-independent bits)

#: Per-interface parameters: one value for every interface, or one per interface.
PER_INTERFACE = ("mu_d", "B", "creep_velocity")


@dataclasses.dataclass(frozen=True)
class LeverParams:
    """Parameters of one virtual run (defaults: the paper's apparatus and the default study)."""

    #: Old names of parameters (:mod:`stickslip.plugin_params`): ``a`` is the interface everywhere else.
    RENAMED: typing.ClassVar[dict] = {"a": "driven_slab"}

    n: int = param(1, "driven slabs (springs attached); 1 for the individual protocol", minimum=1,
                 maximum=100)
    protocol: str = param("stack", "stack: slabs 1..n driven; individual: slab driven_slab alone, slabs below "
                                   "clamped", choices=PROTOCOLS)
    driven_slab: int = param(0, "slab driven alone (individual protocol; its interface slips); 0 for stack",
                             minimum=0, maximum=100)
    n_slabs: int = param(5, "slabs in the stack", minimum=1, maximum=100)
    seed: int = param(0, "seed of every random stream (disorder, sensor noise)", minimum=0, maximum=2**63 - 1)
    duration: float = param(6000.0, "length of the run (the paper: 0.6 rad at 1e-4 /s)", unit="s",
                            minimum=1.0, maximum=1e10)
    gamma_start: float = param(-0.30, "lever rotation gamma = U/H at t = 0", unit="rad", minimum=-1.5, maximum=1.5)
    normal_force: float = param(49.0, "normal force N (5 kg dead weight)", unit="N", minimum=1e-3, maximum=1e5)
    k_spring: float = param(55.0, "spring stiffness K", unit="N/mm", minimum=1e-3, maximum=1e5)
    h: float = param(10.0, "slab thickness h", unit="mm", minimum=1e-3, maximum=1e3)
    H: float = param(100.0, "lever height H", unit="mm", minimum=1e-3, maximum=1e4)
    V: float = param(0.01, "lever-top speed V (individual protocol: the lever moves at V/driven_slab)", unit="mm/s",
                     minimum=1e-9, maximum=1e3)
    mu_d: tuple[float, ...] = param((0.35,), "dynamic friction level per interface (one value: all)", minimum=0,
                                   maximum=10)
    B: tuple[float, ...] = param((0.030, 0.018, 0.039, 0.023, 0.034),
                                 "aging rate per interface (one value: all)", minimum=1e-6, maximum=1)
    T0: float = param(1.0, "aging time scale T0", unit="s", minimum=1e-6, maximum=1e6)
    strength_offset: float = param(0.08, "strength above mu_d gained however short the stick", minimum=0,
                                   maximum=10)
    threshold_noise: float = param(0.015, "scale of the half-normal threshold excess (annealed disorder)",
                                   minimum=0, maximum=10)
    creep_velocity: tuple[float, ...] = param(
        (0.0015, 0.00075, 0.0, 0.0, 0.0),
        "creep velocity per interface with all slabs driven; scaled by (n-1)/(n_slabs-1) (one value: all)",
        unit="mm/s", minimum=0, maximum=1e3)
    creep_onset: float = param(0.8, "creep starts at this fraction of the strength above mu_d",
                               exclusive_minimum=0, maximum=1)
    trigger_margin: float = param(0.0, "interfaces this close to their strength slip with the one that slips",
                                  minimum=0, maximum=10)
    slip_duration: float = param(0.2, "duration of a slip", unit="s", minimum=1e-6, maximum=1e3)
    force_rate: float = param(50.0, "force sampling rate", unit="Hz", minimum=1e-3, maximum=1e5)
    force_noise: float = param(0.01, "standard deviation of the force noise", unit="N", minimum=0,
                                maximum=1e5)
    frame_rate: float = param(5.0, "camera frame rate", unit="Hz", minimum=1e-3, maximum=1e5)
    position_noise: float = param(0.002, "standard deviation of the position noise of every slab", unit="mm",
                                  minimum=0, maximum=1e3)

    def check(self):
        """Check the conditions that involve several fields."""
        check_protocol(self)
        check_sampling(self)
        for name in PER_INTERFACE:
            if len(getattr(self, name)) not in (1, self.n_slabs):
                raise ParameterError(f"parameter '{name}': expected 1 or n_slabs={self.n_slabs} values, "
                                     f"got {len(getattr(self, name))}")
        fastest = apparatus(self).loading_rates().max() * self.slip_duration
        heals = self.strength_offset + np.min(per_interface(self, "B")) * np.log1p(self.slip_duration / self.T0)
        if heals <= fastest:
            raise ParameterError(
                f"parameter 'B': the weakest healing during a slip, strength_offset + B ln(1 + slip_duration/T0) = "
                f"{heals:.3g}, must exceed the loading during a slip, {fastest:.3g}, or an interface slips "
                f"again before it heals")


def check_sampling(params):
    """Raise ParameterError unless the run records at least two force samples and two frames (also used by
    :mod:`stickslip.solvers.rate_state_lever`)."""
    for name in ("force_rate", "frame_rate"):
        samples = params.duration * getattr(params, name)
        if samples < 2:
            raise ParameterError(f"parameter '{name}': {getattr(params, name):g} Hz over a duration of "
                                 f"{params.duration:g} s records {samples:.3g} samples; expected duration * {name} "
                                 ">= 2")


def check_memory(params):
    """Raise ParameterError if the run's recording needs more memory than a process of this machine can have (the
    solvers' preflight: :func:`stickslip.experiment.virtual.sensors.recording_bytes`)."""
    needed = recording_bytes(params.duration, params.force_rate, params.frame_rate, params.n_slabs)
    have = process_memory()
    if needed > have:
        raise ParameterError(f"parameters duration, force_rate, frame_rate: the recording needs at least "
                             f"{size_text(needed)} of memory, more than this machine gives a process "
                             f"({size_text(have)}); expected a shorter duration or lower rates")


def check_protocol(params):
    """Raise ParameterError unless ``n``, ``driven_slab`` and ``n_slabs`` fit the protocol (also used by
    :mod:`stickslip.solvers.rate_state_lever`)."""
    if params.protocol == "stack":
        if params.n > params.n_slabs:
            raise ParameterError(f"parameter 'n': expected a value <= n_slabs={params.n_slabs}, got {params.n}")
        if params.driven_slab != 0:
            raise ParameterError(f"parameter 'driven_slab': must be 0 for the stack protocol, got {params.driven_slab}")
    else:
        if not 1 <= params.driven_slab <= params.n_slabs:
            raise ParameterError(f"parameter 'driven_slab': expected 1..n_slabs={params.n_slabs} for the individual "
                                 f"protocol, got {params.driven_slab}")
        if params.n != 1:
            raise ParameterError(f"parameter 'n': must be 1 for the individual protocol, got {params.n}")


@registry.register("solver", "lever", VERSION, LeverParams, produces="timeseries", preflight=check_memory,
                   summary="virtual lever experiment (aging, disorder, creep) written as a lab time series")
def run(params, output, *, threads, inputs):
    """Run one virtual experiment and write its time-series file with the ground truth."""
    signals, truth, interfaces = simulate(params)
    write_timeseries(output, signals, attrs={"params": params_to_dict(params), "seed": params.seed,
                                             "solver": "lever", "solver_version": VERSION},
                     tables={"truth": truth, "interfaces": interfaces})
