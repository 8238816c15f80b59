"""Execution backends of the fem model: how the numbers are computed, not what they are.

A backend is chosen once per run (:func:`make_backend`) and passed to :class:`..system.System`,
which prepares it for its model (``prepare(model, mesh)`` returns the backend with its workspace); the physics
(:class:`..model.Model` and its law) is passed to every call. Its interface:

``prepare(model, mesh)``, ``force(model, state, update_wells=True)``, ``time_step(model, state)``,
``minimise(model, state, tol, niter_tol, max_iter, margin, record, quiet=0)`` (the whole
minimisation loop in the backend), ``residual(model, state)``, ``wells_hold(model, state)``,
and the attributes ``name``, ``summary``, ``threads``.

Built in: ``structured`` (default, :mod:`.structured`) and ``assembled`` (the reference,
:mod:`.assembled`), numba CPU backends (:mod:`.cpu`). A backend whose results are bit-identical
to the default's would be an execution option like ``threads``; both alternatives here change
the round-off, so the choice is the ``backend`` parameter of ``fem`` (recorded in the run file
and its id). docs/developing.md, "A new backend".
"""

from .assembled import AssembledBackend
from .structured import StructuredBackend

__all__ = ["BACKENDS", "DEFAULT_BACKEND", "make_backend", "register_backend"]

#: Backend classes by name.
BACKENDS = {}

#: The backend of a run that names none.
DEFAULT_BACKEND = "structured"


def register_backend(cls):
    """Register a backend class (class decorator); its ``name`` becomes a choice of the ``backend`` parameter."""
    if cls.name in BACKENDS:
        raise ValueError(f"backend {cls.name!r} is registered twice")
    BACKENDS[cls.name] = cls
    return cls


register_backend(StructuredBackend)
register_backend(AssembledBackend)


def make_backend(name=DEFAULT_BACKEND, threads=1):
    """The backend ``name`` with ``threads`` threads (:class:`..system.System` prepares it for its model).

    Raises
    ------
    ValueError
        If no backend of that name is registered.
    """
    if name not in BACKENDS:
        raise ValueError(f"backend {name!r}: expected one of {', '.join(sorted(BACKENDS))}")
    return BACKENDS[name](threads=threads)
