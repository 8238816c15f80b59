"""Host copies of a backend's state fields, made at most once per state: what a device backend copies to the host.

A device backend copies every field :meth:`.backends.base.Backend.read` names; the stack reads through
:class:`HostCopies` instead, which keeps the copies of the state now and copies a field only the first time it is
read. Whatever changes the state starts a new set (:meth:`HostCopies.changed`); a checkpoint keeps the set of its
state (:meth:`HostCopies.now`), and the rollback to it takes that set back (:meth:`HostCopies.resume`), so a state
returned to is not copied again (the kinetic Monte Carlo's draws after a hop that fell back). Part of the stack
(:class:`.stack.Stack`), which shares its backend.
"""

import numpy as np

from .backends.base import read_only

__all__ = ["HostCopies"]


class HostCopies:
    """Read-only host copies of the state fields of ``backend``, each made once per state.

    Parameters
    ----------
    backend : stickslip.fem.backends.base.Backend
    """

    def __init__(self, backend):
        self._backend = backend
        self._copies = {}

    def read(self, *fields):
        """The fields ``fields`` (:data:`.backends.base.FIELDS`) of the state now: a tuple of read-only host copies; one
        read of the backend for those not copied yet."""
        missing = [name for name in fields if name not in self._copies]
        if missing:
            for name, value in zip(missing, self._backend.read(*missing)):
                self._copies[name] = read_only(np.array(value))
        return tuple(self._copies[name] for name in fields)

    def changed(self):
        """The state changed: the copies made so far are of another state."""
        self._copies = {}

    def now(self):
        """The copies of the state now (a mapping that the reads of this state go on filling), for a checkpoint."""
        return self._copies

    def resume(self, copies):
        """The state is again the one whose copies are ``copies`` (:meth:`now` then)."""
        self._copies = copies

    def same_wells(self, copies):
        """The wells now are those of the state whose copies are ``copies``, numbered alike: share their copy."""
        if "idx" in copies:
            self._copies.setdefault("idx", copies["idx"])
