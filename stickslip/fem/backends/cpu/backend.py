"""What the CPU backends share: numba kernels over a state and a workspace with a plate operator of their choice.

A CPU backend is :class:`CpuBackend` with a plate operator (:mod:`.plates`): the kernels of
:mod:`.forces`, :mod:`.dynamics` and :mod:`.minimise` run on its :class:`.state.State` with a
:class:`CpuWork` (the operator, the interface elements' field-by-field layout and scratch, the
number of parallel blocks), compiled by numba for the types of the law and of the operator.
Threads split elements and DOFs into blocks that are computed exactly as serially, so the results
do not depend on the number of threads. The state lives in host memory: :meth:`CpuBackend.read`
returns read-only views of it and every change is made in place, by its methods.
"""

import copy
from collections import namedtuple

import numpy as np

from ..base import Backend, read_only
from .dynamics import residual, time_steps
from .forces import compute_force, wells_hold
from .interface_elements import NIN, NOUT, interface_layout
from .minimise import minimise
from .state import new_state

__all__ = ["CpuBackend", "CpuWork", "InterfaceWork", "parallel_blocks"]

#: The interface elements' arrays of the vectorised kernel (:mod:`.interface_elements`).
InterfaceWork = namedtuple("InterfaceWork", [
    "grad",     # float64 [32, ni]: shape-function gradients field by field [1/length]
    "volume",   # float64 [4, ni]: integration volumes field by field [length^2]
    "inp",      # float64 [NIN, ni]: scratch (element displacements, well bounds)
    "out",      # float64 [NOUT, ni]: strain, stress, element force rows, outside flags
    "fe",       # float64 [ni, 8]: element forces [force]
])

#: The workspace of a CPU backend, passed whole to the kernels.
CpuWork = namedtuple("CpuWork", [
    "nblock",   # int: 1 = serial kernels; > 1 = parallel kernels over this many blocks
    "plates",   # the plate operator (a registered named tuple, :mod:`.plates`)
    "iface",    # InterfaceWork
])


def parallel_blocks(threads):
    """Number of parallel blocks for ``threads`` threads (1: the serial kernels); four per thread balance the load."""
    return 4 * int(threads) if threads > 1 else 1


class CpuBackend(Backend):
    """A numba CPU backend: the package's kernels with a plate operator chosen by the subclass (:class:`..base.Backend`).

    Subclasses set :attr:`name`, :attr:`summary` and implement :meth:`plate_operator`.

    Parameters
    ----------
    threads : int, optional
        Threads of the parallel kernels (1: serial kernels); the results do not depend on it.

    Attributes
    ----------
    model : stickslip.fem.model.Model or None
        The model of a prepared backend.
    state : State or None
        Its state (the kernels' argument).
    work : CpuWork or None
        Its workspace.
    """

    def __init__(self, threads=1):
        if threads < 1:
            raise ValueError(f"threads must be >= 1, got {threads}")
        self.threads = int(threads)
        self.work = self.model = self.state = None
        self._direction = None

    def plate_operator(self, model, mesh, nblock):
        """The plate operator of a model on its mesh (a registered named tuple, :mod:`.plates`)."""
        raise NotImplementedError

    def prepare(self, model, mesh, epsy):
        nblock = parallel_blocks(self.threads)
        grad, volume = interface_layout(model.iface_dNdx, model.iface_dV)
        ni = model.iface_dofs.shape[0]
        iface = InterfaceWork(grad=grad, volume=volume, inp=np.zeros((NIN, ni)), out=np.zeros((NOUT, ni)),
                              fe=np.zeros((ni, 8)))
        prepared = copy.copy(self)
        prepared.work = CpuWork(nblock=nblock, plates=self.plate_operator(model, mesh, nblock), iface=iface)
        return prepared.for_model(model, epsy)

    def for_model(self, model, epsy):
        other = copy.copy(self)
        other.model = model
        other.state = new_state(model, np.ascontiguousarray(epsy, dtype=np.float64))
        other._direction = None
        other._evaluate(True)
        return other

    def _evaluate(self, update_wells):
        compute_force(self.model, self.work, self.state, update_wells)

    def read(self, *fields):
        return tuple(read_only(getattr(self.state, name)) for name in fields)

    def set_state(self, u, target, lever_target, t):
        s = self.state
        s.u[:] = u
        s.v[:] = 0.0
        s.a[:] = 0.0
        s.target[:] = target
        s.lever[0] = lever_target
        s.t[0] = t
        self._evaluate(True)

    def set_load_direction(self, delta_u, delta_target, delta_lever):
        self._direction = (np.asarray(delta_u, dtype=np.float64), np.asarray(delta_target, dtype=np.float64),
                           float(delta_lever))

    def load(self, step):
        s = self.state
        delta_u, delta_target, delta_lever = self._direction
        s.u[:] += step * delta_u
        s.target[:] += step * delta_target
        s.lever[0] += step * delta_lever
        self._evaluate(True)

    def add_u(self, dofs, delta):
        self.state.u[dofs] += delta
        self._evaluate(True)

    def correct(self, dofs, solve):
        s = self.state
        s.u[dofs] -= solve(s.f[dofs])
        self._evaluate(False)
        return self.residual()

    def rest_in_wells(self):
        self.state.v[:] = 0.0
        self.state.a[:] = 0.0
        self._evaluate(False)

    def set_yield_strains(self, epsy, shift=None):
        # kept, not copied: whoever gives yield strains gives a new array for new values (the window does)
        self.state = self.state._replace(epsy=np.ascontiguousarray(epsy, dtype=np.float64))
        if shift is not None:
            self.state.idx[...] -= np.asarray(shift, dtype=np.int64)[:, None]
        self._evaluate(True)

    def checkpoint(self):
        # the yield strains are never changed in place: the checkpoint keeps the array itself
        return self.state._replace(**{name: value.copy() for name, value in self.state._asdict().items()
                                      if name != "epsy"})

    def rollback(self, token):
        for name, kept in token._asdict().items():
            if name != "epsy":
                getattr(self.state, name)[...] = kept
        self.state = self.state._replace(epsy=token.epsy)

    def wells_changed(self, token, shift=None, elements=None):
        rows = slice(None) if elements is None else np.asarray(elements, dtype=np.int64)
        now = self.state.idx[rows] if shift is None else self.state.idx[rows] + np.asarray(shift)[rows, None]
        return int(np.count_nonzero(now != token.idx[rows]))

    def minimise(self, tol, niter_tol, max_iter, margin, record, quiet=0):
        return minimise(self.model, self.work, self.state, tol, niter_tol, max_iter, margin, record, quiet)

    def advance(self, nsteps):
        time_steps(self.model, self.work, self.state, nsteps)

    def residual(self):
        return residual(self.model, self.state)

    def wells_hold(self):
        return wells_hold(self.model, self.state)
