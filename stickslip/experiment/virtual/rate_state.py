"""Dieterich–Ruina rate-and-state friction with the aging or the slip law, one set of parameters per interface.

Interface ``i`` slides at ``V > 0`` [mm/s] with the state ``theta`` [s] (the age of its contacts)::

    mu = mu0 + a ln(V / V0) + b ln(V0 theta / D_c)          (friction)
    d theta / dt = 1 - V theta / D_c                         (aging law, Dieterich)
    d theta / dt = -(V theta / D_c) ln(V theta / D_c)        (slip law, Ruina)

In steady sliding ``theta = D_c / V`` and ``mu_ss(V) = mu0 + (a - b) ln(V / V0)``: velocity weakening
for ``b > a``. At rest the state grows as ``theta = theta_0 + t`` (aging): after a hold of ``T`` the
static friction peak is larger by about ``b ln(T)``. A single degree of freedom of mass ``M`` on
a spring ``K`` slides steadily (linear stability) if ``K > K_c = N (b - a) / D_c (1 + M V^2 / (N a D_c))``
(Ruina 1983; Rice & Ruina 1983; the inertial term is below 1e-9 at the loading speeds here), and
stick-slips below it.

The state is written as ``psi = ln(V0 theta / D_c)`` and the slip rate as ``phi = ln(V / V0)``
(the logarithms keep both well scaled from nm/s creep to mm/s slips)::

    mu = mu0 + a phi + b psi,      d psi / dt = (V0 / D_c) exp(-psi) - V / D_c       (aging law)
                                   d psi / dt = -(V / D_c) (phi + psi)                 (slip law)

The two laws have the same steady state and the same linear stability; they differ at rest. Under the aging law the
state grows with time whatever the slip rate (the contacts age: the static peak after a hold rises by ``b`` per
e-fold of the hold). Under the slip law it changes only by slip: at rest (``V -> 0``) it stays, so a hold does not
raise the peak beyond what the creep in it slides (Ruina 1983). The slip law is the rate-and-state interface without
time-dependent aging: the aging-off control of the twin (docs/experiment-model-rate-state.md).

Units: velocities [mm/s], lengths [mm], times [s].
"""

import dataclasses

import numpy as np

__all__ = ["RateStateLaw", "STATE_LAWS"]

#: The state's evolution laws: time-dependent healing (``"aging"``) or none at rest (``"slip"``).
STATE_LAWS = ("aging", "slip")


@dataclasses.dataclass(frozen=True)
class RateStateLaw:
    """Rate-and-state parameters of every interface.

    Attributes
    ----------
    a, b : numpy.ndarray
        Direct and evolution effects, float64 [n_slabs] (-).
    D_c : numpy.ndarray
        Memory length, float64 [n_slabs] [mm].
    mu0 : numpy.ndarray
        Steady friction at ``V0``, float64 [n_slabs].
    V0 : float
        Reference slip rate [mm/s].
    state_law : {"aging", "slip"}
        The state's evolution law (:data:`STATE_LAWS`; module docstring).
    """

    a: np.ndarray
    b: np.ndarray
    D_c: np.ndarray
    mu0: np.ndarray
    V0: float
    state_law: str = "aging"

    def friction(self, phi, psi):
        """mu = mu0 + a phi + b psi, from ``phi = ln(V/V0)`` and ``psi = ln(V0 theta/D_c)``, [..., n_slabs]."""
        return self.mu0 + self.a * phi + self.b * psi

    def state_rate(self, phi, psi):
        """d psi / dt [1/s], [..., n_slabs]: ``(V0 / D_c) (exp(-psi) - exp(phi))`` under the aging law,
        ``-(V0 / D_c) exp(phi) (phi + psi)`` under the slip law."""
        if self.state_law == "slip":
            return -self.V0 / self.D_c * np.exp(phi) * (phi + psi)
        return self.V0 / self.D_c * (np.exp(-psi) - np.exp(phi))

    def steady_state(self, V):
        """Steady friction mu_ss(V) = mu0 + (a - b) ln(V / V0) at slip rates ``V`` [mm/s], [..., n_slabs]."""
        return self.mu0 + (self.a - self.b) * np.log(np.asarray(V, dtype=float) / self.V0)

    def state_of_age(self, theta):
        """psi = ln(V0 theta / D_c) of a state (contact age) ``theta`` [s], [..., n_slabs]."""
        return np.log(self.V0 * np.asarray(theta, dtype=float) / self.D_c)

    def phi_at(self, mu, psi):
        """Slip rate variable phi = ln(V/V0) at which the friction equals ``mu``, [..., n_slabs]."""
        return (np.asarray(mu, dtype=float) - self.mu0 - self.b * psi) / self.a

    def critical_stiffness(self, normal_force):
        """Quasi-static critical stiffness K_c = N (b - a) / D_c [N/mm], [n_slabs] (<= 0: always stable)."""
        return normal_force * (self.b - self.a) / self.D_c
