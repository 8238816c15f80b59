"""Aftershock trials: a stored state held at its load, every thermally activated event recorded with the interfaces it moved.

The paper's outlook asks whether aftershocks appear in the top layers. After a slip (the stored event
increment of a mainshock, at rest at the post-slip load) the drive is held for ``hold_time`` while
the blocks hop and the junctions are redrawn; every event of the hold (a hop, an athermal kick, a
redraw that makes a block yield, with the avalanche it triggers) is recorded with its time since the
start of the hold and the number of blocks of each interface that changed well (Gauss point 0). A
**control** hold starts from a state in the middle of a stick phase instead, brought back along the
linear response (an elastic unloading; a block pushed out of its well by it is relaxed first) until
one interface's stress equals a given one (the mainshock's post-slip stress): the same stress, but
no recent slip. Trials of the same replica draw the same random numbers.
"""

import numpy as np

from ..observables import Observer
from .aging import thermal_protocol
from .holds import REPLICAS
from .protocol import STREAM

__all__ = ["aftershock_trial", "MAX_HOLD_EVENTS"]

#: Events after which a hold is cut short (its ``complete`` is then False).
MAX_HOLD_EVENTS = 300


class _Unload:
    """A perturbation: a step along the linear response (negative: unloading)."""

    def __init__(self, loading, step):
        self.loading, self.step = loading, step

    def apply(self):
        self.loading.load(self.step)


def _stress(observer, a):
    return observer.observe(observer.well_index())[f"sigd_{2 * a - 1}"]


def _unload_to(simulation, protocol, observer, a, stress):
    """Bring the load back along the linear response until interface ``a``'s stress is ``stress`` [sig0]."""
    s, stack = simulation, simulation.stack
    start = stack.checkpoint()
    now = _stress(observer, a)
    probe = -1.0
    s.loading.load(probe)
    slope = (_stress(observer, a) - now) / probe
    stack.rollback(start)
    step = min((stress - now) / slope, 0.0) if slope > 0 else 0.0
    s.loading.load(step)
    if stack.changed_since(start):
        stack.rollback(start)
        protocol.perturb_and_relax(_Unload(s.loading, step), s.params.margin)
        protocol.after_event(s.params.margin, 0)


def aftershock_trial(simulation, state, hold_time, replica, control=None, max_events=MAX_HOLD_EVENTS):
    """One aftershock (or control) hold from a stored state (module docstring).

    Parameters
    ----------
    simulation : stickslip.fem.simulation.Simulation
        Of a thermal run.
    state : stickslip.formats.fem_run.StoredState
        A stored increment (:meth:`stickslip.formats.fem_run.RunFile.state`).
    hold_time : float
        Duration of the hold [time].
    replica : int
        Index of the trial's random stream.
    control : tuple, optional
        ``(a, stress)``: unload first until interface ``a``'s stress is ``stress`` [sig0] (a control hold).
    max_events : int, optional

    Returns
    -------
    dict
        ``events`` (float64 [k, 1 + n]: time since the hold's start and the blocks of every interface
        that changed well, for each event within the hold), ``stress`` (float64 [n]: every interface's
        stress at the hold's start [sig0]), ``complete`` (the hold reached ``hold_time`` within
        ``max_events`` events).
    """
    s, p = simulation, simulation.params
    s.stack.restore(state)
    observer = Observer(s)
    protocol = thermal_protocol(s.stack, s.model, s.loading, s.relaxation, p, s.mesh, s.constants,
                                stream=STREAM + REPLICAS * (replica + 1))
    if control is not None:
        _unload_to(s, protocol, observer, *control)
    interfaces = range(1, p.plates)
    start = observer.observe(observer.well_index())
    t0 = s.stack.time
    protocol.schedule.hold_now(t0, hold_time)
    events, complete = [], False
    previous = observer.well_index()
    for k in range(1, max_events + 1):
        protocol.step(p.margin, 2 * k - 1)  # the load to the next event
        t = s.stack.time - t0
        if t >= hold_time:
            complete = True
            break
        previous = observer.well_index()
        protocol.step(p.margin, 2 * k)  # that event
        event = observer.observe(previous)
        previous = observer.well_index()
        events.append([t, *(event[f"A_a{a}"] for a in interfaces)])
    return {"events": np.asarray(events, dtype=np.float64).reshape(-1, p.plates),
            "stress": np.array([start[f"sigd_{2 * a - 1}"] for a in interfaces]), "complete": complete}
