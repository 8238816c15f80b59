"""Statics of the lever apparatus: rigid slabs, springs to a rotating lever, force and moment balance.

Slab ``i`` (1 = lowest, up to ``n_slabs``) sits on interface ``i``; its absolute horizontal
position is ``x_i = R_1 + ... + R_i`` with ``R_i`` the slip accumulated by interface ``i``
(the base, ``x_0 = 0``, is fixed). A driven slab ``j`` is pulled by a spring of stiffness
``K`` attached to the lever at distance ``j h`` from the pivot; the lever top (distance
``H``) moves horizontally by ``U(t) = U_0 + V t``. The lever is rigid, so the attachment point
moves by ``(j h / H) U``; with ``gamma = U / H`` (the paper's lever rotation, ``gamma_dot =
V / H``) the spring force is exactly linear in time::

    f_j = K (j h gamma - x_j)         (j driven; 0 otherwise)

Force balance on interface ``i`` (it carries every spring at or above it) and moment balance
on the lever (horizontal forces, arms ``j h`` and ``H`` measured along the lever, so the
``cos(gamma)`` factors cancel)::

    mu_i = sum_{j driven, j >= i} f_j / N,        F = sum_{j driven} f_j j h / H.

Both are linear in the slips: ``mu_i = mu_i(R = 0) - sum_k C_ik R_k`` with the coupling
matrix ``C_ik = (K / N) #{j driven: j >= max(i, k)}``.

Units: lengths [mm], forces [N], stiffness [N/mm], speed [mm/s], time [s].
"""

import dataclasses

import numpy as np

from ...fixed_order import dot, solve

__all__ = ["Apparatus"]


@dataclasses.dataclass(frozen=True)
class Apparatus:
    """Geometry, springs and drive of one run.

    Attributes
    ----------
    n_slabs : int
        Slabs in the stack.
    driven : tuple[int, ...]
        Slabs that carry a spring (1-based): ``1..n`` ("stack") or ``(a,)`` ("individual").
    slippable : tuple[int, ...]
        Interfaces that can slip (1-based): those under the driven slabs (the slabs below
        a driven slab in the individual protocol are clamped; interfaces above the highest
        driven slab carry no shear).
    k_spring : float
        K [N/mm].
    normal_force : float
        N [N].
    h : float
        Slab thickness [mm].
    H : float
        Lever height [mm].
    lever_speed : float
        Speed of the lever top V [mm/s].
    gamma_start : float
        Lever rotation ``gamma = U / H`` at t = 0 [rad].
    """

    n_slabs: int
    driven: tuple
    slippable: tuple
    k_spring: float
    normal_force: float
    h: float
    H: float
    lever_speed: float
    gamma_start: float

    @classmethod
    def from_protocol(cls, protocol, *, n, a, n_slabs, k_spring, normal_force, h, H, V, gamma_start):
        """Build the apparatus of a protocol.

        Parameters
        ----------
        protocol : {"stack", "individual"}
            "stack": slabs 1..n driven at lever-top speed ``V``. "individual": slab ``a`` alone
            driven, slabs below clamped, lever top at ``V / a`` so that the spring moves at
            ``h V / H`` whatever ``a`` (appendix "Individual sliding").
        n, a : int
            Driven slabs (stack) and the slab driven alone (individual); the other is ignored.
        n_slabs : int
        k_spring, normal_force, h, H, V, gamma_start : float
            K [N/mm], N [N], h [mm], H [mm], nominal lever-top speed [mm/s], gamma at t = 0 [rad].

        Returns
        -------
        Apparatus
        """
        if protocol == "stack":
            driven, speed = tuple(range(1, n + 1)), V
        elif protocol == "individual":
            driven, speed = (a,), V / a
        else:
            raise ValueError(f"protocol must be 'stack' or 'individual', got {protocol!r}")
        return cls(n_slabs=n_slabs, driven=driven, slippable=driven, k_spring=k_spring,
                   normal_force=normal_force, h=h, H=H, lever_speed=speed, gamma_start=gamma_start)

    @property
    def heights(self):
        """Attachment heights of the driven springs ``j h`` (0 for undriven slabs) [mm], [n_slabs]."""
        heights = np.zeros(self.n_slabs)
        index = np.asarray(self.driven) - 1
        heights[index] = np.asarray(self.driven, dtype=float) * self.h
        return heights

    @property
    def shear_rate(self):
        """Lever rotation rate gamma_dot = V / H [1/s]."""
        return self.lever_speed / self.H

    def gamma(self, t):
        """Lever rotation gamma = U / H at times ``t`` [s] (any shape) [rad]."""
        return self.gamma_start + self.shear_rate * np.asarray(t, dtype=float)

    def positions(self, R):
        """Absolute slab positions x_i = R_1 + ... + R_i [mm], shape of ``R`` [..., n_slabs]."""
        return np.cumsum(R, axis=-1)

    def spring_forces(self, t, x):
        """Spring forces f_j = K (j h gamma(t) - x_j) on driven slabs, 0 elsewhere.

        Parameters
        ----------
        t : float or numpy.ndarray
            Times [s], shape [...].
        x : numpy.ndarray
            Slab positions [mm], shape [..., n_slabs].

        Returns
        -------
        numpy.ndarray
            Forces [N], shape [..., n_slabs].
        """
        gamma = np.asarray(self.gamma(t))[..., np.newaxis]
        driven = self.heights > 0
        return np.where(driven, self.k_spring * (self.heights * gamma - x), 0.0)

    def friction_coefficients(self, f):
        """Force balance: mu_i = sum_{j >= i} f_j / N, shape [..., n_slabs] from forces [..., n_slabs] [N]."""
        return np.cumsum(f[..., ::-1], axis=-1)[..., ::-1] / self.normal_force

    def lever_force(self, f):
        """Moment balance: F = sum_j f_j j h / H [N], shape [...] from forces [..., n_slabs] [N]."""
        return dot(f, self.heights) / self.H

    def mu(self, t, R):
        """Friction coefficients of every interface at time ``t`` [s] and slips ``R`` [n_slabs] [mm]."""
        return self.friction_coefficients(self.spring_forces(t, self.positions(R)))

    def coupling(self):
        """Coupling matrix C [n_slabs, n_slabs]: d mu_i = -sum_k C_ik dR_k [1/mm].

        ``C_ik = (K / N) #{j driven: j >= max(i, k)}`` (symmetric, positive semi-definite).
        """
        above = np.cumsum((self.heights > 0)[::-1])[::-1].astype(float)
        index = np.arange(self.n_slabs)
        return self.k_spring / self.normal_force * above[np.maximum.outer(index, index)]

    def loading_rates(self):
        """d mu_i / dt while nothing slips: (K / N) sum_{j driven, j >= i} j h gamma_dot [1/s], [n_slabs]."""
        rate = self.k_spring * self.heights * self.shear_rate
        return self.friction_coefficients(rate)

    def relaxed_slips(self, mu_target):
        """Slips R [n_slabs] [mm] at t = 0 that put every slippable interface at ``mu_target``.

        Interfaces that cannot slip keep ``R_i = 0`` (clamped slabs at the base position, riding
        slabs on the one below).

        Parameters
        ----------
        mu_target : numpy.ndarray
            Friction coefficients wanted at t = 0, [n_slabs] (only slippable entries are used).

        Returns
        -------
        numpy.ndarray
            float64 [n_slabs].
        """
        index = np.asarray(self.slippable) - 1
        R = np.zeros(self.n_slabs)
        unloaded = self.mu(0.0, R)
        coupling = self.coupling()[np.ix_(index, index)]
        R[index] = solve(coupling, unloaded[index] - np.asarray(mu_target)[index])
        return R
