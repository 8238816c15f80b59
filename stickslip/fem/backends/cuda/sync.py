"""How the threads of a realisation meet and sum: the bounded barrier of its blocks, fixed-order trees.

- :func:`build` ``barrier``: the ``G`` blocks of a realisation meet at an integer counter (one atomic
  add per block, then a spin on the counter, no floating-point atomics). The spin is **bounded**: past
  ``deadline`` clock cycles (the SM's ``%clock64``; nanoseconds on numba's simulator) the block gives
  up and the kernel ends its realisation with :data:`BARRIER_TIMEOUT`, which the host raises
  (:mod:`.launch`): a block that never arrives (not co-resident, or a logic error) is an error, never a
  hang.
  ``barrier_acquire`` (the resident kernel's, :mod:`.resident`): the same meeting with a release reduction for
  the arrival and acquire loads with a growing back-off (``nanosleep``) for the spin, instead of two full fences
  and an atomic per poll (on the simulator: the same as ``barrier``).
- ``tile_tree``: a tile's slot values summed by a binary tree over its ``tile`` slots (fixed order).
- ``tile_sums``: the tiles' sums added by :data:`.layout.LEAVES` leaves (leaf ``l``: tiles ``l, l + LEAVES,
  ...`` in order) and a binary tree over the leaves; every block of a realisation computes the same bits.
"""

import time
from types import SimpleNamespace

from numba import config, cuda, uint32

from .layout import LEAVES

__all__ = ["build", "BARRIER_TIMEOUT", "cycles"]

#: Status of a realisation whose blocks did not all meet at a barrier within the deadline.
BARRIER_TIMEOUT = 5

if config.ENABLE_CUDASIM:
    def cycles():
        """The clock the deadline counts (on the simulator: nanoseconds; a call yields to the other threads)."""
        time.sleep(0)
        return time.perf_counter_ns()

    def arrive(counter, m):
        """This block arrived at realisation ``m``'s barrier (the simulator: a fence and an atomic add)."""
        cuda.threadfence()
        cuda.atomic.add(counter, m, 1)

    def arrivals(counter, m, pause):
        """The arrivals counted at realisation ``m``'s barrier (the simulator: an atomic read, then a fence)."""
        count = cuda.atomic.or_(counter, m, 0)
        cuda.threadfence()
        return count
else:
    from llvmlite import ir
    from numba.core import types
    from numba.cuda import cgutils
    from numba.cuda.extending import intrinsic

    @intrinsic
    def _clock64(typingctx):
        def codegen(context, builder, signature, args):
            read = ir.InlineAsm(ir.FunctionType(ir.IntType(64), []), "mov.u64 $0, %clock64;", "=l",
                                side_effect=True)
            return builder.call(read, [])
        return types.int64(), codegen

    def cycles():
        """The SM's cycle counter (``%clock64``)."""
        return _clock64()

    def _pointer(context, builder, array_type, array, index):
        """The address of ``array[index]`` (a 1-d array, no wrap-around)."""
        struct = context.make_array(array_type)(context, builder, value=array)
        return cgutils.get_item_pointer(context, builder, array_type, struct, [index], wraparound=False)

    @intrinsic
    def _add_release(typingctx, counter, index):
        """``counter[index] += 1`` by ``red.release.gpu``: the block's earlier writes are visible before it."""
        def codegen(context, builder, signature, args):
            pointer = _pointer(context, builder, signature.args[0], args[0], args[1])
            add = ir.InlineAsm(ir.FunctionType(ir.VoidType(), [pointer.type]), "red.release.gpu.add.u32 [$0], 1;",
                               "l,~{memory}", side_effect=True)
            builder.call(add, [pointer])
        return types.void(counter, index), codegen

    @intrinsic
    def _load_acquire(typingctx, counter, index):
        """``counter[index]`` by ``ld.acquire.gpu``: what was written before the arrivals it counts is visible after."""
        def codegen(context, builder, signature, args):
            pointer = _pointer(context, builder, signature.args[0], args[0], args[1])
            load = ir.InlineAsm(ir.FunctionType(ir.IntType(32), [pointer.type]), "ld.acquire.gpu.u32 $0, [$1];",
                                "=r,l,~{memory}", side_effect=True)
            return builder.call(load, [pointer])
        return types.int32(counter, index), codegen

    def arrive(counter, m):
        """This block arrived at realisation ``m``'s barrier (release)."""
        _add_release(counter, m)

    def arrivals(counter, m, pause):
        """The arrivals counted at realisation ``m``'s barrier (acquire), after ``pause`` ns asleep."""
        if pause > 0:
            cuda.nanosleep(uint32(pause))
        return _load_acquire(counter, m)


def build(device):
    """The synchronisation device functions, compiled by ``device`` (module docstring)."""
    clock, arrive_, arrivals_ = device(cycles), device(arrive), device(arrivals)

    def barrier(counter, m, G, passed, deadline, ok):
        """All threads of realisation ``m``'s ``G`` blocks meet; returns ``passed + 1``, or -1 past the deadline.

        ``counter`` int32 [batch] (zeroed before the launch), ``passed`` the barriers this block passed in the
        launch, ``ok`` an int64 shared scratch of one entry.
        """
        cuda.syncthreads()
        if G == 1:
            return passed + 1
        if cuda.threadIdx.x == 0:
            cuda.threadfence()
            cuda.atomic.add(counter, m, 1)
            goal = G * (passed + 1)
            start = clock()
            ok[0] = 1
            while cuda.atomic.or_(counter, m, 0) < goal:
                if clock() - start > deadline:
                    ok[0] = 0
                    break
            cuda.threadfence()
        cuda.syncthreads()
        if ok[0] == 0:
            return -1
        return passed + 1

    def barrier_acquire(counter, m, G, passed, deadline, ok):
        """As ``barrier``, with a release arrival and acquire polls that back off from 32 ns to 1 us."""
        cuda.syncthreads()
        if G == 1:
            return passed + 1
        if cuda.threadIdx.x == 0:
            arrive_(counter, m)
            goal = G * (passed + 1)
            start = clock()
            ok[0] = 1
            pause = 0
            while arrivals_(counter, m, pause) < goal:
                if clock() - start > deadline:
                    ok[0] = 0
                    break
                pause = min(1024, max(32, 2 * pause))
        cuda.syncthreads()
        if ok[0] == 0:
            return -1
        return passed + 1

    def tile_tree(rows, nrows, tile, t, bd):
        """Sum ``rows[:nrows, :tile]`` into column 0: level by level, ``rows[r, i] += rows[r, i + stride]``."""
        stride = tile // 2
        while stride > 0:
            cuda.syncthreads()
            for item in range(t, nrows * stride, bd):
                r, i = item // stride, item % stride
                rows[r, i] = rows[r, i] + rows[r, i + stride]
            stride //= 2
        cuda.syncthreads()

    def tile_sums(partials, ntile, first, nrows, leaves, t, bd):
        """Sum ``partials[:, first:first + nrows]`` over the tiles into ``leaves[first + r, 0]`` (fixed order)."""
        for item in range(t, nrows * LEAVES, bd):
            r, leaf = first + item // LEAVES, item % LEAVES
            s = 0.0
            for k in range(leaf, ntile, LEAVES):
                s += partials[k, r]
            leaves[r, leaf] = s
        stride = LEAVES // 2
        while stride > 0:
            cuda.syncthreads()
            for item in range(t, nrows * stride, bd):
                r, i = first + item // stride, item % stride
                leaves[r, i] = leaves[r, i] + leaves[r, i + stride]
            stride //= 2
        cuda.syncthreads()

    return SimpleNamespace(clock=clock, barrier=device(barrier), barrier_acquire=device(barrier_acquire),
                           tile_tree=device(tile_tree),
                           tile_sums=device(tile_sums))
