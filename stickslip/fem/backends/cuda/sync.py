"""How the threads of a realisation meet and sum: the bounded barrier of its blocks, fixed-order trees.

- :func:`build` ``barrier``: the ``G`` blocks of a realisation meet at an integer counter (one atomic
  add per block, then a spin on the counter, no floating-point atomics). The spin is **bounded**: past
  ``deadline`` clock cycles (the SM's ``%clock64``; nanoseconds on numba's simulator) the block gives
  up and the kernel ends its realisation with :data:`BARRIER_TIMEOUT`, which the host raises
  (:mod:`.launch`): a block that never arrives (not co-resident, or a logic error) is an error, never a
  hang.
- ``tile_tree``: a tile's slot values summed by a binary tree over its ``tile`` slots (fixed order).
- ``tile_sums``: the tiles' sums added by :data:`.layout.LEAVES` leaves (leaf ``l``: tiles ``l, l + LEAVES,
  ...`` in order) and a binary tree over the leaves; every block of a realisation computes the same bits.
"""

import time
from types import SimpleNamespace

from numba import config, cuda

from .layout import LEAVES

__all__ = ["build", "BARRIER_TIMEOUT", "cycles"]

#: Status of a realisation whose blocks did not all meet at a barrier within the deadline.
BARRIER_TIMEOUT = 5

if config.ENABLE_CUDASIM:
    def cycles():
        """The clock the deadline counts (on the simulator: nanoseconds; a call yields to the other threads)."""
        time.sleep(0)
        return time.perf_counter_ns()
else:
    from llvmlite import ir
    from numba.core import types
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


def build(device):
    """The synchronisation device functions, compiled by ``device`` (module docstring)."""
    clock = device(cycles)

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

    return SimpleNamespace(clock=clock, barrier=device(barrier), tile_tree=device(tile_tree),
                           tile_sums=device(tile_sums))
