"""The elastic law: one well without yield strains, ``W = G eps_eq^2``, the plates' own elasticity.

The stress is ``K eps_m I + G eps_d`` whatever the yield strains (``g = G``): interface blocks
with this law are plain elastic elements. The linear response of a stack
(:mod:`..linear_response`) is the equilibrium of its interfaces made elastic. It never yields
(``yields`` False: no choice of the ``interface_law`` parameter) and has no barrier to cross.
GMatElastoPlasticQPot's ``Elastic``.
"""

import math
from collections import namedtuple

from ...numba_options import njit
from .generic import register_law

__all__ = ["Elastic"]


@njit(inline="always")
def _deviatoric_factor(law, eq, lo, hi):
    return law.G


@njit(inline="always")
def _well_energy(law, eq, lo, hi):
    return law.G * eq * eq


@njit(inline="always")
def _no_barrier(law, eq, lo, hi):
    return math.inf


@register_law
class Elastic(namedtuple("Elastic", ("K", "G"))):
    """The elastic law with moduli ``K`` and ``G`` [stress]."""

    __slots__ = ()
    name = "elastic"
    summary = "linear elasticity, no wells (the linear response)"
    yields = False
    exact_relaxation = True
    thermal = False
    deviatoric_factor = staticmethod(_deviatoric_factor)
    well_energy = staticmethod(_well_energy)
    forward_barrier = staticmethod(_no_barrier)
    backward_barrier = staticmethod(_no_barrier)

    def newton_moduli(self):
        """Moduli ``(K, G)`` of the exact relaxation's constant matrix: the law's own, exactly."""
        return self.K, self.G
