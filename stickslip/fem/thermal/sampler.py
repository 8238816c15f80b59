"""Exact sampling of the next event of a thermally activated, driven interface (kinetic Monte Carlo).

Every block hops forward or backward at the Arrhenius rate ``r = nu exp(-E / T)`` of its barrier
``E`` (:mod:`.barriers`); while the drive advances (drive offset ``ds = ds0 + speed t``) the
barriers, hence the rates, change. The next hop is the first event of this inhomogeneous Poisson
process, whose survival function is ``exp(-int_0^t R(t') dt')`` with ``R`` the sum of all rates;
it competes with the athermal threshold (a Gauss point reaching its yield strain at ``ds_c``)
and with the end of the current stretch of the schedule (``duration``, e.g. the end of a hold).

The sampling is exact (no time step): by **thinning** (Lewis and Shedler 1979). Over a window of
time the rate of each block is bounded from above by the Arrhenius rate of a lower bound of its
barrier (:func:`.barriers.barrier_bounds`); candidate times are drawn from the homogeneous process
of the summed bound, a candidate is given to a block with probability ``bound_j / sum``, and is
accepted with probability ``r_j(t) / bound_j``. The accepted candidates are distributed exactly as
the hops of the inhomogeneous process, whichever the bound; a tight bound only makes rejections
rare. Windows are halved until the bound is within a factor :data:`TIGHT` of the rate at the
window's start or expects at most one candidate, and doubled after each window. During a hold
(``speed = 0``) the rates are constant and the waiting time is one exponential draw.

Random numbers: pcg32 (:mod:`..random`), 53-bit uniforms from two draws; the caller seeds one
stream per increment, so that a run resumed from any stored increment draws the same numbers.

Bounded: one draw (:func:`draw_event`, the compiled kernel) makes at most :data:`MAX_DRAWS` windows and
candidates (a few to a few hundred in the regimes the studies run), then gives up (:data:`STALLED`);
:func:`sample_event` turns that into a :class:`..errors.SolverError` naming the parameters, so that no
rates, however extreme, make a run loop for ever (and one call returns to Python within a second or so,
where Ctrl-C and SIGTERM are handled).
"""

import math

import numpy as np

from ...numba_options import njit
from ..errors import SolverError
from ..random import pcg32_next
from .barriers import barrier_bounds, block_barrier, block_barriers

__all__ = ["NONE", "HOP", "THRESHOLD", "STALLED", "TIGHT", "MAX_DRAWS", "sample_event", "draw_event", "uniform",
           "exponential", "stalled_error"]

#: Kinds of event returned by :func:`sample_event`: nothing before the end of the stretch,
#: a thermally activated hop, the athermal threshold.
NONE = 0
HOP = 1
THRESHOLD = 2
#: Kind returned by :func:`draw_event` when it gave up after :data:`MAX_DRAWS` windows and candidates.
STALLED = -1

#: Windows and candidate hops one draw makes at most: far beyond any draw of the studies' regimes (tens),
#: reached only when the rates are beyond what the method resolves (then an error, never an endless loop).
MAX_DRAWS = 1_000_000

#: A window is accepted when its bound exceeds the rate at its start by at most this factor (or
#: expects at most one candidate).
TIGHT = 4.0


@njit
def uniform(state, inc):
    """Uniform double in [0, 1) with 53 random bits (two pcg32 draws of generator 0 of ``state``, ``inc``)."""
    a = pcg32_next(state, inc, 0) >> np.uint64(5)
    b = pcg32_next(state, inc, 0) >> np.uint64(6)
    return (float(a) * 67108864.0 + float(b)) / 9007199254740992.0


@njit
def exponential(state, inc):
    """Exponential variate of mean 1."""
    return -math.log1p(-uniform(state, inc))


@njit
def _rates(energies, allowed, beta, nu, out):
    """``out = nu exp(-beta E)`` where allowed, else 0; returns the sum."""
    total = 0.0
    for e in range(energies.shape[0]):
        for d in range(2):
            r = nu * math.exp(-beta * energies[e, d]) if allowed[e, d] else 0.0
            out[e, d] = r
            total += r
    return total


@njit
def _pick(weights, total, u):
    """Index (block, direction) of the weight in which ``u * total`` falls (cumulative order)."""
    target = u * total
    cumulative = 0.0
    last_e, last_d = -1, -1
    for e in range(weights.shape[0]):
        for d in range(2):
            w = weights[e, d]
            if w > 0.0:
                cumulative += w
                last_e, last_d = e, d
                if target < cumulative:
                    return e, d
    return last_e, last_d


def sample_event(law, epsy, idx, eps, deps, dV, allowed, beta, nu, ds0, speed, duration, ds_c, state, inc):
    """The next event after now, drawn exactly (:func:`draw_event`; its bound raised as an error).

    Parameters and returns as :func:`draw_event`, which never returns :data:`STALLED` here.

    Raises
    ------
    stickslip.fem.errors.SolverError
        If the draw gave up after :data:`MAX_DRAWS` windows and candidates (:func:`stalled_error`).
    """
    drawn = draw_event(law, epsy, idx, eps, deps, dV, allowed, beta, nu, ds0, speed, duration, ds_c, state, inc)
    if drawn[0] == STALLED:
        raise stalled_error(beta, nu, speed)
    return drawn


def stalled_error(beta, nu, speed):
    """The :class:`..errors.SolverError` of a draw that reached :data:`MAX_DRAWS`, naming the parameters.

    Parameters
    ----------
    beta : float
        ``1 / T`` [1/energy].
    nu : float
        Attempt rate [1/time].
    speed : float
        Drive offset per unit time.
    """
    return SolverError(f"the thermal sampling made {MAX_DRAWS} windows and candidate hops without finding the next "
                       f"event (attempt_rate = {nu:g}/time, 1/T = {beta:.6g} per energy unit, drive offset speed "
                       f"{speed:.6g}/time): the hop rates change faster than the kinetic Monte Carlo resolves; "
                       "expected a lower attempt_rate, temperature or drive_rate (docs/fem.md, 'Limits of the regime')")


@njit
def draw_event(law, epsy, idx, eps, deps, dV, allowed, beta, nu, ds0, speed, duration, ds_c, state, inc):
    """The next event after now, drawn exactly (the compiled kernel of :func:`sample_event`).

    Parameters
    ----------
    law, epsy, idx, eps, deps, dV
        The interface as in :func:`.barriers.block_barrier` (``eps`` the strain of the state at
        drive offset 0).
    allowed : numpy.ndarray
        bool [ni, 2]: hops that may happen (a hop that fell back is left out until the next event).
    beta : float
        ``1 / T`` [1/energy].
    nu : float
        Attempt rate [1/time].
    ds0 : float
        Drive offset now.
    speed : float
        Drive offset per unit time (0: the drive is held).
    duration : float
        Time to the end of this stretch of the schedule (``inf``: none).
    ds_c : float
        Drive offset of the athermal threshold (> ``ds0`` when ``speed > 0``).
    state, inc : numpy.ndarray
        uint64 [1]: the pcg32 generator (advanced in place).

    Returns
    -------
    kind : int
        :data:`NONE` (the stretch ended first), :data:`HOP` or :data:`THRESHOLD`; :data:`STALLED` after
        :data:`MAX_DRAWS` windows and candidates without an event.
    block, direction : int
        The hop (-1 otherwise).
    dt : float
        Time from now to the event (or to the end of the stretch; for :data:`STALLED` to where it gave up).
    """
    ni = idx.shape[0]
    energies = np.empty((ni, 2))
    rates = np.empty((ni, 2))
    if speed == 0.0:
        block_barriers(law, epsy, idx, eps, deps, dV, ds0, energies)
        total = _rates(energies, allowed, beta, nu, rates)
        dt = exponential(state, inc) / total if total > 0.0 else math.inf
        if dt >= duration:
            return NONE, -1, -1, duration
        e, d = _pick(rates, total, uniform(state, inc))
        return HOP, e, d, dt
    t_c = (ds_c - ds0) / speed
    t_end = min(t_c, duration)
    t = 0.0
    width = t_end
    bounds = np.empty((ni, 2))
    draws = 0
    while t < t_end:
        draws += 1
        if draws > MAX_DRAWS:
            return STALLED, -1, -1, t
        ta = t
        tb = min(t + width, t_end)
        barrier_bounds(law, epsy, idx, eps, deps, dV, ds0 + speed * t, ds0 + speed * tb, energies)
        bound = _rates(energies, allowed, beta, nu, bounds)
        if bound * (tb - ta) > 1.0 and tb - ta > 1e-15 * t_end:
            block_barriers(law, epsy, idx, eps, deps, dV, ds0 + speed * ta, energies)
            if bound > TIGHT * _rates(energies, allowed, beta, nu, rates):
                width = 0.5 * (tb - ta)
                continue
        while True:
            draws += 1
            if draws > MAX_DRAWS:
                return STALLED, -1, -1, t
            t = t + exponential(state, inc) / bound if bound > 0.0 else math.inf
            if t >= tb:
                t = tb
                break
            e, d = _pick(bounds, bound, uniform(state, inc))
            rate = nu * math.exp(-beta * block_barrier(law, epsy, idx, eps, deps, dV, ds0 + speed * t, e, d))
            if uniform(state, inc) * bounds[e, d] < rate:
                return HOP, e, d, t
        width = 2.0 * (tb - ta)
    if t_c <= duration:
        return THRESHOLD, -1, -1, t_c
    return NONE, -1, -1, duration
