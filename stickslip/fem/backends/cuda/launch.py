"""How a batch's kernels are launched: threads per block, blocks per realisation, co-residency, errors.

A realisation spread over ``G > 1`` blocks waits at barriers for all of them, so all blocks of a launch
must be resident on the device at once: :meth:`Launcher.groups_for` asks the compiled kernel how many
blocks the device holds at once (its occupancy: ``max_cooperative_grid_blocks``) and never launches more
than that with ``G > 1``; ``G = 1`` (a block per realisation) waits for no other block and needs no
such bound. Should a block still not arrive (another program on the device), the barrier's deadline
ends the launch and :class:`BarrierTimeout` is raised, never a hang.
"""

import collections
import contextlib
import sys
import threading

import numba
import numpy as np
from numba import config, cuda

from .kernels import MINIMISERS, kernels_for
from .records import Launch
from .resident import block_threads
from .sync import BARRIER_TIMEOUT

__all__ = ["Launcher", "BarrierTimeout", "LAUNCHES", "launching", "STEPS_PER_LAUNCH", "DEADLINE_CYCLES",
           "threads_per_block"]

#: Time steps of one launch of a minimisation at most (then the host reads the status words and relaunches).
STEPS_PER_LAUNCH = 4096

#: Clock cycles a block waits at a barrier before it gives up (about 10 s at 2 GHz; ns on the simulator).
DEADLINE_CYCLES = 20_000_000_000

#: Held around every launch and while kernels are built: an ensemble's runs launch from their own threads (numba's
#: simulator executes a launch in the caller, is not safe for launches from two threads at once, and replaces the
#: ``cuda`` of the kernels' modules by its own while a launch runs).
LAUNCHES = threading.RLock()

#: The interpreter's thread switch interval [s] during a launch on numba's simulator. The simulator polls a block's
#: threads while holding the GIL and releases a ``syncthreads`` only when it runs again: at Python's default (5 ms) a
#: block barrier costs up to a slice per thread, and a force evaluation of an N = 9 stack about 1 s.
SIMULATOR_SWITCH_INTERVAL = 5e-4


@contextlib.contextmanager
def launching():
    """Hold :data:`LAUNCHES`; on the simulator, switch threads every :data:`SIMULATOR_SWITCH_INTERVAL` meanwhile."""
    with LAUNCHES:
        if not config.ENABLE_CUDASIM:
            yield
            return
        interval = sys.getswitchinterval()
        sys.setswitchinterval(min(interval, SIMULATOR_SWITCH_INTERVAL))
        try:
            yield
        finally:
            sys.setswitchinterval(interval)


class BarrierTimeout(RuntimeError):
    """The blocks of a realisation did not all meet at a barrier within the deadline."""


def threads_per_block(tile, elements=0):
    """Threads of a block: one per node of a tile on a GPU, and per element of a tile where ``elements`` (the resident
    kernel's, :func:`.resident.block_threads`); 8 on numba's simulator (each a Python thread)."""
    return min(8, tile) if config.ENABLE_CUDASIM else block_threads(tile, elements)


class Launcher:
    """The launches of one batch's kernels.

    Parameters
    ----------
    mesh : .device.DeviceMesh
    law : tuple
        The law of the batch (it chooses the kernels).
    groups : int, optional
        Blocks per realisation of a minimisation at most (default: as many as there are tiles and the
        device holds at once).
    deadline : int, optional
        Clock cycles of a barrier's wait (default :data:`DEADLINE_CYCLES`).
    kernel : str, optional
        The minimisation kernel (:data:`.kernels.MINIMISERS`): ``"tiles"`` (:mod:`.minimise`, the default) or
        ``"resident"`` (:mod:`.resident`: a realisation over all its tiles' blocks, as many realisations per launch
        as the device holds together, the others in further launches of the same call); the same bytes.

    Attributes
    ----------
    groups_used : collections.Counter
        Launches of the minimisation kernel by blocks per realisation.
    """

    def __init__(self, mesh, law, groups=None, deadline=None, kernel="tiles"):
        if kernel not in MINIMISERS:
            raise ValueError(f"cuda: the minimisation kernel must be one of {sorted(MINIMISERS)}; got {kernel!r}")
        self.mesh, self.law, self.groups, self.kernel = mesh, law, groups, kernel
        self.minimiser = MINIMISERS[kernel]
        self.deadline = int(DEADLINE_CYCLES if deadline is None else deadline)
        with LAUNCHES:  # the simulator swaps the kernel modules' ``cuda`` for its own during a launch
            self.kernels = kernels_for(type(law).name)
        elements = int(np.diff(mesh.host.tile_element_ptr).max()) if kernel == "resident" else 0
        self.block = threads_per_block(mesh.layout.tile, elements)
        self.groups_used = collections.Counter()
        self._capacity = None

    def record(self, slots, groups=1, nsteps=0, update_wells=True):
        """The :class:`.records.Launch` of ``slots``."""
        members = self.mesh.place(np.asarray(slots, dtype=np.int64))
        return Launch(members, int(groups), int(nsteps), self.deadline, self.mesh.dt, self.mesh.free_lever,
                      bool(update_wells))

    def co_resident(self, arguments):
        """Blocks of the minimisation kernel the device holds at once (asked of the compiled kernel once)."""
        if self._capacity is None:
            kernel = getattr(self.kernels, self.minimiser)
            if config.ENABLE_CUDASIM:
                compiled = kernel.overloads[None]
            else:
                compiled = kernel.compile(tuple(numba.typeof(argument) for argument in arguments))
            self._capacity = int(compiled.max_cooperative_grid_blocks(self.block))
        return self._capacity

    @property
    def capacity(self):
        """Blocks of the minimisation kernel the device holds at once (None before the first launch)."""
        return self._capacity

    def groups_for(self, count, arguments):
        """Blocks per realisation for a launch of ``count`` realisations: all co-resident if more than one (the
        resident kernel: every tile's block)."""
        ntile = self.mesh.layout.ntile
        if self.kernel == "resident":
            return ntile
        wanted = min(self.groups or ntile, ntile)
        return max(1, min(wanted, self.co_resident(arguments) // count))

    def per_launch(self, arguments):
        """Realisations one launch of the minimisation kernel holds at most (the resident kernel's co-resident
        realisations; every one for the other kernel).

        Raises
        ------
        ValueError
            If the device cannot hold the blocks of one realisation of the resident kernel at once.
        """
        if self.kernel != "resident":
            return sys.maxsize
        ntile = self.mesh.layout.ntile
        capacity = self.co_resident(arguments)
        if ntile > 1 and capacity < ntile:
            raise ValueError(f"cuda: the resident kernel needs the {ntile} blocks of a realisation at once; the device "
                             f"holds {capacity} (choose kernel='tiles')")
        return max(1, capacity // ntile) if ntile > 1 else sys.maxsize

    def arguments(self, name, slots, state, nsteps=0, update_wells=True, extra=()):
        """The arguments of a launch of kernel ``name`` for ``slots`` (also for compiling without a device).

        Kernels of a launch record take ``(law?, launch, mesh, state, control?)`` and then ``extra``; the
        kernels of one slot's items (``add_u``, ``shift_wells``, ``zero_motion``) take ``(slot, *extra, state)``.
        """
        if name in ("add_u", "shift_wells", "zero_motion"):
            return (int(slots[0]), *extra, state.record())
        head = (self.law,) if name in ("minimise", "resident", "evaluate") else ()
        tail = (state.control_record(),) if name in ("minimise", "resident") else ()
        return (*head, self.record(slots, 1, nsteps, update_wells), self.mesh.layout, state.record(), *tail, *extra)

    def minimise(self, slots, state, nsteps=None):
        """One launch of at most ``nsteps`` (default :data:`STEPS_PER_LAUNCH`) time steps of the minimisation kernel
        for ``slots`` (the resident kernel: as many launches as :meth:`per_launch` needs); their status words
        afterwards.

        Raises
        ------
        BarrierTimeout
            If a realisation's blocks did not meet at a barrier.
        ValueError
            If the device cannot hold the blocks of one realisation of the resident kernel at once.
        """
        nsteps = STEPS_PER_LAUNCH if nsteps is None else nsteps
        with launching():
            arguments = list(self.arguments(self.minimiser, slots, state, nsteps))
            size = self.per_launch(arguments)
            for first in range(0, len(slots), size):
                chunk = list(slots[first:first + size])
                arguments = list(self.arguments(self.minimiser, chunk, state, nsteps))
                G = self.groups_for(len(chunk), arguments)
                arguments[1] = arguments[1]._replace(groups=G)
                state.reset_counters()
                getattr(self.kernels, self.minimiser)[len(chunk) * G, self.block](*arguments)
                self.groups_used[G] += 1
        status = state.control["status"].copy_to_host()
        failed = [slot for slot in slots if status[slot] == BARRIER_TIMEOUT]
        if failed:
            raise BarrierTimeout(f"cuda: the {G} blocks of realisation(s) {failed} did not meet at a barrier within "
                                 f"{self.deadline} clock cycles (blocks not resident together, or another program "
                                 "holds the device)")
        return {slot: int(status[slot]) for slot in slots}

    def per_tile(self, name, slots, state, update_wells=True):
        """Launch kernel ``name`` with one block per (slot, tile)."""
        with launching():
            getattr(self.kernels, name)[len(slots) * self.mesh.layout.ntile, self.block](
                *self.arguments(name, slots, state, update_wells=update_wells))

    def per_slot(self, name, slots, state, *extra):
        """Launch kernel ``name`` with one block per slot."""
        with launching():
            getattr(self.kernels, name)[len(slots), self.block](*self.arguments(name, slots, state, extra=extra))

    def per_item(self, name, slot, count, state, *extra):
        """Launch kernel ``name`` for ``count`` items of ``slot`` (one thread each)."""
        with launching():
            getattr(self.kernels, name)[max(1, -(-count // self.block)), self.block](
                *self.arguments(name, [slot], state, extra=extra))
