"""Hold trials: a stored state of a thermal run held at a load below its athermal threshold, then reloaded.

The slide-hold-slide experiment done on the states of a run, paired: every trial starts from the
same stored state, so that the hold time is the only difference between trials of that state.
From a stored state the load is brought (an elastic step along the linear response) to ``below``
[eps0 of imposed shear] under the state's athermal threshold: a step forward where the state is
farther from it, an elastic unload where it is nearer (as the state a slip leaves often is at a soft
drive), as far as no block leaves its well (then the hold is nearer than ``below``, and the trial says
how near: ``held_below``); the drive is held there for
``hold_time`` while the blocks hop (creep); then it is driven on at the run's drive rate until the
next slip event (every block of some interface in another well), which may also come during the
hold (delayed failure). The trial records the peak stress of the slipping interface (its stress at
the load increment before the slip), the creep during the hold (the interface's slip in well hops),
and every block's forward barrier
at the start and at the end of the hold (the state at rest after the last hop within it).

With ``each > 0`` the trial goes on after the first slip until every interface has slipped ``each``
times, and records every slip: its interface, peak, time, and the share of the interface's blocks
that changed well (Gauss point 0) between the end of the hold (or the interface's previous slip) and
the load before the slip (the precursors; with junction aging, the blocks whose junction the
precursors renewed), so that a second slip tells whether the first one erased the memory of the hold. With junction aging the
trial also records the junctions of every interface at the end of the hold.
"""

import numpy as np

from ..observables import Observer
from .aging import thermal_protocol
from .barriers import FORWARD, block_barriers
from .protocol import STREAM, drive_scale

__all__ = ["hold_trial", "MAX_EVENTS", "REPLICAS"]

#: Events after which a trial gives up waiting for a slip.
MAX_EVENTS = 2000

#: Spacing of the random streams of trials (each trial's increments draw from its own range).
REPLICAS = 2**40


def _barriers(simulation, unit):
    model, stack = simulation.model, simulation.stack
    idx, eps = stack.read("idx", "eps")
    out = np.empty((model.iface_dofs.shape[0], 2))
    block_barriers(model.law, stack.yield_strains, idx, eps, simulation.loading.response.delta_eps, model.iface_dV, 0.0,
                   out)
    return out[:, FORWARD] / unit


def _slips(observer):
    """Plastic slip of every interface in well hops: the sum of its blocks' well indices (Gauss point 0)."""
    return observer.well_index().sum(axis=1).astype(np.float64)


def _junctions(stack, a, N):
    """Mean depth [G eps0^2 h^2], mean widening [eps0] and capped share of the junctions of interface ``a`` (NaN: none)."""
    junctions = stack.modifier  # an aging run's junctions (:class:`.aging.AgingProtocol`); None without aging
    mine = slice((a - 1) * N, a * N)
    if junctions is None or not np.any(junctions.well[mine] >= 0):
        return [np.nan] * 3
    widening, capped = junctions.widenings(stack.wells)
    whole = junctions.well[mine] >= 0
    return [junctions.depth[mine][whole].mean(), widening[mine][whole].mean() / junctions.eps0,
            capped[mine][whole].mean()]


def hold_trial(simulation, state, hold_time, below, replica, each=0):
    """One hold trial from a stored state (module docstring).

    Parameters
    ----------
    simulation : stickslip.fem.simulation.Simulation
        Of a thermal run.
    state : stickslip.formats.fem_run.StoredState
        A stored increment (:meth:`stickslip.formats.fem_run.RunFile.state`).
    hold_time : float
        Duration of the hold [time].
    below : float
        Imposed shear between the hold's load and the athermal threshold [eps0] (>= 0).
    replica : int
        Index of the trial's random stream (trials with the same index draw the same numbers).
    each : int, optional
        0: the trial ends at the first slip; ``k > 0``: once every interface has slipped ``k`` times.

    Returns
    -------
    dict
        ``t0`` (time at the hold's start), ``held_below`` (the imposed shear between the hold's load and the
        athermal threshold [eps0]: ``below``, or less where the unload to it would move a block out of its well),
        ``peak`` [sig0] and ``interface`` (lowest slipping one; NaN and
        0 if no slip came within :data:`MAX_EVENTS` events), ``mu_start`` [sig0] (its stress at the hold's
        start), ``failed_in_hold`` (bool), ``t_slip`` (time from the hold's start to the slip),
        ``hold_hops``, ``events``; ``creep`` (float64 [k, 1 + n]: time since the hold's start and the
        slip of every interface since then in well hops of its blocks (Gauss point 0), after each of the
        ``k`` hops within the hold);
        ``barriers_start``, ``barriers_end`` (float64 [ni]: forward barrier of every block /
        temperature, at the start and the end of the hold); ``slips`` (float64 [m, 7]: interface, peak
        [sig0], time since the hold's start, precursor share, and the interface's junctions at the peak,
        :func:`_junctions` (NaN without aging), of every slip of an interface in order).
    """
    s, p = simulation, simulation.params
    s.stack.restore(state)
    scale = drive_scale(s.loading.response, p.eps0, s.mesh)
    ds_c = s.loading.step_size(False)
    if ds_c >= below / scale:
        s.loading.load(ds_c - below / scale)
        held_below = below
    else:
        unload = s.loading.unload_size(below / scale - ds_c)
        s.loading.load(-unload)
        held_below = (ds_c + unload) * scale
    observer = Observer(s)
    protocol = thermal_protocol(s.stack, s.model, s.loading, s.relaxation, p, s.mesh, s.constants,
                                stream=STREAM + REPLICAS * (replica + 1))
    unit = protocol.energy_unit * p.temperature
    t0 = s.stack.time
    protocol.schedule.hold_now(t0, hold_time)
    interfaces = range(1, p.plates)
    names = [f"sigd_{2 * a - 1}" for a in interfaces]
    start = observer.observe(observer.well_index())
    r0 = _slips(observer)
    barriers_start = barriers_end = _barriers(s, unit)
    previous = observer.well_index()
    hold_end = previous.copy()
    creep, slips = [], []
    counts = np.zeros(p.plates, dtype=np.int64)
    result = {"t0": t0, "held_below": held_below, "peak": np.nan, "interface": 0, "mu_start": np.nan, "failed_in_hold": False,
              "t_slip": np.nan, "hold_hops": 0}
    for k in range(1, MAX_EVENTS + 1):
        protocol.step(p.margin, 2 * k - 1)  # the load to the next event
        load = observer.observe(previous)
        t = s.stack.time - t0
        previous = load_wells = observer.well_index()
        at_peak = [_junctions(s.stack, a, p.N) for a in interfaces]
        protocol.step(p.margin, 2 * k)  # that event
        event = observer.observe(previous)
        previous = observer.well_index()
        if t < hold_time:
            result["hold_hops"] += 1
            creep.append([t, *(_slips(observer) - r0)])
            barriers_end = _barriers(s, unit)
        slipping = [a for a in interfaces if event[f"A_a{a}"] == p.N]
        for a in slipping:
            counts[a] += 1
            slips.append([a, load[names[a - 1]], t, np.mean(load_wells[a - 1] != hold_end[a - 1]), *at_peak[a - 1]])
            hold_end[a - 1] = previous[a - 1]
        if slipping and np.isnan(result["peak"]):
            a = slipping[0]
            result.update(peak=load[names[a - 1]], interface=a, mu_start=start[names[a - 1]],
                          failed_in_hold=bool(t < hold_time), t_slip=t)
        if slipping and np.all(counts[1:] >= each):
            break
        if t < hold_time:
            hold_end = previous.copy()
    result["events"] = k
    result["creep"] = np.asarray(creep, dtype=np.float64).reshape(-1, p.plates)
    result["barriers_start"], result["barriers_end"] = barriers_start, barriers_end
    result["slips"] = np.asarray(slips, dtype=np.float64).reshape(-1, 7)
    return result
