"""The device kernels of the ``cuda`` backend: whole minimisations of a batch of realisations per launch.

Realisation ``m`` of a batch is computed by ``G`` blocks of any number of threads (``G = 1`` in a large
batch: one block per realisation, no two blocks sharing anything; ``G > 1`` spreads one realisation
over the device). Its work items (DOFs, interface elements, chunks of the fixed-order
sums, :mod:`.layout`) are dealt to its ``G`` blocks' threads in turn; its blocks meet at
:func:`member_barrier` (``G > 1``: an integer atomic counter per realisation, spun on; no
floating-point atomics anywhere). A time step is three phases and three barriers:

1. predict ``u`` (every DOF);
2. the plates' rows of the force, every interface element (strain, well, stress, element force), the
   chunks of every layer's average;
3. (every block alone) the layers' averages, the drive; every DOF's force gathered in a fixed order,
   the velocity-Verlet correction, the chunks of the residual's norms;

then every block sums the residual in the same fixed order and takes the same decision (the
residual criterion, the margin, the quiet window, the step limit), so all blocks of a realisation
stop at the same step. A launch makes at most ``nsteps`` steps; the state of the minimisation
(its step count, residual history, quiet counter, status) stays on the device between launches, so
the host reads only a status word per realisation between them. Compiled per law class from the
plain work items of :mod:`.items` (:func:`kernels_for`).
"""

import functools

import numpy as np
from numba import cuda, float64, int64

from ..base import CONVERGED, MARGIN, MAX_ITER_REACHED, QUIET
from ...laws import LAWS
from .items import build
from .layout import LEAVES

__all__ = ["kernels_for", "RUNNING", "EVENTS_FULL", "MAX_LAYERS"]

#: Status of a realisation whose minimisation goes on in the next launch.
RUNNING = 3
#: Status of a realisation whose event buffer is nearly full (the host empties it; the minimisation goes on).
EVENTS_FULL = 4
#: Layers a mesh may have (6 plates and 5 interfaces: the shared-memory tree holds this many sums).
MAX_LAYERS = 11

_L = LEAVES
_ROWS = MAX_LAYERS + 2

if not hasattr(np, "row_stack"):
    # numba-cuda 0.30.4 overloads np.row_stack when its numpy support loads (at the first compilation); NumPy 2.5
    # removed that alias of np.vstack, and the compilation then fails (seen on the GPU machine's numpy 2.5.2)
    np.row_stack = np.vstack  # the tree's rows: the layers' averages, then the residual's two norms


def _device(function):
    return cuda.jit(device=True, inline="always")(function)


@functools.lru_cache(maxsize=None)
def kernels_for(law_name):
    """The kernels for laws named ``law_name`` (compiled on first launch; cached per law).

    Returns
    -------
    types.SimpleNamespace
        ``minimise``, ``evaluate``, ``residual``, ``wells_hold``, ``load``, ``add_u``, ``shift_wells``,
        ``zero_motion`` (cuda kernels, launched by :mod:`.batch`), and ``python`` (the same kernels as
        plain functions, for :func:`numba.cuda.compile`).
    """
    items = build(_device, LAWS[law_name])
    predict, plate_row, interface_element = items.predict, items.plate_row, items.interface_element
    dof_force, correct, residual_terms, chunk_sum_ubar = (items.dof_force, items.correct, items.residual_terms,
                                                          items.chunk_sum_ubar)
    equivalent, well = items.equivalent, items.well

    @_device
    def placement(members, G):
        """Where the calling thread works in a launch of ``G`` blocks per listed realisation.

        Returns ``(m, part, t, bd, gt, nt)``: the realisation ``m``, the block's ``part`` of its ``G`` blocks, the
        thread ``t`` of ``bd`` in the block, and its rank ``gt`` of the ``nt`` threads over the realisation's blocks.
        """
        block = cuda.blockIdx.x
        part = block % G
        t, bd = cuda.threadIdx.x, cuda.blockDim.x
        return members[block // G], part, t, bd, part * bd + t, G * bd

    @_device
    def member_barrier(counter, m, G, passed):
        """All threads of realisation ``m``'s ``G`` blocks meet; ``passed``: barriers this block passed before."""
        cuda.syncthreads()
        if G > 1:
            if cuda.threadIdx.x == 0:
                cuda.threadfence()
                cuda.atomic.add(counter, m, 1)
                target = G * (passed + 1)
                while cuda.atomic.add(counter, m, 0) < target:
                    pass
                cuda.threadfence()
            cuda.syncthreads()
        return passed + 1

    @_device
    def tree(leaves, first, rows, t, bd):
        """Sum the rows ``first:first + rows`` of ``leaves`` [., LEAVES] by a binary tree (all ``bd`` threads call).

        Every level adds leaf ``i + stride`` to leaf ``i`` for ``i < stride``, whichever thread does it.
        """
        stride = _L // 2
        while stride > 0:
            cuda.syncthreads()
            for i in range(t, stride, bd):
                for r in range(first, first + rows):
                    leaves[r, i] = leaves[r, i] + leaves[r, i + stride]
            stride //= 2
        cuda.syncthreads()

    @_device
    def forces(law, m, gt, nt, update_wells, limit, k_ptr, k_col, k_val, iface_dofs, iface_dNdx, iface_dV,
               layer_ptr, layer_xdofs, layer_w, nlayer, layer_chunks, u, f, idx, eps, sig, fe, epsy, ny, ubar_part,
               ue, strain):
        """Phase 2: plate rows into ``f``, interface elements, layer-average chunks; returns (moved, near)."""
        ndof = u.shape[1]
        for d in range(gt, ndof, nt):
            f[m, d] = plate_row(k_ptr, k_col, k_val, u[m], d)
        moved = 0
        near = 0
        for e in range(gt, iface_dofs.shape[0], nt):
            changed, top = interface_element(law, e, u[m], iface_dofs, iface_dNdx, iface_dV, epsy[m], ny[m], idx[m],
                                             eps[m], sig[m], fe[m], update_wells, ue, strain)
            moved = max(moved, changed)
            if top >= limit:
                near = 1
        chunks = _L * layer_chunks
        for item in range(gt, nlayer * chunks, nt):
            layer = item // chunks
            ubar_part[m, layer, item % chunks] = chunk_sum_ubar(layer_ptr[layer], layer_ptr[layer + 1], chunks,
                                                               item % chunks, layer_xdofs, layer_w, u[m])
        return moved, near

    @_device
    def drive(m, t, bd, leader, nlayer, layer_chunks, layer_volume, drive_active, lever_ratio, free_lever, k_drive,
              ubar_part, ubar, target, lever, leaves, scale):
        """Phase 3a, every block alone: the layers' averages (fixed-order sums) and the drive per unit weight."""
        for leaf in range(t, _L, bd):
            for layer in range(nlayer):
                s = 0.0
                for r in range(layer_chunks):
                    s += ubar_part[m, layer, leaf + r * _L]
                leaves[layer, leaf] = s
        tree(leaves, 0, nlayer, t, bd)
        if t == 0:
            position = 0.0
            if free_lever:
                num = lever[m, 0]
                den = 1.0
                for layer in range(nlayer):
                    if drive_active[layer]:
                        num += lever_ratio[layer] * leaves[layer, 0]
                        den += lever_ratio[layer] ** 2
                position = num / den
                if leader:
                    lever[m, 1] = position
            for layer in range(nlayer):
                goal = target[m, layer]
                if free_lever and drive_active[layer]:
                    goal = lever_ratio[layer] * position
                scale[layer] = k_drive[m] * (leaves[layer, 0] - goal) * layer_volume[layer]
                if leader:
                    ubar[m, layer] = leaves[layer, 0]
                    target[m, layer] = goal
        cuda.syncthreads()

    @_device
    def assemble(m, gt, nt, dt, motion, dof_chunks, mass_inv, damping, free, multiplicity, gather_ptr, gather_index,
                 drive_layer, drive_w, scale, f, v, a, fe, res_part):
        """Phase 3b: every DOF's force (and with ``motion`` its Verlet correction), the residual's chunks."""
        ndof = f.shape[1]
        chunks = _L * dof_chunks
        for c in range(gt, chunks, nt):
            res = 0.0
            ext = 0.0
            for d in range(c, ndof, chunks):
                f[m, d] = dof_force(d, f[m, d], gather_ptr, gather_index, fe[m], drive_layer, drive_w, scale)
                if motion:
                    correct(dt, mass_inv, damping, f[m], v[m], a[m], d)
                r, x = residual_terms(free, multiplicity, damping, f[m], v[m], d)
                res += r
                ext += x
            res_part[m, 0, c] = res
            res_part[m, 1, c] = ext

    @_device
    def residual_of(m, t, bd, dof_chunks, res_part, leaves):
        """Every block alone: the relative residual from the chunks of its two norms (fixed order)."""
        for leaf in range(t, _L, bd):
            for row in range(2):
                s = 0.0
                for r in range(dof_chunks):
                    s += res_part[m, row, leaf + r * _L]
                leaves[MAX_LAYERS + row, leaf] = s
        tree(leaves, MAX_LAYERS, 2, t, bd)
        res, ext = leaves[MAX_LAYERS, 0], leaves[MAX_LAYERS + 1, 0]
        cuda.syncthreads()
        if ext > 0.0:
            return (res / ext) ** 0.5
        return res ** 0.5

    @_device
    def residual_chunks(m, gt, nt, dof_chunks, free, multiplicity, damping, f, v, res_part):
        """The residual's chunks of the state as it is (no force evaluation)."""
        ndof = f.shape[1]
        chunks = _L * dof_chunks
        for c in range(gt, chunks, nt):
            res = 0.0
            ext = 0.0
            for d in range(c, ndof, chunks):
                r, x = residual_terms(free, multiplicity, damping, f[m], v[m], d)
                res += r
                ext += x
            res_part[m, 0, c] = res
            res_part[m, 1, c] = ext

    def evaluate(law, members, G, update_wells, free_lever, k_ptr, k_col, k_val, mass_inv, damping, free,
                 multiplicity, iface_dofs, iface_dNdx, iface_dV, gather_ptr, gather_index, drive_layer, drive_w,
                 layer_ptr, layer_xdofs, layer_w, layer_volume, drive_active, lever_ratio, nlayer, layer_chunks,
                 dof_chunks, u, v, a, f, idx, eps, sig, fe, target, ubar, lever, epsy, ny, k_drive, ubar_part,
                 res_part, residual, counter):
        """Evaluate everything that follows from ``u`` (and the drive) for the listed realisations; their residual."""
        m, part, t, bd, gt, nt = placement(members, G)
        leaves = cuda.shared.array((_ROWS, _L), float64)
        scale = cuda.shared.array(MAX_LAYERS, float64)
        ue = cuda.local.array(8, float64)
        strain = cuda.local.array((4, 3), float64)
        forces(law, m, gt, nt, update_wells, ny[m], k_ptr, k_col, k_val, iface_dofs, iface_dNdx, iface_dV,
               layer_ptr, layer_xdofs, layer_w, nlayer, layer_chunks, u, f, idx, eps, sig, fe, epsy, ny, ubar_part,
               ue, strain)
        passed = member_barrier(counter, m, G, 0)
        drive(m, t, bd, part == 0, nlayer, layer_chunks, layer_volume, drive_active, lever_ratio, free_lever, k_drive,
              ubar_part, ubar, target, lever, leaves, scale)
        assemble(m, gt, nt, 0.0, False, dof_chunks, mass_inv, damping, free, multiplicity, gather_ptr, gather_index,
                 drive_layer, drive_w, scale, f, v, a, fe, res_part)
        member_barrier(counter, m, G, passed)
        value = residual_of(m, t, bd, dof_chunks, res_part, leaves)
        if part == 0 and t == 0:
            residual[m] = value

    def minimise(law, members, G, nsteps, dt, free_lever, k_ptr, k_col, k_val, mass_inv, damping, free, multiplicity,
                 iface_dofs, iface_dNdx, iface_dV, gather_ptr, gather_index, drive_layer, drive_w, layer_ptr,
                 layer_xdofs, layer_w, layer_volume, drive_active, lever_ratio, nlayer, layer_chunks, dof_chunks,
                 u, v, a, f, idx, eps, sig, fe, target, ubar, lever, clock, epsy, ny, k_drive, ubar_part, res_part,
                 tol, niter_tol, max_iter, margin, quiet, record, steps, unchanged_steps, history, moved_at, near_at,
                 status, previous, events, nevent, counter):
        """Up to ``nsteps`` time steps of the minimisation of every listed realisation (module docstring)."""
        m, part, t, bd, gt, nt = placement(members, G)
        leaves = cuda.shared.array((_ROWS, _L), float64)
        scale = cuda.shared.array(MAX_LAYERS, float64)
        decision = cuda.shared.array(1, int64)
        ue = cuda.local.array(8, float64)
        strain = cuda.local.array((4, 3), float64)
        ndof = u.shape[1]
        done = steps[m]
        unchanged = unchanged_steps[m]
        limit = ny[m] - margin[m] if margin[m] > 0 else ny[m] + 1
        ntol = niter_tol[m]
        hist = history[m, part]
        passed = 0
        verdict = RUNNING
        for _ in range(nsteps):
            step = done + 1
            for d in range(gt, ndof, nt):
                predict(u[m], v[m], a[m], dt, d)
            if gt == 0:
                clock[m] += dt
            passed = member_barrier(counter, m, G, passed)
            moved, near = forces(law, m, gt, nt, True, limit, k_ptr, k_col, k_val, iface_dofs, iface_dNdx, iface_dV,
                                 layer_ptr, layer_xdofs, layer_w, nlayer, layer_chunks, u, f, idx, eps, sig, fe, epsy,
                                 ny, ubar_part, ue, strain)
            if moved:
                moved_at[m] = step
            if near:
                near_at[m] = step
            passed = member_barrier(counter, m, G, passed)
            drive(m, t, bd, part == 0, nlayer, layer_chunks, layer_volume, drive_active, lever_ratio, free_lever,
                  k_drive, ubar_part, ubar, target, lever, leaves, scale)
            assemble(m, gt, nt, dt, True, dof_chunks, mass_inv, damping, free, multiplicity, gather_ptr,
                     gather_index, drive_layer, drive_w, scale, f, v, a, fe, res_part)
            passed = member_barrier(counter, m, G, passed)
            value = residual_of(m, t, bd, dof_chunks, res_part, leaves)
            done = step
            if t == 0:
                if record[m] and part == 0:
                    count = nevent[m]
                    for e in range(idx.shape[1]):
                        hops = idx[m, e, 0] - previous[m, e]
                        direction = 1.0 if hops > 0 else -1.0
                        for _ in range(abs(hops)):
                            if count < events.shape[1]:
                                events[m, count, 0] = e
                                events[m, count, 1] = clock[m]
                                events[m, count, 2] = direction
                            count += 1
                        previous[m, e] = idx[m, e, 0]
                    nevent[m] = count
                for j in range(ntol - 1):
                    hist[j] = hist[j + 1]
                hist[ntol - 1] = value
                below = True
                below2 = True
                descending = True
                for j in range(ntol):
                    if hist[j] >= tol[m]:
                        below = False
                    if hist[j] >= tol[m] * tol[m]:
                        below2 = False
                    if j > 0 and hist[j] > hist[j - 1]:
                        descending = False
                verdict = RUNNING
                if (below and descending) or below2:
                    verdict = CONVERGED
                elif near_at[m] == step:
                    verdict = MARGIN
                elif quiet[m] > 0:
                    unchanged = 0 if moved_at[m] == step else unchanged + 1
                    if unchanged >= quiet[m]:
                        verdict = QUIET
                if verdict == RUNNING and step >= max_iter[m]:
                    verdict = MAX_ITER_REACHED
                if verdict == RUNNING and record[m] and nevent[m] > events.shape[1] - 8 * idx.shape[1]:
                    verdict = EVENTS_FULL
                decision[0] = verdict
            cuda.syncthreads()
            verdict = decision[0]
            if verdict != RUNNING:
                break
        if verdict == CONVERGED:
            for d in range(gt, ndof, nt):
                v[m, d] = 0.0
                a[m, d] = 0.0
        if part == 0 and t == 0:
            steps[m] = done
            unchanged_steps[m] = unchanged
            status[m] = verdict

    def residual(members, G, dof_chunks, free, multiplicity, damping, f, v, res_part, out, counter):
        """The relative residual of every listed realisation's state as it is."""
        m, part, t, bd, gt, nt = placement(members, G)
        leaves = cuda.shared.array((_ROWS, _L), float64)
        residual_chunks(m, gt, nt, dof_chunks, free, multiplicity, damping, f, v, res_part)
        member_barrier(counter, m, G, 0)
        value = residual_of(m, t, bd, dof_chunks, res_part, leaves)
        if part == 0 and t == 0:
            out[m] = value

    def wells_hold(members, epsy, ny, idx, eps, out):
        """``out[m]`` = 0 if some Gauss point of realisation ``m`` lies outside its held well (one block each)."""
        m = members[cuda.blockIdx.x]
        for item in range(cuda.threadIdx.x, idx.shape[1] * 4, cuda.blockDim.x):
            e, q = item // 4, item % 4
            i = idx[m, e, q]
            x = equivalent(eps[m, e, q, 0], eps[m, e, q, 1], eps[m, e, q, 2])
            if well(epsy[m, e, :ny[m]], x, i) != i:
                out[m] = 0

    def load(members, step, delta_u, delta_target, delta_lever, u, target, lever):
        """Move realisation ``members[0]`` by ``step`` times its load direction (one block per listed realisation)."""
        m = members[cuda.blockIdx.x]
        for d in range(cuda.threadIdx.x, u.shape[1], cuda.blockDim.x):
            u[m, d] += step * delta_u[m, d]
        for layer in range(cuda.threadIdx.x, target.shape[1], cuda.blockDim.x):
            target[m, layer] += step * delta_target[m, layer]
        if cuda.threadIdx.x == 0:
            lever[m, 0] += step * delta_lever[m]

    def add_u(m, dofs, delta, u):
        """``u[m, dofs] += delta`` (distinct DOFs)."""
        i = cuda.grid(1)
        if i < dofs.size:
            u[m, dofs[i]] += delta[i]

    def shift_wells(m, shift, idx):
        """Renumber the held wells of realisation ``m``: ``idx[m, e] -= shift[e]``."""
        e = cuda.grid(1)
        if e < idx.shape[1]:
            for q in range(4):
                idx[m, e, q] -= shift[e]

    def zero_motion(m, v, a):
        """Stop realisation ``m``: ``v = a = 0``."""
        d = cuda.grid(1)
        if d < v.shape[1]:
            v[m, d] = 0.0
            a[m, d] = 0.0

    python = {function.__name__: function for function in (minimise, evaluate, residual, wells_hold, load, add_u,
                                                            shift_wells, zero_motion)}
    compiled = {name: cuda.jit(function) for name, function in python.items()}
    return type("Kernels", (), {**compiled, "python": python})
