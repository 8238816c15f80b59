"""Friction law of one interface: logarithmic aging, threshold disorder, creep onset.

Interface ``i`` sticks until its friction coefficient reaches its static strength::

    mu_s,i(T) = mu_d,i + eps + B_i ln(1 + T / T0),     eps = offset + threshold_noise |xi|

with ``T`` the time since the onset of its previous slip (the paper's ``T_a``), ``mu_d,i``
its dynamic level (a slip drops ``mu_i`` to it), ``B_i`` its aging rate and ``eps`` the
threshold excess: a fixed ``offset`` (the strength gained however short the stick) plus
annealed disorder, ``xi`` standard normal, drawn anew after every slip. ``ln(1 + T/T0)`` instead of ``ln(T/T0)`` keeps the strength above
``mu_d`` for ``T < T0`` (the pure law is negative there and would make an interface slip
again right after a slip); for ``T >> T0`` they differ by ``B T0 / T``.

Creep (slow slip): an interface whose ``creep_velocity`` is positive starts sliding steadily
at that velocity once ``mu_i`` reaches the fraction ``creep_onset`` of its strength above
``mu_d``, i.e. ``mu_i = mu_d,i + creep_onset (eps + B_i ln(1 + T/T0))``; any slip stops it.

Between events every ``mu_i`` is linear in time, so the time an interface reaches a level of
the form ``L + S ln(1 + T / T0)`` solves ``mu + r tau = L + S ln(1 + (T + tau) / T0)``: a
Lambert-W equation, evaluated by :func:`first_crossing`.
"""

import dataclasses
import math

import numpy as np

__all__ = ["FrictionLaw", "first_crossing"]


@dataclasses.dataclass(frozen=True)
class FrictionLaw:
    """Friction parameters of every interface.

    Attributes
    ----------
    mu_d : numpy.ndarray
        Dynamic friction level per interface, float64 [n_slabs].
    B : numpy.ndarray
        Aging rate per interface, float64 [n_slabs] (>= 0).
    T0 : float
        Aging time scale [s].
    offset : float
        Part of the threshold excess common to every stick (>= 0).
    threshold_noise : float
        Scale of the half-normal part of the threshold excess (0: no disorder).
    creep_velocity : numpy.ndarray
        Creep (slow-slip) velocity per interface [mm/s], float64 [n_slabs] (0: no creep).
    creep_onset : float
        Fraction of the strength above ``mu_d`` at which creep starts, in (0, 1).
    trigger_margin : float
        An interface within this distance of its strength slips together with the one
        that reaches its strength (0: never).
    """

    mu_d: np.ndarray
    B: np.ndarray
    T0: float
    offset: float
    threshold_noise: float
    creep_velocity: np.ndarray
    creep_onset: float
    trigger_margin: float

    def strength(self, T, excess):
        """Static strength mu_s,i(T) = mu_d,i + eps_i + B_i ln(1 + T_i / T0), [n_slabs].

        Parameters
        ----------
        T : numpy.ndarray
            Time since the onset of each interface's previous slip [s], [n_slabs].
        excess : numpy.ndarray
            Threshold excesses eps, [n_slabs].
        """
        return self.mu_d + excess + self.B * np.log1p(T / self.T0)

    def draw_excess(self, rng, size):
        """Draw ``size`` threshold excesses eps = offset + threshold_noise |xi|, xi standard normal."""
        return self.offset + self.threshold_noise * np.abs(rng.standard_normal(size))


def first_crossing(mu, rate, level, slope, T, T0):
    """Smallest ``tau >= 0`` at which ``mu + rate tau`` reaches ``level + slope ln(1 + (T + tau) / T0)``.

    The gap ``g(tau) = mu + rate tau - level - slope ln(1 + (T + tau) / T0)`` is convex; if
    ``g(0) < 0``, or ``g(0) = 0`` and ``g`` decreases (the level moves away, as right after
    a slip without disorder), the crossing lies beyond the minimum of ``g``, where Newton's method started from a
    point with ``g >= 0`` decreases monotonically onto the root (so the returned time never
    falls short of it by more than rounding).

    Parameters
    ----------
    mu : float
        Current value of the loaded quantity.
    rate : float
        Its rate of change [1/s].
    level : float
        Level at ``T + tau = 0``.
    slope : float
        Coefficient of the logarithm (>= 0).
    T : float
        Time already elapsed in the logarithm [s] (>= 0).
    T0 : float
        Time scale [s] (> 0).

    Returns
    -------
    float
        ``tau`` [s]; ``math.inf`` if the level is never reached.
    """
    def gap(tau):
        return mu + rate * tau - level - slope * math.log1p((T + tau) / T0)

    now = gap(0.0)
    if now > 0.0 or (now == 0.0 and rate >= slope / (T0 + T)):
        return 0.0
    if rate <= 0.0:
        return math.inf
    start = max(0.0, slope / rate - T0 - T)  # minimum of the gap
    step = max(start, T0)
    tau = start + step
    while gap(tau) < 0.0:
        step *= 2.0
        tau = start + step
    for _ in range(200):
        value = gap(tau)
        if value <= 0.0:
            break
        update = value / (rate - slope / (T0 + T + tau))
        tau -= update
        if update <= 1e-15 * tau:
            break
    return tau
