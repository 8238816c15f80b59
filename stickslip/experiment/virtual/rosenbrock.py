"""Compiled L-stable Rosenbrock methods with adaptive steps for the slab equations (:mod:`.slab_equations`).

A Rosenbrock method of ``s`` stages in the form of Hairer & Wanner (*Solving Ordinary Differential
Equations II*, 2nd ed., 1996, Sec. IV.7, Eq. (7.25)), for the autonomous ``dy/dt = f(y)`` with
Jacobian ``J`` and step ``h``::

    (I - gamma h J) u_i = gamma h f(y_n + sum_{j<i} alpha_ij u_j) + gamma sum_{j<i} Gamma_ij u_j
    y_{n+1} = y_n + sum_i m_i u_i,        error = sum_i e_i u_i

with one matrix ``I - gamma h J`` for all stages, factorised once per step
(:mod:`.slab_linear_system`). The step is accepted when the root-mean-square of
``error / (atol + rtol max(|y_n|, |y_{n+1}|))`` (``atol`` and ``rtol`` per component) is at most 1, and the next one
is scaled by ``0.9 err^(-1/q)`` (between 0.2 and 5 times; ``q`` = order of the embedded solution + 1).

The methods (:data:`TABLEAUX`):

- ``ROS2`` (Verwer, Spee, Blom & Hundsdorfer 1999, SIAM J. Sci. Comput. 20, 1456): 2 stages, order 2,
  L-stable, ``gamma = 1 + 1/sqrt(2)``; embedded: the linearly implicit Euler step (order 1). The
  first session's method of issue 12.
- ``RODAS4`` (Hairer & Wanner 1996, Sec. VI.4, the coefficients of their code RODAS): 6 stages,
  order 4 with an embedded order 3, L-stable and stiffly accurate, ``gamma = 1/4``; the error is
  the last stage ``u_6``.

Why compiled methods instead of ``scipy.integrate.solve_ivp``: the rate-and-state slabs need ~100
steps per slip and ~500 slips per run; scipy's Radau costs ~4 ms a step in Python (measured,
docs/experiment-model-rate-state.md), these a few microseconds.
"""

import dataclasses
import math

import numpy as np

from ...numba_options import njit
from .slab_equations import rhs_into
from .slab_linear_system import factorize, new_factors, solve

__all__ = ["Tableau", "TABLEAUX", "FIRST_STEP", "MIN_STEP", "START", "step", "integrate"]

#: First trial step of an integration [s].
FIRST_STEP = 1e-6
#: Smallest step [s]: a step size below it is an underflow (the integration fails).
MIN_STEP = 1e-18
#: The carried step control of a new integration (``h0`` of :func:`integrate`).
START = (FIRST_STEP, 0.0, 1.0, 0.0)


@dataclasses.dataclass(frozen=True)
class Tableau:
    """Coefficients of a Rosenbrock method in Hairer & Wanner's form (module docstring).

    Attributes
    ----------
    gamma : float
    alpha, Gamma : numpy.ndarray
        Strictly lower triangular, float64 [s, s].
    weights, error_weights : numpy.ndarray
        ``m`` and ``e``, float64 [s].
    order : int
        Order of the method.
    error_order : int
        ``q``: the local error estimate is ``O(h^q)``.
    """

    gamma: float
    alpha: np.ndarray
    Gamma: np.ndarray
    weights: np.ndarray
    error_weights: np.ndarray
    order: int
    error_order: int

    def arrays(self):
        """The arguments of :func:`step` and :func:`integrate` that describe the method."""
        return self.gamma, self.alpha, self.Gamma, self.weights, self.error_weights, 1.0 / self.error_order


def _ros2():
    gamma = 1.0 + 1.0 / math.sqrt(2.0)
    # (I - gamma h J) k1 = f(y), (I - gamma h J) k2 = f(y + h k1) - 2 k1, y1 = y + h (3 k1 + k2) / 2,
    # error h (k1 + k2) / 2; with u_i = gamma h k_i:
    return Tableau(gamma=gamma, alpha=np.array([[0.0, 0.0], [1.0 / gamma, 0.0]]),
                   Gamma=np.array([[0.0, 0.0], [-2.0 / gamma, 0.0]]),
                   weights=np.array([1.5, 0.5]) / gamma, error_weights=np.array([0.5, 0.5]) / gamma,
                   order=2, error_order=2)


def _rodas4():
    a5 = [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950]
    alpha = np.zeros((6, 6))
    alpha[1, 0] = 1.544
    alpha[2, :2] = [0.9466785280815826, 0.2557011698983284]
    alpha[3, :3] = [3.314825187068521, 2.896124015972201, 0.9986419139977817]
    alpha[4, :4] = a5
    alpha[5, :5] = a5 + [1.0]              # stiffly accurate: stage 6 at the embedded solution
    Gamma = np.zeros((6, 6))
    Gamma[1, 0] = -5.6688
    Gamma[2, :2] = [-2.430093356833875, -0.2063599157091915]
    Gamma[3, :3] = [-0.1073529058151375, -9.594562251023355, -20.47028614809616]
    Gamma[4, :4] = [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160]
    Gamma[5, :5] = [8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136,
                    -6.058818238834054]
    return Tableau(gamma=0.25, alpha=alpha, Gamma=Gamma, weights=np.array(a5 + [1.0, 1.0]),
                   error_weights=np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0]), order=4, error_order=4)


#: The compiled methods by name.
TABLEAUX = {"RODAS4": _rodas4(), "ROS2": _ros2()}


@njit
def _add_scaled(out, scale, x):
    """``out += scale x`` without a temporary array."""
    for i in range(out.size):
        out[i] += scale * x[i]


@njit
def step(y, fy, h, gamma, alpha, Gamma, weights, error_weights, stages, y_new, error, work, factors, args):
    """One Rosenbrock step of size ``h`` from ``y`` (with ``fy = f(y)``): writes ``y_new`` and the
    local ``error`` (both float64 [n]); ``stages`` float64 [s, n] and ``work`` float64 [2, n] are
    scratch, ``factors`` from :func:`.slab_linear_system.new_factors`; ``args`` those of
    :func:`.slab_equations.rhs` after ``y``; returns None."""
    s = weights.size
    c = gamma * h
    factorize(y, c, factors, *args)
    point, right = work[0], work[1]
    for i in range(s):
        if i == 0:
            right[:] = fy
        else:
            point[:] = y
            for j in range(i):
                if alpha[i, j] != 0.0:
                    _add_scaled(point, alpha[i, j], stages[j])
            rhs_into(point, right, *args)
        right *= c
        for j in range(i):
            if Gamma[i, j] != 0.0:
                _add_scaled(right, gamma * Gamma[i, j], stages[j])
        solve(right, stages[i], c, factors, *args)
    y_new[:] = y
    error[:] = 0.0
    for i in range(s):
        if weights[i] != 0.0:
            _add_scaled(y_new, weights[i], stages[i])
        if error_weights[i] != 0.0:
            _add_scaled(error, error_weights[i], stages[i])
    return None


@njit
def integrate(y0, t0, h0, t_pause, t_end, args, rtol, atol, method):
    """Integrate ``dy/dt = rhs(y, *args)`` (:func:`.slab_equations.rhs`) from ``t0`` towards ``t_end``
    with the Rosenbrock ``method``, returning after the first accepted step at or beyond ``t_pause``.

    Step control: module docstring, with Gustafsson's predictive controller (Hairer & Wanner 1996,
    Sec. IV.8, as in their RODAS: after an accepted step the next one is the smaller of the classical
    and the predicted size; after a rejection the step does not grow).

    Only ``t_end`` cuts a step short; ``t_pause`` does not, so that integrating in pieces (each call
    starting from the last state, time and next step size of the previous one) accepts exactly the
    same steps, bit for bit, as one call from 0 to ``t_end`` (the caller reports progress between
    the pieces, :meth:`.slab_dynamics.SlabDynamics.integrate`). The right-hand side is called
    directly (not passed as an argument) so that numba caches the compiled integrator on disk.

    Time is carried as a sum of two doubles (Knuth's two-sum), so that steps far below the spacing of
    doubles at ``t`` still advance it: a slab that ends a slip still decelerating (hundreds of mm/s^2
    at V ~ 1e-8 mm/s) stops within ~1e-9 s, in steps of ~3e-11 s, while the spacing of doubles at
    t = 4000 s is 9e-13 s (stack n = 5, seed 5, path_disorder 0.02, t = 4010.3 s: with one double the
    step "underflowed" at 4e-11 s). Only steps below :data:`MIN_STEP` fail. Steps that do not change
    the rounded time replace the last stored state instead of adding one (the output times are
    increasing).

    Parameters
    ----------
    y0 : numpy.ndarray
        State at ``t0``, float64 [n].
    t0 : float
        Start time.
    h0 : tuple
        ``(h, h_accepted, norm_accepted, t_low)``: first trial step (> 0), size and error norm of the
        last accepted step and the low part of ``t0`` (:data:`START` for a new integration; else the
        ``h0`` returned by the previous piece).
    t_pause : float
        Return once an accepted step reaches it (``t0 < t_pause <= t_end``).
    t_end : float
        End time of the whole integration (no step goes beyond it).
    args : tuple
        Arguments of :func:`.slab_equations.rhs` after ``y``.
    rtol, atol : numpy.ndarray
        Relative and absolute tolerance per component, float64 [n].
    method : tuple
        :meth:`Tableau.arrays` of the method.

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
    h0 : tuple
        ``(h, h_accepted, norm_accepted, t_low)`` for the next piece.
    """
    n = y0.size
    capacity = 1024
    ts = np.empty(capacity)
    ys = np.empty((capacity, n))
    fs = np.empty((capacity, n))
    gamma, alpha, Gamma, weights, error_weights, exponent = method
    stages = np.empty((weights.size, n))
    work = np.empty((2, n))
    factors = new_factors(n)
    y, fy, y_new, error = y0.copy(), np.empty(n), np.empty(n), np.empty(n)
    rhs_into(y, fy, *args)
    t = t0
    ts[0], ys[0], fs[0] = t, y, fy
    count, rejected = 1, False
    h, h_accepted, norm_accepted, t_low = h0
    while t < t_pause:
        if h < MIN_STEP:
            return ts[:count], ys[:count], fs[:count], False, (h, h_accepted, norm_accepted, t_low)
        remaining = (t_end - t) - t_low
        h = min(h, remaining)
        step(y, fy, h, gamma, alpha, Gamma, weights, error_weights, stages, y_new, error, work, factors, args)
        total = 0.0
        for i in range(n):
            scaled = error[i] / (atol[i] + rtol[i] * max(abs(y[i]), abs(y_new[i])))
            total += scaled * scaled
        norm = math.sqrt(total / n)
        if not math.isfinite(norm):
            h *= 0.2
            rejected = True
            continue
        norm = max(norm, 1e-12)
        factor = min(5.0, max(0.2, 0.9 * norm ** -exponent))
        if norm > 1.0:
            h *= min(factor, 0.9)
            rejected = True
            continue
        if h_accepted > 0.0:               # Gustafsson's prediction
            predicted = 0.9 * h / h_accepted * (norm_accepted / (norm * norm)) ** exponent
            factor = min(factor, max(0.2, predicted))
        if rejected:
            factor = min(factor, 1.0)
        rejected = False
        h_accepted, norm_accepted = h, max(norm, 1e-2)
        if remaining > h:                  # t + t_low += h, exactly (two-sum), then renormalised
            total = t + h
            virtual = total - t
            low = t_low + ((t - (total - virtual)) + (h - virtual))
            t = total + low
            t_low = low - (t - total)
        else:
            t, t_low = t_end, 0.0
        y[:] = y_new
        rhs_into(y, fy, *args)
        if t == ts[count - 1]:             # a step below the rounding of t: replace, do not add
            ys[count - 1], fs[count - 1] = y, fy
            h *= factor
            continue
        if count == capacity:
            capacity *= 2
            ts_new, ys_new, fs_new = np.empty(capacity), np.empty((capacity, n)), np.empty((capacity, n))
            ts_new[:count], ys_new[:count], fs_new[:count] = ts[:count], ys[:count], fs[:count]
            ts, ys, fs = ts_new, ys_new, fs_new
        ts[count], ys[count], fs[count] = t, y, fy
        count += 1
        h *= factor
    return ts[:count], ys[:count], fs[:count], True, (h, h_accepted, norm_accepted, t_low)
