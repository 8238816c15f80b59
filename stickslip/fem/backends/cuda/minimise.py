"""The minimisation kernel: up to ``nsteps`` time steps of every listed realisation, one barrier per step.

Realisation ``m`` of a launch is computed by ``G`` blocks; block ``part`` takes the tiles ``part, part + G,
...`` (:mod:`.layout`). A time step ``s`` of a tile is one fused pass (:mod:`.tiles`): its elements, then
for every node the force (plate rows from the stencils in shared memory, interface terms, drive), the
velocity-Verlet correction, the residual's terms, the **next** displacement ``u_{s+1}`` (into the other of
two buffers) and its layers' averages; the tile's sums go to the partials of parity ``s``. Then the
realisation's blocks meet at **the one barrier of the step** (:mod:`.sync`, bounded). After it every
block sums the partials of step ``s`` in the same fixed order and takes the same decision about step ``s``
(*one step late*: the residual criterion, the margin, the quiet window, the step limit, the event buffer);
if it stops, the state of step ``s`` is still held whole (``u_s`` in its buffer, the prediction
``u_{s+1}`` in the other is dropped); otherwise the layers' averages of ``u_{s+1}`` give the drive of
step ``s + 1``. Nothing persists in a block between launches: what the decision needs (step count,
the residual's runs below ``tol``, the quiet counter, the event count) is the realisation's, in
:class:`.records.Control`, read by every block at the start of a launch, so the blocks per realisation
may change from launch to launch. A full event buffer stops the launch *before* the step is judged
(:data:`EVENTS_FULL`, the rows it needs in ``needed``); the next launch judges it first.
"""

from types import SimpleNamespace

from numba import cuda, float64, int32, int64

from ..base import CONVERGED, MARGIN, MAX_ITER_REACHED, QUIET
from .layout import LEAVES, MAX_LAYERS, MAX_TILE, MAX_TILE_ELEMENTS, MAX_TILE_TRIPLETS
from .sync import BARRIER_TIMEOUT
from .tiles import LAYER_ROW

__all__ = ["build", "RUNNING", "EVENTS_FULL", "ROWS"]

#: Status of a realisation whose minimisation goes on in the next launch.
RUNNING = 3
#: Status of a realisation whose event buffer cannot hold a step's well changes (the host empties or grows it).
EVENTS_FULL = 4
#: Rows of a tile's sums at most (the residual's two norms, every layer's average).
ROWS = LAYER_ROW + MAX_LAYERS


def build(device, items, sync, tiles):
    """The minimisation kernel (plain function; :func:`numba.cuda.jit` compiles it) and its drive function."""
    barrier, tile_sums = sync.barrier, sync.tile_sums
    load_stencils, elements, step_nodes, publish = tiles.load_stencils, tiles.elements, tiles.step_nodes, tiles.publish

    @device
    def drive(launch, mesh, state, m, leaves, out):
        """Thread 0: from the layers' averages ``leaves[LAYER_ROW + l, 0]`` into ``out`` [4, MAX_LAYERS]: the
        averages, the drive per unit weight, the layers' targets, and (``out[3, 0]``) the free lever's position."""
        if cuda.threadIdx.x == 0:
            nlayer = mesh.nlayer
            position = 0.0
            if launch.free_lever:
                num = state.lever[m, 0]
                den = 1.0
                for layer in range(nlayer):
                    if mesh.drive_active[layer]:
                        num += mesh.lever_ratio[layer] * leaves[LAYER_ROW + layer, 0]
                        den += mesh.lever_ratio[layer] ** 2
                position = num / den
            out[3, 0] = position
            for layer in range(nlayer):
                ubar = leaves[LAYER_ROW + layer, 0]
                goal = state.target[m, layer]
                if launch.free_lever and mesh.drive_active[layer]:
                    goal = mesh.lever_ratio[layer] * position
                out[0, layer] = ubar
                out[1, layer] = state.k_drive[m] * (ubar - goal) * mesh.layer_volume[layer]
                out[2, layer] = goal
        cuda.syncthreads()

    @device
    def sums(mesh, state, m, parity, leaves, counts, t, bd):
        """Every block: step ``parity``'s sums over the tiles (``leaves[r, 0]``) and flags (``counts[0:3]``)."""
        if t == 0:
            counts[0] = 0
            counts[1] = 0
            counts[2] = 0
        tile_sums(state.partials[m, parity], mesh.ntile, 0, LAYER_ROW + mesh.nlayer, leaves, t, bd)
        for k in range(t, mesh.ntile, bd):
            cuda.atomic.max(counts, 0, state.flags[m, parity, k, 0])
            cuda.atomic.max(counts, 1, state.flags[m, parity, k, 1])
            cuda.atomic.add(counts, 2, state.flags[m, parity, k, 2])
        cuda.syncthreads()

    @device
    def record_events(mesh, state, control, m, part, G, parity, count, time):
        """Thread 0 of every block: the well changes of Gauss point 0 of the elements its tiles own, from row
        ``count`` in element order; ``previous`` follows."""
        if cuda.threadIdx.x == 0:
            offset = count
            for k in range(mesh.ntile):
                hops_k = state.flags[m, parity, k, 2]
                if k % G == part and hops_k > 0:
                    row = offset
                    for j in range(mesh.tile_element_ptr[k], mesh.tile_element_ptr[k + 1]):
                        e = mesh.tile_elements[j]
                        if mesh.tile_owns[j]:
                            hops = state.idx[m, e, 0] - state.previous[m, e]
                            direction = 1.0 if hops > 0 else -1.0
                            for _ in range(abs(hops)):
                                control.events[m, row, 0] = e
                                control.events[m, row, 1] = time
                                control.events[m, row, 2] = direction
                                row += 1
                            state.previous[m, e] = state.idx[m, e, 0]
                offset += hops_k
        cuda.syncthreads()

    @device
    def criteria(control, m, value, moved, near, done, runs):
        """The decision on a judged step (the CPU's order of the criteria); ``runs`` [4] is updated."""
        tol = control.tol[m]
        runs[0] = 0 if value >= tol else runs[0] + 1
        runs[1] = 0 if value >= tol * tol else runs[1] + 1
        runs[2] = 0 if value > runs[4] else runs[2] + 1
        runs[4] = value
        ntol = control.niter_tol[m]
        if (runs[0] >= ntol and runs[2] >= ntol - 1) or runs[1] >= ntol:
            return CONVERGED
        if near:
            return MARGIN
        if control.quiet[m] > 0:
            runs[3] = 0 if moved else runs[3] + 1
            if runs[3] >= control.quiet[m]:
                return QUIET
        if done >= control.max_iter[m]:
            return MAX_ITER_REACHED
        return RUNNING

    @device
    def judge(mesh, state, control, m, part, G, parity, done, time, leaves, counts, runs, shared):
        """Every thread of every block, after the step's sums: the verdict on step ``done``."""
        res, ext = leaves[0, 0], leaves[1, 0]
        value = (res / ext) ** 0.5 if ext > 0.0 else res ** 0.5
        count = shared[1]
        if control.record[m] and counts[2] > 0:
            if count + counts[2] > control.events.shape[1]:
                return EVENTS_FULL
            record_events(mesh, state, control, m, part, G, parity, count, time)
            if cuda.threadIdx.x == 0:
                shared[1] = count + counts[2]
        verdict = criteria(control, m, value, counts[0], counts[1], done, runs)
        cuda.syncthreads()
        return verdict

    @device
    def finish(mesh, state, control, m, part, G, verdict, done, judged, time, drive_out, runs, shared, counts):
        """The end of a launch: a final state in buffer 0 (quenched if converged); the realisation's counters."""
        t, bd = cuda.threadIdx.x, cuda.blockDim.x
        if verdict != RUNNING and verdict != EVENTS_FULL and verdict != BARRIER_TIMEOUT:
            for k in range(part, mesh.ntile, G):
                for s in range(t, mesh.tile, bd):
                    n = mesh.slot_node[k * mesh.tile + s]
                    if n >= 0:
                        for d in range(2 * n, 2 * n + 2):
                            if done % 2 == 1:
                                state.u[m, 0, d] = state.u[m, 1, d]
                            if verdict == CONVERGED:
                                state.v[m, d] = 0.0
                                state.a[m, d] = 0.0
            if part == 0 and t == 0:
                for layer in range(mesh.nlayer):
                    state.ubar[m, layer] = drive_out[0, layer]
                    state.target[m, layer] = drive_out[2, layer]
                state.lever[m, 1] = drive_out[3, 0]
        if part == 0 and t == 0:
            control.done[m] = done
            control.judged[m] = judged
            control.status[m] = verdict
            control.needed[m] = counts[2] if verdict == EVENTS_FULL else 0
            control.nevent[m] = shared[1]
            for j in range(4):
                control.runs[m, j] = int64(runs[j])
            control.last[m] = runs[4]
            state.clock[m] = time

    @device
    def resume(state, control, m, runs, shared, t):
        """A launch's start: the realisation's counters into ``runs`` [5] and (thread 0) its event count into
        ``shared[1]``; returns its steps done, whether the last was judged, its clock, and the well a Gauss point
        may reach before the margin stops it."""
        for j in range(4):
            runs[j] = control.runs[m, j]
        runs[4] = control.last[m]
        if t == 0:
            shared[1] = control.nevent[m]
        margin = control.margin[m]
        limit = state.ny[m] - margin if margin > 0 else state.ny[m] + 1
        return control.done[m], control.judged[m], state.clock[m], limit

    @device
    def start(launch, mesh, state, control, m, part, G, done, judged, time, leaves, counts, runs, shared, drive_out, t,
              bd):
        """The sums of step ``done`` and, if it was not judged (a full event buffer stopped the last launch before),
        the drive of its state and its verdict; returns the verdict (:data:`RUNNING` if judged) and ``judged``."""
        verdict = RUNNING
        if not judged:  # stopped before this step was judged (a full event buffer): the drive of its state first
            sums(mesh, state, m, (done + 1) % 2, leaves, counts, t, bd)
            drive(launch, mesh, state, m, leaves, drive_out)
            sums(mesh, state, m, done % 2, leaves, counts, t, bd)
            verdict = judge(mesh, state, control, m, part, G, done % 2, done, time, leaves, counts, runs, shared)
            judged = 0 if verdict == EVENTS_FULL else 1
        else:
            sums(mesh, state, m, done % 2, leaves, counts, t, bd)
        return verdict, judged

    def minimise(law, launch, mesh, state, control):
        """Up to ``launch.nsteps`` time steps of the minimisation of every listed realisation (module docstring)."""
        G = launch.groups
        m = launch.members[cuda.blockIdx.x // G]
        part = cuda.blockIdx.x % G
        t, bd = cuda.threadIdx.x, cuda.blockDim.x
        rows = cuda.shared.array((ROWS, MAX_TILE), float64)
        leaves = cuda.shared.array((ROWS, LEAVES), float64)
        coef = cuda.shared.array((MAX_TILE_TRIPLETS, 12), float64)
        target = cuda.shared.array((MAX_TILE_TRIPLETS, 3, 4), int32)
        fe = cuda.shared.array((MAX_TILE_ELEMENTS, 8), float64)
        drive_out = cuda.shared.array((4, MAX_LAYERS), float64)
        counts = cuda.shared.array(3, int64)
        flags = cuda.shared.array(3, int64)
        shared = cuda.shared.array(2, int64)  # the barrier's verdict, the event count
        ue = cuda.local.array(8, float64)
        strain = cuda.local.array((4, 3), float64)
        runs = cuda.local.array(5, float64)  # control.runs, then the last residual
        done, judged, time, limit = resume(state, control, m, runs, shared, t)
        nrows = LAYER_ROW + mesh.nlayer
        verdict, judged = start(launch, mesh, state, control, m, part, G, done, judged, time, leaves, counts, runs,
                                shared, drive_out, t, bd)
        passed = 0
        steps = 0
        while verdict == RUNNING and steps < launch.nsteps:
            drive(launch, mesh, state, m, leaves, drive_out)
            step = done + 1
            parity = step % 2
            u, u_next = state.u[m, parity], state.u[m, 1 - parity]
            time += launch.dt
            for k in range(part, mesh.ntile, G):
                load_stencils(mesh, k, coef, target, t, bd)
                elements(law, mesh, k, u, state, m, fe, flags, True, limit, control.record[m], True, t, bd, ue,
                         strain)
                step_nodes(mesh, k, m, u, u_next, state, launch.dt, coef, target, fe, drive_out[1], rows, nrows,
                                 t, bd)
                for j in range(t, 3, bd):
                    state.flags[m, parity, k, j] = flags[j]
                publish(rows, nrows, mesh.tile, state.partials[m, parity, k], t, bd)
            passed = barrier(control.counter, m, G, passed, launch.deadline, shared)
            if passed < 0:
                verdict = BARRIER_TIMEOUT
                break
            done = step
            steps += 1
            sums(mesh, state, m, parity, leaves, counts, t, bd)
            verdict = judge(mesh, state, control, m, part, G, parity, done, time, leaves, counts, runs, shared)
            judged = 0 if verdict == EVENTS_FULL else 1
        finish(mesh, state, control, m, part, G, verdict, done, judged, time, drive_out, runs, shared, counts)

    return SimpleNamespace(minimise=minimise, drive=drive, sums=sums, judge=judge, resume=resume, start=start,
                           finish=finish)
