"""What the solver asks of an interface law, dispatched on the law's type when a kernel is compiled.

A law is a small immutable value (a named tuple of its parameters, ``K`` and ``G`` first, e.g.
``Cusp(K, G)``) whose class provides scalar functions of a Gauss point in the well
``lo < eps_eq <= hi`` (``lo``, ``hi``: the yield strains that bound it):

``deviatoric_factor(law, eq, lo, hi)``
    ``g`` such that the deviatoric stress is ``g eps_d`` [stress];
``well_energy(law, eq, lo, hi)``
    the deviatoric part ``W(eps_eq)`` of the energy density [stress]; the whole density is
    ``K eps_m^2 + W`` and ``g = W'(eps_eq) / (2 eps_eq)``;
``forward_barrier(law, eq, lo, hi)``
    the energy density [stress] to carry the point from ``eq`` over the well's forward
    edge ``hi`` against its current load: ``max_{y in [eq, hi]} W(y) - W(eq) - W'(eq) (y - eq)``
    (the load ``W'(eq)`` held constant: the surroundings do not relax during the hop);
``backward_barrier(law, eq, lo, hi)`` (optional)
    the same over the back edge ``lo``. A law without its own gets the mirror of its forward
    barrier, the forward barrier of the point ``lo + hi - eq``: exact for a well symmetric about
    its centre, ``W(lo + hi - y) = W(y)`` (the cusp and smooth laws).

These are plain Python functions compiled by the caller: numba CPU kernels call them through the
generic names of this module (:func:`register_law` makes numba resolve the call by the law's type
and inline the law's own function), and a device backend compiles the same Python functions for
its target (``function.py_func``), so a new law runs everywhere without code of its own.

A law class also declares what it can be used for: ``yields`` (it has wells and yield strains: a
choice of the ``interface_law`` parameter; the elastic law has not), ``exact_relaxation`` (its
curvature in every well is bounded from above by the elastic stiffness of ``newton_moduli()``, which
the exact relaxation's modified Newton iterations need, :mod:`..equilibrium`) and ``thermal`` (its
backward barrier is exact and its barriers are quasi-concave in ``eps_eq`` within a well, which the
exact sampling of :mod:`..thermal` needs); optionally ``junction_aging`` (its stress in a well depends on
the well's centre only, so that a junction widening the current well about its centre changes no
stress, :mod:`..thermal.junctions`; absent means False). Parameters after ``K`` and ``G`` (its ``extra``
fields, given by the ``law_params`` parameter of ``fem``) are documented in ``parameter_docs`` and
checked by ``check_parameters()``.

Strains are ``(xx, yy, xy)`` with tensorial shear; ``eps_m = (xx + yy) / 2``,
``eps_eq = sqrt(((xx - yy) / 2)^2 + xy^2)`` (:func:`stickslip.fem.materials.equivalent_strain`).
"""

from numba.core import types
from numba.extending import overload

from ...numba_options import njit
from ..materials import equivalent_strain

__all__ = ["LAWS", "INTERFACE_LAWS", "register_law", "deviatoric_factor", "well_energy", "forward_barrier",
           "backward_barrier", "well_stress", "energy_density"]

#: Registered laws by name (:func:`register_law`).
LAWS = {}

#: The laws with wells (``yields``): the choices of the ``interface_law`` parameter, by name.
INTERFACE_LAWS = {}

#: The functions a law provides, by name (``backward_barrier`` mirrored from the forward one if absent).
_PROVIDED = ("deviatoric_factor", "well_energy", "forward_barrier", "backward_barrier")


def deviatoric_factor(law, eq, lo, hi):
    """``g`` of the deviatoric stress ``g eps_d`` in the well ``(lo, hi]`` at equivalent strain ``eq`` [stress]."""
    return type(law).deviatoric_factor(law, eq, lo, hi)


def well_energy(law, eq, lo, hi):
    """Deviatoric energy density ``W(eq)`` in the well ``(lo, hi]`` [stress]."""
    return type(law).well_energy(law, eq, lo, hi)


def forward_barrier(law, eq, lo, hi):
    """Energy density [stress] to cross the well's forward edge ``hi`` from ``eq`` at constant load."""
    return type(law).forward_barrier(law, eq, lo, hi)


def backward_barrier(law, eq, lo, hi):
    """Energy density [stress] to cross the well's back edge ``lo`` from ``eq`` at constant load (cusp: ``G (eq - lo)^2``)."""
    return type(law).backward_barrier(law, eq, lo, hi)


def mirrored(forward):
    """The backward barrier of a law whose wells are symmetric about their centre: ``forward(law, lo + hi - eq, lo, hi)``.

    Parameters
    ----------
    forward : callable
        The law's forward barrier ``(law, eq, lo, hi)`` (compiled or plain, for the target that calls the result).

    Returns
    -------
    callable
        Plain Python function ``(law, eq, lo, hi)``, to be compiled by the caller.
    """

    def backward_barrier(law, eq, lo, hi):
        return forward(law, lo + hi - eq, lo, hi)

    return backward_barrier


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
        and ``G`` first), with the class attributes ``name``, ``summary`` (one line), ``yields``,
        ``exact_relaxation`` and ``thermal`` (module docstring), the compiled functions
        ``deviatoric_factor``, ``well_energy`` and ``forward_barrier`` (static methods taking
        ``(law, eq, lo, hi)``; ``backward_barrier`` too if its wells are not symmetric), a method
        ``newton_moduli()`` (the moduli ``(K, G)`` of an elastic element whose stiffness bounds the
        law's curvature in every well from above, for the exact relaxation, :mod:`..equilibrium`),
        and, if it has fields after ``K`` and ``G``, a default for each of them (``namedtuple(...,
        defaults=(...))``: a representative value, so that ``cls(K, G)`` is a law, as the package's
        tests build every registered law), ``parameter_docs`` (name -> one line with the unit) and
        ``check_parameters()`` (raises ValueError naming the field).

    Returns
    -------
    type
        ``cls``, now callable through the generic functions of this module and listed in :data:`LAWS`
        (and in :data:`INTERFACE_LAWS` if it ``yields``).

    Raises
    ------
    ValueError
        If a law of that name is registered already, or a field after ``K`` and ``G`` has no default.
    """
    if cls.name in LAWS:
        raise ValueError(f"interface law {cls.name!r} is registered twice")
    missing = [name for name in cls._fields[2:] if name not in cls._field_defaults]
    if missing:
        raise ValueError(f"interface law {cls.name!r}: parameter(s) {', '.join(missing)} without a default; give "
                         f"each field after K and G one: namedtuple({cls.__name__!r}, {cls._fields!r}, "
                         "defaults=(...))")
    if "backward_barrier" not in vars(cls):
        cls.backward_barrier = staticmethod(njit(inline="always")(mirrored(cls.forward_barrier)))
    for name in _PROVIDED:
        _dispatch(globals()[name], cls)
    LAWS[cls.name] = cls
    if cls.yields:
        INTERFACE_LAWS[cls.name] = cls
    return cls


@njit
def well_stress(law, xx, yy, xy, lo, hi):
    """Stress ``K eps_m I + g eps_d`` of strain ``(xx, yy, xy)`` in the well ``(lo, hi]``; returns ``(sxx, syy, sxy)``.

    The scalar reference of the interface kernel (:mod:`stickslip.fem.backends.cpu.interface_elements`), which
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
