"""Runs whose minimisations share launches: an :class:`Ensemble` and its explicit :class:`Member` objects.

Each run of an ensemble holds a :class:`Member` (handed to its backend, and on to every backend made from
it); a minimisation of a member waits in :meth:`Member.meet` until every member still running waits
too, then one launch per batch advances all of them (a *round*). A member that ends its run leaves
(:meth:`Member.leave`), so the others no longer wait for it; membership is this object, not the thread
a call comes from.
"""

import threading

from .batch import DeviceBatch, same_law
from .device import DeviceMesh

__all__ = ["Ensemble", "Member"]


class Member:
    """One run's place in an :class:`Ensemble` (made by :meth:`Ensemble.join`)."""

    def __init__(self, ensemble):
        self.ensemble = ensemble
        self.active = True

    def meet(self, batch, slot):
        """Wait for the round of every active member, then return this slot's status word (:meth:`Ensemble.meet`)."""
        if not self.active:
            return batch.launch([slot])[slot]
        return self.ensemble.meet(batch, slot)

    def leave(self):
        """This run ended (however): the other members no longer wait for it."""
        self.ensemble.leave(self)


class Ensemble:
    """The runs whose minimisations share launches: a batch of realisations of one mesh.

    Parameters
    ----------
    size : int
        Runs.
    groups : int, optional
        Blocks per realisation at most (:class:`.launch.Launcher`).
    kernel : str, optional
        The minimisation kernel (:class:`.launch.Launcher`).
    """

    def __init__(self, size, groups=None, kernel="tiles"):
        self.size, self.groups, self.kernel = int(size), groups, kernel
        self.mesh = None
        self._batches = []
        self._lock = threading.Lock()
        self._round = threading.Condition()
        self._active = 0
        self._waiting = {}  # batch -> its slots waiting for the next round
        self._results = {}
        self._generation = 0

    def join(self):
        """A new :class:`Member` (one per run, made before any of them minimises)."""
        with self._round:
            self._active += 1
        return Member(self)

    def leave(self, member):
        """``member`` ended: launch the round if every other active member waits."""
        with self._round:
            if member.active:
                member.active = False
                self._active -= 1
            if self._waiting and self._everyone_waits():
                self._launch_round()

    def meet(self, batch, slot):
        """Wait until every active member waits for a round, then launch each batch's waiting slots.

        A run waits in the batch of the law it minimises at that moment (the elastic law of a linear
        response, the interface law of an event): the round starts when the waiting runs, summed over the
        batches, are all the active runs, so runs in different batches at once do not wait for each other.

        Returns
        -------
        int
            The slot's status word after the round.
        """
        with self._round:
            self._waiting.setdefault(batch, []).append(slot)
            generation = self._generation
            if self._everyone_waits():
                self._launch_round()
            else:
                while self._generation == generation:
                    self._round.wait()
            result = self._results[batch, slot]
        if isinstance(result, BaseException):
            raise result
        return result

    def _everyone_waits(self):
        return sum(map(len, self._waiting.values())) >= self._active

    def _launch_round(self):
        """One launch per batch with waiting slots; wake the waiting runs (called holding ``_round``)."""
        results = {}
        for batch, slots in self._waiting.items():
            try:
                results.update({(batch, slot): status for slot, status in batch.launch(sorted(slots)).items()})
            except Exception as error:  # every run of the failed launch raises it
                results.update({(batch, slot): error for slot in slots})
        self._results = results
        self._waiting = {}
        self._generation += 1
        self._round.notify_all()

    def batch_for(self, model, mesh):
        """The ensemble's batch for ``model``'s law on ``mesh`` (made on first use, ``2 size`` slots: a run may hold
        a second backend while its first is being released)."""
        with self._lock:
            if self.mesh is None:
                self.mesh = DeviceMesh(model, mesh)
            elif not self.mesh.serves(model):
                raise ValueError("an ensemble's runs must share the mesh, the operators, the time step and the drive")
            for batch in self._batches:
                if same_law(batch.law, model.law):
                    return batch
            batch = DeviceBatch(self.mesh, model.law, 2 * self.size, self.groups, self.kernel)
            self._batches.append(batch)
            return batch
