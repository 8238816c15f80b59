"""Solver ``rate-state-lever``: the paper's apparatus with inertial slabs on Dieterich–Ruina interfaces.

The apparatus, protocols, sensors and file format of the ``lever`` solver
(:mod:`stickslip.solvers.lever`), but every slippable interface obeys rate-and-state friction with
the aging law (:mod:`stickslip.experiment.virtual.rate_state`) and the slabs move by Newton's law
(:mod:`stickslip.experiment.virtual.slab_dynamics`): sticks, slips, creep and any simultaneous
slip follow from the equations, nothing is scheduled. Optionally (``path_disorder`` > 0) each interface's
``mu0`` varies along its slip path (:mod:`stickslip.experiment.virtual.slip_path`). Model, defaults and their sources:
docs/experiment-model-rate-state.md.

Output: the experimental time-series file with the attributes ``params`` (JSON), ``seed``, ``solver``,
``solver_version``, ``integration`` (JSON: ``method``, accepted ``steps``, ``fallback`` and
``fallback_spans``, see :func:`simulate`) and two ground-truth tables: ``truth`` (one row per interface per slip, see
:func:`stickslip.experiment.virtual.slip_intervals.slip_intervals`) and ``interfaces`` (one row per
interface: ``a``, ``slippable``, ``a_rs``, ``b``, ``D_c`` [mm], ``mu0``, ``K_c`` [N/mm] (linear-stability
boundary ``N (b - a) / D_c``), ``n_slips``, ``slip_total``, ``creep_total`` (``R_total - slip_total``),
``R_total`` [mm]).
"""

import dataclasses

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from .. import registry
from ..experiment.timeseries import write_timeseries
from ..experiment.virtual.model import apparatus as apparatus_of, per_interface, random_streams, sensor_signals
from ..experiment.virtual.rate_state import RateStateLaw
from ..experiment.virtual.slab_dynamics import DEFAULT_METHOD, FALLBACK, METHODS, SlabDynamics
from ..experiment.virtual.slip_intervals import slip_intervals
from ..experiment.virtual.slip_path import PathProfiles
from ..params import ParameterError, param, params_to_dict
from .lever import LeverParams, check_protocol

__all__ = ["RateStateLeverParams", "run", "simulate", "law_of", "dynamics_of", "ground_truth"]

VERSION = "2"  # 2: RODAS4 with relative slip-rate tolerances (issue 12, third session)

#: Parameters shared with the ``lever`` solver: apparatus, protocol, drive, sensors.
SHARED = ("n", "protocol", "a", "n_slabs", "seed", "duration", "gamma_start", "normal_force", "k_spring", "h", "H",
          "V", "force_rate", "force_noise", "frame_rate", "position_noise")
#: Per-interface parameters: one value for every interface, or one per interface.
PER_INTERFACE = ("rs_a", "rs_b", "D_c", "mu0")


def _shared_fields():
    fields = {f.name: f for f in dataclasses.fields(LeverParams)}
    return [(name, fields[name].type, dataclasses.field(default=fields[name].default, metadata=fields[name].metadata))
            for name in SHARED]


_OWN = [
    ("rs_a", tuple[float, ...], param((0.013,), "rate-and-state direct effect a per interface (one value: all)",
                                      exclusive_minimum=0)),
    ("rs_b", tuple[float, ...], param((0.019, 0.017, 0.021, 0.018, 0.020),
                                      "rate-and-state evolution effect b per interface (one value: all)", minimum=0)),
    ("D_c", tuple[float, ...], param((5e-4,), "memory length D_c per interface (one value: all)", unit="mm",
                                     exclusive_minimum=0)),
    ("mu0", tuple[float, ...], param((0.35,), "steady friction at V0 per interface (one value: all)",
                                     exclusive_minimum=0)),
    ("V0", float, param(1e-3, "reference slip rate V0", unit="mm/s", exclusive_minimum=0)),
    ("disorder", float, param(0.05, "relative standard deviation of b and D_c drawn per interface and seed "
                                    "(quenched disorder; 0: none)", minimum=0)),
    ("path_disorder", float, param(0.0, "relative standard deviation of mu0 along each interface's slip path "
                                         "(heterogeneity of the surface, drawn per interface and seed; 0: none)",
                                   minimum=0)),
    ("path_correlation_length", float, param(0.025, "correlation length of mu0 along the slip path (the paper's "
                                                    "asperity size)", unit="mm", minimum=0.001, maximum=1.0)),
    ("slab_mass", float, param(0.143, "mass of one slab (PMMA 10 x 150 x 80 mm)", unit="kg", exclusive_minimum=0)),
    ("load_mass", float, param(5.0, "dead weight on the top slab", unit="kg", minimum=0)),
    ("theta_start", float, param(0.01, "contact age of every interface at t = 0 (just slipped)", unit="s",
                                 exclusive_minimum=0)),
    ("V_start", float, param(1e-6, "slip rate of every interface at t = 0", unit="mm/s", exclusive_minimum=0)),
    ("slip_velocity", float, param(0.1, "slip rate above which the ground truth counts a slip", unit="mm/s",
                                   exclusive_minimum=0)),
    ("method", str, param(DEFAULT_METHOD, "implicit integrator (RODAS4: compiled Rosenbrock; others: scipy solve_ivp)",
                          choices=METHODS)),
    ("rtol", float, param(1e-4, "relative tolerance of the integrator (the absolute tolerances scale with it)",
                          exclusive_minimum=0)),
]


def _check(self):
    """Check the protocol, the per-interface lengths and that every slippable interface weakens."""
    check_protocol(self)
    for name in PER_INTERFACE:
        if len(getattr(self, name)) not in (1, self.n_slabs):
            raise ParameterError(f"parameter '{name}': expected 1 or n_slabs={self.n_slabs} values, "
                                 f"got {len(getattr(self, name))}")


RateStateLeverParams = dataclasses.make_dataclass(
    "RateStateLeverParams", _shared_fields() + _OWN, frozen=True, namespace={"check": _check})
RateStateLeverParams.__module__ = __name__
RateStateLeverParams.__doc__ = ("Parameters of one rate-and-state virtual run: the lever's apparatus, protocol and "
                                "sensors, and the interfaces' rate-and-state friction and inertia.")


def law_of(params):
    """The :class:`RateStateLaw` of a run: the per-interface values with the seed's quenched disorder
    (``b`` and ``D_c`` multiplied by ``exp(disorder xi - disorder^2 / 2)``, ``xi`` standard normal,
    drawn from the disorder stream of :func:`~stickslip.experiment.virtual.model.random_streams`)."""
    rng, _ = random_streams(params)
    spread = np.exp(params.disorder * rng.standard_normal((2, params.n_slabs)) - params.disorder ** 2 / 2)
    return RateStateLaw(a=per_interface(params, "rs_a"), b=per_interface(params, "rs_b") * spread[0],
                        D_c=per_interface(params, "D_c") * spread[1], mu0=per_interface(params, "mu0"), V0=params.V0)


def dynamics_of(params):
    """The equations of motion of a run and its initial state.

    Returns
    -------
    dynamics : SlabDynamics
    R0 : numpy.ndarray
        Slip of every interface at t = 0 [mm], [n_slabs].
    y0 : numpy.ndarray
        Initial state of the integration, [3 m + 1] (:meth:`SlabDynamics.initial_state`).
    """
    path = (PathProfiles.draw(params.seed, params.n_slabs, params.path_disorder, params.path_correlation_length)
            if params.path_disorder > 0 else None)
    dynamics = SlabDynamics(apparatus_of(params), law_of(params), params.slab_mass, params.load_mass, path=path)
    R0, y0 = dynamics.initial_state(params.V_start, params.theta_start, params.gamma_start)
    return dataclasses.replace(dynamics, path_origin=y0[:dynamics.interfaces.size]), R0, y0


def ground_truth(params, dynamics, R0, trajectory):
    """Every slip of an integrated trajectory and the slips at any time.

    Parameters
    ----------
    params : RateStateLeverParams
    dynamics, R0 : SlabDynamics, numpy.ndarray
        From :func:`dynamics_of`.
    trajectory : Trajectory
        Its integration from t = 0 (:meth:`SlabDynamics.integrate`).

    Returns
    -------
    truth : pandas.DataFrame
        One row per interface per slip (:func:`~stickslip.experiment.virtual.slip_intervals.slip_intervals`).
    slips_at : callable
        ``slips_at(times [k]) -> [k, n_slabs]``: the slip of every interface [mm] (cubic Hermite
        interpolation between the steps).
    """
    t, y, dydt = trajectory.t, trajectory.y, trajectory.dydt
    index, m = dynamics.interfaces, dynamics.interfaces.size
    spline = CubicHermiteSpline(t, y[:, :m], dydt[:, :m], axis=0)

    def slips_at(times):
        R = np.tile(R0, (np.size(times), 1))
        R[:, index] = spline(np.asarray(times, dtype=float))
        return R

    law = dynamics.law
    V = np.zeros((t.size, params.n_slabs))
    V[:, index] = y[:, m:2 * m]
    theta = np.zeros((t.size, params.n_slabs))
    theta[:, index] = law.D_c[index] / law.V0 * np.exp(y[:, 2 * m:3 * m])
    return slip_intervals(dynamics.apparatus, t, slips_at, V, theta, params.slip_velocity), slips_at


def simulate(params):
    """Run the rate-and-state virtual experiment.

    Parameters
    ----------
    params : RateStateLeverParams

    Returns
    -------
    record, truth, interfaces
        The sensor signals and the ground truth, as from the ``lever`` solver's
        :func:`~stickslip.experiment.virtual.model.simulate` (the tables' columns: module docstring).
    integration : dict
        How the run was integrated: ``method``, ``steps`` (accepted steps, int), ``fallback`` (the
        method that takes over where ``method``'s step size underflows) and ``fallback_spans`` (start
        and end [s] of every span it integrated: a list of pairs, empty for nearly every run).
    """
    dynamics, R0, y0 = dynamics_of(params)
    apparatus, law = dynamics.apparatus, dynamics.law
    trajectory = dynamics.integrate(y0, params.duration, apparatus.shear_rate, method=params.method,
                                    rtol=params.rtol)
    truth, slips_at = ground_truth(params, dynamics, R0, trajectory)
    signals = sensor_signals(params, apparatus, slips_at, random_streams(params)[1])
    index = dynamics.interfaces
    slippable = np.zeros(params.n_slabs, bool)
    slippable[index] = True
    a = np.arange(1, params.n_slabs + 1)
    slips = truth.groupby("a")["dR"].agg(["size", "sum"]).reindex(a, fill_value=0)
    ends = slips_at(np.array([0.0, params.duration]))
    R_total = ends[1] - ends[0]
    interfaces = pd.DataFrame({"a": a, "slippable": slippable, "a_rs": law.a, "b": law.b, "D_c": law.D_c,
                               "mu0": law.mu0, "K_c": law.critical_stiffness(params.normal_force),
                               "n_slips": slips["size"].to_numpy(np.int64), "slip_total": slips["sum"].to_numpy(float),
                               "creep_total": R_total - slips["sum"].to_numpy(float), "R_total": R_total})
    integration = {"method": params.method, "steps": int(trajectory.t.size - 1), "fallback": FALLBACK,
                   "fallback_spans": trajectory.fallback_spans.tolist()}
    return signals, truth, interfaces, integration


@registry.register("solver", "rate-state-lever", VERSION, RateStateLeverParams, produces="timeseries",
                   summary="virtual lever experiment with inertial slabs on rate-and-state (aging law) interfaces")
def run(params, output, *, threads, inputs):
    """Run one rate-and-state virtual experiment and write its time-series file with the ground truth."""
    signals, truth, interfaces, integration = simulate(params)
    write_timeseries(output, signals, attrs={"params": params_to_dict(params), "seed": params.seed,
                                             "solver": "rate-state-lever", "solver_version": VERSION,
                                             "integration": integration},
                     tables={"truth": truth, "interfaces": interfaces})
