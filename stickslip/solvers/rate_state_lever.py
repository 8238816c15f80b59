"""Solver ``rate-state-lever``: the paper's apparatus with inertial slabs on Dieterich–Ruina interfaces.

The apparatus, protocols, sensors and file format of the ``lever`` solver
(:mod:`stickslip.solvers.lever`), but every slippable interface obeys rate-and-state friction with
the aging law, or the slip law with ``rs_state_law: slip`` (the aging-off control; :mod:`stickslip.experiment.virtual.rate_state`), and the slabs move by Newton's law
(:mod:`stickslip.experiment.virtual.slab_dynamics`): sticks, slips, creep and any simultaneous
slip follow from the equations, nothing is scheduled. Optionally (``path_disorder`` > 0) each interface's
``mu0`` varies along its slip path (:mod:`stickslip.experiment.virtual.slip_path`). Model, defaults and their sources:
docs/experiment-model-rate-state.md. The run is assembled from the parameters in
:mod:`stickslip.experiment.virtual.rate_state_model`; this module is the plugin's adapter: parameters
in, time-series file out.

Output: the experimental time-series file with the attributes ``params`` (JSON), ``seed``, ``solver``,
``solver_version``, ``slab_order`` (JSON list of n_slabs ints: the physical slab at each position from the
bottom, 1..n_slabs in order unless shuffled), ``integration`` (JSON: ``method``, ``state``, accepted ``steps``, see
:func:`stickslip.experiment.virtual.rate_state_model.simulate`) and two ground-truth tables: ``truth`` (one row per interface per slip, see
:func:`stickslip.experiment.virtual.slip_intervals.slip_intervals`) and ``interfaces`` (one row per
interface (position from the bottom): ``a``, ``slab`` (the physical slab there), ``slippable``, ``a_rs``, ``b``, ``D_c`` [mm], ``mu0``, ``K_c`` [N/mm] (linear-stability
boundary ``N (b - a) / D_c``), ``n_slips``, ``slip_total``, ``creep_total`` (``R_total - slip_total``),
``R_total`` [mm]).
"""

import dataclasses

from .. import registry
from ..experiment.timeseries import write_timeseries
from ..experiment.virtual.rate_state import STATE_LAWS
from ..experiment.virtual.rate_state_model import simulate, slab_order
from ..experiment.virtual.slab_dynamics import DEFAULT_METHOD, METHODS
from ..plugin_params import ParameterError, param, params_to_dict
from .lever import LeverParams, check_memory, check_protocol, check_sampling

__all__ = ["RateStateLeverParams", "run", "VERSION"]

VERSION = "4"  # 4: coupling matrices in a fixed order (host-independent bits); 2: RODAS4 with relative slip-rate tolerances (issue 12); 3: the friction as state (issue 24)

#: Parameters shared with the ``lever`` solver: apparatus, protocol, drive, sensors.
SHARED = ("n", "protocol", "driven_slab", "n_slabs", "seed", "duration", "gamma_start", "normal_force", "k_spring", "h", "H",
          "V", "force_rate", "force_noise", "frame_rate", "position_noise")
#: Per-interface parameters: one value for every interface, or one per interface.
PER_INTERFACE = ("rs_a", "rs_b", "D_c", "mu0")


def _shared_fields():
    fields = {f.name: f for f in dataclasses.fields(LeverParams)}
    return [(name, fields[name].type, dataclasses.field(default=fields[name].default, metadata=fields[name].metadata))
            for name in SHARED]


_OWN = [
    ("rs_a", tuple[float, ...], param((0.013,), "rate-and-state direct effect a per interface (one value: all)",
                                      minimum=1e-6, maximum=1)),
    ("rs_b", tuple[float, ...], param((0.019, 0.017, 0.021, 0.018, 0.020),
                                      "rate-and-state evolution effect b per interface (one value: all)", minimum=0,
                                      maximum=1)),
    ("D_c", tuple[float, ...], param((5e-4,), "memory length D_c per interface (one value: all)", unit="mm",
                                     minimum=1e-9, maximum=1e3)),
    ("mu0", tuple[float, ...], param((0.35,), "steady friction at V0 per interface (one value: all)",
                                     minimum=1e-3, maximum=10)),
    ("V0", float, param(1e-3, "reference slip rate V0", unit="mm/s", minimum=1e-12, maximum=1e6)),
    ("rs_state_law", str, param("aging", "evolution law of the state: aging (Dieterich: the contacts heal with time at "
                                         "rest) or slip (Ruina: no healing at rest, the aging-off control)",
                                choices=STATE_LAWS, extension=True)),
    ("disorder", float, param(0.05, "relative standard deviation of b and D_c drawn per interface and seed "
                                    "(quenched disorder; 0: none)", minimum=0, maximum=1)),
    ("path_disorder", float, param(0.0, "relative standard deviation of mu0 along each interface's slip path "
                                         "(heterogeneity of the surface, drawn per interface and seed; 0: none)",
                                   minimum=0, maximum=1)),
    ("path_correlation_length", float, param(0.025, "correlation length of mu0 along the slip path (the paper's "
                                                    "asperity size)", unit="mm", minimum=0.001, maximum=1.0)),
    ("slab_order", tuple[int, ...], param((), "physical slab at each position from the bottom, a permutation of "
                                               "1..n_slabs (empty: in order); each slab's interface parameters, "
                                               "quenched disorder and slip path travel with it (the paper's shuffled "
                                               "control: 4,3,2,1,5)", minimum=1, maximum=100)),
    ("slab_mass", float, param(0.143, "mass of one slab (PMMA 10 x 150 x 80 mm)", unit="kg", minimum=1e-6,
                                maximum=1e6)),
    ("load_mass", float, param(5.0, "dead weight on the top slab", unit="kg", minimum=0, maximum=1e6)),
    ("theta_start", float, param(0.01, "contact age of every interface at t = 0 (just slipped)", unit="s",
                                 minimum=1e-12, maximum=1e12)),
    ("V_start", float, param(1e-6, "slip rate of every interface at t = 0", unit="mm/s", minimum=1e-15,
                                 maximum=1e6)),
    ("slip_velocity", float, param(0.1, "slip rate above which the ground truth counts a slip", unit="mm/s",
                                   minimum=1e-9, maximum=1e6)),
    ("method", str, param(DEFAULT_METHOD, "implicit integrator (RODAS4: compiled Rosenbrock; others: scipy solve_ivp)",
                          choices=METHODS)),
    ("rtol", float, param(1e-5, "relative tolerance of the integrator (the absolute tolerances scale with it)",
                          minimum=1e-12, maximum=0.1)),
]


def _check(self):
    """Check the protocol, the sampling, the slab order and the per-interface lengths."""
    check_protocol(self)
    check_sampling(self)
    if self.slab_order and sorted(self.slab_order) != list(range(1, self.n_slabs + 1)):
        raise ParameterError(f"parameter 'slab_order': expected a permutation of 1..n_slabs={self.n_slabs} "
                             f"(or nothing), got {list(self.slab_order)}")
    for name in PER_INTERFACE:
        if len(getattr(self, name)) not in (1, self.n_slabs):
            raise ParameterError(f"parameter '{name}': expected 1 or n_slabs={self.n_slabs} values, "
                                 f"got {len(getattr(self, name))}")


RateStateLeverParams = dataclasses.make_dataclass(
    "RateStateLeverParams", _shared_fields() + _OWN, frozen=True,
    namespace={"check": _check, "RENAMED": LeverParams.RENAMED})
RateStateLeverParams.__module__ = __name__
RateStateLeverParams.__doc__ = ("Parameters of one rate-and-state virtual run: the lever's apparatus, protocol and "
                                "sensors, and the interfaces' rate-and-state friction and inertia.")


@registry.register("solver", "rate-state-lever", VERSION, RateStateLeverParams, produces="timeseries",
                   preflight=check_memory,
                   summary="virtual lever experiment with inertial slabs on rate-and-state (aging or slip law) interfaces")
def run(params, output, *, threads, inputs):
    """Run one rate-and-state virtual experiment and write its time-series file with the ground truth."""
    signals, truth, interfaces, integration = simulate(params)
    write_timeseries(output, signals, attrs={"params": params_to_dict(params), "seed": params.seed,
                                             "solver": "rate-state-lever", "solver_version": VERSION,
                                             "integration": integration,
                                             "slab_order": [int(slab) + 1 for slab in slab_order(params)]},
                     tables={"truth": truth, "interfaces": interfaces})
