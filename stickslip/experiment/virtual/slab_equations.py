"""Right-hand side and Jacobian of the slab equations (:mod:`.slab_dynamics`), compiled.

State ``y = [R, V, psi, gamma]`` (3 m + 1 values for m slippable interfaces): slips [mm], slip
rates [mm/s], ``psi = ln(V0 theta/D_c)``, lever rotation [rad]::

    dR/dt = V
    dV/dt = drive gamma - stiffness R - coupling mu
    dpsi/dt = (V0 exp(-psi) - |V|) / D_c
    dgamma/dt = rate

``drive``, ``stiffness`` and ``coupling`` are the spring and friction forces on the bodies turned
into relative accelerations of the interfaces [mm/s^2] (``A = D M^-1`` times the force matrices, see
:class:`.slab_dynamics.SlabDynamics`). The friction is the regularised Dieterich–Ruina law (Rice &
Ben-Zion 1996), odd in ``V`` so that an interface may also slide backwards::

    mu = a asinh(V / (2 V0) exp((mu0 + b psi) / a))

which equals ``mu0 + a ln(V/V0) + b psi`` to within ``exp(-2 (mu0 + b psi)/a)`` (< 1e-20 here)
for ``V > 0``. ``mu0`` may vary along the slip path, ``mu0_k(R_k)`` (:mod:`.slip_path`), so that the
friction also depends on the slip ``R``.

The arguments after ``y`` are the same for every function here (``rate, drive, stiffness, coupling,
mu0, a, b, D_c, V0, path``, see :func:`rhs`), so that the integrator passes one tuple to all of them.
"""

import math

import numpy as np

from ...numba_options import njit
from .slip_path import level

__all__ = ["rhs", "rhs_into", "jacobian", "friction", "friction_slopes"]


@njit
def _friction(V, psi, mu0, a, b, V0):
    """Friction coefficient of one interface (scalars)."""
    return a * math.asinh(V / (2.0 * V0) * math.exp((mu0 + b * psi) / a))


@njit
def friction_slopes(V, psi, mu0, a, b, V0):
    """``d mu / dV`` [s/mm], ``d mu / d psi`` and ``d mu / d mu0`` of one interface (scalars)."""
    width = 2.0 * V0 * math.exp(-(mu0 + b * psi) / a)    # mu = a asinh(V / width)
    root = math.sqrt(width * width + V * V)
    return a / root, b * V / root, V / root


@njit
def friction(R, V, psi, mu0, a, b, V0, path):
    """Regularised friction coefficients at slips ``R`` [mm], slip rates ``V`` [mm/s] and states
    ``psi``, all float64 [k, m] (one row per time, one column per interface), with the parameters
    ``mu0, a, b`` [m], ``V0`` and the slip ``path`` (:func:`.slip_path.slip_path`); returns [k, m]."""
    mu = np.empty(V.shape)
    for row in range(V.shape[0]):
        for k in range(V.shape[1]):
            level_k, _ = level(k, R[row, k], mu0, path)
            mu[row, k] = _friction(V[row, k], psi[row, k], level_k, a[k], b[k], V0)
    return mu


@njit
def rhs_into(y, out, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path):
    """dy/dt written into ``out`` (float64 [3 m + 1]; no allocation); arguments of :func:`rhs`."""
    m = mu0.size
    for k in range(m):                     # out[2m:3m] holds mu until the last loop
        level_k, _ = level(k, y[k], mu0, path)
        out[2 * m + k] = _friction(y[m + k], y[2 * m + k], level_k, a[k], b[k], V0)
    gamma = y[3 * m]
    for i in range(m):
        acceleration = drive[i] * gamma
        for k in range(m):
            acceleration -= stiffness[i, k] * y[k] + coupling[i, k] * out[2 * m + k]
        out[m + i] = acceleration
    for i in range(m):
        out[i] = y[m + i]
        out[2 * m + i] = (V0 * math.exp(-y[2 * m + i]) - abs(y[m + i])) / D_c[i]
    out[3 * m] = rate


@njit
def rhs(y, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path):
    """dy/dt, float64 [3 m + 1].

    Parameters
    ----------
    y : numpy.ndarray
        State [3 m + 1].
    rate : float
        d gamma/dt [1/s].
    drive : numpy.ndarray
        Relative accelerations of the interfaces per radian of lever rotation [mm/s^2], [m].
    stiffness : numpy.ndarray
        Relative accelerations per mm of slip [1/s^2], [m, m].
    coupling : numpy.ndarray
        Relative accelerations per unit friction coefficient [mm/s^2], [m, m].
    mu0, a, b, D_c : numpy.ndarray
        Rate-and-state parameters of the slippable interfaces, [m] (D_c [mm]; ``mu0`` at the start
        of the slip path).
    V0 : float
        Reference slip rate [mm/s].
    path : tuple
        Heterogeneity of ``mu0`` along the slip path (:func:`.slip_path.slip_path`;
        :func:`.slip_path.no_path`: none).
    """
    out = np.empty(y.size)
    rhs_into(y, out, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path)
    return out


@njit
def jacobian(y, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path):
    """d(dy/dt)/dy, float64 [3 m + 1, 3 m + 1]; arguments of :func:`rhs`."""
    m = mu0.size
    J = np.zeros((3 * m + 1, 3 * m + 1))
    for k in range(m):
        level_k, level_slope = level(k, y[k], mu0, path)
        by_V, by_psi, by_level = friction_slopes(y[m + k], y[2 * m + k], level_k, a[k], b[k], V0)
        for i in range(m):
            J[m + i, k] = -stiffness[i, k] - coupling[i, k] * by_level * level_slope
            J[m + i, m + k] = -coupling[i, k] * by_V
            J[m + i, 2 * m + k] = -coupling[i, k] * by_psi
        J[k, m + k] = 1.0
        J[m + k, 3 * m] = drive[k]
        J[2 * m + k, m + k] = -np.sign(y[m + k]) / D_c[k]
        J[2 * m + k, 2 * m + k] = -V0 / D_c[k] * math.exp(-y[2 * m + k])
    return J
