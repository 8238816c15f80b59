"""A batch of realisations of one mesh and one law on the device: its slots and what a run asks of its slot.

A :class:`DeviceBatch` holds ``size`` realisations (:class:`.state.DeviceState`) and launches the kernels
for them (:class:`.launch.Launcher`). A realisation is a *slot*; the backend of one run
(:class:`..CudaBackend`) is bound to one slot, and every call acts on that slot alone, except
:meth:`DeviceBatch.minimise`: a run that is a member of an ensemble (:mod:`.ensemble`) meets the other
members there, and one launch advances all of them. A realisation computes the same bits whatever the
batch and the number of blocks it is spread over (:mod:`.layout`).
"""

import threading
import weakref

import numpy as np

from ..base import MAX_ITER_REACHED
from .launch import LAUNCHES, Launcher
from .minimise import EVENTS_FULL, RUNNING
from .state import DeviceState

__all__ = ["DeviceBatch", "EVENT_CAPACITY", "same_law"]

#: Rows of a recording slot's event buffer at first (emptied when full, grown when one step needs more).
EVENT_CAPACITY = 1 << 16


def same_law(first, second):
    """True if two laws are one law: the same class and the same parameters (laws are named tuples, and two
    classes' tuples with equal fields compare equal: ``Elastic(K, G) == Cusp(K, G)``)."""
    return type(first) is type(second) and first == second


class DeviceBatch:
    """The state of ``size`` realisations of one law on one device mesh, and what a run does with its slot.

    Parameters
    ----------
    mesh : .device.DeviceMesh
    law : tuple
        The law of every slot (one value: it is a kernel argument).
    size : int
    groups : int, optional
        Blocks per realisation of a minimisation at most (:class:`.launch.Launcher`).
    kernel : str, optional
        The minimisation kernel (:class:`.launch.Launcher`; default ``"tiles"``).
    """

    def __init__(self, mesh, law, size, groups=None, kernel="tiles"):
        self.mesh, self.law, self.size = mesh, law, int(size)
        self.state = DeviceState(mesh, size)
        self.launcher = Launcher(mesh, law, groups, kernel=kernel)
        self._free = list(range(self.size))
        self._lock = threading.Lock()

    def attach(self, model, owner):
        """A free slot for ``model`` (its drive stiffness; the owner gives it yield strains); released when ``owner``
        is collected."""
        if not same_law(model.law, self.law):
            raise ValueError(f"a batch computes one law: {model.law!r} is not {self.law!r}")
        with self._lock:
            if not self._free:
                raise ValueError(f"the batch's {self.size} slots are taken")
            slot = self._free.pop(0)
        weakref.finalize(owner, self._release, slot)
        self.state.upload(slot, k_drive=float(model.k_drive), idx=np.zeros((model.iface_dofs.shape[0], 4), np.int64))
        return slot

    def _release(self, slot):
        with self._lock:
            self._free.append(slot)

    # --- one slot ---------------------------------------------------------------------------------

    def read(self, slot, fields):
        """Host copies of the slot's ``fields`` (:data:`..base.FIELDS`)."""
        return self.state.read(slot, fields)

    def upload(self, slot, **fields):
        """Copy host values into the slot's state (:meth:`.state.DeviceState.upload`)."""
        self.state.upload(slot, **fields)

    def evaluate(self, slot, update_wells):
        """Everything that follows from the slot's displacement and drive; returns its residual."""
        self.launcher.per_tile("layer_sums", [slot], self.state)
        self.launcher.per_tile("evaluate", [slot], self.state, update_wells=update_wells)
        self.launcher.per_slot("residual", [slot], self.state)
        return float(self.state.arrays["scalar"][slot])

    def residual(self, slot):
        """The slot's relative residual."""
        self.launcher.per_tile("residual_rows", [slot], self.state)
        self.launcher.per_slot("residual", [slot], self.state)
        return float(self.state.arrays["scalar"][slot])

    def load(self, slot, step):
        """Move the slot by ``step`` along its load direction (then :meth:`evaluate`)."""
        self.launcher.per_slot("load", [slot], self.state, float(step))

    def add_u(self, slot, dofs, delta):
        """``u[dofs] += delta`` of the slot (then :meth:`evaluate`)."""
        dofs = np.asarray(dofs, dtype=np.int64)
        self.launcher.per_item("add_u", slot, dofs.size, self.state, self.mesh.place(dofs),
                               self.mesh.place(np.asarray(delta, dtype=np.float64)))

    def stop(self, slot):
        """``v = a = 0`` in the slot."""
        self.launcher.per_item("zero_motion", slot, self.mesh.layout.ndof, self.state)

    def wells_hold(self, slot):
        """True if every Gauss point of the slot lies in its held well."""
        self.state.upload(slot, flag=1)
        self.launcher.per_slot("wells_hold", [slot], self.state)
        return bool(self.state.arrays["flag"][slot])

    def set_yield_strains(self, slot, epsy, shift):
        """Hold ``epsy`` [ni, ny] in the slot; renumber its wells by ``shift`` (int64 [ni]) if given."""
        with LAUNCHES:  # no launch uses the yield strains while they are replaced
            self.state.hold_yield_strains(slot, epsy)
        if shift is not None:
            self.launcher.per_item("shift_wells", slot, epsy.shape[0], self.state,
                                   self.mesh.place(np.asarray(shift, np.int64)))

    def checkpoint(self, slot):
        """Device copies of the slot's state."""
        return self.state.checkpoint(slot)

    def rollback(self, slot, token):
        """Restore a :meth:`checkpoint`."""
        self.state.rollback(slot, token)

    # --- minimisation -----------------------------------------------------------------------------

    def minimise(self, slot, criteria, member=None):
        """The whole minimisation of a slot (:meth:`..base.Backend.minimise`), in launches.

        Parameters
        ----------
        slot : int
        criteria : tuple
            ``(tol, niter_tol, max_iter, margin, record, quiet)``.
        member : .ensemble.Member, optional
            The run's membership of an ensemble: its launches are the ensemble's rounds.
        """
        tol, niter_tol, max_iter, margin, record, quiet = criteria
        if max_iter <= 0:
            return MAX_ITER_REACHED, 0, np.empty((0, 3))
        self.begin(slot, criteria)
        found = []
        while True:
            status = member.meet(self, slot) if member is not None else self.launch([slot])[slot]
            if record:
                found.append(self.state.events(slot, self.state.scalar("nevent", slot)))
                self.state.upload(slot, nevent=0)
            if status == EVENTS_FULL:
                with LAUNCHES:
                    self.state.grow_events(self.state.scalar("needed", slot))
            elif status != RUNNING:
                events = np.concatenate(found) if found else np.empty((0, 3))
                return status, self.state.scalar("done", slot), events

    def begin(self, slot, criteria):
        """Set the slot's minimisation going: its criteria, counters, recording, and the first step's prediction."""
        tol, niter_tol, max_iter, margin, record, quiet = criteria
        if record:
            with LAUNCHES:
                self.state.grow_events(EVENT_CAPACITY)
        self.state.upload(slot, tol=tol, niter_tol=niter_tol, max_iter=max_iter, margin=margin, record=int(record),
                          quiet=quiet, done=0, judged=1, status=RUNNING, needed=0, runs=np.zeros(4, np.int64),
                          last=np.inf, nevent=0, previous=self.state.read(slot, ("idx",))[0][:, 0])
        self.launcher.per_tile("prime", [slot], self.state)

    def launch(self, slots):
        """One launch of the minimisation kernel for ``slots`` (each begun); their status words afterwards."""
        return self.launcher.minimise(slots, self.state)
