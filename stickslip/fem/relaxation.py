"""How a perturbed stack comes to rest: the relaxations of a kick, each an object that takes the backend.

:class:`DynamicRelaxation` (``relaxation = dynamic``, the paper's protocol): damped inertial
dynamics until the residual criterion (:meth:`.backends.base.Backend.minimise`).
:class:`ExactRelaxation` (``relaxation = exact``): the same dynamics, interrupted once
``quiet_steps`` steps changed no well; then the equilibrium of the current wells is solved
directly (:class:`.equilibrium.WellEquilibrium`) and accepted if every Gauss point of it lies in
its current well, otherwise the dynamics go on (and a solve is tried again after the next quiet
window). When the residual criterion is met first, the solve is tried too (its result, if
accepted, replaces the quenched state). The state's time ``t`` counts the time steps made.
"""

import numpy as np

from .backends import CONVERGED, MARGIN, MAX_ITER_REACHED
from .equilibrium import WellEquilibrium
from .errors import SolverError

__all__ = ["DynamicRelaxation", "ExactRelaxation", "make_relaxation"]


class DynamicRelaxation:
    """Damped inertial dynamics until the residual criterion (the paper's protocol).

    Parameters
    ----------
    tol : float
        Relative residual tolerance.
    niter_tol : int
        Consecutive steps below ``tol`` (and non-increasing).
    max_iter : int
        Time steps after which a relaxation fails.
    """

    #: Time steps without a well change after which the relaxation tries its solve (0: never).
    quiet_steps = 0

    def __init__(self, tol, niter_tol, max_iter):
        self.tol = tol
        self.niter_tol = niter_tol
        self.max_iter = max_iter

    def _solved(self, backend):
        """Whether a pause of the dynamics ends the relaxation by a direct solve (never, here)."""
        return False

    def relax(self, backend, margin=0, record=False):
        """Relax the backend's state to rest (module docstring).

        Parameters
        ----------
        backend : stickslip.fem.backends.base.Backend
        margin : int, optional
            Stop when a Gauss point comes within this many wells of the end of its held yield strains.
        record : bool, optional
            Record the well changes of Gauss point 0 (:meth:`.backends.base.Backend.minimise`).

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
        total = 0
        found = []
        while True:
            status, niter, events = backend.minimise(self.tol, self.niter_tol, self.max_iter - total, margin, record,
                                                     self.quiet_steps)
            total += niter
            found.append(events)
            events = np.concatenate(found) if len(found) > 1 else events
            if status == MAX_ITER_REACHED:
                raise SolverError(f"minimisation did not converge in max_iter = {self.max_iter} steps")
            if status == MARGIN:
                return 0, events
            if self._solved(backend):
                return total, events
            if status == CONVERGED:
                return total, events

    def equilibrate_linear(self, backend):
        """Bring a linear (all elastic) model to equilibrium from rest: :meth:`relax`."""
        self.relax(backend)


class ExactRelaxation(DynamicRelaxation):
    """Damped dynamics interrupted after quiet windows by the equilibrium of the current wells, solved directly.

    Parameters
    ----------
    tol, niter_tol, max_iter
        As :class:`DynamicRelaxation`.
    quiet_steps : int
        Time steps without any well change before a solve is tried (and between tries).
    model : stickslip.fem.model.Model
        The run's model: its linear parts make the factorised matrix (:class:`.equilibrium.WellEquilibrium`,
        built on first use and shared with every model of the same mesh, e.g. the elastic one of the
        linear response).
    """

    def __init__(self, tol, niter_tol, max_iter, quiet_steps, model):
        super().__init__(tol, niter_tol, max_iter)
        self.quiet_steps = quiet_steps
        self._model = model
        self._equilibrium = None

    @property
    def equilibrium(self):
        """The factorised constant stiffness (:class:`.equilibrium.WellEquilibrium`), built on first use."""
        if self._equilibrium is None:
            self._equilibrium = WellEquilibrium(self._model)
        return self._equilibrium

    def solve_in_wells(self, backend):
        """Replace the state by the equilibrium of its current wells if every Gauss point stays in its well.

        Returns
        -------
        bool
            True if the state (now at rest) was replaced; else it is unchanged.
        """
        return self.equilibrium.move_to_equilibrium(backend, self.tol)

    _solved = solve_in_wells

    def equilibrate_linear(self, backend):
        """Bring a linear (all elastic) model to equilibrium: one direct solve (the matrix is its exact stiffness)."""
        if not self.solve_in_wells(backend):
            raise SolverError("the direct solve of the linear response did not converge")


def make_relaxation(params, constants, model):
    """The relaxation of a run's parameters (``relaxation``: ``dynamic`` or ``exact``).

    Parameters
    ----------
    params : FemParams
    constants : dict
        :func:`.constants.derived_constants` (``quiet_steps``).
    model : stickslip.fem.model.Model
        The run's model (the exact relaxation's matrix).
    """
    if params.relaxation == "exact":
        return ExactRelaxation(params.tol, params.niter_tol, params.max_iter, constants["quiet_steps"], model)
    return DynamicRelaxation(params.tol, params.niter_tol, params.max_iter)
