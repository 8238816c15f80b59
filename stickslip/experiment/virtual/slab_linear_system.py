"""The linear systems ``(I - c J) u = r`` of an implicit step on the slab equations, solved by their block structure.

``J`` is the Jacobian of :mod:`.slab_equations` (state ``[R, V, psi, gamma]``, 3 m + 1 values)::

    J = | 0    I             0              0     |       s_k = -sign(V_k) / D_c,k
        | -P'  -C diag(mu_V)  -C diag(mu_psi)  q  |       d_k = -V0 exp(-psi_k) / D_c,k
        | 0    diag(s)       diag(d)        0     |       mu_V, mu_psi, mu_R: slopes of the friction
        | 0    0             0              0     |

(``P' = P + C diag(mu_R)``, ``P`` = stiffness, ``C`` = coupling, ``q`` = drive; ``mu_R`` is the slope
along the slip path, :mod:`.slip_path`, 0 without heterogeneity). Eliminating the slips, the states and the
rotation leaves an m x m system for the slip rates (the Schur complement)::

    u_gamma = r_gamma
    [I + c^2 P' + c C diag(mu_V + c mu_psi s / (1 - c d))] u_V
        = r_V - c P' r_R - c C diag(mu_psi / (1 - c d)) r_psi + c q r_gamma
    u_R = r_R + c u_V
    u_psi = (r_psi + c s u_V) / (1 - c d)

which is exact algebra (``1 - c d >= 1``). The m x m matrix is factorised once per step (LU with
partial pivoting, m <= n_slabs) and the factors serve every stage of the Rosenbrock step: a
factorisation costs ~m^3/3 and a solve ~m^2 operations, against ~(3 m + 1)^3/3 and a copy for a
dense LAPACK solve of the whole system (:mod:`.rosenbrock`; measured in docs/benchmarks.md).
"""

import numpy as np

from ...numba_options import njit
from .slab_equations import friction_slopes
from .slip_path import level

__all__ = ["new_factors", "factorize", "solve"]


@njit
def new_factors(m):
    """Work arrays of the factorisation for ``m`` interfaces: ``lu`` float64 [m, m], ``pivot`` int64
    [m], ``diagonals`` float64 [4, m] (``mu_psi / (1 - c d)``, ``s``, ``1 / (1 - c d)``, ``mu_R``)."""
    return np.empty((m, m)), np.zeros(m, dtype=np.int64), np.empty((4, m))


@njit
def factorize(y, c, factors, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path):
    """Factorise ``I - c J(y)`` into ``factors`` (from :func:`new_factors`), for :func:`solve`.

    Parameters
    ----------
    y : numpy.ndarray
        State at which the Jacobian is taken, [3 m + 1].
    c : float
        ``gamma h`` of the Rosenbrock step [s].
    factors : tuple
        Work arrays, overwritten.
    rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path
        Arguments of :func:`.slab_equations.rhs`.
    """
    lu, pivot, diagonals = factors
    m = mu0.size
    for k in range(m):
        level_k, level_slope = level(k, y[k], mu0, path)
        by_V, by_psi, by_level = friction_slopes(y[m + k], y[2 * m + k], level_k, a[k], b[k], V0)
        by_R = by_level * level_slope
        s = -np.sign(y[m + k]) / D_c[k]
        inverse = 1.0 / (1.0 + c * V0 / D_c[k] * np.exp(-y[2 * m + k]))   # 1 / (1 - c d)
        diagonals[0, k] = by_psi * inverse
        diagonals[1, k] = s
        diagonals[2, k] = inverse
        diagonals[3, k] = by_R
        weight = by_V + c * by_psi * s * inverse
        for i in range(m):
            lu[i, k] = c * c * (stiffness[i, k] + coupling[i, k] * by_R) + c * coupling[i, k] * weight
        lu[k, k] += 1.0
    for j in range(m):                     # LU with partial pivoting, in place
        best = j
        for i in range(j + 1, m):
            if abs(lu[i, j]) > abs(lu[best, j]):
                best = i
        pivot[j] = best
        if best != j:
            for k in range(m):
                lu[j, k], lu[best, k] = lu[best, k], lu[j, k]
        for i in range(j + 1, m):
            lu[i, j] /= lu[j, j]
            for k in range(j + 1, m):
                lu[i, k] -= lu[i, j] * lu[j, k]


@njit
def solve(r, u, c, factors, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path):
    """Solve ``(I - c J) u = r`` with the factors of :func:`factorize` (same ``c``); ``r`` and ``u``
    float64 [3 m + 1] (distinct arrays); returns None."""
    lu, pivot, diagonals = factors
    m = mu0.size
    for i in range(m):                     # the reduced right-hand side, into u_V
        total = r[m + i] + c * drive[i] * r[3 * m]
        for k in range(m):
            total -= c * ((stiffness[i, k] + coupling[i, k] * diagonals[3, k]) * r[k]
                          + coupling[i, k] * diagonals[0, k] * r[2 * m + k])
        u[m + i] = total
    for j in range(m):                     # the factorisation's row swaps, in order
        best = pivot[j]
        if best != j:
            u[m + j], u[m + best] = u[m + best], u[m + j]
    for j in range(m):                     # forward substitution (unit lower triangle)
        for i in range(j + 1, m):
            u[m + i] -= lu[i, j] * u[m + j]
    for i in range(m - 1, -1, -1):         # back substitution
        total = u[m + i]
        for k in range(i + 1, m):
            total -= lu[i, k] * u[m + k]
        u[m + i] = total / lu[i, i]
    for k in range(m):
        u[k] = r[k] + c * u[m + k]
        u[2 * m + k] = (r[2 * m + k] + c * diagonals[1, k] * u[m + k]) * diagonals[2, k]
    u[3 * m] = r[3 * m]
