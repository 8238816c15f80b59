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

The compiled loop (:func:`minimise_steps`) makes at most :data:`STEPS_PER_CALL` time steps per call and
returns to Python (:data:`RUNNING`) with what it carries from step to step (:class:`Carry`: the residuals
of the last ``niter_tol`` steps, the wells, the counters, the recorded hops); :func:`minimise` calls it
again from there, so the steps are those of one call, bit for bit, and Ctrl-C or SIGTERM stop a
minimisation of up to ``max_iter`` steps within one call (~0.01 s at N = 9, ~0.2 s at N = 162).
"""

from collections import namedtuple

import numpy as np

from ....numba_options import njit
from ..base import CONVERGED, MARGIN, MAX_ITER_REACHED, QUIET
from .dynamics import residual, time_step

__all__ = ["minimise", "minimise_steps", "within_margin", "Carry", "RUNNING", "STEPS_PER_CALL"]

#: Time steps one call of :func:`minimise_steps` makes at most before it returns to Python.
STEPS_PER_CALL = 2048

#: Status of :func:`minimise_steps`: not finished after its steps (call it again).
RUNNING = 3

#: What a minimisation carries from one call of :func:`minimise_steps` to the next.
Carry = namedtuple("Carry", [
    "history",   # float64 [niter_tol]: relative residuals of the last steps (inf before the first)
    "previous",  # int64 [ni]: well of Gauss point 0 of every element at the last step (recording)
    "wells",     # int64 [ni, 4] (quiet > 0, else [0, 4]): the wells at the last change
    "counts",    # int64 [3]: steps made, steps since the last well change (quiet), hops recorded
    "events",    # float64 [capacity, 3]: the recorded hops (grown as needed)
])


@njit
def within_margin(epsy, idx, margin):
    """True if every interface Gauss point is more than ``margin`` wells from the end of its held yield strains ``epsy``."""
    limit = epsy.shape[1] - margin
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
    carry = Carry(history=np.full(niter_tol, np.inf), previous=state.idx[:, 0].copy(),
                  wells=state.idx.copy() if quiet > 0 else np.empty((0, 4), dtype=np.int64),
                  counts=np.zeros(3, dtype=np.int64), events=np.empty((16 if record else 0, 3)))
    while True:
        status, events = minimise_steps(model, work, state, tol, niter_tol, max_iter, margin, record, quiet,
                                        carry, STEPS_PER_CALL)
        carry = carry._replace(events=events)
        if status != RUNNING:
            return status, int(carry.counts[0]), events[:carry.counts[2]]


@njit
def minimise_steps(model, work, state, tol, niter_tol, max_iter, margin, record, quiet, carry, steps):
    """At most ``steps`` time steps of :func:`minimise`, from where ``carry`` says the previous call stopped.

    Parameters
    ----------
    model, work, state, tol, niter_tol, max_iter, margin, record, quiet
        As :func:`minimise`.
    carry : Carry
        Updated in place (its ``events`` may be replaced by a larger array: the one returned).
    steps : int
        Time steps of this call at most.

    Returns
    -------
    status : int
        As :func:`minimise`, or :data:`RUNNING` (call again).
    events : numpy.ndarray
        The recorded hops (``carry.events`` or a larger copy).
    """
    history, previous, wells, counts, events = carry
    tol2 = tol * tol
    ni = state.idx.shape[0]
    unchanged, nevent = counts[1], counts[2]
    first = counts[0] + 1
    for iiter in range(first, min(max_iter, first + steps - 1) + 1):
        counts[0] = iiter
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
            counts[2] = nevent
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
            return CONVERGED, events
        if margin > 0 and not within_margin(state.epsy, state.idx, margin):
            return MARGIN, events
        if quiet > 0:
            unchanged += 1
            for e in range(ni):
                for q in range(4):
                    if state.idx[e, q] != wells[e, q]:
                        wells[e, q] = state.idx[e, q]
                        unchanged = 0
            counts[1] = unchanged
            if unchanged >= quiet:
                return QUIET, events
    if counts[0] >= max_iter:
        counts[0] = max_iter
        return MAX_ITER_REACHED, events
    return RUNNING, events
