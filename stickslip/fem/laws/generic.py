"""What the solver asks of an interface law, dispatched on the law's type when a kernel is compiled.

A law is a small immutable value (a named tuple of its parameters, e.g. ``Cusp(K, G)``)
whose class provides three scalar functions of a Gauss point in the well
``lo < eps_eq <= hi`` (``lo``, ``hi``: the yield strains that bound it):

``deviatoric_factor(law, eq, lo, hi)``
    ``g`` such that the deviatoric stress is ``g eps_d`` [stress];
``well_energy(law, eq, lo, hi)``
    the deviatoric part ``W(eps_eq)`` of the energy density [stress]; the whole density is
    ``K eps_m^2 + W`` and ``g = W'(eps_eq) / (2 eps_eq)``;
``forward_barrier(law, eq, lo, hi)``
    the energy density [stress] to carry the point from ``eq`` over the well's forward
    edge ``hi`` against its current load: ``max_{y in [eq, hi]} W(y) - W(eq) - W'(eq) (y - eq)``
    (the load ``W'(eq)`` held constant: the surroundings do not relax during the hop).

Derived from these: :func:`backward_barrier`, the barrier over the back edge ``lo``, by the
mirror symmetry of a well about its centre (both built-in laws have it).

:func:`register_law` makes these callable, under the generic names below, both from Python
(the law's own compiled function) and from any compiled kernel, where numba resolves the
call by the law's type when it compiles the kernel for that law and inlines it. So a kernel
written with the generic names serves every law, bit for bit as if the law were written into
it, and a new law is one module plus :func:`register_law` (and its name in :data:`LAWS`).
Strains are ``(xx, yy, xy)`` with tensorial shear; ``eps_m = (xx + yy) / 2``,
``eps_eq = sqrt(((xx - yy) / 2)^2 + xy^2)`` (:func:`stickslip.fem.materials.equivalent_strain`).
"""

from numba.core import types
from numba.extending import overload

from ...numba_options import njit
from ..materials import equivalent_strain

__all__ = ["LAWS", "register_law", "deviatoric_factor", "well_energy", "forward_barrier", "backward_barrier",
           "well_stress", "energy_density"]

#: Registered laws by name (:func:`register_law`).
LAWS = {}

#: The functions every law provides, by name.
_PROVIDED = ("deviatoric_factor", "well_energy", "forward_barrier")


def deviatoric_factor(law, eq, lo, hi):
    """``g`` of the deviatoric stress ``g eps_d`` in the well ``(lo, hi]`` at equivalent strain ``eq`` [stress]."""
    return type(law).deviatoric_factor(law, eq, lo, hi)


def well_energy(law, eq, lo, hi):
    """Deviatoric energy density ``W(eq)`` in the well ``(lo, hi]`` [stress]."""
    return type(law).well_energy(law, eq, lo, hi)


def forward_barrier(law, eq, lo, hi):
    """Energy density [stress] to cross the well's forward edge ``hi`` from ``eq`` at constant load."""
    return type(law).forward_barrier(law, eq, lo, hi)


def _dispatch(generic, cls):
    """Let compiled code call ``generic`` on a ``cls`` law: its own function, inlined."""
    implementation = getattr(cls, generic.__name__)

    def select(law, eq, lo, hi):
        if isinstance(law, types.BaseNamedTuple) and law.instance_class is cls:
            return lambda law, eq, lo, hi: implementation(law, eq, lo, hi)
        return None

    overload(generic, inline="always")(select)


def register_law(cls):
    """Register a law class (class decorator).

    Parameters
    ----------
    cls : type
        A :func:`collections.namedtuple` subclass whose fields are the law's parameters (``K``
        and ``G`` first), with a class attribute ``name``, the compiled functions ``deviatoric_factor``,
        ``well_energy`` and ``forward_barrier`` (static methods taking ``(law, eq, lo, hi)``), and
        a method ``newton_moduli()``: the moduli ``(K, G)`` of an elastic element whose stiffness
        bounds the law's curvature in every well from above, which the exact relaxation's
        modified Newton iterations need to converge (:mod:`..equilibrium`).

    Returns
    -------
    type
        ``cls``, now callable through the generic functions of this module and listed in :data:`LAWS`.
    """
    if cls.name in LAWS:
        raise ValueError(f"interface law {cls.name!r} is registered twice")
    for name in _PROVIDED:
        _dispatch(globals()[name], cls)
    LAWS[cls.name] = cls
    return cls


@njit
def backward_barrier(law, eq, lo, hi):
    """Energy density [stress] to cross the well's back edge ``lo`` from ``eq`` at constant load.

    The forward barrier of the mirror point ``lo + hi - eq``: exact for a law whose well is symmetric
    about its centre, ``W(lo + hi - y) = W(y)`` (the cusp and smooth laws), which a new law must be
    for thermal runs (:mod:`stickslip.fem.thermal`) or provide its own. Cusp: ``G (eq - lo)^2``.
    """
    return forward_barrier(law, lo + hi - eq, lo, hi)


@njit
def well_stress(law, xx, yy, xy, lo, hi):
    """Stress ``K eps_m I + g eps_d`` of strain ``(xx, yy, xy)`` in the well ``(lo, hi]``; returns ``(sxx, syy, sxy)``.

    The scalar reference of the interface kernel (:mod:`stickslip.fem.interface`), which
    computes the same operations in the same order.
    """
    m = 0.5 * (xx + yy)
    g = deviatoric_factor(law, equivalent_strain(xx, yy, xy), lo, hi)
    return law.K * m + g * (xx - m), law.K * m + g * (yy - m), g * xy


@njit
def energy_density(law, xx, yy, xy, lo, hi):
    """Energy density ``K eps_m^2 + W(eps_eq)`` of strain ``(xx, yy, xy)`` in the well ``(lo, hi]`` [stress]."""
    m = 0.5 * (xx + yy)
    return law.K * m * m + well_energy(law, equivalent_strain(xx, yy, xy), lo, hi)
