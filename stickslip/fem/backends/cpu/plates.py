"""The plates' elastic force ``f = K_p u``, dispatched on the type of a backend's plate operator.

A CPU backend (:mod:`.backends`) computes the plates' product with its own operator: a named
tuple of the arrays it needs (the stencil plan of :mod:`.structured`, the assembled CSR
matrix, ...). :func:`register_plate_operator` lets the kernels (:func:`.forces.compute_force`)
call its product through :func:`plate_force`, compiled for the operator's type and inlined, so
the kernels are written once for every operator.
"""

from numba.core import types
from numba.extending import overload

__all__ = ["plate_force", "register_plate_operator"]


def plate_force(plates, nblock, u, f):
    """``f = K_p u``: the plates' elastic force by the operator ``plates``.

    Parameters
    ----------
    plates : tuple
        A registered plate operator (:func:`register_plate_operator`).
    nblock : int
        Parallel blocks (1: serial); the result does not depend on it.
    u : numpy.ndarray
        [ndof] displacement [length].
    f : numpy.ndarray
        [ndof] force [force], overwritten.
    """
    type(plates).product(plates, nblock, u, f)


def register_plate_operator(cls):
    """Register a plate operator class (class decorator).

    Parameters
    ----------
    cls : type
        A :func:`collections.namedtuple` subclass of the operator's arrays with a compiled static
        method ``product(plates, nblock, u, f)`` that writes every entry of ``f``.

    Returns
    -------
    type
        ``cls``.
    """
    product = cls.product

    def select(plates, nblock, u, f):
        if isinstance(plates, types.BaseNamedTuple) and plates.instance_class is cls:
            return lambda plates, nblock, u, f: product(plates, nblock, u, f)
        return None

    overload(plate_force, inline="always")(select)
    return cls
