"""The simulated stack: the one face of a state that a backend owns, and the window of yield strains it holds.

The rest of the package reads and changes the state only through :class:`Stack`: its backend is private
(a test greps the package for reach-throughs). The yield strains the backend holds are a window of the
blocks' unbounded sequences (:class:`.window.HeldWindow`): a well's global index is the held index plus
the window's offset, and with ``yield_strains = extend`` the windows are moved ahead of the Gauss points
after every relaxation that moved something (:meth:`Stack.relax`). What the backend holds may be modified
by one **yield-strain modifier** that a protocol registers (:meth:`Stack.modify_yield_strains`; junction
aging): a stored state then includes the modifier's state (:attr:`.formats.fem_run.StoredState.further`). The
stack's time is its backend's (the time steps of the dynamics) unless a protocol keeps its own clock
(:meth:`Stack.keep_time`, a thermal run's: :mod:`.clock`). The stack imports nothing of the protocols.

Two ways back to a state: a **checkpoint** (:meth:`Stack.checkpoint`, :meth:`Stack.rollback`) is kept where the
state is, on a device backend's device, and nothing of it comes to the host; whether a Gauss point changed well
since one is a number counted there (:meth:`Stack.changed_since`). A **stored state** (:meth:`Stack.stored`,
:meth:`Stack.restore`) is the run file's record, host copies. The stack reads the state through host copies made
once per state (:class:`.host_copies.HostCopies`): a state returned to by a rollback is not copied again.
"""

from typing import NamedTuple

import numpy as np

from ..formats.fem_run import StoredState
from .errors import SolverError
from .host_copies import HostCopies
from .laws import make_law
from .model import build_model
from .window import HeldWindow
from .yield_strains import HeldYieldStrains, element_scale, interface_initstate

__all__ = ["Stack", "Checkpoint", "stack_model"]


class Checkpoint(NamedTuple):
    """A checkpoint of a stack (:meth:`Stack.checkpoint`): the backend's own, and what the stack keeps beside it.

    Attributes
    ----------
    backend
        The backend's checkpoint (:meth:`.backends.base.Backend.checkpoint`), kept where the state is.
    window : tuple
        The windows of yield strains (:meth:`.window.HeldWindow.snapshot`).
    modified : dict
        The modifier's state (its ``stored()``); empty without a modifier.
    copies : dict
        The host copies of the state (:meth:`.host_copies.HostCopies.now`).
    """

    backend: object
    window: tuple
    modified: dict
    copies: dict


class Stack:
    """The state of a simulated stack (owned by its backend) with the yield strains the backend holds.

    Parameters
    ----------
    backend : stickslip.fem.backends.base.Backend
        Prepared for the stack's model (it owns the state; it is given the windows' yield strains at once); private.
    wells : HeldYieldStrains
        The held windows of the blocks' yield-strain sequences.
    extend : bool
        ``yield_strains = extend`` (the windows follow the Gauss points); an attribute of the same name.
    """

    def __init__(self, backend, wells, extend):
        self._backend = backend
        self._copies = HostCopies(backend)
        self._window = HeldWindow(backend, wells, self._copies)
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
        return self._clock.time if self._clock is not None else float(self.read("t")[0][0])

    def read(self, *fields):
        """The state fields ``fields`` (:data:`.backends.base.FIELDS`), a tuple of read-only host copies."""
        return self._copies.read(*fields)

    @property
    def yield_strains(self):
        """The yield strains the backend holds now: the windows, modified (if a modifier is registered), float64
        [ni, ny], read only (they change when the windows move)."""
        return self._window.held

    def well_index(self):
        """Global well index of every interface Gauss point (counted from the start of the sequence), int64 [ni, 4]."""
        return self.read("idx")[0] + self.wells.offset[:, None]

    def within_margin(self, margin):
        """True if every Gauss point is more than ``margin`` wells from the end of the held yield strains."""
        return bool(np.all(self.read("idx")[0] < self.wells.epsy.shape[1] - margin))

    def checkpoint(self):
        """A :class:`Checkpoint` of the whole state (the backend's part stays where the state is: no copy to the host)."""
        modified = {} if self.modifier is None else self.modifier.stored()
        return Checkpoint(self._backend.checkpoint(), self._window.snapshot(), modified, self._copies.now())

    def rollback(self, token):
        """Return to the state of :class:`Checkpoint` ``token``, bit for bit: the backend's state, the windows, the
        modifier's state. A protocol's clock is left alone (time goes on: :mod:`.clock`)."""
        self._backend.rollback(token.backend)
        self._window.resume(token.window)
        if token.modified:
            self.modifier.restore(token.modified)
        self._copies.resume(token.copies)

    def changed_since(self, token, elements=None):
        """How many Gauss points (of ``elements``, int64; default all) are in another global well than at
        :class:`Checkpoint` ``token``, counted where the state is (:meth:`.backends.base.Backend.wells_changed`)."""
        shift = self.wells.offset - token.window[0][1]
        moved = not shift.any()
        count = self._backend.wells_changed(token.backend, None if moved else shift, elements)
        if count == 0 and moved and elements is None:
            self._copies.same_wells(token.copies)
        return count

    def stored(self):
        """The state stored per increment: a :class:`.formats.fem_run.StoredState` (``further``: the modifier's state)."""
        u, target, lever = self.read("u", "target", "lever")
        further = {} if self.modifier is None else self.modifier.stored()
        return StoredState(u, target, float(lever[0]), self.time, further)

    def restore(self, state):
        """Set a :class:`.formats.fem_run.StoredState` (at rest; its ``further`` first); with ``extend``, move the
        windows to it (:meth:`hold_wells_ahead`)."""
        if state.further:
            self.modifier.restore(state.further)
            self._window.push()
        self._backend.set_state(state.u, state.target, state.lever_target, state.t)
        self._copies.changed()
        if self._clock is not None:
            self._clock.restore(state.t)
        if self.extend:
            self.hold_wells_ahead()

    def set_load_direction(self, delta_u, delta_target, delta_lever):
        """The direction of :meth:`load`: displacement [ndof], layer targets [nlayer], free lever's drive target."""
        self._backend.set_load_direction(delta_u, delta_target, delta_lever)

    def load(self, step):
        """Move the displacement and the drive by ``step`` times the load direction (no dynamics)."""
        self._backend.load(step)
        self._copies.changed()

    def add_u(self, dofs, delta):
        """Add ``delta`` [len(dofs)] to the displacement of ``dofs`` (int64), no dynamics."""
        self._backend.add_u(dofs, delta)
        self._copies.changed()

    def relax(self, relaxation, margin, record=False, ahead=True):
        """Relax (as :meth:`.relaxation.DynamicRelaxation.relax`); with ``extend``, then hold the wells ahead, unless
        ``ahead`` is False (a read of the state: the caller calls :meth:`hold_wells_ahead` before the next relaxation)."""
        niter, events = relaxation.relax(self._backend, margin, record)
        self._copies.changed()
        if niter and self.extend and ahead:
            self.hold_wells_ahead()
        return niter, events

    def backend_for(self, model, epsy):
        """A backend for another model on the stack's mesh, its own state (:meth:`.backends.base.Backend.for_model`)."""
        return self._backend.for_model(model, epsy)

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
    wells : HeldYieldStrains
        Its yield strains those a :class:`Stack` gives its backend (:attr:`Stack.yield_strains`).

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
    model = build_model(mesh, law=make_law(params.interface_law, params.K, params.G, params.law_params),
                        rho=params.rho, alpha=constants["alpha"], dt=constants["dt"], k_drive=params.k_drive,
                        drive_active=~plastic & (np.arange(mesh.nlayer) > 0), free_lever=params.drive == "free-lever",
                        lever_height=constants["H"])
    return model, wells
