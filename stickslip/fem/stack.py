"""The simulated stack: the one face of a state that a backend owns, and the window of yield strains it holds.

The rest of the package reads and changes the state only through :class:`Stack`: its backend is private
(a test greps the package for reach-throughs). The yield strains the backend holds are a window of the
blocks' unbounded sequences (:class:`.window.HeldWindow`): a well's global index is the held index plus
the window's offset, and with ``yield_strains = extend`` the windows are moved ahead of the Gauss points
after every relaxation that moved something (:meth:`Stack.relax`). What the backend holds may be modified
by one **yield-strain modifier** that a protocol registers (:meth:`Stack.modify_yield_strains`; junction
aging): a stored state then includes the modifier's state as a fifth item. The stack's time is its backend's
(the time steps of the dynamics) unless a protocol keeps its own clock (:meth:`Stack.keep_time`, a thermal
run's: :mod:`.clock`). The stack imports nothing of the protocols.
"""

import numpy as np

from .backends.base import read_only
from .errors import SolverError
from .laws import make_law
from .model import build_model
from .window import HeldWindow
from .yield_strains import HeldYieldStrains, element_scale, interface_initstate

__all__ = ["Stack", "stack_model"]


class Stack:
    """The state of a simulated stack (owned by its backend) with the yield strains the backend holds.

    Parameters
    ----------
    backend : stickslip.fem.backends.base.Backend
        Prepared for the stack's model (it owns the state); private to the stack from then on.
    wells : HeldYieldStrains
        The held windows of the blocks' yield-strain sequences.
    extend : bool
        ``yield_strains = extend``: the windows follow the Gauss points (else they hold the whole sequence); an
        attribute of the same name.
    """

    def __init__(self, backend, wells, extend):
        self._backend = backend
        self._window = HeldWindow(backend, wells)
        self._clock = None
        self.extend = extend

    @property
    def wells(self):
        """The held windows (:class:`HeldYieldStrains`: read them; the stack moves them)."""
        return self._window.wells

    def modify_yield_strains(self, modifier):
        """Register the yield-strain modifier (:mod:`.window`); the backend is given its yield strains at once."""
        self._window.register(modifier)

    @property
    def modifier(self):
        """The registered yield-strain modifier (None: none)."""
        return self._window.modifier

    def keep_time(self, clock):
        """Let a protocol's :class:`.clock.Clock`, set to the time now, keep the stack's time (:attr:`time`, the stored
        states' and :meth:`restore`'s); the relaxations no longer advance it (the backend's dynamics go on counting)."""
        clock.restore(self.time)
        self._clock = clock

    @property
    def clock(self):
        """The protocol's clock that keeps the stack's time (None: the backend's time of the dynamics)."""
        return self._clock

    @property
    def time(self):
        """The stack's time [time]: the kept clock's, else the time of the backend's dynamics."""
        return self._clock.time if self._clock is not None else float(self._backend.read("t")[0][0])

    def read(self, *fields):
        """The state fields ``fields`` (:data:`.backends.base.FIELDS`), a tuple of read-only arrays."""
        return self._backend.read(*fields)

    @property
    def yield_strains(self):
        """The yield strains the backend holds now: the windows, modified (if a modifier is registered), float64
        [ni, ny], read only (they change when the windows move)."""
        return read_only(self._backend.model.epsy)

    def well_index(self):
        """Global well index of every interface Gauss point (counted from the start of the sequence), int64 [ni, 4]."""
        return self._backend.read("idx")[0] + self.wells.offset[:, None]

    def watch(self):
        """A token for :meth:`moved` and :meth:`well_changes`: the well of every Gauss point now."""
        return self.well_index()

    def moved(self, token):
        """Whether a Gauss point changed well since :meth:`watch` gave ``token``."""
        return not np.array_equal(self.well_index(), token)

    def well_changes(self, token):
        """Wells moved by every Gauss point since :meth:`watch` gave ``token``: int64 [ni, 4] (+ forward)."""
        return self.well_index() - token

    def within_margin(self, margin):
        """True if every Gauss point is more than ``margin`` wells from the end of the held yield strains."""
        return bool(np.all(self._backend.read("idx")[0] < self.wells.epsy.shape[1] - margin))

    def stored(self):
        """Copies of what :meth:`restore` needs, the state stored per increment: (u, target, lever_target, t),
        and with a modifier its state (``stored()``) as a fifth item."""
        u, target, lever = self._backend.read("u", "target", "lever")
        state = (u.copy(), target.copy(), float(lever[0]), self.time)
        return state if self.modifier is None else (*state, self.modifier.stored())

    def restore(self, u, target, lever_target, t, modified=None):
        """Set a stored state (at rest) and, with ``extend``, move the windows to it (:meth:`hold_wells_ahead`).

        Parameters
        ----------
        u, target, lever_target, t
            A stored state (:meth:`stored`): displacement [ndof], drive targets [nlayer] (recomputed for a free
            lever), a free lever's drive target, time.
        modified : dict, optional
            The modifier's state (its ``stored()``), set before the displacement.
        """
        if modified is not None:
            self.modifier.restore(modified)
            self._window.push()
        self._backend.set_state(u, target, lever_target, t)
        if self._clock is not None:
            self._clock.restore(t)
        if self.extend:
            self.hold_wells_ahead()

    def set_load_direction(self, delta_u, delta_target, delta_lever):
        """The direction of :meth:`load`: displacement [ndof], layer targets [nlayer], free lever's drive target."""
        self._backend.set_load_direction(delta_u, delta_target, delta_lever)

    def load(self, step):
        """Move the displacement and the drive by ``step`` times the load direction (no dynamics)."""
        self._backend.load(step)

    def add_u(self, dofs, delta):
        """Add ``delta`` [len(dofs)] to the displacement of ``dofs`` (int64), no dynamics."""
        self._backend.add_u(dofs, delta)

    def relax(self, relaxation, margin, record=False):
        """Bring the stack to rest with ``relaxation``; with ``extend``, then hold the wells ahead.

        Parameters and returns (``niter``, 0 if stopped by the margin; ``events``) as
        :meth:`.relaxation.DynamicRelaxation.relax`; ``relaxation`` a ``DynamicRelaxation`` or ``ExactRelaxation``.
        """
        niter, events = relaxation.relax(self._backend, margin, record)
        if niter and self.extend:
            self.hold_wells_ahead()
        return niter, events

    def backend_for(self, model):
        """A backend prepared for another model on the stack's mesh and drive, with a state of its own (the linear
        response's elastic twin; :meth:`.backends.base.Backend.for_model`)."""
        return self._backend.for_model(model)

    def push_yield_strains(self):
        """Give the backend the yield strains it holds anew (a modifier's state changed: :meth:`.window.HeldWindow.push`)."""
        self._window.push()

    def widen_wells(self):
        """Hold twice as many wells per block (the window's start unchanged)."""
        self._window.widen()

    def hold_wells_ahead(self):
        """Hold at least half a window of wells ahead of every Gauss point (:meth:`.window.HeldWindow.hold_ahead`)."""
        self._window.hold_ahead()


def stack_model(params, mesh, constants):
    """The model of a run's stack and the held windows of its yield strains (at the origin).

    Parameters
    ----------
    params : FemParams
    mesh : stickslip.mesh.LayeredMesh
    constants : dict
        :func:`.constants.derived_constants`.

    Returns
    -------
    model : stickslip.fem.model.Model
        Its ``epsy`` the windows' yield strains (a :class:`Stack` tells those held later, :attr:`Stack.yield_strains`).
    wells : HeldYieldStrains

    Raises
    ------
    SolverError
        If a held well is narrower than the kick ``deps``.
    """
    extend = params.yield_strains == "extend"
    scale = element_scale(params.interface_strength, mesh.N, mesh.n_interfaces)
    wells = HeldYieldStrains(interface_initstate(params.seed, mesh.N, mesh.n_interfaces),
                             params.window if extend else params.nchunk, params.eps0, params.eps_offset,
                             params.weibull_k, scale)
    narrowest = min(np.min(np.diff(wells.epsy, axis=1)), params.eps_offset * scale.min() if extend else np.inf)
    if narrowest <= constants["deps"]:
        raise SolverError("a well is narrower than the kick 'deps'; use a smaller 'deps' or larger 'eps_offset'")
    plastic = np.asarray(mesh.layer_is_plastic, dtype=bool)
    model = build_model(mesh, epsy=wells.epsy,
                        law=make_law(params.interface_law, params.K, params.G, params.law_params),
                        rho=params.rho, alpha=constants["alpha"], dt=constants["dt"], k_drive=params.k_drive,
                        drive_active=~plastic & (np.arange(mesh.nlayer) > 0), free_lever=params.drive == "free-lever",
                        lever_height=constants["H"])
    return model, wells
