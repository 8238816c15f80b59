"""Inertial dynamics of the slabs on rate-and-state interfaces, integrated by an implicit stiff ODE method.

The slippable interfaces ``s_1 < ... < s_m`` of an :class:`.apparatus.Apparatus` (the stack:
1..n; the individual protocol: a) cut the stack into ``m`` rigid bodies: body ``k`` holds slabs
``s_k .. s_{k+1} - 1`` (the last one every slab above ``s_m`` and the dead weight; the slabs below
``s_1`` are clamped to the base). Body ``k`` moves at ``u_k = V_1 + ... + V_k`` (``V_l`` the slip
rate of interface ``s_l``) and obeys Newton's law::

    M_k du_k/dt = S_k - N mu_k + N mu_{k+1}          (mu_{m+1} = 0)

with ``S_k`` the spring forces on its driven slabs (:meth:`.apparatus.Apparatus.spring_forces`, ``K
(j h gamma(t) - x_j)``) and ``N mu_k`` the friction of interface ``s_k``
(:class:`.rate_state.RateStateLaw`; the same normal force ``N`` on every interface, as in the
statics), whose ``mu0`` may vary along the slip path (:mod:`.slip_path`). In quasi-static equilibrium ``mu_k`` equals the apparatus's ``mu_i = sum_{j >= i} f_j / N``.

State vector ``y = [R_S, mu_S, psi_S, gamma]`` (3 m + 1 values, :mod:`.slab_equations`): slips
[mm], friction coefficients, ``psi = ln(V0 theta / D_c)``, lever rotation [rad]; the slip rates are
functions of the state (:meth:`SlabDynamics.slip_rates`). The friction, not the slip rate, is the
state because the stick's force balance is linear in it (:mod:`.slab_equations` says why that makes
the integration fail-safe). The system is very stiff while the interfaces stick (the friction's
stiffness ``N a / V`` with ``V`` down to 1e-17 mm/s gives rates up to ~1e19 /s) and fast during a
slip (ms), so it is integrated with an implicit method with the analytic Jacobian: the compiled
L-stable Rosenbrock method RODAS4 of :mod:`.rosenbrock` (default), or ``scipy.integrate.solve_ivp``'s
Radau (~1000 times slower a step in Python); an explicit method would need time steps below 1e-12 s.
scipy's BDF and LSODA are not offered: their Newton iterations factorise ``I - h J`` without
equilibrating its rows, which span ~19 orders of magnitude in a stick (:mod:`.slab_linear_system`);
BDF's step size underflows and LSODA skips slips (individual protocol, a = 1).

Units: lengths [mm], forces [N], masses [kg] (accelerations ``1000 F / M`` [mm/s^2]), time [s].
"""

import dataclasses
import math
from typing import NamedTuple

import numpy as np

from ... import progress
from ...errors import SolverError
from ...fixed_order import dot, inverse
from . import rosenbrock
from .slab_equations import jacobian as _jacobian, rhs as _rhs, slip_rates as _slip_rates
from .slip_path import no_path

__all__ = ["SlabDynamics", "Trajectory", "METHODS", "DEFAULT_METHOD"]

#: Implicit methods: the numba-compiled Rosenbrock methods, and scipy.integrate.solve_ivp's Radau.
METHODS = (*rosenbrock.TABLEAUX, "Radau")
#: The method of the solver (docs/experiment-model-rate-state.md: the fewest steps, ~1000 times cheaper
#: per step than Radau).
DEFAULT_METHOD = "RODAS4"
#: mm/s^2 per N/kg.
MM_PER_M = 1000.0
#: The compiled integration runs in this many pieces of equal simulated time, with a progress
#: report after each (the steps are the same as in one piece).
PROGRESS_PIECES = 500


class Trajectory(NamedTuple):
    """The accepted steps of an integration (:meth:`SlabDynamics.integrate`).

    Attributes
    ----------
    t : numpy.ndarray
        Step times from 0 [s], [n_steps + 1].
    y : numpy.ndarray
        States there, [n_steps + 1, 3 m + 1].
    dydt : numpy.ndarray
        Their time derivatives, [n_steps + 1, 3 m + 1] (for Hermite interpolation; the first m
        columns are the slip rates).
    """

    t: np.ndarray
    y: np.ndarray
    dydt: np.ndarray


@dataclasses.dataclass(frozen=True)
class SlabDynamics:
    """Equations of motion of the bodies above the slippable interfaces.

    Attributes
    ----------
    apparatus : Apparatus
    law : RateStateLaw
        Parameters of every interface (only the slippable ones are used).
    slab_mass : float
        Mass of one slab [kg].
    load_mass : float
        Mass of the dead weight on the top slab [kg].
    path : PathProfiles, optional
        Heterogeneity of ``mu0`` along the slip path (:class:`.slip_path.PathProfiles`); None: none.
    path_origin : numpy.ndarray, optional
        Slips [mm] of the slippable interfaces at which the path starts (``delta = 0``), [m]; None: 0.
        A run sets it to the slips of its initial state (:meth:`initial_state` takes the friction
        there), with ``dataclasses.replace``.
    """

    apparatus: object
    law: object
    slab_mass: float
    load_mass: float
    path: object = None
    path_origin: object = None

    @property
    def interfaces(self):
        """0-based slippable interfaces, int [m]."""
        return np.asarray(self.apparatus.slippable, dtype=int) - 1

    @property
    def masses(self):
        """Mass of every body [kg], [m]: its slabs, and the dead weight for the top one."""
        s = self.interfaces
        upper = np.append(s[1:], self.apparatus.n_slabs)
        masses = (upper - s) * self.slab_mass
        masses[-1] += self.load_mass
        return masses

    def _matrices(self):
        s, n_slabs = self.interfaces, self.apparatus.n_slabs
        m = s.size
        upper = np.append(s[1:], n_slabs)
        body_of_slab = np.full(n_slabs, -1)
        for k in range(m):
            body_of_slab[s[k]:upper[k]] = k
        heights = self.apparatus.heights
        driven = heights > 0
        K = self.apparatus.k_spring
        drive = np.zeros(m)              # S_k = drive_k gamma(t) - (stiffness @ R)_k
        n_driven = np.zeros(m)
        for j in range(n_slabs):
            if driven[j] and body_of_slab[j] >= 0:
                drive[body_of_slab[j]] += K * heights[j]
                n_driven[body_of_slab[j]] += 1
        lower = np.tril(np.ones((m, m)))
        stiffness = K * n_driven[:, None] * lower
        difference = inverse(lower)               # V = D u
        reaction = np.eye(m) - np.eye(m, k=1)           # friction of interface k minus that of k + 1
        inverse_mass = MM_PER_M / self.masses
        accel = difference * inverse_mass[None, :]      # D M^-1 [mm/s^2 per N]
        return dot(accel, drive), dot(accel, stiffness), dot(accel, self.apparatus.normal_force * reaction)

    def __post_init__(self):
        drive, stiffness, coupling = self._matrices()
        s = self.interfaces
        object.__setattr__(self, "_drive", drive)              # [mm/s^2 per rad]
        object.__setattr__(self, "_stiffness", stiffness)      # [1/s^2]
        object.__setattr__(self, "_coupling", coupling)        # [mm/s^2 per unit friction coefficient]
        for name in ("a", "b", "D_c", "mu0"):
            object.__setattr__(self, "_" + name, np.asarray(getattr(self.law, name), dtype=float)[s])
        origin = np.zeros(s.size) if self.path_origin is None else np.asarray(self.path_origin, dtype=float)
        object.__setattr__(self, "_origin", origin)
        object.__setattr__(self, "_path", no_path(s.size) if self.path is None else
                           self.path.arguments(s, self._mu0, origin))

    def _arrays(self):
        return (self._drive, self._stiffness, self._coupling, self._mu0, self._a, self._b, self._D_c,
                float(self.law.V0), self._path, self.law.state_law == "slip")

    def slip_rates(self, mu, psi, R=None):
        """Slip rates [mm/s] of the slippable interfaces at friction coefficients ``mu``, states ``psi``
        and slips ``R`` [mm] (None: at the start of the slip path), [..., m] (the shape of ``mu``)."""
        R = self._origin if R is None else R
        R, mu, psi = np.broadcast_arrays(np.asarray(R, dtype=float), np.asarray(mu, dtype=float),
                                         np.asarray(psi, dtype=float))
        m = self._a.size
        rows = [np.ascontiguousarray(x.reshape(-1, m)) for x in (R, mu, psi)]
        V = _slip_rates(*rows, self._mu0, self._a, self._b, float(self.law.V0), self._path)
        return V.reshape(mu.shape)

    def friction(self, V, psi):
        """Friction coefficients ``mu = a asinh(V / w)`` of the slippable interfaces at slip rates ``V``
        [mm/s] and states ``psi`` at the start of the slip path, [..., m] (the inverse of
        :meth:`slip_rates` there)."""
        width = 2.0 * self.law.V0 * np.exp(-(self._mu0 + self._b * np.asarray(psi, dtype=float)) / self._a)
        return self._a * np.arcsinh(np.asarray(V, dtype=float) / width)

    def accelerations(self, y):
        """Newton's law: the rate of change of the slip rates, ``dV/dt = drive gamma - stiffness R -
        coupling mu`` [mm/s^2], of states ``y`` [..., 3 m + 1], [..., m]."""
        y = np.asarray(y, dtype=float)
        m = self._a.size
        return (y[..., 3 * m:] * self._drive - dot(y[..., :m], self._stiffness.T)
                - dot(y[..., m:2 * m], self._coupling.T))

    def rhs(self, y, rate):
        """dy/dt of the state ``y = [R, mu, psi, gamma]`` [3 m + 1] with the lever turning at ``rate`` [1/s]."""
        return _rhs(y, rate, *self._arrays())

    def jacobian(self, y, rate):
        """d(dy/dt)/dy, float64 [3 m + 1, 3 m + 1]."""
        return _jacobian(y, rate, *self._arrays())

    def initial_state(self, V_start, theta_start, gamma_start):
        """State at rest in equilibrium: slip rates ``V_start`` [mm/s] and contact ages ``theta_start`` [s]
        of the slippable interfaces, lever rotation ``gamma_start`` [rad], and the slips that make the
        springs balance the friction (that at the start of the slip path, ``delta = 0``).

        Returns
        -------
        R0 : numpy.ndarray
            Slip of every interface [mm], [n_slabs] (at ``gamma_start``).
        y0 : numpy.ndarray
            State vector ``[R_S, mu_S, psi_S, gamma]``, [3 m + 1].
        """
        V = np.broadcast_to(np.asarray(V_start, dtype=float), self._a.shape)
        psi = np.broadcast_to(np.log(self.law.V0 * np.asarray(theta_start, dtype=float) / self._D_c), self._a.shape)
        mu = self.friction(V, psi)
        target = np.zeros(self.apparatus.n_slabs)
        target[self.interfaces] = mu
        shifted = dataclasses.replace(self.apparatus, gamma_start=gamma_start)
        R0 = shifted.relaxed_slips(target)
        return R0, np.concatenate([R0[self.interfaces], mu, psi, [gamma_start]])

    def tolerances(self, rtol, R=1e-2, psi=1.0):
        """Relative and absolute tolerances of the state components, both proportional to ``rtol``
        (so that ``rtol`` alone sets how tight an integration is).

        The slips ``R``, states ``psi`` and the rotation have the relative tolerance ``rtol`` and the
        absolute ones ``rtol`` times the scales ``R`` [mm], ``psi`` (and 1e-8 rad); at ``rtol`` = 1e-4:
        1e-6 mm, 1e-4, 1e-12 rad. The friction ``mu`` of interface ``k`` has no relative tolerance and
        the absolute one ``a_k rtol``: since ``d mu = a dV / V`` on the rate-and-state branch, that is
        the relative tolerance ``rtol`` on its slip rate, from creep at 1e-17 mm/s to slips at mm/s
        (the slip rate's tolerance of the earlier formulation, which integrated ``V``), and it holds
        through ``V = 0``.

        Returns
        -------
        rtol, atol : numpy.ndarray
            Float64 [3 m + 1] each.
        """
        m = self.interfaces.size
        relative = np.concatenate([np.full(m, rtol), np.zeros(m), np.full(m + 1, rtol)])
        absolute = rtol * np.concatenate([np.full(m, R), self._a, np.full(m, psi), [1e-8]])
        return relative, absolute

    def integrate(self, y0, duration, rate, *, method=DEFAULT_METHOD, rtol=1e-4):
        """Integrate ``duration`` [s] from ``y0`` with the lever turning at ``rate`` [1/s].

        Parameters
        ----------
        y0 : numpy.ndarray
            Initial state [3 m + 1] (:meth:`initial_state`, or the last state of a previous call).
        duration : float
            [s] (> 0).
        rate : float
            d gamma / dt [1/s] (0: a hold).
        method : {"RODAS4", "ROS2", "Radau"}
            "RODAS4" (and "ROS2"): the numba-compiled L-stable Rosenbrock methods of
            :func:`rosenbrock.integrate`; the others: ``scipy.integrate.solve_ivp`` (:data:`METHODS`).
        rtol : float
            Relative tolerance of the step control; the tolerances of every component follow from it
            (:meth:`tolerances`; scipy takes one relative tolerance for all, so there ``mu`` also has
            ``rtol`` relative to its value).

        Notes
        -----
        Progress (seconds simulated of ``duration``, rate, time left, steps so far) goes to stderr
        through :mod:`stickslip.progress`: a live bar on a terminal, a line every interval in a job's
        log. The compiled methods integrate in :data:`PROGRESS_PIECES` pieces for that, with the same
        steps (and results, bit for bit) as in one piece.

        Returns
        -------
        Trajectory
            Step times, states and their derivatives.

        Raises
        ------
        RuntimeError
            If the integrator fails (the step size underflows; no run of the shipped studies does).
        """
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}; got {method!r}")
        y0 = np.ascontiguousarray(y0, dtype=float)
        relative, absolute = self.tolerances(rtol)
        duration = float(duration)
        with _SimulatedTime(duration) as clock:
            if method in rosenbrock.TABLEAUX:
                return self._integrate_compiled(method, y0, duration, float(rate), relative, absolute, clock)
            return self._integrate_scipy(method, y0, duration, rate, rtol, absolute, clock)

    def _integrate_scipy(self, method, y0, duration, rate, rtol, atol, clock):
        """``scipy.integrate.solve_ivp`` with ``method`` over ``duration`` [s]: a :class:`Trajectory`
        (scipy.integrate is imported here, not with the module: the default jobs never need it)."""
        from scipy.integrate import solve_ivp  # ~0.5 s of import (measured here) that the default jobs never need

        def rhs(t, y):
            clock.at(t, None)
            return self.rhs(y, rate)

        solution = solve_ivp(rhs, (0.0, duration), y0, method=method, rtol=rtol, atol=atol,
                             jac=lambda t, y: self.jacobian(y, rate))
        if not solution.success:
            raise SolverError(f"rate-and-state integration failed at t = {solution.t[-1]:.6g} s: {solution.message}")
        clock.at(duration, solution.t.size - 1)
        y = solution.y.T
        return Trajectory(solution.t, y, np.array([self.rhs(row, rate) for row in y]))

    def _integrate_compiled(self, name, y0, duration, rate, rtol, atol, clock):
        """:func:`rosenbrock.integrate` with the method ``name`` in :data:`PROGRESS_PIECES` pieces of
        simulated time (the same steps as in one piece), reporting to ``clock`` after each; ``rtol``
        and ``atol`` per component. Returns a :class:`Trajectory`."""
        args = (rate, *self._arrays())
        method = rosenbrock.TABLEAUX[name].arrays()
        t_now, y_now, h, steps = 0.0, y0, rosenbrock.START, 0
        ts, ys, fs = [np.array([0.0])], [y0[None, :]], [self.rhs(y0, rate)[None, :]]
        for k in range(1, PROGRESS_PIECES + 1):
            t_pause = duration * k / PROGRESS_PIECES
            t, y, dydt, ok, h = rosenbrock.integrate(y_now, t_now, h, t_pause, duration, args, rtol, atol, method)
            if not ok:
                raise SolverError(f"rate-and-state integration failed at t = {t[-1]:.6g} s: step size underflow "
                                  f"of {name}")
            ts.append(t[1:])            # every call starts where the previous one ended
            ys.append(y[1:])
            fs.append(dydt[1:])
            t_now, y_now, steps = t[-1], y[-1], steps + t.size - 1
            clock.at(t_now, steps)
        return Trajectory(np.concatenate(ts), np.concatenate(ys), np.concatenate(fs))


class _SimulatedTime:
    """Progress of an integration in whole seconds of simulated time, with the steps taken so far
    (:func:`stickslip.progress.bar`: a live bar on a terminal, a line every interval in a log)."""

    def __init__(self, duration):
        self.bar = progress.bar(math.ceil(duration), desc="virtual experiment", unit="s simulated")
        self.done = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.bar.close()

    def at(self, t, steps):
        """Report that the integration reached time ``t`` [s] after ``steps`` accepted steps (None:
        unknown, the scipy methods); returns None."""
        if steps is not None:
            self.bar.set_postfix_str(f"{steps} steps", refresh=False)
        seconds = min(math.floor(t), self.bar.total)
        if seconds > self.done:
            self.bar.update(seconds - self.done)
            self.done = seconds
