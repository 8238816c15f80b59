"""Right-hand side and Jacobian of the slab equations (:mod:`.slab_dynamics`), compiled.

State ``y = [R, V, psi, gamma]`` (3 m + 1 values for m slippable interfaces): slips [mm], slip
rates [mm/s], ``psi = ln(V0 theta/D_c)``, lever rotation [rad]::

    dR/dt = V
    dV/dt = A (drive gamma - stiffness R - friction_matrix mu)
    dpsi/dt = (V0 exp(-psi) - |V|) / D_c
    dgamma/dt = rate

``A = D M^-1`` turns the net forces on the bodies [N] into relative accelerations of the
interfaces [mm/s^2] (see :class:`.slab_dynamics.SlabDynamics`). The friction is the regularised
Dieterich–Ruina law (Rice & Ben-Zion 1996), odd in ``V`` so that an interface may also slide
backwards::

    mu = a asinh(V / (2 V0) exp((mu0 + b psi) / a))

which equals ``mu0 + a ln(V/V0) + b psi`` to within ``exp(-2 (mu0 + b psi)/a)`` (< 1e-20 here)
for ``V > 0``.
"""

import numpy as np

from ...numba_options import njit

__all__ = ["rhs", "jacobian", "friction"]


@njit
def friction(V, psi, mu0, a, b, V0):
    """Regularised friction coefficient, shape of ``V`` [m]."""
    return a * np.arcsinh(V / (2.0 * V0) * np.exp((mu0 + b * psi) / a))


@njit
def rhs(y, rate, drive, stiffness, accel, friction_matrix, mu0, a, b, D_c, V0):
    """dy/dt, float64 [3 m + 1].

    Parameters
    ----------
    y : numpy.ndarray
        State [3 m + 1].
    rate : float
        d gamma/dt [1/s].
    drive : numpy.ndarray
        Spring force per radian of lever rotation on every body [N], [m].
    stiffness : numpy.ndarray
        Spring force per mm of slip [N/mm], [m, m].
    accel : numpy.ndarray
        ``A``: relative accelerations per body force [mm/s^2/N], [m, m].
    friction_matrix : numpy.ndarray
        Friction forces on the bodies per friction coefficient [N], [m, m].
    mu0, a, b, D_c : numpy.ndarray
        Rate-and-state parameters of the slippable interfaces, [m] (D_c [mm]).
    V0 : float
        Reference slip rate [mm/s].
    """
    m = mu0.size
    R, V, psi, gamma = y[:m], y[m:2 * m], y[2 * m:3 * m], y[3 * m]
    force = drive * gamma - stiffness @ R - friction_matrix @ friction(V, psi, mu0, a, b, V0)
    out = np.empty(3 * m + 1)
    out[:m] = V
    out[m:2 * m] = accel @ force
    out[2 * m:3 * m] = (V0 * np.exp(-psi) - np.abs(V)) / D_c
    out[3 * m] = rate
    return out


@njit
def jacobian(y, rate, drive, stiffness, accel, friction_matrix, mu0, a, b, D_c, V0):
    """d(dy/dt)/dy, float64 [3 m + 1, 3 m + 1]; arguments of :func:`rhs`."""
    m = mu0.size
    V, psi = y[m:2 * m], y[2 * m:3 * m]
    width = 2.0 * V0 * np.exp(-(mu0 + b * psi) / a)    # mu = a asinh(V / width)
    root = np.sqrt(width * width + V * V)
    by_V = a / root                                     # d mu / dV
    by_psi = b * V / root                               # d mu / d psi
    coupling = accel @ friction_matrix
    by_R = accel @ stiffness
    by_gamma = accel @ drive
    J = np.zeros((3 * m + 1, 3 * m + 1))
    for i in range(m):
        J[i, m + i] = 1.0
        for k in range(m):
            J[m + i, k] = -by_R[i, k]
            J[m + i, m + k] = -coupling[i, k] * by_V[k]
            J[m + i, 2 * m + k] = -coupling[i, k] * by_psi[k]
        J[m + i, 3 * m] = by_gamma[i]
        J[2 * m + i, m + i] = -np.sign(V[i]) / D_c[i]
        J[2 * m + i, 2 * m + i] = -V0 / D_c[i] * np.exp(-psi[i])
    return J
