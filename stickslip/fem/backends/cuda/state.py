"""The device arrays of a batch of realisations: allocated, read, written, copied and grown by slot.

A :class:`DeviceState` holds the :class:`.records.State` and :class:`.records.Control` arrays of ``size``
realisations of one mesh (``[size, ...]`` arrays; realisation ``slot`` is row ``slot``) and builds the
records the kernels take. Arrays that grow (the held yield strains, the event buffers) are replaced by
larger ones, their content kept, so a record is built for each launch. Whether a Gauss point changed well since a
checkpoint is counted on the device (:meth:`DeviceState.wells_changed`, :mod:`.changed_wells`; one integer to the
host).
"""

import numpy as np
from numba import cuda

from .changed_wells import COUNT_THREADS, count_changed
from .launch import launching
from .minimise import ROWS
from .records import CHECKPOINT_FIELDS, STATE_FIELDS, Control, State

__all__ = ["DeviceState"]

class DeviceState:
    """The state and minimisation control of ``size`` realisations of ``mesh`` on the device.

    Parameters
    ----------
    mesh : .device.DeviceMesh
    size : int
    """

    def __init__(self, mesh, size):
        self.place = mesh.place
        h, B = mesh.layout, int(size)
        self.size = B

        def zeros(shape, dtype=np.float64):
            return self.place(np.zeros(shape, dtype=dtype))

        ndof, ni, nl = h.ndof, h.ni, h.nlayer
        self.arrays = dict(
            u=zeros((B, 2, ndof)), v=zeros((B, ndof)), a=zeros((B, ndof)), f=zeros((B, ndof)),
            idx=zeros((B, ni, 4), np.int64), eps=zeros((B, ni, 4, 3)), sig=zeros((B, ni, 4, 3)),
            target=zeros((B, nl)), ubar=zeros((B, nl)), lever=zeros((B, 2)), clock=zeros(B),
            epsy=self.place(np.full((B, ni, 2), np.inf)), ny=self.place(np.full(B, 2, dtype=np.int64)),
            k_drive=zeros(B), delta_u=zeros((B, ndof)), delta_target=zeros((B, nl)), delta_lever=zeros(B),
            partials=zeros((B, 2, h.ntile, ROWS)), flags=zeros((B, 2, h.ntile, 3), np.int64),
            previous=zeros((B, ni), np.int64), scalar=zeros(B), flag=zeros(B, np.int64))
        self._every = self.place(np.arange(ni, dtype=np.int64))  # all elements, and no renumbering
        self._unshifted = zeros(ni, np.int64)
        self._changed = zeros(B, np.int64)  # one count per slot: the runs of an ensemble count at once
        self.control = dict(
            tol=zeros(B), niter_tol=zeros(B, np.int64), max_iter=zeros(B, np.int64), margin=zeros(B, np.int64),
            quiet=zeros(B, np.int64), record=zeros(B, np.int64), done=zeros(B, np.int64), judged=zeros(B, np.int64),
            status=zeros(B, np.int64), needed=zeros(B, np.int64), runs=zeros((B, 4), np.int64), last=zeros(B),
            nevent=zeros(B, np.int64), events=zeros((B, 1, 3)), counter=zeros(B, np.int32))

    def record(self):
        """The :class:`.records.State` of the batch (for a launch)."""
        return State(**self.arrays)

    def control_record(self):
        """The :class:`.records.Control` of the batch (for a launch)."""
        return Control(**self.control)

    # --- one slot ---------------------------------------------------------------------------------

    def read(self, slot, fields):
        """Host copies of the slot's ``fields`` (:data:`..base.FIELDS`); ``u`` is buffer 0."""
        out = []
        for name in fields:
            array = self.arrays[STATE_FIELDS[name]][slot]
            if name == "u":
                array = array[0]
            out.append(np.array([array]) if np.ndim(array) == 0 else array.copy_to_host())
        return tuple(out)

    def upload(self, slot, **fields):
        """Copy host values into the slot's state (``u`` into buffer 0; ``lever0`` the free lever's drive target)
        or control (``tol``, ``runs``, ...) arrays."""
        for name, value in fields.items():
            if name == "lever0":
                self.arrays["lever"][slot, 0:1].copy_to_device(np.array([float(value)]))
                continue
            array = self.arrays[name] if name in self.arrays else self.control[name]
            target = array[slot, 0:1] if name == "u" else array[slot:slot + 1]
            target.copy_to_device(np.ascontiguousarray(value, dtype=target.dtype).reshape(target.shape))

    def scalar(self, name, slot):
        """One entry of a per-realisation control array (``status``, ``done``, ``nevent``, ``needed``)."""
        return int(self.control[name][slot])

    def checkpoint(self, slot):
        """Device copies of the slot's state (:data:`.records.CHECKPOINT_FIELDS`)."""
        token = {}
        for name in CHECKPOINT_FIELDS:
            source = self.arrays[name][slot:slot + 1]
            token[name] = cuda.device_array_like(source)
            token[name].copy_to_device(source)
        return token

    def rollback(self, slot, token):
        """Restore a :meth:`checkpoint`."""
        for name, kept in token.items():
            self.arrays[name][slot:slot + 1].copy_to_device(kept)

    def wells_changed(self, slot, token, shift=None, elements=None):
        """How many Gauss points of the slot are in another well than at :meth:`checkpoint` ``token`` (counted on the
        device; ``shift``, ``elements`` as :meth:`..base.Backend.wells_changed`)."""
        elements = self._every if elements is None else self.place(np.asarray(elements, dtype=np.int64))
        shift = self._unshifted if shift is None else self.place(np.asarray(shift, dtype=np.int64))
        count = self._changed[slot:slot + 1]
        count.copy_to_device(np.zeros(1, dtype=np.int64))
        points = 4 * elements.size
        with launching():  # as every launch (the simulator's are not safe from two threads at once)
            count_changed[max(1, -(-points // COUNT_THREADS)), COUNT_THREADS](self.arrays["idx"][slot],
                                                                               token["idx"][0], shift, elements, count)
        return int(count.copy_to_host()[0])

    def hold_yield_strains(self, slot, epsy):
        """Hold ``epsy`` [ni, ny] in the slot (the batch's window widened as needed: call between launches)."""
        ni, ny = epsy.shape
        held = self.arrays["epsy"]
        if ny > held.shape[2]:
            wider = np.full((self.size, ni, ny), np.inf)
            wider[:, :, :held.shape[2]] = held.copy_to_host()
            self.arrays["epsy"] = held = self.place(wider)
        row = np.full((ni, held.shape[2]), np.inf)
        row[:, :ny] = epsy
        held[slot].copy_to_device(row)
        self.arrays["ny"][slot:slot + 1].copy_to_device(np.array([ny], dtype=np.int64))

    def events(self, slot, count):
        """Host copy of the slot's first ``count`` recorded events."""
        return self.control["events"][slot, :count].copy_to_host()

    def grow_events(self, rows):
        """Make every slot's event buffer at least ``rows`` rows (call between launches)."""
        old = self.control["events"]
        if old.shape[1] >= rows:
            return
        wider = np.zeros((self.size, rows, 3))
        wider[:, :old.shape[1]] = old.copy_to_host()
        self.control["events"] = self.place(wider)

    def reset_counters(self):
        """Zero the barrier counters (before a launch of the minimisation kernel)."""
        self.control["counter"].copy_to_device(np.zeros(self.size, dtype=np.int32))
