"""The second minimisation kernel, *resident tiles*: every block owns one tile for the whole launch.

The same time steps, sums and decisions as :mod:`.minimise` (its functions: the drive, the sums over the
tiles, the verdict, the end of a launch), arranged for the time between two barriers:

- a realisation is spread over exactly its ``ntile`` blocks, block ``part`` computes tile ``part`` in every step
  of the launch (:class:`.launch.Launcher` launches as many realisations at once as the device holds blocks
  together, and the others in the next launch of the same round);
- what a node's thread needs every step is read once per launch: the tile's stencil triplets into shared memory,
  and into registers its node's stencil row and, per DOF, displacement, velocity, acceleration and constants
  (inverse mass, damping, multiplicity, free); the forces, needed at the end only, are kept in shared memory
  (``SLOTS`` nodes per thread: 1 on a GPU, where a block has at least ``tile`` threads; more on numba's
  simulator, whose blocks are 8 threads);
- a step reads what other blocks wrote (displacements, the tiles' sums) before it writes (the next
  displacement, its own sums); the velocities, accelerations, forces, strains and stresses reach device memory
  at the end of the launch only (the strains and stresses by the tile's elements computed once more from the
  final displacement: the same bits as in the step that ended there);
- the barrier of a step is :func:`.sync.build`'s ``barrier_acquire`` (release arrival, acquire polls with
  back-off). The verdict's root stays the power of the tiles kernel and the CPU: ``math.sqrt`` there (ptxas's
  double square root calls a subroutine) made the kernel spill 184 bytes under its register cap;
- a block has ``tile`` threads rounded up to hold every element of its tile, one element per thread (160 for
  tiles of 128 nodes touching 129 elements).

Every sum runs in the order of :mod:`.minimise` (a DOF's terms, a tile's tree, the tiles' leaves), so a
realisation gives the bytes of that kernel (tests/test_fem_cuda_blocks.py).
"""

from numba import config, cuda, float64, int32, int64

from .layout import LEAVES, MAX_LAYERS, MAX_TILE, MAX_TILE_ELEMENTS, MAX_TILE_TRIPLETS
from .minimise import EVENTS_FULL, ROWS, RUNNING
from .sync import BARRIER_TIMEOUT
from .tiles import LAYER_ROW

__all__ = ["build", "SLOTS", "block_threads"]

#: Nodes of a tile one thread of the resident kernel holds: one on a GPU (a block holds at least a tile); on numba's
#: simulator, whose blocks are 8 threads (:func:`.launch.threads_per_block`), a tile's worth.
SLOTS = MAX_TILE // 8 if config.ENABLE_CUDASIM else 1

#: What a thread holds of each DOF of its slots in registers (``motion`` [slot, DOF, 7]): displacement, velocity,
#: acceleration, inverse mass, damping, multiplicity, free.
U, V, A, INVERSE_MASS, DAMPING, MULTIPLICITY, FREE = range(7)


def block_threads(tile, elements):
    """Threads of a block of the resident kernel on a GPU: a tile's nodes and its ``elements``, one per thread, in
    whole warps (160 for 128 nodes touching 129 elements)."""
    return -(-max(tile, elements) // 32) * 32


def build(device, items, sync, tiles, step):
    """The resident kernel (plain function) from the work ``items``, ``sync``, ``tiles`` and :mod:`.minimise`'s
    ``step`` (:func:`.minimise.build`)."""
    verlet, residual_terms, predict = items.verlet, items.residual_terms, items.predict
    barrier, load_stencils, elements, publish = sync.barrier_acquire, tiles.load_stencils, tiles.elements, tiles.publish
    clear, layer_rows, stencil_force = tiles.clear, tiles.layer_rows, tiles.stencil_force
    drive, sums, judge, resume, start, finish = step.drive, step.sums, step.judge, step.resume, step.start, step.finish

    @device
    def hold(mesh, state, m, k, parity, node, stencil, motion, t, bd):
        """This thread's slots of tile ``k`` into registers: node, stencil row and ``motion`` [slot, DOF, :] (:data:`U`:
        the displacement of buffer ``parity``, :data:`V`, :data:`A`, the constants :data:`INVERSE_MASS`,
        :data:`DAMPING`, :data:`MULTIPLICITY`, :data:`FREE`)."""
        for r in range(SLOTS):
            s = t + r * bd
            n = mesh.slot_node[k * mesh.tile + s] if s < mesh.tile else -1
            node[r] = n
            if n >= 0:
                for j in range(4):
                    stencil[r, j] = mesh.slot_stencil[n, j]
                for c in range(2):
                    d = 2 * n + c
                    motion[r, c, INVERSE_MASS] = mesh.mass_inv[d]
                    motion[r, c, DAMPING] = mesh.damping[d]
                    motion[r, c, MULTIPLICITY] = mesh.multiplicity[d]
                    motion[r, c, FREE] = mesh.free[d]
                    motion[r, c, U] = state.u[m, parity, d]
                    motion[r, c, V] = state.v[m, d]
                    motion[r, c, A] = state.a[m, d]

    @device
    def step_slots(mesh, k, u, u_next, dt, coef, target, fe, scale, rows, nrows, node, stencil, motion, force, t,
                   bd):
        """One time step of this thread's slots (:func:`.tiles.step_nodes` on what :func:`hold` holds): the next
        displacement into ``u_next`` and ``motion``, the velocity and acceleration into ``motion``, the forces into
        ``force`` [slot, DOF] (shared)."""
        for r in range(SLOTS):
            s = t + r * bd
            if s < mesh.tile:
                clear(rows, nrows, s)
                n = node[r]
                if n >= 0:
                    fx, fy = stencil_force(mesh, n, stencil[r, 0], stencil[r, 1], stencil[r, 2], stencil[r, 3], u,
                                           coef, target, fe, scale)
                    for c in range(2):
                        f = fx if c == 0 else fy
                        damping = motion[r, c, DAMPING]
                        v, a = verlet(dt, motion[r, c, INVERSE_MASS], damping, f, motion[r, c, V], motion[r, c, A])
                        res, ext = residual_terms(motion[r, c, FREE] != 0.0, motion[r, c, MULTIPLICITY], damping, f, v)
                        rows[0, s] += res
                        rows[1, s] += ext
                        motion[r, c, U] = predict(motion[r, c, U], v, a, dt)
                        motion[r, c, V] = v
                        motion[r, c, A] = a
                        force[s, c] = f
                    for c in range(2):
                        u_next[2 * n + c] = motion[r, c, U]
                    layer_rows(mesh, n, motion[r, 0, U], rows, s)

    @device
    def release(state, m, node, motion, force, t, bd):
        """The held velocities, accelerations and forces into the state (the end of a launch with steps)."""
        for r in range(SLOTS):
            n = node[r]
            if n >= 0:
                for c in range(2):
                    d = 2 * n + c
                    state.v[m, d] = motion[r, c, V]
                    state.a[m, d] = motion[r, c, A]
                    state.f[m, d] = force[t + r * bd, c]

    def resident(law, launch, mesh, state, control):
        """Up to ``launch.nsteps`` time steps of the minimisation of every listed realisation (module docstring)."""
        G = mesh.ntile
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
        force = cuda.shared.array((MAX_TILE, 2), float64)
        node = cuda.local.array(SLOTS, int32)
        stencil = cuda.local.array((SLOTS, 4), int32)
        motion = cuda.local.array((SLOTS, 2, 7), float64)
        done, judged, time, limit = resume(state, control, m, runs, shared, t)
        nrows = LAYER_ROW + mesh.nlayer
        load_stencils(mesh, part, coef, target, t, bd)
        hold(mesh, state, m, part, (done + 1) % 2, node, stencil, motion, t, bd)
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
            elements(law, mesh, part, u, state, m, fe, flags, True, limit, control.record[m], False, t, bd, ue, strain)
            step_slots(mesh, part, u, u_next, launch.dt, coef, target, fe, drive_out[1], rows, nrows, node, stencil,
                       motion, force, t, bd)
            for j in range(t, 3, bd):
                state.flags[m, parity, part, j] = flags[j]
            publish(rows, nrows, mesh.tile, state.partials[m, parity, part], t, bd)
            passed = barrier(control.counter, m, G, passed, launch.deadline, shared)
            if passed < 0:
                verdict = BARRIER_TIMEOUT
                break
            done = step
            steps += 1
            sums(mesh, state, m, parity, leaves, counts, t, bd)
            verdict = judge(mesh, state, control, m, part, G, parity, done, time, leaves, counts, runs, shared)
            judged = 0 if verdict == EVENTS_FULL else 1
        if steps > 0 and verdict != BARRIER_TIMEOUT:
            release(state, m, node, motion, force, t, bd)
            elements(law, mesh, part, state.u[m, done % 2], state, m, fe, flags, True, limit, 0, True, t, bd, ue,
                     strain)
        finish(mesh, state, control, m, part, G, verdict, done, judged, time, drive_out, runs, shared, counts)

    return resident
