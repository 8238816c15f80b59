"""The device state of a batch of realisations of one mesh, and the launches that advance them.

A :class:`DeviceMesh` holds what the realisations share (the layout of :mod:`.layout`, on the device);
a :class:`DeviceBatch` holds the state of up to ``size`` realisations of one law as ``[batch, ...]``
arrays and launches the kernels of :mod:`.kernels` for them. A realisation is a *slot*; the backend of
one run (:class:`..CudaBackend`) is bound to one slot. Every call of a backend acts on its slot alone,
with small kernels of one block, except :meth:`DeviceBatch.minimise`: there the slots of the runs that
share the batch (the *participants*, one thread each: :class:`Ensemble`) meet, and one launch advances
all of them; a slot that ends early waits for the next round. A realisation computes the same bits
whatever the batch and the number of blocks it is spread over (:mod:`.layout`).
"""

import threading
import weakref

import numpy as np
from numba import cuda
from numba import config  # ENABLE_CUDASIM: numba-cuda reads the same variable

from ..base import MAX_ITER_REACHED
from .kernels import EVENTS_FULL, MAX_LAYERS, RUNNING, kernels_for
from .layout import LEAVES, device_layout

__all__ = ["DeviceMesh", "DeviceBatch", "Ensemble", "STEPS_PER_LAUNCH", "EVENT_CAPACITY", "threads_per_block"]

#: Time steps of one launch of a minimisation (then the host reads the status words and relaunches).
STEPS_PER_LAUNCH = 4096

#: Rows of a recording slot's event buffer beyond 8 per interface element.
EVENT_CAPACITY = 1 << 16

#: Held around every kernel launch: the runs of an ensemble launch from their own threads (on a GPU this
#: only orders the launches in the stream; numba's simulator executes a launch in the caller and is not safe
#: for launches from two threads at once).
LAUNCHES = threading.RLock()

def threads_per_block():
    """Threads of every block: 256 on a GPU; 8 on numba's simulator (each a Python thread). The results do not
    depend on it (:mod:`.layout`)."""
    return 8 if config.ENABLE_CUDASIM else 256


#: Per-slot fields of the state (:data:`..base.FIELDS`: ``t`` is ``clock``), and what a checkpoint copies.
_STATE = ("u", "v", "a", "f", "idx", "eps", "sig", "fe", "target", "ubar", "lever", "clock")
_FIELD = {"t": "clock"}


class DeviceMesh:
    """The layout of a model's mesh, linear operators and drive on the device, shared by batches.

    Parameters
    ----------
    model : stickslip.fem.model.Model
    place : callable, optional
        Puts a host array where the kernels read it (default ``numba.cuda.to_device``; a host copy for
        compiling without a device, :func:`.compile.ptx`).
    sm_count : int, optional
        The device's multiprocessors (default: asked of the device; 1 on the simulator, which runs a
        launch's blocks one after another, so a realisation is never spread there).
    """

    def __init__(self, model, place=cuda.to_device, sm_count=None):
        if model.layer_volume.size > MAX_LAYERS:
            raise ValueError(f"the cuda backend holds at most {MAX_LAYERS} layers (6 plates); got "
                             f"{model.layer_volume.size}")
        self.place = place
        self.host = device_layout(model)
        self.arrays = {name: place(np.ascontiguousarray(value)) for name, value in self.host._asdict().items()
                       if isinstance(value, np.ndarray)}
        self.free_lever = bool(model.free_lever)
        self.dt = float(model.dt)
        if sm_count is None:
            sm_count = 1 if config.ENABLE_CUDASIM else cuda.get_current_device().MULTIPROCESSOR_COUNT
        self.sm_count = sm_count

    def serves(self, model):
        """True if ``model`` has this mesh, these operators and this drive (then its batches may share it)."""
        if model.free_lever != self.free_lever or float(model.dt) != self.dt:
            return False
        other = device_layout(model)
        return all(np.array_equal(a, b) for a, b in zip(self.host, other))

    def operands(self):
        """The kernels' leading shared arguments (layout arrays and sizes), in their order."""
        a, h = self.arrays, self.host
        return (a["k_ptr"], a["k_col"], a["k_val"], a["mass_inv"], a["damping"], a["free"], a["multiplicity"],
                a["iface_dofs"], a["iface_dNdx"], a["iface_dV"], a["gather_ptr"], a["gather_index"],
                a["drive_layer"], a["drive_w"], a["layer_ptr"], a["layer_xdofs"], a["layer_w"],
                a["layer_volume"], a["drive_active"], a["lever_ratio"], h.nlayer, h.layer_chunks, h.dof_chunks)


class DeviceBatch:
    """The state of ``size`` realisations of one law on one device mesh, and the launches that advance them.

    Parameters
    ----------
    mesh : DeviceMesh
    law : tuple
        The law of every slot (one value: it is a kernel argument).
    size : int
        Slots.
    groups : int or None
        Blocks per realisation in a minimisation (None: as many as the device's multiprocessors allow).
    participants : Ensemble or None
        The runs whose minimisations meet (None: every minimisation is launched alone).
    """

    def __init__(self, mesh, law, size, groups=None, participants=None):
        self.mesh, self.law, self.size, self.groups, self.participants = mesh, law, int(size), groups, participants
        self.kernels = kernels_for(type(law).name)
        h = mesh.host
        B, ndof, ni, nl = self.size, h.ndof, h.ni, h.nlayer
        place = mesh.place

        def zeros(shape, dtype=np.float64):
            return place(np.zeros(shape, dtype=dtype))

        self.u, self.v, self.a, self.f = (zeros((B, ndof)) for _ in range(4))
        self.idx = zeros((B, ni, 4), np.int64)
        self.eps, self.sig = (zeros((B, ni, 4, 3)) for _ in range(2))
        self.fe = zeros((B, 8 * ni))
        self.target, self.ubar = (zeros((B, nl)) for _ in range(2))
        self.lever = zeros((B, 2))
        self.clock = zeros(B)
        self.epsy = place(np.full((B, ni, 2), np.inf))
        self.ny = place(np.full(B, 2, dtype=np.int64))
        self.k_drive = zeros(B)
        self.delta_u = zeros((B, ndof))
        self.delta_target = zeros((B, nl))
        self.delta_lever = zeros(B)
        self.ubar_part = zeros((B, nl, LEAVES * h.layer_chunks))
        self.res_part = zeros((B, 2, LEAVES * h.dof_chunks))
        self.block = threads_per_block()
        self.scalar = zeros(B)
        self.flag = zeros(B, np.int64)
        self.counter = zeros(B, np.int32)
        # the minimisations' own state (kept on the device between launches)
        self.tol = zeros(B)
        self.niter_tol, self.max_iter, self.margin, self.quiet, self.record, self.steps, self.unchanged, \
            self.moved_at, self.near_at, self.status, self.nevent = (zeros(B, np.int64) for _ in range(11))
        self.history = zeros((B, 1, 1))
        self.previous = zeros((B, ni), np.int64)
        self.events = zeros((B, 1, 3))
        self._slots = list(range(B))
        self._lock = threading.Lock()

    # --- slots ---------------------------------------------------------------------------------

    def attach(self, model, owner):
        """A free slot for ``model`` (its yield strains and drive stiffness); released when ``owner`` is collected."""
        if model.law != self.law:
            raise ValueError(f"a batch computes one law: {model.law!r} is not {self.law!r}")
        with self._lock:
            if not self._slots:
                raise ValueError(f"the batch's {self.size} slots are taken")
            slot = self._slots.pop(0)
        weakref.finalize(owner, self._release, slot)
        self.k_drive[slot:slot + 1].copy_to_device(np.array([float(model.k_drive)]))
        self.idx[slot].copy_to_device(np.zeros(self.idx.shape[1:], dtype=np.int64))
        self.set_yield_strains(slot, model.epsy, None)
        return slot

    def _release(self, slot):
        with self._lock:
            self._slots.append(slot)

    # --- state ---------------------------------------------------------------------------------

    def read(self, slot, fields):
        """Host copies of the slot's ``fields`` (:data:`..base.FIELDS`)."""
        out = []
        for name in fields:
            array = getattr(self, _FIELD.get(name, name))[slot]
            host = np.array([array]) if np.ndim(array) == 0 else array.copy_to_host()
            out.append(host)
        return tuple(out)

    def upload(self, slot, **fields):
        """Copy host values into the slot's fields (``clock``, ``lever0`` for the free lever's drive target)."""
        for name, value in fields.items():
            if name == "lever0":
                self.lever[slot, 0:1].copy_to_device(np.array([float(value)]))
                continue
            target = getattr(self, name)[slot:slot + 1]
            target.copy_to_device(np.ascontiguousarray(value, dtype=target.dtype).reshape(target.shape))

    def set_yield_strains(self, slot, epsy, shift):
        """Hold ``epsy`` [ni, ny] in the slot (the batch's windows are widened as needed); renumber by ``shift``."""
        ni, ny = epsy.shape
        with LAUNCHES:
            if ny > self.epsy.shape[2]:
                wider = np.full((self.size, ni, ny), np.inf)
                wider[:, :, :self.epsy.shape[2]] = self.epsy.copy_to_host()
                self.epsy = cuda.to_device(wider)
        row = np.full((ni, self.epsy.shape[2]), np.inf)
        row[:, :ny] = epsy
        self.epsy[slot].copy_to_device(row)
        self.ny[slot:slot + 1].copy_to_device(np.array([ny], dtype=np.int64))
        if shift is not None:
            self._one(self.kernels.shift_wells, slot, -(-ni // self.block),
                      cuda.to_device(np.asarray(shift, np.int64)), self.idx)

    def checkpoint(self, slot):
        """Device copies of the slot's state."""
        token = {}
        for name in _STATE:
            source = getattr(self, name)[slot:slot + 1]
            token[name] = cuda.device_array_like(source)
            token[name].copy_to_device(source)
        return token

    def rollback(self, slot, token):
        """Restore a :meth:`checkpoint`."""
        for name, kept in token.items():
            getattr(self, name)[slot:slot + 1].copy_to_device(kept)

    # --- small launches (one block per slot) -----------------------------------------------------

    def _one(self, kernel, slot, blocks, *args):
        with LAUNCHES:
            kernel[blocks, self.block](slot, *args)

    def _members(self, slots):
        return self.mesh.place(np.asarray(slots, dtype=np.int64))

    def arguments(self, kernel, members, update_wells=True, groups=1, step=0.0):
        """The arguments of a launch of ``kernel`` (a name of :func:`.kernels.kernels_for`) for ``members``.

        One list per kernel, for the launches here and for compiling without a device (:func:`.compile.ptx`).
        """
        shared = self.mesh.operands()
        if kernel == "evaluate":
            return (self.law, members, 1, update_wells, self.mesh.free_lever, *shared, self.u, self.v, self.a,
                    self.f, self.idx, self.eps, self.sig, self.fe, self.target, self.ubar, self.lever, self.epsy,
                    self.ny, self.k_drive, self.ubar_part, self.res_part, self.scalar, self.counter)
        if kernel == "minimise":
            return (self.law, members, groups, STEPS_PER_LAUNCH, self.mesh.dt, self.mesh.free_lever, *shared,
                    self.u, self.v, self.a, self.f, self.idx, self.eps, self.sig, self.fe, self.target, self.ubar,
                    self.lever, self.clock, self.epsy, self.ny, self.k_drive, self.ubar_part, self.res_part, self.tol,
                    self.niter_tol, self.max_iter, self.margin, self.quiet, self.record, self.steps, self.unchanged,
                    self.history, self.moved_at, self.near_at, self.status, self.previous, self.events, self.nevent,
                    self.counter)
        if kernel == "residual":
            a = self.mesh.arrays
            return (members, 1, self.mesh.host.dof_chunks, a["free"], a["multiplicity"], a["damping"], self.f, self.v,
                    self.res_part, self.scalar, self.counter)
        if kernel == "wells_hold":
            return members, self.epsy, self.ny, self.idx, self.eps, self.flag
        if kernel == "load":
            return members, float(step), self.delta_u, self.delta_target, self.delta_lever, self.u, self.target, \
                self.lever
        slot = int(members[0])
        if kernel == "add_u":
            return slot, self.mesh.place(np.zeros(1, np.int64)), self.mesh.place(np.zeros(1)), self.u
        if kernel == "shift_wells":
            return slot, self.mesh.place(np.zeros(self.mesh.host.ni, np.int64)), self.idx
        if kernel == "zero_motion":
            return slot, self.v, self.a
        raise ValueError(f"no kernel {kernel!r}")

    def evaluate(self, slot, update_wells):
        """Everything that follows from the slot's displacement and drive; returns its residual."""
        with LAUNCHES:
            self.kernels.evaluate[1, self.block](*self.arguments("evaluate", self._members([slot]), update_wells))
        return float(self.scalar[slot])

    def load(self, slot, step):
        """Move the slot by ``step`` along its load direction (then :meth:`evaluate`)."""
        with LAUNCHES:
            self.kernels.load[1, self.block](*self.arguments("load", self._members([slot]), step=step))

    def add_u(self, slot, dofs, delta):
        """``u[dofs] += delta`` of the slot (then :meth:`evaluate`)."""
        dofs = np.asarray(dofs, dtype=np.int64)
        self._one(self.kernels.add_u, slot, max(1, -(-dofs.size // self.block)), cuda.to_device(dofs),
                  cuda.to_device(np.asarray(delta, dtype=np.float64)), self.u)

    def stop(self, slot):
        """``v = a = 0`` in the slot."""
        self._one(self.kernels.zero_motion, slot, -(-self.mesh.host.ndof // self.block), self.v, self.a)

    def residual(self, slot):
        """The slot's relative residual."""
        with LAUNCHES:
            self.kernels.residual[1, self.block](*self.arguments("residual", self._members([slot])))
        return float(self.scalar[slot])

    def wells_hold(self, slot):
        """True if every Gauss point of the slot lies in its held well."""
        self.flag[slot:slot + 1].copy_to_device(np.ones(1, dtype=np.int64))
        with LAUNCHES:
            self.kernels.wells_hold[1, self.block](*self.arguments("wells_hold", self._members([slot])))
        return bool(self.flag[slot])

    # --- minimisation ----------------------------------------------------------------------------

    def minimise(self, slot, tol, niter_tol, max_iter, margin, record, quiet):
        """The whole minimisation of a slot (:meth:`..base.Backend.minimise`), in rounds of launches."""
        if max_iter <= 0:
            return MAX_ITER_REACHED, 0, np.empty((0, 3))
        self._begin(slot, tol, niter_tol, max_iter, margin, record, quiet)
        found = []
        while True:
            status, steps = self._run_round(slot)
            if record:
                count = int(self.nevent[slot])
                found.append(self.events[slot, :count].copy_to_host())
                self.nevent[slot:slot + 1].copy_to_device(np.zeros(1, dtype=np.int64))
            if status not in (RUNNING, EVENTS_FULL):
                events = np.concatenate(found) if found else np.empty((0, 3))
                return status, steps, events

    def _grow(self, name, shape):
        """Make the array ``name`` at least ``shape`` (its content kept at the start of every axis)."""
        old = getattr(self, name)
        if all(have >= want for have, want in zip(old.shape, shape)):
            return
        wider = np.zeros(tuple(max(have, want) for have, want in zip(old.shape, shape)), dtype=old.dtype)
        wider[tuple(slice(0, n) for n in old.shape)] = old.copy_to_host()
        setattr(self, name, cuda.to_device(wider))

    def _begin(self, slot, tol, niter_tol, max_iter, margin, record, quiet):
        ni = self.mesh.host.ni
        with LAUNCHES:  # no launch uses an array while it is replaced (a grow waits for the launches in flight)
            self._grow("history", (self.size, self._groups_cap(), max(niter_tol, 64)))
            if record:
                self._grow("events", (self.size, EVENT_CAPACITY + 8 * ni, 3))
        self.history[slot].copy_to_device(np.full(self.history.shape[1:], np.inf))
        for name, value in (("tol", tol), ("niter_tol", niter_tol), ("max_iter", max_iter), ("margin", margin),
                            ("record", int(record)), ("quiet", quiet), ("steps", 0), ("unchanged", 0),
                            ("moved_at", -1), ("near_at", -1), ("status", RUNNING), ("nevent", 0)):
            array = getattr(self, name)
            array[slot:slot + 1].copy_to_device(np.array([value], dtype=array.dtype))
        self.previous[slot].copy_to_device(np.ascontiguousarray(self.idx[slot].copy_to_host()[:, 0]))

    def _groups_cap(self):
        return min(self.groups or self.mesh.sm_count, self.mesh.sm_count)

    def _groups(self, count):
        """Blocks per realisation for a launch of ``count`` realisations (all co-resident: at most one block per SM)."""
        return max(1, min(self._groups_cap(), self.mesh.sm_count // count))

    def launch(self, slots):
        """One launch of the minimisation kernel for ``slots``; their (status, steps) afterwards."""
        G = self._groups(len(slots))
        with LAUNCHES:
            self.counter.copy_to_device(np.zeros(self.size, dtype=np.int32))
            self.kernels.minimise[len(slots) * G, self.block](*self.arguments("minimise", self._members(slots),
                                                                               groups=G))
        status, steps = self.status.copy_to_host(), self.steps.copy_to_host()
        return {slot: (int(status[slot]), int(steps[slot])) for slot in slots}

    def _run_round(self, slot):
        """Launch the slot's next round: alone, or with the ensemble's runs (:meth:`Ensemble.meet`)."""
        ensemble = self.participants
        if ensemble is None or not ensemble.includes(threading.get_ident()):
            return self.launch([slot])[slot]
        return ensemble.meet(self, slot)


class Ensemble:
    """The runs (one thread each) whose minimisations share launches: a batch of realisations of one mesh.

    Parameters
    ----------
    size : int
        Realisations.
    groups : int or None
        Blocks per realisation (None: spread over the device's multiprocessors).
    """

    def __init__(self, size, groups=None):
        self.size = int(size)
        self.groups = groups
        self._threads = set()
        self._lock = threading.Lock()
        self._batches = []
        self.mesh = None
        self._round = threading.Condition()
        self._waiting = {}  # batch -> its slots waiting for the next round
        self._results = {}
        self._generation = 0

    def join(self):
        """Register the calling thread as a run of the ensemble."""
        with self._lock:
            self._threads.add(threading.get_ident())

    def leave(self):
        """The calling thread's run ended (however): the others no longer wait for it."""
        with self._lock:
            self._threads.discard(threading.get_ident())
        with self._round:
            if self._waiting and self._everyone_waits():
                self._launch_round()

    def meet(self, batch, slot):
        """Wait until every run of the ensemble waits for a minimisation round, then launch each batch's waiting slots.

        A run waits in the batch of the law it minimises at that moment (the elastic law of a linear response, the
        interface law of an event): the round starts when the waiting runs, summed over the batches, are all the
        runs still going, so runs that are in different batches at the same time do not wait for each other.

        Parameters
        ----------
        batch : DeviceBatch
        slot : int
            The calling run's slot in ``batch``.

        Returns
        -------
        (int, int)
            The slot's status word and its time steps after the launch.
        """
        with self._round:
            self._waiting.setdefault(batch, []).append(slot)
            generation = self._generation
            if self._everyone_waits():
                self._launch_round()
            else:
                while self._generation == generation:
                    self._round.wait()
            return self._results[batch, slot]

    def _everyone_waits(self):
        return sum(map(len, self._waiting.values())) >= self.active()

    def _launch_round(self):
        """One launch per batch with waiting slots; wake the waiting runs (called holding ``_round``)."""
        self._results = {(batch, slot): result for batch, slots in self._waiting.items()
                         for slot, result in batch.launch(sorted(slots)).items()}
        self._waiting = {}
        self._generation += 1
        self._round.notify_all()

    def includes(self, ident):
        """Whether thread ``ident`` is a run of the ensemble."""
        with self._lock:
            return ident in self._threads

    def active(self):
        """Runs still going."""
        with self._lock:
            return len(self._threads)

    def batch_for(self, model):
        """The batch of the ensemble's runs for ``model``'s law (made on first use, ``2 size`` slots: a run may
        hold a second backend while its first is being released)."""
        with self._lock:
            if self.mesh is None:
                self.mesh = DeviceMesh(model)
            elif not self.mesh.serves(model):
                raise ValueError("an ensemble's runs must share the mesh, the operators, the time step and the drive")
            for batch in self._batches:
                if batch.law == model.law:
                    return batch
            batch = DeviceBatch(self.mesh, model.law, 2 * self.size, self.groups, participants=self)
            self._batches.append(batch)
            return batch
