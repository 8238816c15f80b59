"""The simulated stack: a backend that owns the state, and the window of yield strains it holds.

Every block's sequence of yield strains is unbounded (:class:`.yield_strains.HeldYieldStrains`);
the backend holds a window of it and numbers the wells from the window's start. :class:`Stack`
keeps the two in step: a well's global index is the held index plus the window's offset, and
with ``yield_strains = extend`` the windows are moved ahead of the Gauss points after every event
(:meth:`Stack.hold_wells_ahead`), always through the backend (:meth:`.backends.base.Backend.set_yield_strains`).
With junction aging (:mod:`.thermal.junctions`) the yield strains the backend holds are that window with
every junction's well widened (:meth:`Stack.push_yield_strains`), and a stored state includes the junctions.
"""

import numpy as np

from .errors import SolverError
from .laws import make_law
from .materials import equivalent_strains
from .model import build_model
from .thermal.junctions import Junctions
from .yield_strains import HeldYieldStrains, interface_initstate

__all__ = ["Stack", "build_stack"]


class Stack:
    """The state of a simulated stack (in its backend) with the yield strains the backend holds.

    Parameters
    ----------
    backend : stickslip.fem.backends.base.Backend
        Prepared for the stack's model (it owns the state).
    wells : HeldYieldStrains
        The held windows of the blocks' yield-strain sequences; ``backend.model.epsy`` is ``wells.epsy``.
    extend : bool
        ``yield_strains = extend``: the windows follow the Gauss points (else they hold the whole sequence).
    junctions : stickslip.fem.thermal.junctions.Junctions, optional
        Junction aging: the junctions that widen the blocks' current wells (None: no aging; then
        ``backend.model.epsy`` is ``wells.epsy``).

    Attributes
    ----------
    backend, wells, extend, junctions
    """

    def __init__(self, backend, wells, extend, junctions=None):
        self.backend = backend
        self.wells = wells
        self.extend = extend
        self.junctions = junctions

    @property
    def model(self):
        """The backend's :class:`.model.Model` (read only)."""
        return self.backend.model

    @property
    def time(self):
        """The clock [time]."""
        return float(self.backend.read("t")[0][0])

    def set_time(self, t):
        """Set the clock [time]."""
        self.backend.set_time(t)

    def well_index(self):
        """Global well index of every interface Gauss point (counted from the start of the sequence), int64 [ni, 4]."""
        return self.backend.read("idx")[0] + self.wells.offset[:, None]

    def within_margin(self, margin):
        """True if every Gauss point is more than ``margin`` wells from the end of the held yield strains."""
        return bool(np.all(self.backend.read("idx")[0] < self.wells.epsy.shape[1] - margin))

    def stored(self):
        """Copies of what :meth:`restore` needs, the state stored per increment: (u, target, lever_target, t),
        and with junctions their state (:meth:`.thermal.junctions.Junctions.stored`) as a fifth item."""
        u, target, lever, t = self.backend.read("u", "target", "lever", "t")
        state = (u.copy(), target.copy(), float(lever[0]), float(t[0]))
        return state if self.junctions is None else (*state, self.junctions.stored())

    def restore(self, u, target, lever_target, t, junctions=None):
        """Set a stored state (at rest) and, with ``extend``, move the windows to it (:meth:`hold_wells_ahead`).

        Parameters
        ----------
        u : numpy.ndarray
            [ndof] displacement.
        target : numpy.ndarray
            [nlayer] drive targets (fixed lever; recomputed for a free lever).
        lever_target : float
            Free lever: drive target ``x_target``.
        t : float
            Time.
        junctions : dict, optional
            The junctions' state (:meth:`.thermal.junctions.Junctions.stored`), set before the displacement.
        """
        if junctions is not None:
            self.junctions.restore(junctions)
            self.push_yield_strains()
        self.backend.set_state(u, target, lever_target, t)
        if self.extend:
            self.hold_wells_ahead()

    def push_yield_strains(self, shift=None):
        """Give the backend the yield strains it holds: the window, each junction's well widened (if any).

        Parameters
        ----------
        shift : numpy.ndarray, optional
            int64 [ni]: the windows moved forward by this many values (:meth:`.backends.base.Backend.set_yield_strains`).
        """
        epsy = self.wells.epsy if self.junctions is None else self.junctions.aged(self.wells)
        self.backend.set_yield_strains(epsy, shift)

    def widen_wells(self):
        """Hold twice as many wells per block (the window's start unchanged)."""
        self.wells.widen(self.wells.epsy.shape[1] - 1)
        self.push_yield_strains()

    def hold_wells_ahead(self):
        """``yield_strains = extend``: hold at least half a window of wells ahead of every Gauss point.

        A block with fewer than ``(ny - 1) // 2`` held wells ahead of its furthest Gauss
        point has its window moved forward to start ``(ny - 1) // 4`` wells behind its
        nearest one (or widened if its points are spread too far for that). A state
        beyond the held wells (after :meth:`restore`) is followed to its wells; a state
        behind them restarts the windows from the origin. The values held never change
        the physics: they are the same numbers wherever the window is.
        """
        wells = self.wells
        idx, eps = self.backend.read("idx", "eps")
        if np.any((wells.offset > 0) & (idx.min(axis=1) == 0)
                  & (equivalent_strains(eps).min(axis=1) <= wells.epsy[:, 0])):
            wells.start(wells.epsy.shape[1] - 1)
            self.push_yield_strains()
        while True:
            ny = wells.epsy.shape[1]
            ahead, behind = (ny - 1) // 2, (ny - 1) // 4
            idx, eps = self.backend.read("idx", "eps")
            short = idx.max(axis=1) > ny - 1 - ahead
            if not short.any():
                return
            beyond = equivalent_strains(eps).max(axis=1) > wells.epsy[:, -1]
            shift = np.where(short, np.where(beyond, ny - 1 - behind, idx.min(axis=1) - behind), 0)
            if np.any(short & (shift <= 0)):
                self.widen_wells()
                continue
            wells.slide(shift)
            self.push_yield_strains(shift)


def build_stack(params, mesh, backend, constants):
    """The stack of a run at rest at the origin: its yield strains, its model, the backend prepared for it.

    Parameters
    ----------
    params : FemParams
    mesh : stickslip.mesh.LayeredMesh
    backend : stickslip.fem.backends.base.Backend
        Not yet prepared (:func:`.backends.make_backend`).
    constants : dict
        :func:`.constants.derived_constants`.

    Returns
    -------
    Stack
        With :class:`.thermal.junctions.Junctions` if ``junction_strengthening > 0`` (none drawn yet).

    Raises
    ------
    SolverError
        If a held well is narrower than the kick ``deps``.
    """
    extend = params.yield_strains == "extend"
    wells = HeldYieldStrains(interface_initstate(params.seed, mesh.N, mesh.n_interfaces),
                             params.window if extend else params.nchunk, params.eps0, params.eps_offset,
                             params.weibull_k)
    narrowest = min(np.min(np.diff(wells.epsy, axis=1)), params.eps_offset if extend else np.inf)
    if narrowest <= constants["deps"]:
        raise SolverError("a well is narrower than the kick 'deps'; use a smaller 'deps' or larger 'eps_offset'")
    plastic = np.asarray(mesh.layer_is_plastic, dtype=bool)
    model = build_model(mesh, epsy=wells.epsy,
                        law=make_law(params.interface_law, params.K, params.G, params.law_params),
                        rho=params.rho, alpha=constants["alpha"], dt=constants["dt"], k_drive=params.k_drive,
                        drive_active=~plastic & (np.arange(mesh.nlayer) > 0), free_lever=params.drive == "free-lever",
                        lever_height=constants["H"])
    junctions = None
    if params.junction_strengthening > 0.0:
        junctions = Junctions(wells.epsy.shape[0], params.junction_strengthening, params.junction_glass_temperature,
                              params.junction_attempt_rate, params.eps0)
    return Stack(backend.prepare(model, mesh), wells, extend, junctions)
