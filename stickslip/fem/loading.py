"""Quasistatic loading of a stack along its linear response: elastic steps to the brink of yielding, kicks past it.

The load direction (:class:`.linear_response.LinearResponse`) is given to the stack once
(:meth:`.stack.Stack.set_load_direction`); a step along it moves the displacement and
the drive together (:meth:`.stack.Stack.load`). The step to the brink, or just past
it, is found on the host from the interface strain (:func:`.event_driven.step_size`).
Reference: shared/reference-model.md, section 8a-8b.
"""

from .errors import SolverError
from .event_driven import step_size, unload_size

__all__ = ["Loading", "KickAlongResponse"]


class Loading:
    """Steps of a stack along its linear response (elastic load steps and kicks).

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
    model : stickslip.fem.model.Model
        The stack's model (its interface elements; the held yield strains are the stack's).
    response : stickslip.fem.linear_response.LinearResponse
    deps : float
        Kick size in equivalent strain (:func:`.constants.derived_constants`).
    """

    def __init__(self, stack, model, response, deps):
        self.stack = stack
        self.model = model
        self.response = response
        self.deps = deps
        stack.set_load_direction(response.delta_u, response.delta_target, response.delta_lever)

    def step_size(self, kick, yield_element=False, bisect=True):
        """The step along the linear response that :meth:`step` makes (nothing is changed).

        Parameters
        ----------
        kick : bool
            Kick (smallest step that changes a well index) or elastic load step (largest step that changes none).
        yield_element : bool
            Kick until all Gauss points of one element change well.
        bisect : bool, optional
            False: a kick to ``deps / 2`` past the nearest yield strain, not refined to just past it
            (:func:`.event_driven.step_size`).

        Returns
        -------
        float
            The step [in units of the linear response] (0: already at the brink).

        Raises
        ------
        SolverError
            If no yielding step exists.
        """
        m, stack = self.model, self.stack
        u, eps, idx = stack.read("u", "eps", "idx")
        r = self.response
        step = step_size(stack.yield_strains, m.iface_dofs, m.iface_dNdx, u, r.delta_u, eps, r.delta_eps, idx, self.deps, kick,
                         yield_element and kick, bisect)
        if step < 0.0:
            raise SolverError("no step along the linear response makes a block yield")
        return step

    def unload_size(self, step):
        """The largest elastic step back along the linear response, at most ``step`` (nothing is changed).

        Parameters
        ----------
        step : float
            The unload wanted (>= 0) [in units of the linear response].

        Returns
        -------
        float
            ``s`` in ``[0, step]`` such that ``load(-s)`` changes no well index (:func:`.event_driven.unload_size`).
        """
        m, stack = self.model, self.stack
        u, idx = stack.read("u", "idx")
        return unload_size(stack.yield_strains, m.iface_dofs, m.iface_dNdx, u, self.response.delta_u, idx, step)

    def load(self, step):
        """Move the state by ``step`` along the linear response (displacement and drive; no dynamics)."""
        self.stack.load(step)

    def step(self, kick, yield_element=False):
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
        token = self.stack.checkpoint()
        step = self.step_size(kick, yield_element)
        self.load(step)
        changed = self.stack.changed_since(token) > 0
        if kick and not changed:
            # the step is found with the CPU's arithmetic, to just past a yield strain; a backend of other round-off
            # (a GPU's fused multiply-adds) can leave the point a rounding error short of it: kick again from where
            # it is, to deps / 2 past it. Never on the CPU backends, which evaluate the trial displacement bit for
            # bit as the step was found.
            extra = self.step_size(kick, yield_element, bisect=False)
            self.load(extra)
            step += extra
            changed = self.stack.changed_since(token) > 0
        if kick != changed:
            raise SolverError(f"{'kick' if kick else 'load step'} of size {step:.6e}: well indices "
                              f"{'did not change' if kick else 'changed'}")
        return step


class KickAlongResponse:
    """The athermal kick, a perturbation: the smallest step along the linear response that makes a block yield.

    Parameters
    ----------
    loading : Loading
    yield_element : bool
        Kick until all four Gauss points of one element change well (the fallback).
    """

    def __init__(self, loading, yield_element):
        self.loading = loading
        self.yield_element = yield_element

    def apply(self):
        """Kick the stack (:meth:`Loading.step`)."""
        self.loading.step(True, self.yield_element)
