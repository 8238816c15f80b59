"""The simulated stack: model arrays, current state and the steps of the event-driven protocol.

:class:`System` holds a :class:`.model.Model` and a :class:`.model.State` and
offers the operations of the quasistatic protocol (shared/reference-model.md,
section 8): the linear response, the elastic load step, the kick, the
minimisation, and restoring a stored state.
"""

import math

import numpy as np

from .equilibrium import WellEquilibrium
from .event_driven import autoscale, step_size
from .laws import Cusp, make_law
from .materials import equivalent_strains
from .minimise import CONVERGED, MARGIN, MAX_ITER_REACHED, QUIET
from .model import build_model, new_state
from .yield_strains import HeldYieldStrains, interface_initstate, narrowest_well

__all__ = ["System", "SolverError", "derived_constants"]


class SolverError(RuntimeError):
    """The protocol cannot continue (no convergence, no yielding step found)."""


def derived_constants(params, mesh):
    """Constants that follow from the parameters and the mesh.

    Parameters
    ----------
    params : FemParams
    mesh : stickslip.mesh.LayeredMesh

    Returns
    -------
    dict
        ``L`` (periodic length), ``c`` = sqrt(G / rho), ``c_s`` = sqrt(G / 2 / rho)
        (shear-wave speed), ``alpha`` = sqrt(2) (2 pi / L) c rho (critical damping of
        the shear wave of wavelength L), ``dt`` = ``dt_scale`` h / (2 pi c) / 10, ``sig0`` = 2 G eps0,
        ``deps`` (kick, strain), ``H`` (free-lever drive height), ``quiet_steps`` (the
        exact relaxation's quiet window in time steps: ``params.quiet_steps``, or if that
        is 0 the shear-wave transit time over a third of the interface, ``L / (3 c_s)``,
        rounded up to whole steps).
    """
    h = float(mesh.h)
    L = mesh.N * h
    c = math.sqrt(params.G / params.rho)
    c_s = math.sqrt(params.G / 2.0 / params.rho)
    dt = params.dt_scale * (1.0 / (c * 2.0 * math.pi / h)) / 10.0
    heights = np.asarray(mesh.layer_mid_height, dtype=np.float64)
    return {
        "h": h, "L": L, "c": c, "c_s": c_s,
        "alpha": math.sqrt(2.0) * (2.0 * math.pi / L) * c * params.rho,
        "dt": dt,
        "quiet_steps": params.quiet_steps or math.ceil(L / (3.0 * c_s) / dt),
        "sig0": 2.0 * params.G * params.eps0,
        "deps": params.deps * params.eps0,
        "H": params.lever_height * float(heights[1] - heights[0]),
    }


class System:
    """A stack of plates and interfaces driven by springs (fixed or free lever).

    Parameters
    ----------
    params : FemParams
        The physics: the interface law is ``params.interface_law`` (:mod:`.laws`).
    mesh : stickslip.mesh.LayeredMesh
    backend
        How the numbers are computed (:mod:`.backends`, e.g. ``make_backend(params.backend,
        threads)``); the system keeps it prepared for its model.

    Attributes
    ----------
    model : Model
        Physics and discretisation; replaced (never modified) when the held yield strains move.
    backend
    state : State
    constants : dict
        See :func:`derived_constants`.
    delta_u, delta_eps, delta_target, delta_lever
        Scaled linear response (None until :meth:`set_linear_response` or
        :meth:`compute_linear_response`): displacement [ndof], interface strain
        [ni, 4, 3], layer targets [nlayer], lever drive target (free lever).
    """

    def __init__(self, params, mesh, backend):
        self.params = params
        self.mesh = mesh
        self.constants = derived_constants(params, mesh)
        initstate = interface_initstate(params.seed, mesh.N, mesh.n_interfaces)
        self.extend = params.yield_strains == "extend"
        self.wells = HeldYieldStrains(initstate, params.window if self.extend else params.nchunk, params.eps0,
                                      params.eps_offset, params.weibull_k)
        self.narrowest_well = narrowest_well(initstate, params.nchunk, params.eps0, params.eps_offset,
                                             params.weibull_k)
        epsy = self.wells.epsy
        narrowest = min(np.min(np.diff(epsy, axis=1)), params.eps_offset if self.extend else np.inf)
        if narrowest <= self.constants["deps"]:
            raise SolverError("a well is narrower than the kick 'deps'; use a smaller 'deps' or larger 'eps_offset'")
        plastic = np.asarray(mesh.layer_is_plastic, dtype=bool)
        self.drive_active = ~plastic & (np.arange(mesh.nlayer) > 0)
        self.heights = np.asarray(mesh.layer_mid_height, dtype=np.float64)
        c = self.constants
        self.model = build_model(mesh, epsy=epsy, law=make_law(params.interface_law, params.K, params.G),
                                 rho=params.rho, alpha=c["alpha"], dt=c["dt"], k_drive=params.k_drive,
                                 drive_active=self.drive_active, free_lever=params.drive == "free-lever",
                                 lever_height=c["H"])
        self.backend = backend.prepare(self.model, mesh)
        self.state = new_state(self.model)
        self.delta_u = self.delta_eps = self.delta_target = None
        self.delta_lever = 0.0
        self._equilibrium = None
        self.refresh()

    # --- state -----------------------------------------------------------------------------

    def refresh(self):
        """Recompute forces, interface strain/stress/indices and drive targets from ``state.u``."""
        self.backend.force(self.model, self.state)

    def restore(self, u, target, lever_target, t):
        """Set a stored state (at rest) and recompute everything that follows from it.

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
        """
        s = self.state
        s.u[:] = u
        s.v[:] = 0.0
        s.a[:] = 0.0
        s.target[:] = target
        s.lever[0] = lever_target
        s.t[0] = t
        self.refresh()
        if self.extend:
            self.hold_wells_ahead()

    def well_index(self):
        """Global well index of every interface Gauss point (counted from the start of the sequence), int64 [ni, 4]."""
        return self.state.idx + self.wells.offset[:, None]

    def _set_epsy(self):
        self.model = self.model._replace(epsy=self.wells.epsy)

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
        if np.any((wells.offset > 0) & (self.state.idx.min(axis=1) == 0)
                  & (equivalent_strains(self.state.eps).min(axis=1) <= wells.epsy[:, 0])):
            wells.start(wells.epsy.shape[1] - 1)
            self._set_epsy()
            self.refresh()
        while True:
            ny = wells.epsy.shape[1]
            ahead, behind = (ny - 1) // 2, (ny - 1) // 4
            idx = self.state.idx
            short = idx.max(axis=1) > ny - 1 - ahead
            if not short.any():
                return
            beyond = equivalent_strains(self.state.eps).max(axis=1) > wells.epsy[:, -1]
            shift = np.where(short, np.where(beyond, ny - 1 - behind, idx.min(axis=1) - behind), 0)
            if np.any(short & (shift <= 0)):
                wells.widen(ny - 1)
                self._set_epsy()
                continue
            wells.slide(idx, shift)
            if beyond.any():
                self.refresh()

    def snapshot(self):
        """Copies of what :meth:`restore` needs: (u, target, lever_target, t)."""
        s = self.state
        return s.u.copy(), s.target.copy(), float(s.lever[0]), float(s.t[0])

    # --- protocol --------------------------------------------------------------------------

    @property
    def equilibrium(self):
        """The factorised constant stiffness (:class:`.equilibrium.WellEquilibrium`), built on first use."""
        if self._equilibrium is None:
            self._equilibrium = WellEquilibrium(self.model)
        return self._equilibrium

    def relax_in_wells(self, model=None, state=None):
        """Replace a state by the equilibrium of its current wells if every Gauss point stays in its well.

        Parameters
        ----------
        model, state : optional
            Default: the system's own.

        Returns
        -------
        bool
            True if the state (now at rest) was replaced.
        """
        model = self.model if model is None else model
        state = self.state if state is None else state
        found = self.equilibrium.relax(model, state, self.backend, self.params.tol)
        if found is None:
            return False
        for name, value in zip(found._fields, found):
            getattr(state, name)[...] = value
        return True

    def minimise(self, margin=0, record=False, model=None, state=None):
        """Minimise: the kick's relaxation (:func:`.minimise.minimise`, then with ``relaxation = exact`` solves).

        ``relaxation = dynamic``: damped dynamics until the residual criterion (the
        paper's protocol). ``relaxation = exact``: the same dynamics, interrupted once
        ``constants["quiet_steps"]`` steps changed no well index; then the equilibrium of the current
        wells is solved (:meth:`relax_in_wells`) and accepted if every Gauss point of it
        lies in its current well, otherwise the dynamics continue (and a solve is tried
        again after the next quiet window). When the residual
        criterion is met first, the solve is tried too (its result, if accepted, replaces
        the quenched state). The state's time ``t`` counts the time steps made.

        Parameters
        ----------
        margin : int, optional
            Stop when a Gauss point comes within this many wells of the end of its sequence.
        record : bool, optional
            Record the well changes of Gauss point 0 (see :func:`.minimise.minimise`).
        model, state : optional
            Default: the system's own (the linear response minimises an elastic model in a state of its own).

        Returns
        -------
        niter : int
            Time steps made if converged, 0 if stopped by the margin.
        events : numpy.ndarray
            [nevent, 3] (element, time, direction) when ``record``.

        Raises
        ------
        SolverError
            If ``max_iter`` steps do not converge.
        """
        model = self.model if model is None else model
        state = self.state if state is None else state
        p = self.params
        quiet = self.constants["quiet_steps"] if p.relaxation == "exact" else 0
        total = 0
        found = []
        while True:
            status, niter, events = self.backend.minimise(model, state, p.tol, p.niter_tol, p.max_iter - total,
                                                          margin, record, quiet)
            total += niter
            found.append(events)
            events = np.concatenate(found) if len(found) > 1 else events
            if status == MAX_ITER_REACHED:
                raise SolverError(f"minimisation did not converge in max_iter = {p.max_iter} steps")
            if status == MARGIN:
                return 0, events
            if quiet and self.relax_in_wells(model, state):
                return total, events
            if status == CONVERGED:
                return total, events
            assert status == QUIET

    def compute_linear_response(self):
        """Compute the scaled elastic response to a unit drive (all interfaces elastic).

        Fixed lever: targets ``2 eps0 H_l`` (affine simple shear ``gamma = eps0``);
        free lever: lever drive target ``eps0``. ``relaxation = dynamic``: minimised from
        rest by damped dynamics (the paper's protocol); ``exact``: one direct solve with
        the run's factorisation (the model is linear). The interfaces are elastic, whatever the
        run's law: the cusp law in one infinitely wide well centred on zero strain, which is linear
        elasticity bit for bit (``G (1 - 0 / eps_eq) = G``) and needs no kernels compiled for
        another law type, in a model and state of their own. Then scaled so that the largest interface equivalent strain is
        0.1 of the narrowest well. The system's model and state are not changed.
        """
        huge = np.finfo(np.float64).max
        elastic = self.model._replace(law=Cusp(self.params.K, self.params.G),
                                      epsy=np.tile(np.array([[-huge, huge]]), (self.model.epsy.shape[0], 1)))
        state = new_state(elastic)
        unit_target = 2.0 * self.params.eps0 * self.heights
        state.target[:] = unit_target
        state.lever[0] = self.params.eps0
        self.backend.force(elastic, state)
        if self.params.relaxation == "exact":
            if not self.relax_in_wells(elastic, state):
                raise SolverError("the direct solve of the linear response did not converge")
        else:
            self.minimise(model=elastic, state=state)
        scale = autoscale(self.narrowest_well, state.eps)
        lever = scale * self.params.eps0 if self.model.free_lever else 0.0
        self.set_linear_response(scale * state.u, scale * state.eps, scale * unit_target, lever)

    def set_linear_response(self, delta_u, delta_eps, delta_target, delta_lever):
        """Set a (stored) scaled linear response; see the class attributes."""
        self.delta_u = np.asarray(delta_u, dtype=np.float64)
        self.delta_eps = np.asarray(delta_eps, dtype=np.float64)
        self.delta_target = np.asarray(delta_target, dtype=np.float64)
        self.delta_lever = float(delta_lever)

    def step_size(self, kick, yield_element=False):
        """The step along the linear response that :meth:`event_step` makes (nothing is changed).

        Parameters
        ----------
        kick : bool
            Kick (smallest step that changes a well index) or elastic load step (largest step that changes none).
        yield_element : bool
            Kick until all Gauss points of one element change well.

        Returns
        -------
        float
            The step [in units of the linear response] (0: already at the brink).

        Raises
        ------
        SolverError
            If no yielding step exists.
        """
        s, m = self.state, self.model
        step = step_size(m.epsy, m.iface_dofs, m.iface_dNdx, s.u, self.delta_u, s.eps, self.delta_eps, s.idx,
                         self.constants["deps"], kick, yield_element and kick)
        if step < 0.0:
            raise SolverError("no step along the linear response makes a block yield")
        return step

    def load(self, step):
        """Move the state by ``step`` along the linear response (displacement and drive; no dynamics)."""
        s = self.state
        s.u[:] += step * self.delta_u
        s.target[:] += step * self.delta_target
        s.lever[0] += step * self.delta_lever
        self.refresh()

    def event_step(self, kick, yield_element=False):
        """Elastic load step to the brink of yielding, or kick past it (no dynamics).

        Parameters
        ----------
        kick : bool
        yield_element : bool
            Kick until all Gauss points of one element change well.

        Returns
        -------
        float
            The step along the linear response (0: already at the brink).

        Raises
        ------
        SolverError
            If no yielding step exists or the step broke its promise (an index changed
            during a load step, or none during a kick).
        """
        s = self.state
        idx = s.idx.copy()
        step = self.step_size(kick, yield_element)
        self.load(step)
        changed = np.any(s.idx != idx)
        if kick != changed:
            raise SolverError(f"{'kick' if kick else 'load step'} of size {step:.6e}: well indices "
                              f"{'did not change' if kick else 'changed'}")
        return step

    def kick_and_minimise(self, yield_element, margin, record=False, kick=None):
        """Kick (:meth:`event_step`, or ``kick``) and :meth:`minimise`; with ``extend``, redone until the held wells suffice.

        With ``yield_strains = extend``, a minimisation that comes within ``margin``
        wells of the end of the held wells is discarded: the state before the kick is
        restored, the windows are widened (doubled) and the kick redone, which gives
        the state a longer sequence held from the start would give.

        Parameters
        ----------
        yield_element : bool
            Kick until all Gauss points of one element change well.
        margin : int
            See :meth:`minimise`.
        record : bool, optional
            Record the well changes of Gauss point 0, the kick's own included (at the
            time of the kick).
        kick : callable, optional
            ``kick()`` changes the state instead of the kick along the linear response (e.g. the
            local kick of a thermally activated block, :mod:`.thermal.hop`); it is called again
            after every restore.

        Returns
        -------
        niter : int
            Time steps made (0: stopped by the margin, ``stop`` only).
        events : numpy.ndarray
            [nevent, 3] (element, time, direction) when ``record``.
        """
        before = self.snapshot()
        while True:
            index = self.state.idx[:, 0].copy()
            if kick is None:
                self.event_step(True, yield_element=yield_element)
            else:
                kick()
            kicked = self.state.idx[:, 0] - index
            niter, events = self.minimise(margin=margin, record=record)
            if niter or not self.extend:
                break
            self.restore(*before)
            self.wells.widen(self.wells.epsy.shape[1] - 1)
            self._set_epsy()
        if record:
            rows = [(e, before[3], np.sign(kicked[e])) for e in np.flatnonzero(kicked) for _ in range(abs(kicked[e]))]
            events = np.concatenate([np.asarray(rows, dtype=np.float64).reshape(-1, 3), events])
        return niter, events

    def kick(self, margin):
        """Kick and minimise (an even increment of the protocol), with the whole-element fallback.

        :meth:`kick_and_minimise`; if the minimisation ends with no well index changed
        (the kicked point fell back), the state before the kick is restored and the kick
        redone so that all Gauss points of one element yield (``yield_element``). With
        ``yield_strains = extend``, the held wells are then moved ahead
        (:meth:`hold_wells_ahead`).

        Parameters
        ----------
        margin : int
            Stop when a Gauss point comes within this many wells of the end of its sequence.

        Returns
        -------
        converged : bool
            False if stopped by the margin (``yield_strains = stop`` only).
        yield_element : bool
            Whether the whole-element kick was needed.
        """
        before = self.snapshot()
        index = self.well_index()
        niter, _ = self.kick_and_minimise(False, margin)
        fallback = niter != 0 and np.array_equal(self.well_index(), index)
        if fallback:
            self.restore(*before)
            niter, _ = self.kick_and_minimise(True, margin)
        if niter != 0 and self.extend:
            self.hold_wells_ahead()
        return niter != 0, fallback
