"""Interface laws: the potential of an interface Gauss point in its current well.

A law is an immutable value passed to the kernels (``model.law``), which call it through the
generic functions of :mod:`.generic`, compiled for its type. Built in: :class:`.cusp.Cusp`
(the paper's) and :class:`.smooth.Smooth` (wells joined smoothly). :mod:`.wells` finds the
well a strain lies in. A new law:
one module with its class decorated by :func:`.generic.register_law`, imported here.
"""

from .cusp import Cusp
from .generic import (LAWS, backward_barrier, deviatoric_factor, energy_density, forward_barrier, register_law,
                      well_energy, well_stress)
from .smooth import Smooth
from .wells import well_index

__all__ = ["LAWS", "INTERFACE_LAWS", "Cusp", "Smooth", "make_law", "register_law", "deviatoric_factor",
           "well_energy", "forward_barrier", "backward_barrier", "well_stress", "energy_density", "well_index"]

#: The laws a run's interfaces may have (the ``interface_law`` parameter of ``fem``).
INTERFACE_LAWS = tuple(LAWS)


def make_law(name, K, G):
    """The law ``name`` with moduli ``K`` and ``G`` [stress].

    Raises
    ------
    ValueError
        If no law of that name is registered.
    """
    if name not in LAWS:
        raise ValueError(f"interface law {name!r}: expected one of {', '.join(sorted(LAWS))}")
    return LAWS[name](float(K), float(G))
