"""The linear systems ``(I - c J) u = r`` of an implicit step on the slab equations.

``J`` is the Jacobian of :mod:`.slab_equations` (state ``[R, mu, psi, gamma]``, 3 m + 1 <= 16 values).
Its rows of ``dmu/dt`` carry ``a / W`` times the springs and the friction coupling, with ``W`` ~ the
slip rate: ~1e19 /s deep in a stick against ~1 in the other rows. So the matrix is equilibrated
(each row divided by its largest entry, the right-hand side with it) before an LU factorisation with
partial pivoting; without that, the pivots come from the huge rows and the rounding errors they carry
(~1e-16 of 1e19) swamp the other rows.

Why dense and not by blocks: eliminating a slip and a state per interface first (the rows of ``R``
and ``psi`` are diagonal) divides by ``1 - c dpsi'/dpsi``, which passes through zero while a slip
accelerates (``dpsi'/dpsi = (b |V| / a - V0 exp(-psi)) / D_c > 0`` at fixed ``mu``); pivoting over
the whole matrix has no such point. At m <= 5 the factorisation costs ~(3 m + 1)^3 / 3 ~ 1400
multiply-adds per step and each of the stages' solves ~(3 m + 1)^2 (measured in
docs/experiment-model-rate-state.md).
"""

import numpy as np

from ...numba_options import njit
from .slab_equations import jacobian_into

__all__ = ["new_factors", "factorize", "solve"]


@njit
def new_factors(n):
    """Work arrays of the factorisation of an ``n`` x ``n`` system: ``lu`` float64 [n, n], ``pivot``
    int64 [n], ``scale`` float64 [n] (the rows' equilibration factors)."""
    return np.empty((n, n)), np.zeros(n, dtype=np.int64), np.empty(n)


@njit
def factorize(y, c, factors, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law):
    """Factorise ``I - c J(y)`` into ``factors`` (from :func:`new_factors`), for :func:`solve`.

    Parameters
    ----------
    y : numpy.ndarray
        State at which the Jacobian is taken, [3 m + 1].
    c : float
        ``gamma h`` of the Rosenbrock step [s].
    factors : tuple
        Work arrays, overwritten.
    rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law
        Arguments of :func:`.slab_equations.rhs`.
    """
    lu, pivot, scale = factors
    n = y.size
    jacobian_into(y, lu, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law)
    for i in range(n):
        largest = 0.0
        for k in range(n):
            lu[i, k] *= -c
            if k == i:
                lu[i, k] += 1.0
            largest = max(largest, abs(lu[i, k]))
        scale[i] = 1.0 / largest
        for k in range(n):
            lu[i, k] *= scale[i]
    for j in range(n):                     # LU with partial pivoting, in place
        best = j
        for i in range(j + 1, n):
            if abs(lu[i, j]) > abs(lu[best, j]):
                best = i
        pivot[j] = best
        if best != j:
            for k in range(n):
                lu[j, k], lu[best, k] = lu[best, k], lu[j, k]
        if lu[j, j] == 0.0:
            continue                       # singular: solve returns inf/nan, and the step is rejected
        for i in range(j + 1, n):
            factor = lu[i, j] / lu[j, j]
            lu[i, j] = factor
            if factor != 0.0:
                for k in range(j + 1, n):
                    lu[i, k] -= factor * lu[j, k]


@njit
def solve(r, u, c, factors, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law):
    """Solve ``(I - c J) u = r`` with the factors of :func:`factorize` (same ``c``); ``r`` and ``u``
    float64 [3 m + 1] (distinct arrays); returns None."""
    lu, pivot, scale = factors
    n = r.size
    for i in range(n):
        u[i] = r[i] * scale[i]
    for j in range(n):                     # the factorisation's row swaps, in order
        best = pivot[j]
        if best != j:
            u[j], u[best] = u[best], u[j]
    for j in range(n):                     # forward substitution (unit lower triangle)
        if u[j] != 0.0:
            for i in range(j + 1, n):
                u[i] -= lu[i, j] * u[j]
    for i in range(n - 1, -1, -1):         # back substitution
        total = u[i]
        for k in range(i + 1, n):
            total -= lu[i, k] * u[k]
        u[i] = total / lu[i, i]
