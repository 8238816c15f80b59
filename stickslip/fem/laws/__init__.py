"""Interface laws: the potential of an interface Gauss point in its current well.

A law is an immutable value passed to the kernels (``model.law``), which call it through the
generic functions of :mod:`.generic`, compiled for its type. Built in: :class:`.cusp.Cusp`
(the paper's), :class:`.smooth.Smooth` (wells joined smoothly) and :class:`.elastic.Elastic` (no
wells: the linear response). :mod:`.wells` finds the well a strain lies in. A new law: one module
with its class decorated by :func:`.generic.register_law`, in this package (every module of it is
imported) or in another package that names it in the entry-point group :data:`ENTRY_POINT_GROUP`
(docs/writing-a-plugin.md). A run's code hash covers the law it chooses, not the others
(:func:`stickslip.provenance.code.plugin_code_hash`: the imports of a law's module in this file, the
re-exports below and the discovery, do not count).
"""

from ...discovery import import_modules, load_entry_points
from .cusp import Cusp
from .elastic import Elastic
from .generic import (INTERFACE_LAWS, LAWS, backward_barrier, deviatoric_factor, energy_density, forward_barrier,
                      mirrored, register_law, well_energy, well_stress)
from .smooth import Smooth
from .wells import well_index

__all__ = ["LAWS", "INTERFACE_LAWS", "ENTRY_POINT_GROUP", "Cusp", "Smooth", "Elastic", "make_law", "register_law",
           "mirrored", "deviatoric_factor", "well_energy", "forward_barrier", "backward_barrier", "well_stress",
           "energy_density", "well_index", "extra_parameters"]

#: The entry-point group through which other packages add interface laws (a module registering them).
ENTRY_POINT_GROUP = "stickslip.fem.laws"


def extra_parameters(cls):
    """Names of a law's parameters after ``K`` and ``G`` (given by the ``law_params`` parameter of ``fem``)."""
    return cls._fields[2:]


def make_law(name, K, G, extra=()):
    """The law ``name`` with moduli ``K`` and ``G`` [stress] and its further parameters ``extra``.

    Parameters
    ----------
    name : str
        A registered law (:data:`LAWS`).
    K, G : float
        Moduli [stress].
    extra : Sequence[float], optional
        Values of :func:`extra_parameters`, in order.

    Raises
    ------
    ValueError
        If no law of that name is registered, ``extra`` has another length than the law's further
        parameters, or the law's ``check_parameters()`` refuses them.
    """
    if name not in LAWS:
        raise ValueError(f"interface law {name!r}: expected one of {', '.join(sorted(LAWS))}")
    cls = LAWS[name]
    names = extra_parameters(cls)
    if len(extra) != len(names):
        expected = f"the values of ({', '.join(names)})" if names else "none"
        raise ValueError(f"law {name!r} takes {len(names)} parameters after K and G: expected {expected}, "
                         f"got {len(extra)}")
    law = cls(float(K), float(G), *(float(value) for value in extra))
    if names:
        law.check_parameters()
    return law


import_modules(__name__)
load_entry_points(ENTRY_POINT_GROUP)
