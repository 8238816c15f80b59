"""numba's CUDA simulator with the blocks of a launch running at once: the multi-block paths without a GPU.

The simulator runs a launch's blocks one after another, so a realisation spread over ``G > 1`` blocks
(:mod:`.minimise`) would wait at its first barrier for blocks that have not started: there it meets its
deadline and fails (:class:`.launch.BarrierTimeout`), as blocks that are not co-resident would on a GPU.
:func:`concurrent_blocks` makes the simulator run all blocks of a launch at once (each block's threads
in its own Python threads, as the simulator does; shared memory per block) and report ``capacity``
co-resident blocks, so the
barriers, the fixed-order sums across blocks and the choice of ``G`` run in tests
(tests/test_fem_cuda_blocks.py). Needs ``NUMBA_ENABLE_CUDASIM=1``.
"""

import contextlib
import functools
import sys
import threading
import traceback

import numpy as np

__all__ = ["concurrent_blocks", "co_resident"]


def _concurrent_call(original):
    """A ``FakeCUDAKernel.__call__`` that runs a launch's blocks at once (kernels; device functions unchanged)."""
    from numba.cuda.simulator import kernel as sim
    from numba.cuda.simulator.kernelapi import FakeCUDAModule, swapped_cuda_module
    from numba.cuda.simulator.cudadrv.devicearray import FakeCUDAArray, FakeWithinKernelCUDAArray

    @functools.wraps(original)
    def call(self, *args):
        if self._device or sim._kernel_context:
            return original(self, *args)
        grid_dim, block_dim = sim.normalize_kernel_dimensions(self.grid_dim, self.block_dim)
        fake = FakeCUDAModule(grid_dim, block_dim, self.dynshared_size)
        if any(isinstance(arg, np.ndarray) for arg in args):
            raise TypeError("concurrent_blocks: launch with device arrays (host arrays are not copied back)")
        arguments = [FakeWithinKernelCUDAArray(arg) if isinstance(arg, FakeCUDAArray) else arg for arg in args]
        errors = []

        def block(point):
            try:
                sim.BlockManager(self.fn, grid_dim, block_dim, self._debug).run(point, *arguments)
            except BaseException as error:  # raised in the caller after every block ended
                errors.append(error)

        with sim._push_kernel_context(fake), swapped_cuda_module(self.fn, fake):
            threads = [threading.Thread(target=block, args=(point,)) for point in np.ndindex(*grid_dim)]
            for thread in threads:
                thread.start()
            for thread in threads:
                thread.join()
        if errors:
            raise errors[0]

    return call


def _shared_array_per_block(self, shape, dtype, alignment=None):
    """``cuda.shared.array`` of the block of the calling thread (the simulator's own is one per call site and launch,
    right only when blocks run one after another)."""
    from numba.cuda import types
    from numba.cuda.np import numpy_support

    if isinstance(dtype, types.Type):
        dtype = numpy_support.as_dtype(dtype)
    caller = traceback.extract_stack(sys._getframe())[-2][0:2]
    block = threading.current_thread().blockIdx
    key = (caller, block.x, block.y, block.z)
    with _SHARED_LOCK:
        if key not in self._allocations:
            self._allocations[key] = np.empty(shape, dtype)
        return self._allocations[key]


_SHARED_LOCK = threading.Lock()


@contextlib.contextmanager
def co_resident(capacity):
    """Within the context, the simulator reports ``capacity`` co-resident blocks (its blocks still run one at a time)."""
    from numba.cuda.simulator import kernel as sim

    original = sim.FakeOverload.max_cooperative_grid_blocks
    sim.FakeOverload.max_cooperative_grid_blocks = lambda self, blockdim, dynsmemsize=0: capacity
    try:
        yield
    finally:
        sim.FakeOverload.max_cooperative_grid_blocks = original


@contextlib.contextmanager
def concurrent_blocks(capacity):
    """Within the context, the simulator runs every launch's blocks at once and reports ``capacity`` co-resident
    blocks (module docstring)."""
    from numba.cuda.simulator import kernel as sim
    from numba.cuda.simulator.kernelapi import FakeCUDAShared

    original, shared = sim.FakeCUDAKernel.__call__, FakeCUDAShared.array
    sim.FakeCUDAKernel.__call__ = _concurrent_call(original)
    FakeCUDAShared.array = _shared_array_per_block
    try:
        with co_resident(capacity):
            yield
    finally:
        sim.FakeCUDAKernel.__call__ = original
        FakeCUDAShared.array = shared
