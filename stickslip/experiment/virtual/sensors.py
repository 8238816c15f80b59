"""Sensors of the virtual experiment: the camera (slab positions) and the force sensor (lever force).

:func:`record` samples any noise-free slip history ``R(t)``. For the event-by-event lever model,
:func:`relative_positions` turns the slips of a :class:`.history.SlipHistory` into continuous signals: interface
``i`` slips by ``dR`` along the smooth ramp ``dR (1 - cos(pi s)) / 2``, ``s = (t - t_start) /
slip_duration`` in [0, 1], and creeps linearly at its creep velocity during each creep segment.
The slab positions follow as ``x = cumsum(R)``, the lever force from the moment balance
(:meth:`.apparatus.Apparatus.lever_force`). The sensors sample these at fixed rates from
t = 0 to the end of the run and add independent Gaussian noise: ``position_noise`` [mm] on
every slab position of every frame, ``force_noise`` [N] on every force sample.
"""

import numpy as np

from ..timeseries import ExperimentRecord

__all__ = ["sample_times", "relative_positions", "record"]


def sample_times(duration, rate):
    """Sample times ``k / rate`` for k = 0, 1, ... up to ``duration`` [s], float64 [n]."""
    return np.arange(int(np.floor(duration * rate + 1e-9)) + 1) / rate


def recording_bytes(duration, force_rate, frame_rate, n_slabs):
    """Memory that :func:`record` takes at least for a run [B].

    Every force sample takes its time and force and, while it is made, the slip and position of every slab; every
    frame its time and the slip, position and noise of every slab (float64).

    Parameters
    ----------
    duration : float
        [s].
    force_rate, frame_rate : float
        [Hz].
    n_slabs : int

    Returns
    -------
    float
    """
    return 8.0 * (duration * force_rate * (2 * n_slabs + 2) + duration * frame_rate * (3 * n_slabs + 1))


def _accumulated(times, starts, ends, amounts, ramp):
    """Sum of amounts reached at ``times`` by episodes that do not overlap.

    Parameters
    ----------
    times : numpy.ndarray
        Sample times [s], increasing, [n_t].
    starts, ends, amounts : numpy.ndarray
        Episodes: start and end [s] and the amount reached at the end, [n_episodes].
    ramp : callable
        Fraction reached at relative progress ``s`` in (0, 1) (0 at 0, 1 at 1).

    Returns
    -------
    numpy.ndarray
        float64 [n_t].
    """
    first = np.searchsorted(times, starts, side="right")   # first sample after the start
    last = np.searchsorted(times, ends, side="left")       # first sample at or after the end
    jumps = np.zeros(times.size + 1)
    np.add.at(jumps, last, amounts)
    total = np.cumsum(jumps[:-1])
    for begin, stop, start, end, amount in zip(first, last, starts, ends, amounts):
        if begin < stop:
            total[begin:stop] += amount * ramp((times[begin:stop] - start) / (end - start))
    return total


def _cosine_ramp(s):
    return 0.5 * (1.0 - np.cos(np.pi * s))


def _linear_ramp(s):
    return s


def relative_positions(history, times):
    """Noise-free slip R_i(t) of every interface at ``times``.

    Parameters
    ----------
    history : SlipHistory
    times : numpy.ndarray
        Sample times [s], increasing, [n_t].

    Returns
    -------
    numpy.ndarray
        float64 [n_t, n_slabs] [mm].
    """
    R = np.tile(history.R0, (times.size, 1))
    for column in range(history.R0.size):
        slips = history.slips[history.slips["a"] == column + 1]
        R[:, column] += _accumulated(times, slips["t_start"].to_numpy(float), slips["t_end"].to_numpy(float),
                                     slips["dR"].to_numpy(float), _cosine_ramp)
        creep = history.creep[history.creep["a"] == column + 1].sort_values("t_on")
        on, off = creep["t_on"].to_numpy(float), creep["t_off"].to_numpy(float)
        R[:, column] += _accumulated(times, on, off, creep["velocity"].to_numpy(float) * (off - on), _linear_ramp)
    return R


def record(apparatus, slips_at, duration, *, n, protocol, a, force_rate, frame_rate, force_noise, position_noise,
           rng):
    """Sample the sensors and return the experiment record.

    Parameters
    ----------
    apparatus : Apparatus
    slips_at : callable
        Noise-free slip of every interface at given times: ``slips_at(times [n_t]) -> R [n_t, n_slabs]``
        [mm] (e.g. ``lambda t: relative_positions(history, t)``).
    duration : float
        Length of the run [s]; samples from 0 to ``duration``.
    n, a : int
        Driven slabs and the slab driven alone (0 for "stack"), as recorded.
    protocol : {"stack", "individual"}
    force_rate, frame_rate : float
        Sampling rates of the force sensor and the camera [Hz].
    force_noise : float
        Standard deviation of the force noise [N].
    position_noise : float
        Standard deviation of the position noise [mm].
    rng : numpy.random.Generator
        Source of the sensor noise (positions first, then force).

    Returns
    -------
    ExperimentRecord
    """
    t_x = sample_times(duration, frame_rate)
    t_F = sample_times(duration, force_rate)
    x = apparatus.positions(slips_at(t_x))
    F = apparatus.lever_force(apparatus.spring_forces(t_F, apparatus.positions(slips_at(t_F))))
    x = x + position_noise * rng.standard_normal(x.shape)
    F = F + force_noise * rng.standard_normal(F.shape)
    return ExperimentRecord(t_F=t_F, F=F, t_x=t_x, x=x, n=n, n_slabs=apparatus.n_slabs, protocol=protocol, a=a,
                            normal_force=apparatus.normal_force, k_spring=apparatus.k_spring, h=apparatus.h,
                            H=apparatus.H, V=apparatus.lever_speed)
