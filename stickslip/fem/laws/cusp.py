"""The cusp law (the paper's): a parabola in every well, joined to its neighbours by cusps.

In the well ``lo < eps_eq <= hi``, with centre ``eps_min = (lo + hi) / 2`` and half-width
``Delta = (hi - lo) / 2``: ``W = G [(eps_eq - eps_min)^2 - Delta^2]`` (zero at both edges, so
the energy is continuous and its slope jumps by ``4 G Delta`` at a yield strain), stress factor
``g = G (1 - eps_min / eps_eq)``, and at constant load the barrier to the forward edge
``G (hi - eps_eq)^2``: it vanishes as the square of the strain (or load) distance to the
yield strain, which is the athermal threshold. GMatElastoPlasticQPot's ``Cusp``;
shared/reference-model.md, section 4.
"""

from collections import namedtuple

from ...numba_options import njit
from .generic import register_law

__all__ = ["Cusp"]


@njit(inline="always")
def _deviatoric_factor(law, eq, lo, hi):
    # at eps_eq = 0 (possible only in the first, centred well) the deviatoric part is zero
    return 0.0 if eq <= 0.0 else law.G * (1.0 - 0.5 * (lo + hi) / eq)


@njit(inline="always")
def _well_energy(law, eq, lo, hi):
    x = eq - 0.5 * (lo + hi)
    half = 0.5 * (hi - lo)
    return law.G * (x * x - half * half)


@njit(inline="always")
def _forward_barrier(law, eq, lo, hi):
    x = hi - eq
    return law.G * x * x


@register_law
class Cusp(namedtuple("Cusp", ("K", "G"))):
    """The cusp law with moduli ``K`` and ``G`` [stress] (the interfaces' elastic moduli)."""

    __slots__ = ()
    name = "cusp"
    summary = "parabolas joined by cusps (the paper's)"
    yields = True
    exact_relaxation = True
    thermal = True
    junction_aging = True  # the stress depends on the well's centre only: widening a well about it changes none
    deviatoric_factor = staticmethod(_deviatoric_factor)
    well_energy = staticmethod(_well_energy)
    forward_barrier = staticmethod(_forward_barrier)

    def newton_moduli(self):
        """Moduli ``(K, G)`` of the exact relaxation's constant matrix (:mod:`..equilibrium`): the radial curvature of every well, ``2 G``, is the elastic one."""
        return self.K, self.G
