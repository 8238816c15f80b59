"""Barriers of the interface blocks along the drive, and lower bounds of them over a stretch of it.

Between two events the state moves along the linear response (:mod:`..event_driven`): at a
drive offset ``ds`` the strain of a Gauss point is ``eps + ds deps``, every Gauss point staying in
its well up to the athermal threshold. A **block** (an interface element: its four Gauss points
share one yield-strain sequence) hops as a whole; its barrier is the sum over its Gauss points of
the law's constant-load barrier times the point's volume,

``E_forward = sum_q forward_barrier(law, eq_q, lo_q, hi_q) dV_q``,
``E_backward = sum_q backward_barrier(law, eq_q, lo_q, hi_q) dV_q``,

exact for a block strained uniformly with its surroundings held fixed (the cusp:
``G (hi - eq)^2 h^2``). A block with a Gauss point in the first well, which is centred on zero
strain, has no back edge to cross (``E_backward = inf``). Energies are in the model's units
(stress x length^2, per unit thickness).
"""

import math

from ...numba_options import njit
from ..laws import backward_barrier, forward_barrier
from ..materials import equivalent_strain

__all__ = ["FORWARD", "BACKWARD", "block_barriers", "barrier_bounds", "block_barrier"]

#: Index of the forward (towards larger eps_eq) and backward hop in the ``[ni, 2]`` arrays.
FORWARD = 0
BACKWARD = 1


@njit
def _point(law, eq, lo, hi, idx, direction):
    """Constant-load barrier density of one Gauss point [stress]."""
    if direction == FORWARD:
        return forward_barrier(law, eq, lo, hi)
    if idx == 0:
        return math.inf
    return backward_barrier(law, eq, lo, hi)


@njit(inline="always")
def _strain_at(eps, deps, e, q, ds):
    return equivalent_strain(eps[e, q, 0] + ds * deps[e, q, 0], eps[e, q, 1] + ds * deps[e, q, 1],
                             eps[e, q, 2] + ds * deps[e, q, 2])


@njit
def block_barrier(law, epsy, idx, eps, deps, dV, ds, e, direction):
    """Barrier [energy] of block ``e`` in ``direction`` (:data:`FORWARD` or :data:`BACKWARD`) at drive offset ``ds``.

    Parameters
    ----------
    law : tuple
        The interface law (:mod:`..laws`).
    epsy : numpy.ndarray
        [ni, ny] yield strains.
    idx : numpy.ndarray
        int64 [ni, 4] current wells.
    eps, deps : numpy.ndarray
        [ni, 4, 3] interface strain now and of the linear response.
    dV : numpy.ndarray
        [ni, 4] Gauss-point volumes [length^2].
    ds : float
        Drive offset (in units of the linear response).
    e : int
    direction : int

    Returns
    -------
    float
        [stress x length^2].
    """
    total = 0.0
    for q in range(4):
        i = idx[e, q]
        total += _point(law, _strain_at(eps, deps, e, q, ds), epsy[e, i], epsy[e, i + 1], i, direction) * dV[e, q]
    return total


@njit
def block_barriers(law, epsy, idx, eps, deps, dV, ds, out):
    """Barriers of every block in both directions at drive offset ``ds``: ``out`` [ni, 2] [energy] (:func:`block_barrier`)."""
    for e in range(idx.shape[0]):
        for direction in range(2):
            out[e, direction] = block_barrier(law, epsy, idx, eps, deps, dV, ds, e, direction)


@njit
def barrier_bounds(law, epsy, idx, eps, deps, dV, ds_a, ds_b, out):
    """Lower bounds of every block's barriers over the drive offsets ``[ds_a, ds_b]``: ``out`` [ni, 2] [energy].

    Along the drive ``eps_eq^2`` is a convex quadratic of ``ds``, so ``eps_eq`` spans
    ``[eq_min, eq_max]`` over the stretch (the minimum at an end or at the vertex); a barrier
    that is quasi-concave in ``eps_eq`` within a well (monotone for the cusp, rising then falling
    for the smooth law; tested in tests/test_fem_thermal.py) is smallest at one end of that range.
    The block's bound is the sum of its Gauss points' bounds: the rate ``nu exp(-bound / T)``
    bounds the block's rate over the whole stretch, which the exact sampling by thinning needs
    (:mod:`.sampler`).
    """
    for e in range(idx.shape[0]):
        forward = 0.0
        backward = 0.0
        for q in range(4):
            i = idx[e, q]
            lo, hi = epsy[e, i], epsy[e, i + 1]
            et = 0.5 * (eps[e, q, 0] - eps[e, q, 1])
            gt = eps[e, q, 2]
            ed = 0.5 * (deps[e, q, 0] - deps[e, q, 1])
            gd = deps[e, q, 2]
            eq_a = _strain_at(eps, deps, e, q, ds_a)
            eq_b = _strain_at(eps, deps, e, q, ds_b)
            eq_min = min(eq_a, eq_b)
            a = ed * ed + gd * gd
            if a > 0.0:
                vertex = -(et * ed + gt * gd) / a
                if ds_a < vertex < ds_b:
                    eq_min = min(eq_min, _strain_at(eps, deps, e, q, vertex))
            eq_max = max(eq_a, eq_b)
            forward += min(_point(law, eq_min, lo, hi, i, FORWARD), _point(law, eq_max, lo, hi, i, FORWARD)) * dV[e, q]
            backward += min(_point(law, eq_min, lo, hi, i, BACKWARD),
                            _point(law, eq_max, lo, hi, i, BACKWARD)) * dV[e, q]
        out[e, FORWARD] = forward
        out[e, BACKWARD] = backward
