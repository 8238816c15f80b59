"""The window of yield strains a backend holds, kept in step with the blocks' unbounded sequences.

Every block's sequence of yield strains is unbounded (:class:`.yield_strains.HeldYieldStrains`); the backend
holds a window of it and numbers the wells from the window's start. :class:`HeldWindow` gives the backend those
yield strains (through :meth:`.backends.base.Backend.set_yield_strains` only: the backend's copy is the only one
besides the window's own), widens the windows, and with
``yield_strains = extend`` moves them ahead of the Gauss points (:meth:`HeldWindow.hold_ahead`); a checkpoint of
the stack keeps the windows as they are (:meth:`HeldWindow.snapshot`) and its rollback returns to them. One
**yield-strain modifier** may be registered (junction aging, :class:`.thermal.junctions.Junctions`): an object with
``modify(wells)`` (the yield strains the backend holds, float64 [ni, ny], from the windows), ``stored()`` (a dict of
arrays, its state) and ``restore(stored)``. Part of the stack (:class:`.stack.Stack`), which shares its backend and its
host copies of the state (:class:`.host_copies.HostCopies`).
"""

import numpy as np

from .backends.base import read_only
from .materials import equivalent_strains

__all__ = ["HeldWindow"]


class HeldWindow:
    """The yield strains a backend holds: the windows of the sequences, modified (if a modifier is registered).

    Parameters
    ----------
    backend : stickslip.fem.backends.base.Backend
        The stack's backend (prepared); it is given the windows' yield strains at once.
    wells : stickslip.fem.yield_strains.HeldYieldStrains
        The held windows of the blocks' yield-strain sequences.
    copies : stickslip.fem.host_copies.HostCopies
        The stack's host copies of the backend's state.

    Attributes
    ----------
    wells : stickslip.fem.yield_strains.HeldYieldStrains
    modifier : object or None
        The registered yield-strain modifier (module docstring).
    held : numpy.ndarray
        float64 [ni, ny]: the yield strains the backend holds (given last), read only.
    """

    def __init__(self, backend, wells, copies):
        self._backend = backend
        self._copies = copies
        self.wells = wells
        self.modifier = None
        self.held = None
        self.push()

    def register(self, modifier):
        """Register the yield-strain modifier; the backend is given its yield strains at once.

        Raises
        ------
        ValueError
            If a modifier is registered already (a stored state holds one modifier's state).
        """
        if self.modifier is not None:
            raise ValueError(f"the stack's yield strains are modified by {self.modifier!r} already")
        self.modifier = modifier
        self.push()

    def push(self, shift=None):
        """Give the backend the yield strains it holds: the windows, modified (if a modifier is registered).

        Parameters
        ----------
        shift : numpy.ndarray, optional
            int64 [ni]: the windows moved forward by this many values (:meth:`.backends.base.Backend.set_yield_strains`).
        """
        epsy = self.wells.epsy if self.modifier is None else self.modifier.modify(self.wells)
        self._backend.set_yield_strains(epsy, shift)
        self._copies.changed()
        self.held = read_only(epsy)

    def widen(self):
        """Hold twice as many wells per block (the window's start unchanged)."""
        self.wells.widen(self.wells.epsy.shape[1] - 1)
        self.push()

    def hold_ahead(self):
        """Hold at least half a window of wells ahead of every Gauss point.

        A block with fewer than ``(ny - 1) // 2`` held wells ahead of its furthest Gauss
        point has its window moved forward to start ``(ny - 1) // 4`` wells behind its
        nearest one (or widened if its points are spread too far for that). A state
        beyond the held wells (a restored one) is followed to its wells; a state
        behind them restarts the windows from the origin. The values held never change
        the physics: they are the same numbers wherever the window is.
        """
        wells = self.wells
        idx, eps = self._copies.read("idx", "eps")
        if np.any((wells.offset > 0) & (idx.min(axis=1) == 0)
                  & (equivalent_strains(eps).min(axis=1) <= wells.epsy[:, 0])):
            wells.start(wells.epsy.shape[1] - 1)
            self.push()
        while True:
            ny = wells.epsy.shape[1]
            ahead, behind = (ny - 1) // 2, (ny - 1) // 4
            idx, eps = self._copies.read("idx", "eps")
            short = idx.max(axis=1) > ny - 1 - ahead
            if not short.any():
                return
            beyond = equivalent_strains(eps).max(axis=1) > wells.epsy[:, -1]
            shift = np.where(short, np.where(beyond, ny - 1 - behind, idx.min(axis=1) - behind), 0)
            if np.any(short & (shift <= 0)):
                self.widen()
                continue
            wells.slide(shift)
            self.push(shift)

    def snapshot(self):
        """The windows and the yield strains held now (for :meth:`resume`)."""
        return self.wells.snapshot(), self.held

    def resume(self, snapshot):
        """Return to a :meth:`snapshot` (the backend's own rollback returns it to the yield strains it held then)."""
        self.wells.resume(snapshot[0])
        self.held = snapshot[1]
