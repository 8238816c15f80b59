"""Exact sampling of the next event of a thermally activated interface whose junctions age (kinetic Monte Carlo).

Two kinds of thermally activated events compete between two events of the stack: the hops of the
blocks over their barriers, whose rates change as the drive advances (:mod:`.sampler`), and the
redraws of the junctions (:mod:`.junctions`), block ``e`` at the constant rate
``nu_j exp(-E_e / T)``. The redraws form a homogeneous Poisson process of the summed rate ``R_j``
between two of them, so the next redraw comes after an exponential time ``tau`` of mean ``1 / R_j``;
the hops are sampled exactly over the stretch up to ``tau`` (:func:`.sampler.sample_event`). If
neither a hop nor the athermal threshold comes first, the redraw happens at ``tau``: the block is
picked in proportion to its rate and gets a depth drawn from ``rho(E) = exp(-E / T_g) / T_g``; the
hop process then starts afresh from there (it is Markov, so this is exact: no time step, no
tolerance). A redraw that leaves a Gauss point of its block outside its well (now narrower) ends the
sampling (:data:`REDRAW`): the block yields, an event of the stack. Any other redraw is applied at
once (to the junctions and to ``epsy``, the caller's copy of the yield strains the backend holds,
given back to the backend afterwards) and the sampling goes on.

The athermal threshold is the drive offset at which the first Gauss point reaches its forward yield
strain along the linear response (``eps + ds deps``, a quadratic per Gauss point), kept per block and
recomputed for a block whose junction is redrawn (a narrower well comes sooner); the load step of
the protocol then goes to the brink exactly (:meth:`..loading.Loading.step`).

Bounded, and stoppable: the compiled loop (:func:`redraw_loop`) applies at most :data:`REDRAWS_PER_CALL`
redraws per call and returns to Python (:data:`PAUSED`), where Ctrl-C and SIGTERM are handled, then
:func:`sample_with_redraws` calls it again from where it paused: the same draws, bit for bit, as one
call. The redraws before one event are bounded by :func:`redraw_bound` (:data:`REDRAW_MARGIN` times what
the trap model expects, :func:`..trap_model.expected_redraws`): beyond it the sampling stops with an error
naming the parameters instead of running for ever (parameters that would need that many are refused
before the run, :mod:`..parameters`).
"""

import math

import numpy as np

from ...numba_options import njit
from ..errors import SolverError
from ..trap_model import expected_redraws
from .junctions import widening
from .sampler import HOP, NONE, STALLED, THRESHOLD, draw_event, exponential, stalled_error, uniform

__all__ = ["REDRAW", "PAUSED", "REDRAWS_PER_CALL", "REDRAW_MARGIN", "REDRAW_FLOOR", "block_threshold",
           "sample_with_redraws", "redraw_loop", "redraw_bound"]

#: Kind of event returned by :func:`sample_with_redraws` (beside :data:`.sampler.NONE`, ``HOP``,
#: ``THRESHOLD``): a junction redrawn so shallow that a Gauss point of its block leaves its well.
REDRAW = 3

#: Kind returned by :func:`redraw_loop` after :data:`REDRAWS_PER_CALL` redraws (not an event: call it again).
PAUSED = 4

#: Redraws one call of :func:`redraw_loop` applies at most (~10 ms at N = 9, ~0.3 s at N = 162 with 2 interfaces).
REDRAWS_PER_CALL = 10_000

#: The bound on the redraws before one event: this many times the trap model's expectation for every block
#: over the time to the athermal threshold or the end of the stretch (:func:`redraw_bound`) ...
REDRAW_MARGIN = 100.0
#: ... and at least this many.
REDRAW_FLOOR = 100_000


@njit
def block_threshold(epsy, idx, eps, deps, e):
    """Drive offset at which the first Gauss point of block ``e`` reaches its forward yield strain [response units].

    Along the linear response ``eps_eq(ds)^2`` is a convex quadratic; the offset is its positive
    root for the well's forward yield strain (0 if a point is there already; inf if none gets there).

    Parameters
    ----------
    epsy : numpy.ndarray
        [ni, ny] held yield strains.
    idx : numpy.ndarray
        int64 [ni, 4] held wells.
    eps, deps : numpy.ndarray
        [ni, 4, 3] strain at offset 0 and of the linear response.
    e : int
    """
    best = math.inf
    for q in range(4):
        target = epsy[e, idx[e, q] + 1]
        et = 0.5 * (eps[e, q, 0] - eps[e, q, 1])
        gt = eps[e, q, 2]
        ed = 0.5 * (deps[e, q, 0] - deps[e, q, 1])
        gd = deps[e, q, 2]
        a = ed * ed + gd * gd
        b = 2.0 * (et * ed + gt * gd)
        c = et * et + gt * gt - target * target
        if c >= 0.0:
            return 0.0
        if a > 0.0:
            best = min(best, (-b + math.sqrt(b * b - 4.0 * a * c)) / (2.0 * a))
    return best


@njit
def _outside(epsy, idx, eps, deps, e, ds):
    """Whether a Gauss point of block ``e`` at drive offset ``ds`` lies outside its held well."""
    for q in range(4):
        xx = eps[e, q, 0] + ds * deps[e, q, 0]
        yy = eps[e, q, 1] + ds * deps[e, q, 1]
        xy = eps[e, q, 2] + ds * deps[e, q, 2]
        eq = math.sqrt((0.5 * (xx - yy)) ** 2 + xy * xy)
        if eq <= epsy[e, idx[e, q]] or eq > epsy[e, idx[e, q] + 1]:
            return True
    return False


@njit
def _redraw_rates(well, depth, inv_temperature, nu_j, out):
    """``out[e] = nu_j exp(-E_e / T)`` for the blocks with a junction (0 without); returns the sum."""
    total = 0.0
    for e in range(well.size):
        out[e] = nu_j * math.exp(-depth[e] * inv_temperature) if well[e] >= 0 else 0.0
        total += out[e]
    return total


def sample_with_redraws(law, epsy, base, offset, well, depth, scale, glass_temperature, nu_j, inv_temperature,
                        idx, eps, deps, dV, allowed, beta, nu, speed, duration, state, inc):
    """The next event after now (drive offset 0), with the junction redraws before it applied (module docstring).

    Calls :func:`redraw_loop` until it returns an event; between calls Python handles signals.

    Parameters
    ----------
    law, idx, eps, deps, dV, allowed, beta, nu, speed, duration, state, inc
        As :func:`.sampler.sample_event` (``eps`` the strain now, ``duration`` to the end of the
        stretch of the schedule).
    epsy : numpy.ndarray
        [ni, ny] a copy of the yield strains the backend holds (the junctions' widening included);
        redraws before the event are applied to it.
    base : numpy.ndarray
        [ni, ny] the held window without junctions (:class:`..yield_strains.HeldYieldStrains`).
    offset : numpy.ndarray
        int64 [ni] its global index of ``base[:, 0]``.
    well, depth : numpy.ndarray
        The junctions (:class:`.junctions.Junctions`), changed in place by the redraws before the event.
    scale : float
        Widening per unit depth [strain].
    glass_temperature : float
        ``T_g`` [G eps0^2 h^2].
    nu_j : float
        Junction attempt rate [1/time].
    inv_temperature : float
        ``1 / T`` [1 / (G eps0^2 h^2)].

    Returns
    -------
    kind : int
        :data:`.sampler.NONE` (the stretch ended), ``HOP``, ``THRESHOLD`` or :data:`REDRAW`.
    block, direction : int
        The hop's, or the block of a :data:`REDRAW` (direction -1); -1 otherwise.
    dt : float
        Time from now to the event [time].
    ds : float
        Drive offset of the event [response units]; for ``THRESHOLD`` that of the last redraw before it
        (0 if none), where every Gauss point is inside its well, from which the load step to the brink is made.
    redraws : int
        Redraws applied before the event.
    new_depth : float
        A :data:`REDRAW`'s new depth (not applied), else NaN.

    Raises
    ------
    stickslip.fem.errors.SolverError
        If the redraws before the event exceed :func:`redraw_bound`, or a draw of the hops gave up
        (:func:`.sampler.stalled_error`); the message names the parameters.
    """
    thresholds = np.empty(idx.shape[0])
    block_thresholds(epsy, idx, eps, deps, thresholds)
    horizon = min(duration, thresholds.min() / speed) if speed > 0.0 else duration
    bound = redraw_bound(idx.shape[0], nu_j, 1.0 / inv_temperature, glass_temperature, horizon)
    t, ds, redraws = 0.0, 0.0, 0
    while True:
        kind, block, direction, t, ds, redraws, new_depth = redraw_loop(
            law, epsy, base, offset, well, depth, scale, glass_temperature, nu_j, inv_temperature, idx, eps, deps, dV,
            allowed, beta, nu, speed, duration, state, inc, t, ds, redraws, REDRAWS_PER_CALL)
        if kind == STALLED:
            raise stalled_error(beta, nu, speed)
        if kind != PAUSED:
            return kind, block, direction, t, ds, redraws, new_depth
        if redraws > bound:
            T = 1.0 / inv_temperature
            expected = expected_redraws(nu_j, T, glass_temperature, horizon)
            raise SolverError(f"junction aging: {redraws} junction redraws before the next event, more than "
                              f"{REDRAW_MARGIN:g} times the trap model's {expected:.3g} per block "
                              f"({idx.shape[0]} blocks) over the {horizon:.3g} time to the athermal threshold "
                              f"or the end of the stretch (temperature = {T:g}, junction_glass_temperature = "
                              f"{glass_temperature:g}, junction_attempt_rate = {nu_j:g}); expected a glass temperature "
                              "well above the temperature or a lower junction_attempt_rate (docs/fem.md, "
                              "'Junction aging')")


def redraw_bound(blocks, attempt_rate, temperature, glass_temperature, duration):
    """The most redraws :func:`sample_with_redraws` applies before one event (``REDRAW_MARGIN blocks n``, at least
    :data:`REDRAW_FLOOR`).

    Parameters
    ----------
    blocks : int
        Interface blocks.
    attempt_rate, temperature, glass_temperature, duration
        As :func:`..trap_model.expected_redraws` (``n``); ``duration`` the time to the athermal threshold or
        the end of the stretch [time].

    Returns
    -------
    float
        ``inf`` for an infinite duration (a hold without end: tests only).
    """
    return max(REDRAW_FLOOR, REDRAW_MARGIN * blocks * expected_redraws(attempt_rate, temperature, glass_temperature,
                                                                        duration))


@njit
def block_thresholds(epsy, idx, eps, deps, out):
    """``out[e]`` = :func:`block_threshold` of every block ``e``."""
    for e in range(idx.shape[0]):
        out[e] = block_threshold(epsy, idx, eps, deps, e)


@njit
def redraw_loop(law, epsy, base, offset, well, depth, scale, glass_temperature, nu_j, inv_temperature, idx, eps, deps,
                dV, allowed, beta, nu, speed, duration, state, inc, t, ds, redraws, chunk):
    """The compiled loop of :func:`sample_with_redraws`, from time ``t`` and offset ``ds`` after ``redraws`` redraws.

    Parameters
    ----------
    law, epsy, ..., inc
        As :func:`sample_with_redraws`.
    t, ds : float
        Time [time] and drive offset [response units] reached (0 at the first call).
    redraws : int
        Redraws applied so far.
    chunk : int
        Return :data:`PAUSED` after this many more redraws.

    Returns
    -------
    tuple
        As :func:`sample_with_redraws`; kind :data:`PAUSED` with the time and offset reached (call again from
        there) or :data:`.sampler.STALLED`.
    """
    ni = idx.shape[0]
    thresholds = np.empty(ni)
    block_thresholds(epsy, idx, eps, deps, thresholds)
    rates = np.empty(ni)
    total = _redraw_rates(well, depth, inv_temperature, nu_j, rates)
    stop = redraws + chunk
    while True:
        ds_c = thresholds.min()
        if speed > 0.0 and ds_c <= ds:
            return THRESHOLD, -1, -1, t, ds, redraws, math.nan
        tau = exponential(state, inc) / total if total > 0.0 else math.inf
        stretch = min(duration - t, tau)
        kind, e, d, dt = draw_event(law, epsy, idx, eps, deps, dV, allowed, beta, nu, ds, speed, stretch, ds_c,
                                    state, inc)
        if kind == STALLED:
            return STALLED, -1, -1, t + dt, ds, redraws, math.nan
        if kind == HOP:
            return HOP, e, d, t + dt, ds + speed * dt, redraws, math.nan
        if kind == THRESHOLD:
            return THRESHOLD, -1, -1, t + dt, ds, redraws, math.nan
        if tau >= duration - t:
            return NONE, -1, -1, duration, ds + speed * (duration - t), redraws, math.nan
        t += tau
        ds += speed * tau
        target = uniform(state, inc) * total
        b, cumulative = -1, 0.0
        for e in range(ni):
            if rates[e] > 0.0:
                b = e
                cumulative += rates[e]
                if target < cumulative:
                    break
        new_depth = glass_temperature * exponential(state, inc)
        j = well[b] - offset[b]
        lo, hi = epsy[b, j], epsy[b, j + 1]
        w = widening(base[b], j, new_depth, scale)
        epsy[b, j], epsy[b, j + 1] = base[b, j] - w, base[b, j + 1] + w
        if _outside(epsy, idx, eps, deps, b, ds):
            epsy[b, j], epsy[b, j + 1] = lo, hi
            return REDRAW, b, -1, t, ds, redraws, new_depth
        depth[b] = new_depth
        redraws += 1
        total = _redraw_rates(well, depth, inv_temperature, nu_j, rates)
        thresholds[b] = block_threshold(epsy, idx, eps, deps, b)
        if redraws >= stop:
            return PAUSED, -1, -1, t, ds, redraws, math.nan
