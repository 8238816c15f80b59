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

State vector ``y = [R_S, V_S, psi_S, gamma]`` (3 m + 1 values, :mod:`.slab_equations`): slips
[mm], slip rates [mm/s], ``psi = ln(V0 theta / D_c)``, lever rotation [rad]. The system is very
stiff while the interfaces stick (the friction's stiffness ``N a / V`` with ``V`` down to nm/s
gives rates ~1e12 /s) and fast during a slip (ms), so it is integrated with an implicit method
with the analytic Jacobian: the compiled L-stable Rosenbrock method RODAS4 of :mod:`.rosenbrock`
(default), or ``scipy.integrate.solve_ivp``'s Radau, BDF, LSODA (same results, ~1000 times slower a
step in Python); an explicit method would need time steps below 1e-12 s.

Units: lengths [mm], forces [N], masses [kg] (accelerations ``1000 F / M`` [mm/s^2]), time [s].
"""

import dataclasses
import math
import sys
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_ivp

from ... import progress
from . import rosenbrock
from .slab_equations import friction as _friction, jacobian as _jacobian, rhs as _rhs
from .slip_path import no_path

__all__ = ["SlabDynamics", "Trajectory", "METHODS", "DEFAULT_METHOD", "FALLBACK"]

#: Implicit methods: the numba-compiled Rosenbrock methods, and those of scipy.integrate.solve_ivp.
METHODS = (*rosenbrock.TABLEAUX, "Radau", "BDF", "LSODA")
#: The method of the solver (docs/experiment-model-rate-state.md: the fewest steps, ~1000 times cheaper
#: per step than Radau).
DEFAULT_METHOD = "RODAS4"
#: mm/s^2 per N/kg.
MM_PER_M = 1000.0
#: The compiled method that takes over for :data:`FALLBACK_SPAN` seconds, with the first session's
#: absolute slip-rate tolerance (:data:`FALLBACK_V_SCALE`), where RODAS4's step size underflows
#: (:meth:`SlabDynamics._integrate_compiled`).
FALLBACK = "ROS2"
#: [mm/s] per unit rtol: 1e-9 mm/s at rtol = 1e-4.
FALLBACK_V_SCALE = 1e-5
#: [s]
FALLBACK_SPAN = 10.0
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
        Their time derivatives, [n_steps + 1, 3 m + 1] (for Hermite interpolation).
    fallback_spans : numpy.ndarray
        Start and end [s] of every span that :data:`FALLBACK` integrated because the method's step
        size underflowed, float64 [k, 2] (k = 0: none; always none for the scipy methods).
    """

    t: np.ndarray
    y: np.ndarray
    dydt: np.ndarray
    fallback_spans: np.ndarray


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
        difference = np.linalg.inv(lower)               # V = D u
        reaction = np.eye(m) - np.eye(m, k=1)           # friction of interface k minus that of k + 1
        inverse_mass = MM_PER_M / self.masses
        accel = difference * inverse_mass[None, :]      # D M^-1 [mm/s^2 per N]
        return accel @ drive, accel @ stiffness, accel @ (self.apparatus.normal_force * reaction)

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
                float(self.law.V0), self._path)

    def friction(self, V, psi, R=None):
        """Friction coefficients of the slippable interfaces at slip rates ``V`` [mm/s], states ``psi``
        and slips ``R`` [mm] (None: at the start of the slip path), [..., m] (the shape of ``V``)."""
        R = self._origin if R is None else R
        R, V, psi = np.broadcast_arrays(np.asarray(R, dtype=float), np.asarray(V, dtype=float),
                                        np.asarray(psi, dtype=float))
        m = self._a.size
        rows = [np.ascontiguousarray(x.reshape(-1, m)) for x in (R, V, psi)]
        mu = _friction(*rows, self._mu0, self._a, self._b, float(self.law.V0), self._path)
        return mu.reshape(V.shape)

    def rhs(self, y, rate):
        """dy/dt of the state ``y = [R, V, psi, gamma]`` [3 m + 1] with the lever turning at ``rate`` [1/s]."""
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
            State vector ``[R_S, V_S, psi_S, gamma]``, [3 m + 1].
        """
        V = np.broadcast_to(np.asarray(V_start, dtype=float), self._a.shape)
        psi = np.broadcast_to(np.log(self.law.V0 * np.asarray(theta_start, dtype=float) / self._D_c), self._a.shape)
        target = np.zeros(self.apparatus.n_slabs)
        target[self.interfaces] = self.friction(V, psi)
        shifted = dataclasses.replace(self.apparatus, gamma_start=gamma_start)
        R0 = shifted.relaxed_slips(target)
        return R0, np.concatenate([R0[self.interfaces], V, psi, [gamma_start]])

    def tolerances(self, rtol, R=1e-2, V=1e-11, psi=1.0):
        """Absolute tolerances of the state components, proportional to the relative tolerance ``rtol``
        (so that ``rtol`` alone sets how tight an integration is): ``rtol`` times the scales of the slips
        ``R`` [mm], slip rates ``V`` [mm/s], states ``psi`` (and 1e-8 rad for gamma), float64 [3 m + 1].
        At ``rtol`` = 1e-4: 1e-6 mm, 1e-15 mm/s, 1e-4 and 1e-12 rad.

        The slip rates are held to their relative error down to 1e-11 mm/s because the friction
        depends on their logarithm (``d mu = a dV / V``): a stuck interface creeps at 1e-11 to 1e-9
        mm/s, and an absolute 1e-9 mm/s (the tolerance before issue 12's third session) let a step
        carry it through zero, flipping its friction (step-size underflow of RODAS4 at t = 334 s in
        the stack n = 3, seed 1)."""
        m = self.interfaces.size
        return rtol * np.concatenate([np.full(m, R), np.full(m, V), np.full(m, psi), [1e-8]])

    def integrate(self, y0, duration, rate, *, method=DEFAULT_METHOD, rtol=1e-4, atol=None):
        """Integrate ``duration`` [s] from ``y0`` with the lever turning at ``rate`` [1/s].

        Parameters
        ----------
        y0 : numpy.ndarray
            Initial state [3 m + 1] (:meth:`initial_state`, or the last state of a previous call).
        duration : float
            [s] (> 0).
        rate : float
            d gamma / dt [1/s] (0: a hold).
        method : {"RODAS4", "ROS2", "Radau", "BDF", "LSODA"}
            "RODAS4": the numba-compiled L-stable Rosenbrock method :func:`rosenbrock.integrate`; the
            others: ``scipy.integrate.solve_ivp`` (:data:`METHODS`).
        rtol : float
            Relative tolerance of the step control.
        atol : numpy.ndarray, optional
            Absolute tolerances [3 m + 1]; default :meth:`tolerances` of ``rtol``.

        Notes
        -----
        Progress (seconds simulated of ``duration``, rate, time left, steps so far) goes to stderr
        through :mod:`stickslip.progress`: a live bar on a terminal, a line every interval in a job's
        log. The compiled methods integrate in :data:`PROGRESS_PIECES` pieces for that, with the same
        steps (and results, bit for bit) as in one piece.

        Every span of :data:`FALLBACK` (:meth:`_integrate_compiled`) is reported on stderr after the
        integration, as a line ``virtual experiment: RODAS4's step size underflowed 1 time(s); ROS2
        integrated 670.233-680.233 s``.

        Returns
        -------
        Trajectory
            Step times, states, their derivatives and the fallback spans.

        Raises
        ------
        RuntimeError
            If the integrator fails.
        """
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}; got {method!r}")
        y0 = np.ascontiguousarray(y0, dtype=float)
        atol = self.tolerances(rtol) if atol is None else np.ascontiguousarray(atol, dtype=float)
        duration = float(duration)
        with _SimulatedTime(duration) as clock:
            if method in rosenbrock.TABLEAUX:
                trajectory = self._integrate_compiled(method, y0, duration, float(rate), rtol, atol, clock)
            else:
                trajectory = self._integrate_scipy(method, y0, duration, rate, rtol, atol, clock)
        spans = trajectory.fallback_spans
        if spans.size:
            print(f"virtual experiment: {method}'s step size underflowed {len(spans)} time(s); {FALLBACK} integrated "
                  + ", ".join(f"{start:.3f}-{end:.3f} s" for start, end in spans), file=sys.stderr)
        return trajectory

    def _integrate_scipy(self, method, y0, duration, rate, rtol, atol, clock):
        """``scipy.integrate.solve_ivp`` with ``method`` over ``duration`` [s]: a :class:`Trajectory`
        (without fallback spans)."""

        def rhs(t, y):
            clock.at(t, None)
            return self.rhs(y, rate)

        solution = solve_ivp(rhs, (0.0, duration), y0, method=method, rtol=rtol, atol=atol,
                             jac=lambda t, y: self.jacobian(y, rate))
        if not solution.success:
            raise RuntimeError(f"rate-and-state integration failed at t = {solution.t[-1]:.6g} s: {solution.message}")
        clock.at(duration, solution.t.size - 1)
        y = solution.y.T
        return Trajectory(solution.t, y, np.array([self.rhs(row, rate) for row in y]), np.empty((0, 2)))

    def _integrate_compiled(self, name, y0, duration, rate, rtol, atol, clock):
        """:func:`rosenbrock.integrate` with the method ``name`` in :data:`PROGRESS_PIECES` pieces of
        simulated time (the same steps as in one piece), reporting to ``clock`` after each.

        Where its step size underflows, :data:`FALLBACK` (ROS2, with an absolute slip-rate tolerance
        of 1e-9 mm/s at rtol = 1e-4, the first session's integrator, which ran the 10-seed study)
        integrates the next :data:`FALLBACK_SPAN` seconds and the method starts again after them. This
        happens deep in a stick: at slip rates of 1e-17 to 1e-13 mm/s an interface's equation of motion
        is stiff at ~1e17 /s and its slip rate is slaved to the force balance through
        ``mu = a asinh(V / w)``; RODAS4's linearly implicit stages project onto that slow manifold with a
        relative error in ``V`` of ~20 % whatever the step, which its error control (relative in ``V``)
        rejects (stack n = 5, seed 5, t = 670 s; test
        ``test_the_fallback_deep_in_a_stick_keeps_the_slips_of_a_tight_reference``). The switch points
        follow from the steps alone, so the pieces do not change them. Returns a :class:`Trajectory`."""
        args = (rate, *self._arrays())
        method, fallback = rosenbrock.TABLEAUX[name].arrays(), rosenbrock.TABLEAUX[FALLBACK].arrays()
        fallback_atol = self.tolerances(rtol, V=FALLBACK_V_SCALE)
        t_now, y_now, h, steps = 0.0, y0, (rosenbrock.FIRST_STEP, 0.0, 1.0), 0
        ts, ys, fs = [np.array([0.0])], [y0[None, :]], [self.rhs(y0, rate)[None, :]]
        spans = []
        for k in range(1, PROGRESS_PIECES + 1):
            t_pause = duration * k / PROGRESS_PIECES
            while t_now < t_pause:
                t, y, dydt, ok, h = rosenbrock.integrate(y_now, t_now, h, t_pause, duration, args, rtol, atol,
                                                         method)
                if not ok:
                    ts.append(t[1:])
                    ys.append(y[1:])
                    fs.append(dydt[1:])
                    t_now, y_now, steps = t[-1], y[-1], steps + t.size - 1
                    span_end = min(t_now + FALLBACK_SPAN, duration)
                    t, y, dydt, ok, _ = rosenbrock.integrate(y_now, t_now, (rosenbrock.FIRST_STEP, 0.0, 1.0),
                                                             span_end, span_end, args, rtol, fallback_atol, fallback)
                    if not ok:
                        raise RuntimeError(f"rate-and-state integration failed at t = {t[-1]:.6g} s: step size "
                                           f"underflow of {name} and of {FALLBACK}")
                    spans.append((t_now, t[-1]))
                    h = (rosenbrock.FIRST_STEP, 0.0, 1.0)
                ts.append(t[1:])            # every call starts where the previous one ended
                ys.append(y[1:])
                fs.append(dydt[1:])
                t_now, y_now, steps = t[-1], y[-1], steps + t.size - 1
                clock.at(t_now, steps)
        return Trajectory(np.concatenate(ts), np.concatenate(ys), np.concatenate(fs),
                          np.array(spans, dtype=float).reshape(-1, 2))


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
