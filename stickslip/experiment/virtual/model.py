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

__all__ = ["per_interface", "apparatus", "friction_law", "interfaces_table", "simulate"]


def per_interface(params, name):
    """A per-interface parameter as float64 [n_slabs] (a single value is repeated)."""
    values = np.asarray(getattr(params, name), dtype=float)
    return np.broadcast_to(values, (params.n_slabs,)).copy()


def apparatus(params):
    """The :class:`~stickslip.experiment.virtual.Apparatus` of the parameters."""
    return Apparatus.from_protocol(params.protocol, n=params.n, a=params.a, n_slabs=params.n_slabs,
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

    Notes
    -----
    Two independent random streams derive from ``seed``: the threshold disorder and the
    sensor noise, so changing a noise level leaves the slips unchanged.
    """
    disorder_seed, sensor_seed = np.random.SeedSequence(params.seed).spawn(2)
    lever, law = apparatus(params), friction_law(params)
    history = integrate(lever, law, params.duration, params.slip_duration,
                        np.random.Generator(np.random.PCG64(disorder_seed)))
    signals = record(lever, lambda times: relative_positions(history, times), history.duration, n=params.n,
                     protocol=params.protocol, a=params.a, force_rate=params.force_rate, frame_rate=params.frame_rate,
                     force_noise=params.force_noise, position_noise=params.position_noise,
                     rng=np.random.Generator(np.random.PCG64(sensor_seed)))
    return signals, history.slips, interfaces_table(lever, law, history)
