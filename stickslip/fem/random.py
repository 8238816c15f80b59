"""The pcg32 random-number generator (O'Neill's PCG-XSH-RR 64/32), bit for bit.

Written from the published algorithm (M. E. O'Neill, "PCG: A family of simple
fast space-efficient statistically good algorithms for random number
generation", 2014; reference implementation ``pcg32_srandom_r`` /
``pcg32_random_r``), with the conversions of the paper's code (prrng v1.0):

- seeding with ``(initstate, initseq)``: ``state = 0``, ``inc = (initseq << 1) | 1``,
  one step, ``state += initstate``, one step;
- one step: ``old = state``; ``state = old * 6364136223846793005 + inc`` (mod 2^64);
  output ``rotr32(((old >> 18) ^ old) >> 27, old >> 59)``;
- uniform double in [0, 1): ``r = u32 / 2^32``;
- Weibull(k, scale) variate: ``scale * (-log(1 - r)) ** (1 / k)``.

One independent generator per row (one per interface element in the model);
row ``i`` holds the first ``ncol`` draws of generator ``(initstate[i], initseq[i])``.
"""

import numpy as np

from ..numba_options import njit

__all__ = ["pcg32_seed", "pcg32_next", "pcg32_uint32", "pcg32_uniform"]

_MULTIPLIER = np.uint64(6364136223846793005)
_ONE = np.uint64(1)
_MASK32 = np.uint64(0xFFFFFFFF)


@njit
def _step(state, inc):
    """Advance the 64-bit state once; return (new state, 32-bit output as uint64)."""
    old = state
    state = old * _MULTIPLIER + inc
    xorshifted = (((old >> np.uint64(18)) ^ old) >> np.uint64(27)) & _MASK32
    rot = old >> np.uint64(59)
    out = ((xorshifted >> rot) | (xorshifted << ((np.uint64(32) - rot) & np.uint64(31)))) & _MASK32
    return state, out


@njit
def _seed(initstate, initseq):
    inc = (np.uint64(initseq) << _ONE) | _ONE
    state, _ = _step(np.uint64(0), inc)
    state = state + np.uint64(initstate)
    state, _ = _step(state, inc)
    return state, inc


@njit
def pcg32_seed(initstate, initseq):
    """Seeded generators, one per row, ready to draw.

    Parameters
    ----------
    initstate, initseq : numpy.ndarray
        uint64 [nrow]: seeds of each generator.

    Returns
    -------
    state, inc : numpy.ndarray
        uint64 [nrow]: the generators' 64-bit states and increments (``pcg32_next`` advances ``state``).
    """
    state = np.empty(initstate.size, dtype=np.uint64)
    inc = np.empty(initstate.size, dtype=np.uint64)
    for i in range(initstate.size):
        state[i], inc[i] = _seed(initstate[i], initseq[i])
    return state, inc


@njit
def pcg32_next(state, inc, row):
    """Next 32-bit output (as uint64) of generator ``row``; advances ``state[row]`` in place."""
    state[row], out = _step(state[row], inc[row])
    return out


@njit
def pcg32_uint32(initstate, initseq, ncol):
    """Raw 32-bit outputs of one generator per row.

    Parameters
    ----------
    initstate, initseq : numpy.ndarray
        uint64 [nrow]: seeds of each generator.
    ncol : int
        Draws per generator.

    Returns
    -------
    numpy.ndarray
        uint64 [nrow, ncol], values in [0, 2^32).
    """
    out = np.empty((initstate.size, ncol), dtype=np.uint64)
    for i in range(initstate.size):
        state, inc = _seed(initstate[i], initseq[i])
        for j in range(ncol):
            state, out[i, j] = _step(state, inc)
    return out


def _as_seeds(initstate, initseq):
    initstate = np.atleast_1d(np.asarray(initstate)).astype(np.uint64)
    initseq = np.broadcast_to(np.asarray(initseq).astype(np.uint64), initstate.shape).copy()
    return initstate, initseq


def pcg32_uniform(initstate, initseq, ncol):
    """Uniform doubles in [0, 1), one generator per row: ``u32 / 2**32``.

    Parameters
    ----------
    initstate : array_like of int
        [nrow] seeds (state).
    initseq : array_like of int
        [nrow] (or scalar) seeds (sequence).
    ncol : int
        Draws per generator.

    Returns
    -------
    numpy.ndarray
        float64 [nrow, ncol].
    """
    initstate, initseq = _as_seeds(initstate, initseq)
    return pcg32_uint32(initstate, initseq, int(ncol)).astype(np.float64) / 2.0**32

