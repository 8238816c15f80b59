"""Execution backends of the fem model: how the numbers are computed, not what they are.

A backend is chosen once per run (:func:`make_backend`) and prepared for its model (it then owns
the state; :mod:`.base` is the seam every backend implements). Built in: ``structured`` (default)
and ``assembled`` (the reference), numba CPU backends (:mod:`.cpu`), and ``cuda`` (an NVIDIA GPU,
:mod:`.cuda`; optional dependency numba-cuda). A backend whose results are
bit-identical to the default's would be an execution option like ``threads``; both alternatives
here change the round-off, so the choice is the ``backend`` parameter of ``fem`` (recorded in the
run file and its id). A new backend: one module and :func:`register_backend` (docs/developing.md,
"A new backend").
"""

from ...params import ParameterError
from .base import CONVERGED, FIELDS, MARGIN, MAX_ITER_REACHED, QUIET, Backend
from .cpu import AssembledBackend, StructuredBackend
from .cuda import CudaBackend

__all__ = ["BACKENDS", "DEFAULT_BACKEND", "Backend", "make_backend", "register_backend", "FIELDS", "CONVERGED",
           "MARGIN", "QUIET", "MAX_ITER_REACHED"]

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
register_backend(CudaBackend)


def make_backend(name=DEFAULT_BACKEND, threads=1):
    """The backend ``name`` with ``threads`` threads (to be prepared for a model, :meth:`.base.Backend.prepare`).

    Raises
    ------
    stickslip.params.ParameterError
        If no backend of that name is registered, or it cannot run on this machine (the message says why).
    """
    if name not in BACKENDS:
        raise ParameterError(f"parameter 'backend': {name!r} is not a backend; expected one of "
                             f"{', '.join(sorted(BACKENDS))}")
    reason = BACKENDS[name].unavailable()
    if reason:
        raise ParameterError(f"parameter 'backend': {name!r} cannot run on this machine: {reason}")
    return BACKENDS[name](threads=threads)
