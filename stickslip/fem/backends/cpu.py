"""What the CPU backends share: numba kernels over a workspace with a plate operator of their choice.

A CPU backend is :class:`CpuBackend` with a plate operator (:mod:`..plates`): the kernels of
:mod:`..forces`, :mod:`..dynamics` and :mod:`..minimise` run with a :class:`CpuWork` (the
operator, the interface elements' field-by-field layout and scratch, the number of parallel
blocks), compiled by numba for the types of the law and of the operator. Threads split
elements and DOFs into blocks that are computed exactly as serially, so the results do not
depend on the number of threads.
"""

import copy
from collections import namedtuple

import numpy as np

from ..dynamics import residual, time_step
from ..forces import compute_force, wells_hold
from ..interface import NIN, NOUT, interface_layout
from ..minimise import minimise

__all__ = ["CpuBackend", "CpuWork", "InterfaceWork", "parallel_blocks"]

#: The interface elements' arrays of the vectorised kernel (:mod:`..interface`).
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
    "plates",   # the plate operator (a registered named tuple, :mod:`..plates`)
    "iface",    # InterfaceWork
])


def parallel_blocks(threads):
    """Number of parallel blocks for ``threads`` threads (1: the serial kernels); four per thread balance the load."""
    return 4 * int(threads) if threads > 1 else 1


class CpuBackend:
    """A numba CPU backend: the kernels of the package with a plate operator chosen by the subclass.

    Subclasses set :attr:`name`, :attr:`summary` and implement :meth:`plate_operator`.

    Parameters
    ----------
    threads : int, optional
        Threads of the parallel kernels (1: serial kernels); the results do not depend on it.

    Attributes
    ----------
    work : CpuWork or None
        The workspace (of a backend returned by :meth:`prepare`).
    """

    name = ""
    summary = ""

    def __init__(self, threads=1):
        if threads < 1:
            raise ValueError(f"threads must be >= 1, got {threads}")
        self.threads = int(threads)
        self.work = None

    def plate_operator(self, model, mesh, nblock):
        """The plate operator of a model on its mesh (a registered named tuple, :mod:`..plates`)."""
        raise NotImplementedError

    def prepare(self, model, mesh):
        """This backend with a workspace for a model's discretisation (a new object; ``self`` is unchanged).

        Parameters
        ----------
        model : Model
        mesh : stickslip.mesh.LayeredMesh
            The mesh the model was built from.

        Returns
        -------
        CpuBackend
            It serves every model with the same mesh and drive: another law or other yield
            strains (e.g. the elastic linear response) need no new workspace.
        """
        nblock = parallel_blocks(self.threads)
        grad, volume = interface_layout(model.iface_dNdx, model.iface_dV)
        ni = model.iface_dofs.shape[0]
        iface = InterfaceWork(grad=grad, volume=volume, inp=np.zeros((NIN, ni)), out=np.zeros((NOUT, ni)),
                              fe=np.zeros((ni, 8)))
        prepared = copy.copy(self)
        prepared.work = CpuWork(nblock=nblock, plates=self.plate_operator(model, mesh, nblock), iface=iface)
        return prepared

    def force(self, model, state, update_wells=True):
        """Evaluate the force and everything that follows from ``state.u`` (:func:`..forces.compute_force`)."""
        compute_force(model, self.work, state, update_wells)

    def time_step(self, model, state):
        """Advance ``state`` by one time step (:func:`..dynamics.time_step`)."""
        time_step(model, self.work, state)

    def minimise(self, model, state, tol, niter_tol, max_iter, margin, record, quiet=0):
        """Minimise by damped dynamics (:func:`..minimise.minimise`); returns ``(status, niter, events)``."""
        return minimise(model, self.work, state, tol, niter_tol, max_iter, margin, record, quiet)

    @staticmethod
    def residual(model, state):
        """Relative residual of a state (:func:`..dynamics.residual`) [1]."""
        return residual(model, state)

    @staticmethod
    def wells_hold(model, state):
        """True if every Gauss point lies in its well (:func:`..forces.wells_hold`)."""
        return wells_hold(model, state)
