"""The smooth law: wells joined smoothly, GMatElastoPlasticQPot's ``Smooth`` potential.

In the well ``lo < eps_eq <= hi`` (centre ``eps_min``, half-width ``Delta``):

``W = -2 G (Delta / pi)^2 (1 + cos(theta))``, ``theta = pi (eps_eq - eps_min) / Delta``,

so ``W`` and its slope ``W' = 2 G (Delta / pi) sin(theta)`` vanish at both edges (the wells
join smoothly) and the curvature at the bottom, ``2 G``, is the cusp's. The stress factor is
``g = W' / (2 eps_eq) = (G / eps_eq) (Delta / pi) sin(theta)``. A Gauss point held at constant
load loses stability at the inflection ``theta = pi / 2`` (load ``2 G Delta / pi``, the
well's largest), before the yield strain; the barrier at constant load is

``2 G (Delta / pi)^2 [2 cos(theta) - (pi - 2 theta) sin(theta)]`` for ``0 <= theta < pi / 2``,
``2 G (Delta / pi)^2 [1 + cos(theta) - (pi - theta) sin(theta)]`` for ``theta < 0``
(the maximum is then the forward edge), and 0 beyond the inflection. Near the inflection it
vanishes as ``(4 / 3) G (Delta / pi)^2 phi^3``, ``phi = pi / 2 - theta``, i.e. as the 3/2 power
of the load distance to the threshold (the cusp: its square). docs/fem.md, "Interface laws".
"""

import math
from collections import namedtuple

from ...numba_options import njit
from .generic import register_law

__all__ = ["Smooth"]


@njit(inline="always")
def _deviatoric_factor(law, eq, lo, hi):
    half = 0.5 * (hi - lo)
    return 0.0 if eq <= 0.0 else (law.G / eq) * (half / math.pi) * math.sin(math.pi / half * (eq - 0.5 * (lo + hi)))


@njit(inline="always")
def _well_energy(law, eq, lo, hi):
    half = 0.5 * (hi - lo)
    scale = half / math.pi
    return -2.0 * law.G * scale * scale * (1.0 + math.cos(math.pi / half * (eq - 0.5 * (lo + hi))))


@njit(inline="always")
def _forward_barrier(law, eq, lo, hi):
    half = 0.5 * (hi - lo)
    scale = half / math.pi
    theta = math.pi / half * (eq - 0.5 * (lo + hi))
    if theta >= 0.5 * math.pi:
        return 0.0
    if theta >= 0.0:
        return 2.0 * law.G * scale * scale * (2.0 * math.cos(theta) - (math.pi - 2.0 * theta) * math.sin(theta))
    return 2.0 * law.G * scale * scale * (1.0 + math.cos(theta) - (math.pi - theta) * math.sin(theta))


@register_law
class Smooth(namedtuple("Smooth", ("K", "G"))):
    """The smooth law with moduli ``K`` and ``G`` [stress]."""

    __slots__ = ()
    name = "smooth"
    summary = "wells joined smoothly (GMatElastoPlasticQPot's Smooth)"
    yields = True
    exact_relaxation = True
    thermal = True
    deviatoric_factor = staticmethod(_deviatoric_factor)
    well_energy = staticmethod(_well_energy)
    forward_barrier = staticmethod(_forward_barrier)

    def newton_moduli(self):
        """Moduli ``(K, G)`` of the exact relaxation's constant matrix (:mod:`..equilibrium`): the radial curvature ``2 G cos(theta)`` is at most the elastic ``2 G``."""
        return self.K, self.G
