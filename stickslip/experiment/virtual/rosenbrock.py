"""A compiled L-stable Rosenbrock method (ROS2) with adaptive steps for the slab equations (:mod:`.slab_equations`).

ROS2 (Verwer, Spee, Blom & Hundsdorfer 1999, SIAM J. Sci. Comput. 20, 1456), for ``dy/dt = f(y)``
with Jacobian ``J``, step ``h``, ``g = 1 + 1/sqrt(2)``::

    (I - g h J) k1 = f(y_n)
    (I - g h J) k2 = f(y_n + h k1) - 2 k1
    y_{n+1} = y_n + h (3 k1 + k2) / 2

second order and L-stable; ``y_n + h k1`` (linearly implicit Euler) is the embedded first-order
solution, so the local error estimate is ``h (k1 + k2) / 2``. The step is accepted when the
root-mean-square of ``error / (atol + rtol |y|)`` is at most 1, and the next one scaled by
``0.9 / sqrt(err)`` (between 0.2 and 5 times).

Why a compiled method instead of ``scipy.integrate.solve_ivp``: the rate-and-state slabs need ~100
steps per slip and ~500 slips per run; scipy's Radau costs ~4 ms a step in Python (measured,
docs/experiment-model-rate-state.md), this ~10 us.
"""

import numpy as np

from ...numba_options import njit
from .slab_equations import jacobian, rhs

__all__ = ["ros2"]

GAMMA = 1.0 + 1.0 / np.sqrt(2.0)


#: First trial step of an integration [s].
FIRST_STEP = 1e-6


@njit
def ros2(y0, t0, h0, t_pause, t_end, args, rtol, atol):
    """Integrate ``dy/dt = rhs(y, *args)`` (:func:`.slab_equations.rhs`) from ``t0`` towards ``t_end``,
    returning after the first accepted step at or beyond ``t_pause``.

    Only ``t_end`` cuts a step short; ``t_pause`` does not, so that integrating in pieces (each call
    starting from the last state, time and next step size of the previous one) accepts exactly the
    same steps, bit for bit, as one call from 0 to ``t_end`` (the caller reports progress between
    the pieces, :meth:`.slab_dynamics.SlabDynamics.integrate`). The right-hand side is called
    directly (not passed as an argument) so that numba caches the compiled integrator on disk.

    Parameters
    ----------
    y0 : numpy.ndarray
        State at ``t0``, float64 [n].
    t0 : float
        Start time.
    h0 : float
        First trial step (> 0; :data:`FIRST_STEP` for a new integration, else the ``h`` returned
        by the previous piece).
    t_pause : float
        Return once an accepted step reaches it (``t0 < t_pause <= t_end``).
    t_end : float
        End time of the whole integration (no step goes beyond it).
    args : tuple
        Arguments of :func:`.slab_equations.rhs` after ``y``.
    rtol : float
    atol : numpy.ndarray
        Relative tolerance, and absolute tolerance per component [n].

    Returns
    -------
    t : numpy.ndarray
        ``t0`` and the accepted step times, float64 [n_steps + 1].
    y : numpy.ndarray
        States, float64 [n_steps + 1, n].
    dydt : numpy.ndarray
        ``rhs`` at those states, float64 [n_steps + 1, n].
    ok : bool
        False if the step size underflowed (the arrays end at the last accepted step).
    h : float
        Trial size of the next step.
    """
    n = y0.size
    capacity = 1024
    ts = np.empty(capacity)
    ys = np.empty((capacity, n))
    fs = np.empty((capacity, n))
    y = y0.copy()
    fy = rhs(y, *args)
    t = t0
    ts[0], ys[0], fs[0] = t, y, fy
    count = 1
    h = min(h0, t_end - t0)
    identity = np.eye(n)
    while t < t_pause:
        if h < 1e-14 * max(1.0, t):
            return ts[:count], ys[:count], fs[:count], False, h
        h = min(h, t_end - t)
        J = jacobian(y, *args)
        matrix = identity - GAMMA * h * J
        k1 = np.linalg.solve(matrix, fy)
        k2 = np.linalg.solve(matrix, rhs(y + h * k1, *args) - 2.0 * k1)
        y_new = y + h * (1.5 * k1 + 0.5 * k2)
        scale = atol + rtol * np.maximum(np.abs(y), np.abs(y_new))
        error = np.sqrt(np.mean((0.5 * h * (k1 + k2) / scale) ** 2))
        if not np.isfinite(error):
            h *= 0.2
            continue
        factor = min(5.0, max(0.2, 0.9 / np.sqrt(max(error, 1e-12))))
        if error > 1.0:
            h *= min(factor, 0.9)
            continue
        t = t + h if t_end - t > h else t_end
        y = y_new
        fy = rhs(y, *args)
        if count == capacity:
            capacity *= 2
            ts_new, ys_new, fs_new = np.empty(capacity), np.empty((capacity, n)), np.empty((capacity, n))
            ts_new[:count], ys_new[:count], fs_new[:count] = ts[:count], ys[:count], fs[:count]
            ts, ys, fs = ts_new, ys_new, fs_new
        ts[count], ys[count], fs[count] = t, y, fy
        count += 1
        h *= factor
    return ts[:count], ys[:count], fs[:count], True, h
