"""Energy minimisation by damped inertial dynamics, with optional recording of block failures.

Time steps are made until the relative residual (:func:`.dynamics.residual`) of
the last ``niter_tol`` steps are all below ``tol`` and non-increasing, or all
below ``tol^2``; then velocity and acceleration are set to zero (quench).
With a margin, the minimisation also stops (status ``MARGIN``) as soon as a Gauss point
of an interface comes within ``margin`` wells of the end of its yield-strain
sequence (the reference's ``minimise_boundcheck``: index ``>= ny - margin``).

With ``quiet > 0`` it also stops (status ``QUIET``, not quenched) once ``quiet``
consecutive steps changed no well index, so that the caller can try the equilibrium
solve of ``relaxation = exact`` (:class:`stickslip.fem.relaxation.ExactRelaxation`) and call again.

Recording (for the event maps): every change of the well index of Gauss point
0 of an interface element is stored as one row per hop
``(element, time, direction)``, direction +1 or -1.
Reference: shared/reference-model.md, section 8d.
"""

import numpy as np

from ....numba_options import njit
from ..base import CONVERGED, MARGIN, MAX_ITER_REACHED, QUIET
from .dynamics import residual, time_step

__all__ = ["minimise", "within_margin"]


@njit
def within_margin(model, idx, margin):
    """True if every interface Gauss point is more than ``margin`` wells from the end of its sequence."""
    limit = model.epsy.shape[1] - margin
    for e in range(idx.shape[0]):
        for q in range(4):
            if idx[e, q] >= limit:
                return False
    return True


@njit
def _grow(events, n):
    if n < events.shape[0]:
        return events
    bigger = np.empty((2 * events.shape[0] + 16, events.shape[1]))
    bigger[:n] = events[:n]
    return bigger


@njit
def minimise(model, work, state, tol, niter_tol, max_iter, margin, record, quiet=0):
    """Minimise by time stepping (see module doc).

    Parameters
    ----------
    model : Model
    work : CpuWork
        The CPU backend's workspace (:mod:`.backend`).
    state : State
        Modified in place (forces must be up to date on entry).
    tol : float
        Relative residual tolerance.
    niter_tol : int
        Number of consecutive steps checked.
    max_iter : int
        Maximum number of steps.
    margin : int
        Stop when an index comes within this many wells of the end (0: never).
    record : bool
        Record block failures (Gauss point 0).
    quiet : int, optional
        If > 0, also stop (returning ``QUIET``, without quench) once ``quiet``
        consecutive steps changed no well index of any Gauss point; the caller may then
        solve for the equilibrium within the current wells (:mod:`stickslip.fem.equilibrium`) and
        call again to continue. 0: never (the paper's protocol).

    Returns
    -------
    status : int
        :data:`..base.CONVERGED` (quenched), ``MARGIN``, ``QUIET`` or ``MAX_ITER_REACHED``.
    niter : int
        Steps made by this call.
    events : numpy.ndarray
        float64 [nevent, 3]: (interface element, time, direction) (empty unless ``record``).
    """
    history = np.full(niter_tol, np.inf)
    tol2 = tol * tol
    ni = state.idx.shape[0]
    previous = state.idx[:, 0].copy()
    wells = state.idx.copy() if quiet > 0 else np.empty((0, 4), dtype=np.int64)
    unchanged = 0
    events = np.empty((16 if record else 0, 3))
    nevent = 0
    for iiter in range(1, max_iter + 1):
        time_step(model, work, state)
        if record:
            for e in range(ni):
                hops = state.idx[e, 0] - previous[e]
                direction = 1.0 if hops > 0 else -1.0
                for _ in range(abs(hops)):
                    events = _grow(events, nevent)
                    events[nevent, 0] = e
                    events[nevent, 1] = state.t[0]
                    events[nevent, 2] = direction
                    nevent += 1
                previous[e] = state.idx[e, 0]
        history[:-1] = history[1:]
        history[-1] = residual(model, state)
        below = True
        below2 = True
        descending = True
        for j in range(niter_tol):
            if history[j] >= tol:
                below = False
            if history[j] >= tol2:
                below2 = False
            if j > 0 and history[j] > history[j - 1]:
                descending = False
        if (below and descending) or below2:
            state.v[:] = 0.0
            state.a[:] = 0.0
            return CONVERGED, iiter, events[:nevent]
        if margin > 0 and not within_margin(model, state.idx, margin):
            return MARGIN, iiter, events[:nevent]
        if quiet > 0:
            unchanged += 1
            for e in range(ni):
                for q in range(4):
                    if state.idx[e, q] != wells[e, q]:
                        wells[e, q] = state.idx[e, q]
                        unchanged = 0
            if unchanged >= quiet:
                return QUIET, iiter, events[:nevent]
    return MAX_ITER_REACHED, max_iter, events[:nevent]
