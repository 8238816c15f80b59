"""The virtual experiment assembled from its parameters: apparatus, friction law, integration, sensors.

:func:`simulate` turns the parameters of the ``lever`` solver
(:class:`stickslip.solvers.lever.LeverParams`) into the sensor signals and the ground truth;
the solver plugin only writes them to a ``timeseries`` file.
"""

import numpy as np
import pandas as pd

from .apparatus import Apparatus
from .friction import FrictionLaw
from .history import integrate
from .sensors import record, relative_positions

__all__ = ["per_interface", "apparatus", "friction_law", "interfaces_table", "random_streams", "sensor_signals",
           "simulate"]


def per_interface(params, name):
    """A per-interface parameter as float64 [n_slabs] (a single value is repeated)."""
    values = np.asarray(getattr(params, name), dtype=float)
    return np.broadcast_to(values, (params.n_slabs,)).copy()


def apparatus(params):
    """The :class:`~stickslip.experiment.virtual.Apparatus` of the parameters."""
    return Apparatus.from_protocol(params.protocol, n=params.n, a=params.driven_slab, n_slabs=params.n_slabs,
                                   k_spring=params.k_spring, normal_force=params.normal_force, h=params.h,
                                   H=params.H, V=params.V, gamma_start=params.gamma_start)


def friction_law(params):
    """The :class:`~stickslip.experiment.virtual.FrictionLaw` of the parameters.

    The creep velocities are scaled by ``(n_driven - 1) / (n_slabs - 1)``: creep, read as
    activated by the mechanical noise of the other driven interfaces (paper, "Creep effective
    temperature"), vanishes for a single driven slab and reaches ``creep_velocity`` for a full stack.
    """
    n_driven = params.n if params.protocol == "stack" else 1
    scale = (n_driven - 1) / max(params.n_slabs - 1, 1)
    return FrictionLaw(mu_d=per_interface(params, "mu_d"), B=per_interface(params, "B"), T0=params.T0,
                       offset=params.strength_offset, threshold_noise=params.threshold_noise,
                       creep_velocity=scale * per_interface(params, "creep_velocity"),
                       creep_onset=params.creep_onset, trigger_margin=params.trigger_margin)


def interfaces_table(lever, law, history):
    """One row per interface: its friction parameters and slip/creep totals (see :mod:`stickslip.solvers.lever`)."""
    slippable = np.zeros(lever.n_slabs, bool)
    slippable[np.asarray(lever.slippable) - 1] = True
    index = np.arange(1, lever.n_slabs + 1)
    slips = history.slips.groupby("a")["dR"].agg(["size", "sum"]).reindex(index, fill_value=0)
    creep = history.creep.assign(total=history.creep["velocity"] * (history.creep["t_off"] - history.creep["t_on"]))
    creep_total = creep.groupby("a")["total"].sum().reindex(index, fill_value=0.0)
    ends = relative_positions(history, np.array([0.0, history.duration]))
    return pd.DataFrame({"a": index, "slippable": slippable, "mu_d": law.mu_d, "B": law.B,
                         "creep_velocity": law.creep_velocity, "n_slips": slips["size"].to_numpy(np.int64),
                         "slip_total": slips["sum"].to_numpy(float), "creep_total": creep_total.to_numpy(float),
                         "R_total": ends[1] - ends[0]})


def random_streams(params):
    """The two independent random streams of a run, derived from ``params.seed``: the interfaces'
    disorder and the sensor noise (so changing a noise level leaves the slips unchanged).

    Returns
    -------
    disorder, sensors : numpy.random.Generator
        PCG64 generators of the first and second child of ``SeedSequence(seed)``.
    """
    return tuple(np.random.Generator(np.random.PCG64(child)) for child in np.random.SeedSequence(params.seed).spawn(2))


def sensor_signals(params, lever, positions, rng):
    """What the force sensor and the camera record during a run (:func:`.sensors.record`).

    Parameters
    ----------
    params : LeverParams or RateStateLeverParams
        Protocol (``n``, ``protocol``, ``a``), ``duration`` [s] and the sensor parameters
        (``force_rate``, ``frame_rate`` [Hz], ``force_noise`` [N], ``position_noise`` [mm]).
    lever : Apparatus
    positions : callable
        Slip of every interface at given times [s] -> [n_times, n_slabs] [mm].
    rng : numpy.random.Generator
        The sensor stream of :func:`random_streams`.

    Returns
    -------
    ExperimentRecord
    """
    return record(lever, positions, params.duration, n=params.n, protocol=params.protocol, a=params.driven_slab,
                  force_rate=params.force_rate, frame_rate=params.frame_rate, force_noise=params.force_noise,
                  position_noise=params.position_noise, rng=rng)


def simulate(params):
    """Run the virtual experiment.

    Parameters
    ----------
    params : stickslip.solvers.lever.LeverParams

    Returns
    -------
    record : ExperimentRecord
        The sensor signals.
    truth : pandas.DataFrame
        One row per interface per slip.
    interfaces : pandas.DataFrame
        One row per interface.
    """
    disorder, sensors = random_streams(params)
    lever, law = apparatus(params), friction_law(params)
    history = integrate(lever, law, params.duration, params.slip_duration, disorder)
    signals = sensor_signals(params, lever, lambda times: relative_positions(history, times), sensors)
    return signals, history.slips, interfaces_table(lever, law, history)
