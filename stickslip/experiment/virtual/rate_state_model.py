"""The rate-and-state virtual experiment assembled from its parameters: friction law, slab dynamics,
integration, ground truth and sensors.

:func:`simulate` turns the parameters of the ``rate-state-lever`` solver
(:class:`stickslip.solvers.rate_state_lever.RateStateLeverParams`) into the sensor signals, the
ground truth and the record of the integration; the solver plugin only writes them to a
``timeseries`` file (as :mod:`.model` does for the ``lever`` solver). Model, defaults and their
sources: docs/experiment-model-rate-state.md.
"""

import dataclasses

import numpy as np
import pandas as pd

from .model import apparatus as apparatus_of, per_interface, random_streams, sensor_signals
from .rate_state import RateStateLaw
from .slab_dynamics import SlabDynamics
from .slip_intervals import slip_intervals
from .slip_path import PathProfiles

__all__ = ["STATE", "slab_order", "law_of", "dynamics_of", "hermite", "ground_truth", "simulate"]

#: The integrated variables, as recorded in a run's ``integration`` attribute (:mod:`.slab_equations`).
STATE = "R, mu, psi, gamma"


def slab_order(params):
    """0-based index of the physical slab at every position from the bottom, int [n_slabs]:
    ``params.slab_order - 1``, or ``0 .. n_slabs - 1`` (in order) if it is empty."""
    order = np.asarray(params.slab_order, dtype=int) - 1 if params.slab_order else np.arange(params.n_slabs)
    return order


def law_of(params):
    """The :class:`RateStateLaw` of a run: the per-interface values with the seed's quenched disorder
    (``b`` and ``D_c`` multiplied by ``exp(disorder xi - disorder^2 / 2)``, ``xi`` standard normal,
    drawn from the disorder stream of :func:`~stickslip.experiment.virtual.model.random_streams`).

    The values and the draws belong to the physical slabs (interface ``s`` is the one slab ``s`` slides
    on): with a shuffled ``slab_order`` they travel with their slab to its position (:func:`slab_order`),
    and every array of the law is indexed by position."""
    rng, _ = random_streams(params)
    spread = np.exp(params.disorder * rng.standard_normal((2, params.n_slabs)) - params.disorder ** 2 / 2)
    order = slab_order(params)
    return RateStateLaw(a=per_interface(params, "rs_a")[order], b=(per_interface(params, "rs_b") * spread[0])[order],
                        D_c=(per_interface(params, "D_c") * spread[1])[order], mu0=per_interface(params, "mu0")[order],
                        V0=params.V0, state_law=params.rs_state_law)


def dynamics_of(params):
    """The equations of motion of a run and its initial state (the slip-path profiles, like the law,
    travel with their slab: :func:`law_of`).

    Returns
    -------
    dynamics : SlabDynamics
    R0 : numpy.ndarray
        Slip of every interface at t = 0 [mm], [n_slabs].
    y0 : numpy.ndarray
        Initial state of the integration, [3 m + 1] (:meth:`SlabDynamics.initial_state`).
    """
    path = (PathProfiles.draw(params.seed, params.n_slabs, params.path_disorder, params.path_correlation_length)
            .reordered(slab_order(params)) if params.path_disorder > 0 else None)
    dynamics = SlabDynamics(apparatus_of(params), law_of(params), params.slab_mass, params.load_mass, path=path)
    R0, y0 = dynamics.initial_state(params.V_start, params.theta_start, params.gamma_start)
    return dataclasses.replace(dynamics, path_origin=y0[:dynamics.interfaces.size]), R0, y0


def hermite(t, values, slopes):
    """The piecewise cubic Hermite interpolant of ``values`` with the ``slopes`` at the increasing
    times ``t`` [k] (``values``, ``slopes``: [k, m]): a function of times [j] -> [j, m] (outside
    ``t``, the end intervals' cubics continued). numpy only: a job that imports scipy.interpolate
    takes ~0.4 s longer to start."""

    def at(times):
        times = np.asarray(times, dtype=float)
        i = np.clip(np.searchsorted(t, times, side="right") - 1, 0, t.size - 2)
        step = (t[i + 1] - t[i])[:, None]
        s = ((times - t[i]) / (t[i + 1] - t[i]))[:, None]
        s2, s3 = s * s, s * s * s
        return ((2 * s3 - 3 * s2 + 1) * values[i] + (s3 - 2 * s2 + s) * step * slopes[i]
                + (3 * s2 - 2 * s3) * values[i + 1] + (s3 - s2) * step * slopes[i + 1])

    return at


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
    spline = hermite(t, y[:, :m], dydt[:, :m])

    def slips_at(times):
        R = np.tile(R0, (np.size(times), 1))
        R[:, index] = spline(np.asarray(times, dtype=float))
        return R

    law = dynamics.law
    V = np.zeros((t.size, params.n_slabs))
    V[:, index] = dydt[:, :m]
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
        How the run was integrated: ``method``, ``state`` (the integrated variables, "R, mu, psi,
        gamma"), ``steps`` (accepted steps, int).
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
    interfaces = pd.DataFrame({"a": a, "slab": slab_order(params) + 1, "slippable": slippable, "a_rs": law.a,
                               "b": law.b, "D_c": law.D_c,
                               "mu0": law.mu0, "K_c": law.critical_stiffness(params.normal_force),
                               "n_slips": slips["size"].to_numpy(np.int64), "slip_total": slips["sum"].to_numpy(float),
                               "creep_total": R_total - slips["sum"].to_numpy(float), "R_total": R_total})
    integration = {"method": params.method, "state": STATE, "steps": int(trajectory.t.size - 1)}
    return signals, truth, interfaces, integration
