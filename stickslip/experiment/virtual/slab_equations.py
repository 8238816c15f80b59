"""Right-hand side and Jacobian of the slab equations (:mod:`.slab_dynamics`), compiled.

State ``y = [R, mu, psi, gamma]`` (3 m + 1 values for m slippable interfaces): slips [mm], friction
coefficients, ``psi = ln(V0 theta/D_c)``, lever rotation [rad]. The friction is the regularised
Dieterich–Ruina law (Rice & Ben-Zion 1996), odd in the slip rate ``V`` so that an interface may also
slide backwards, written for the slip rate at a given friction::

    V = w sinh(mu / a),        w = 2 V0 exp(-(mu0 + b psi) / a)

(``mu = mu0 + a ln(V/V0) + b psi`` to within ``exp(-2 (mu0 + b psi)/a)`` < 1e-20 for ``V > 0``).
Newton's law for the bodies, ``dV/dt = acc = drive gamma - stiffness R - coupling mu`` (the spring and
friction forces on the bodies turned into relative accelerations of the interfaces [mm/s^2], ``A = D
M^-1`` times the force matrices, see :class:`.slab_dynamics.SlabDynamics`), becomes an equation for
``mu`` through ``dV/dt = dV/dmu dmu/dt + dV/dpsi dpsi/dt + dV/dR dR/dt``::

    dR/dt = V
    dmu/dt = (a acc + V (b dpsi/dt + mu0'(R) V)) / W          W = w cosh(mu / a) = a dV/dmu
    dpsi/dt = (V0 exp(-psi) - |V|) / D_c                       (aging law; slip law: -|V| (ln(|V|/V0) + psi) / D_c)
    dgamma/dt = rate

Why the friction and not the slip rate is the state: deep in a stick (``V`` ~ 1e-17 to 1e-13 mm/s)
the interface's equation of motion is stiff at ~1e17 /s and its slip rate is slaved to the force
balance ``acc = 0``. That balance is linear in ``mu`` (and in ``R``, ``gamma``), so the linearly
implicit stages of a Rosenbrock method land on it exactly; in ``V`` it is logarithmic
(``mu = a asinh(V/w)``), and the stages missed it by ~20 % of ``V`` whatever the step (the RODAS4
-> ROS2 fallback of issue 12). A slip rate through zero is ``mu`` through zero, where ``V`` is linear
in ``mu``; the arrest of a slip is a finite change of ``mu``, not ~30 e-folds of ``V``.

``mu0`` may vary along the slip path, ``mu0_k(R_k)`` (:mod:`.slip_path`), so that the slip rate
also depends on the slip ``R``. ``V`` and ``W`` are computed from ``exp((±|mu| - mu0 - b psi)/a)``,
which neither overflows nor underflows at the values a run reaches.

The arguments after ``y`` are the same for every function here (``rate, drive, stiffness, coupling,
mu0, a, b, D_c, V0, path, slip_law``, see :func:`rhs`), so that the integrator passes one tuple to all of them.
The aging law's expressions are those of the runs before the slip law was added, operation for operation (the same
bits); the slip law's are separate (:func:`slip_law_state_rate`).
"""

import math

import numpy as np

from ...numba_options import njit
from .slip_path import level

__all__ = ["rhs", "rhs_into", "jacobian", "jacobian_into", "slip_rate", "slip_rates", "slip_law_state_rate"]


@njit
def slip_rate(mu, psi, mu0, a, b, V0):
    """Slip rate ``V`` [mm/s] of one interface at friction ``mu``, state ``psi`` and level ``mu0``
    (scalars), and ``W = w cosh(mu / a) = a dV/dmu`` [mm/s] (> 0)."""
    level_psi = mu0 + b * psi
    up = math.exp((abs(mu) - level_psi) / a)
    down = math.exp((-abs(mu) - level_psi) / a)
    V = V0 * (up - down)
    return (V if mu >= 0.0 else -V), V0 * (up + down)


@njit
def slip_law_state_rate(V, W, psi, a, b, D_c, V0, lam):
    """The slip law's ``dpsi/dt = -|V| (x) / D_c``, ``x = ln(|V| / V0) + psi = ln(V theta / D_c)``, and its
    derivatives in ``mu``, ``psi`` and ``R`` through ``V`` (``dV/dmu = W/a``, ``dV/dpsi = -b V/a``, ``dV/dR =
    -lam V/a``; at ``V = 0`` all four are 0: the state stays at rest).

    Returns
    -------
    tuple[float, float, float, float]
        ``dpsi/dt`` [1/s] and its derivatives in ``mu`` [1/s], ``psi`` [1/s] and ``R`` [1/(s mm)].
    """
    if V == 0.0:
        return 0.0, 0.0, 0.0, 0.0
    speed = abs(V)
    x = math.log(speed / V0) + psi
    by_speed = -(x + 1.0) / D_c              # d(dpsi/dt)/d|V| at fixed psi
    sign = 1.0 if V > 0.0 else -1.0
    return (-speed * x / D_c, by_speed * sign * W / a, -speed / D_c - by_speed * b * speed / a,
            -by_speed * lam * speed / a)


@njit
def slip_rates(R, mu, psi, mu0, a, b, V0, path):
    """Slip rates [mm/s] at slips ``R`` [mm], friction coefficients ``mu`` and states ``psi``, all
    float64 [k, m] (one row per time, one column per interface), with the parameters ``mu0, a, b``
    [m], ``V0`` and the slip ``path`` (:func:`.slip_path.slip_path`); returns [k, m]."""
    V = np.empty(mu.shape)
    for row in range(mu.shape[0]):
        for k in range(mu.shape[1]):
            level_k, _, _ = level(k, R[row, k], mu0, path)
            V[row, k], _ = slip_rate(mu[row, k], psi[row, k], level_k, a[k], b[k], V0)
    return V


@njit
def rhs_into(y, out, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law):
    """dy/dt written into ``out`` (float64 [3 m + 1]; no allocation); arguments of :func:`rhs`."""
    m = mu0.size
    gamma = y[3 * m]
    for k in range(m):                     # out[:m] holds V, out[2m:3m] dpsi/dt
        level_k, level_slope, _ = level(k, y[k], mu0, path)
        V, W = slip_rate(y[m + k], y[2 * m + k], level_k, a[k], b[k], V0)
        out[k] = V
        if slip_law:
            out[2 * m + k] = slip_law_state_rate(V, W, y[2 * m + k], a[k], b[k], D_c[k], V0, level_slope)[0]
        else:
            out[2 * m + k] = (V0 * math.exp(-y[2 * m + k]) - abs(V)) / D_c[k]
        acceleration = drive[k] * gamma
        for j in range(m):
            acceleration -= stiffness[k, j] * y[j] + coupling[k, j] * y[m + j]
        out[m + k] = (a[k] * acceleration + V * (b[k] * out[2 * m + k] + level_slope * V)) / W
    out[3 * m] = rate


@njit
def rhs(y, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law):
    """dy/dt, float64 [3 m + 1].

    Parameters
    ----------
    y : numpy.ndarray
        State ``[R, mu, psi, gamma]`` [3 m + 1].
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
    slip_law : bool
        The state evolves by the slip law (True) or the aging law (False) on every interface
        (:mod:`.rate_state`).
    """
    out = np.empty(y.size)
    rhs_into(y, out, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law)
    return out


@njit
def jacobian_into(y, J, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law):
    """d(dy/dt)/dy written into ``J`` (float64 [3 m + 1, 3 m + 1], overwritten); arguments of :func:`rhs`.

    With ``s = a / W``, ``tau = V / W = tanh(mu / a)``, ``lam = mu0'(R)``, ``Q = b dpsi/dt + lam V``,
    ``dmu/dt = s acc + tau Q``: ``dV/dmu = W/a``, ``dV/dpsi = -b V/a``, ``dV/dR = -lam V/a``,
    ``ds/dmu = -tau/W``, ``ds/dpsi = b s/a``, ``ds/dR = lam s/a``, ``dtau/dmu = (1 - tau^2)/a``.
    """
    m = mu0.size
    gamma = y[3 * m]
    J[:, :] = 0.0
    for k in range(m):
        level_k, lam, curvature = level(k, y[k], mu0, path)
        mu, psi = y[m + k], y[2 * m + k]
        V, W = slip_rate(mu, psi, level_k, a[k], b[k], V0)
        ak, bk, Dk = a[k], b[k], D_c[k]
        s = ak / W
        tau = V / W
        sech2 = (2.0 * V0 * math.exp(-(level_k + bk * psi) / ak) / W) ** 2      # 1 - tau^2
        sign = 1.0 if V > 0.0 else (-1.0 if V < 0.0 else 0.0)
        if slip_law:
            psi_rate, psi_by_mu, psi_by_psi, psi_by_R = slip_law_state_rate(V, W, psi, ak, bk, Dk, V0, lam)
        else:
            aging = V0 * math.exp(-psi)
            psi_rate = (aging - abs(V)) / Dk
            psi_by_mu = -sign * W / (ak * Dk)
            psi_by_psi = (-aging + bk / ak * abs(V)) / Dk
            psi_by_R = lam / ak * abs(V) / Dk
        Q = bk * psi_rate + lam * V
        acceleration = drive[k] * gamma
        for j in range(m):
            acceleration -= stiffness[k, j] * y[j] + coupling[k, j] * y[m + j]
        # dR/dt = V
        J[k, k] = -lam / ak * V
        J[k, m + k] = W / ak
        J[k, 2 * m + k] = -bk / ak * V
        # dmu/dt = s acc + tau Q
        for j in range(m):
            J[m + k, j] = -s * stiffness[k, j]
            J[m + k, m + j] = -s * coupling[k, j]
        J[m + k, k] += lam / ak * s * acceleration + tau * (bk * psi_by_R + (curvature - lam * lam / ak) * V)
        J[m + k, m + k] += (-tau / W * acceleration + sech2 / ak * Q
                            + tau * (bk * psi_by_mu + lam * W / ak))
        J[m + k, 2 * m + k] = bk / ak * s * acceleration + tau * (bk * psi_by_psi - lam * bk / ak * V)
        J[m + k, 3 * m] = s * drive[k]
        # dpsi/dt
        J[2 * m + k, k] = psi_by_R
        J[2 * m + k, m + k] = psi_by_mu
        J[2 * m + k, 2 * m + k] = psi_by_psi


@njit
def jacobian(y, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law):
    """d(dy/dt)/dy, float64 [3 m + 1, 3 m + 1]; arguments of :func:`rhs`."""
    J = np.empty((y.size, y.size))
    jacobian_into(y, J, rate, drive, stiffness, coupling, mu0, a, b, D_c, V0, path, slip_law)
    return J
