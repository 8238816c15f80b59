"""Equilibrium within fixed wells by direct solves with one factorisation per run (``relaxation = exact``).

While no Gauss point changes well, the force is the gradient of a fixed energy:
plates ``1/2 u^T K_p u``, every interface Gauss point the potential of its current
well ``K eps_m^2 + W(eps_eq)`` (:mod:`.laws`), the drive springs (with a free lever the
lever's moment balance). The equilibrium ``f(u) = 0`` of the current wells is found by
modified Newton iterations ``u <- u - A^-1 f(u)`` with the constant matrix

``A = K_p + K_i + U M U^T``

on the free DOFs: ``K_i`` the interface elements made elastic with the law's
``newton_moduli()``, moduli whose stiffness bounds the law's curvature from above (the cusp:
along the deviatoric direction of a Gauss point as stiff as the plates, ``2 G`` in ``W''``,
across it ``G (1 - eps_min / eps_eq)``, the bottom of a well being a circle of radius
``eps_min`` in the deviatoric plane; the smooth law: ``2 G cos(theta) <= 2 G``). With
``A >= H`` (``H`` the Hessian) the iterations contract towards a stable equilibrium and are
repelled by unstable ones (an eigenvalue of ``A^-1 H`` below 0 makes ``I - A^-1 H`` expand),
so an accepted solve is a local minimum of the energy. ``U`` [nfree, nlayer] the layer-average weights ``w_l`` and ``M``
[nlayer, nlayer] the drive: ``k V_l`` on the diagonal (fixed lever), times
``I - r r^T / (1 + r.r)`` with a free lever (``r_l = h_l / H``). The periodic wrap is
in the DOF numbering (images share a DOF). ``K_p + K_i`` is sparse, symmetric and
positive definite (the bottom edge is fixed): it is factorised once as ``P L D L^T P^T`` by
QDLDL (the ``qdldl`` package: ``P`` SuiteSparse's approximate minimum degree ordering, integer
arithmetic only; the factorisation and the triangular solves plain serial C loops, with no BLAS);
the drive is added by the Woodbury identity (``A^-1 b = y - Z (I + M U^T Z)^-1 M U^T y``,
``y = (K_p + K_i)^-1 b``, ``Z = (K_p + K_i)^-1 U``), its small dense products and inverse in a
fixed order (:mod:`stickslip.fixed_order`). Nothing here depends on the CPU's BLAS kernel: the solve gives
the same bits on every x86-64 host (``benchmarks/host_bytes.py`` compares them under every OpenBLAS
kernel a host supports; SuperLU, used before, calls the BLAS and did not). For an all-elastic model (the linear response) ``A`` is
the exact stiffness and one iteration is the solution.

The iterations stop when the relative residual (:func:`.dynamics.residual`, at rest)
is below ``tol^2`` (the dynamic protocol's strict criterion), or when no iteration of the last
``STALL`` has halved the smallest residual and it is below ``tol`` (a round-off floor) or has not
halved over those ``STALL`` iterations together either (no convergence; a law whose curvature is
well below the matrix's, as the smooth law's beyond an inflection, contracts steadily but by less
than half per iteration, and goes on), or after
``MAX_NEWTON`` iterations; the result counts only if its residual is below ``tol^2``, or
below ``tol`` at a stall (a round-off floor above ``tol^2``, for a very small ``tol``). All operations are serial and in a fixed order: the result
is the same bit for bit on every run.
"""

import numpy as np
import qdldl
import scipy.sparse as sp

from .assembly import assemble_csr, elastic_element_stiffness
from ..fixed_order import columns_dot_dense, inverse, matmul, woodbury_correct

__all__ = ["WellEquilibrium", "MAX_NEWTON", "STALL"]

#: Maximum number of modified Newton iterations of one solve.
MAX_NEWTON = 200
#: Give up when the residual has not halved in this many consecutive iterations.
STALL = 10


def _drive_matrix(model):
    """The drive's ``M`` [nlayer, nlayer] (module docstring), each entry in a fixed order of operations."""
    nlayer = model.layer_volume.size
    stiffness = [model.k_drive * float(model.layer_volume[l]) if model.drive_active[l] else 0.0 for l in range(nlayer)]
    M = np.diag(stiffness)
    if model.free_lever:
        r = [float(model.lever_ratio[l]) if model.drive_active[l] else 0.0 for l in range(nlayer)]
        norm = 1.0
        for value in r:
            norm += value * value
        for i in range(nlayer):
            for j in range(nlayer):
                M[i, j] = stiffness[i] * ((1.0 if i == j else 0.0) - r[i] * r[j] / norm)
    return M


class WellEquilibrium:
    """The factorised constant stiffness of a model and the equilibrium solve within fixed wells.

    Parameters
    ----------
    model : Model
        Only its linear parts are used (plates, interface geometry, the law's
        ``newton_moduli()``, drive, prescribed DOFs), so a model with other yield strains or
        the elastic law (the linear response) can share the factorisation.

    Attributes
    ----------
    free : numpy.ndarray
        int64 [nfree]: the free DOFs.
    matrix : scipy.sparse.csc_matrix
        [nfree, nfree] ``K_p + K_i`` (without the drive).
    """

    def __init__(self, model):
        ndof = model.ndof
        self.free = np.flatnonzero(~model.prescribed)
        plates = sp.csr_matrix((model.k_val, model.k_col, model.k_ptr), shape=(ndof, ndof))
        ke = elastic_element_stiffness(model.iface_dNdx, model.iface_dV, *model.law.newton_moduli())
        interfaces = sp.csr_matrix(assemble_csr(model.iface_dofs, ke, ndof)[::-1], shape=(ndof, ndof))
        self.matrix = (plates + interfaces)[self.free][:, self.free].tocsc()
        self._ldl = qdldl.Solver(self.matrix)
        position = np.full(ndof, -1, dtype=np.int64)
        position[self.free] = np.arange(self.free.size)
        nlayer = model.layer_volume.size
        weights = np.zeros((self.free.size, nlayer))  # U, dense
        for layer in np.flatnonzero(model.drive_active):
            span = slice(model.layer_ptr[layer], model.layer_ptr[layer + 1])
            dofs = position[model.layer_xdofs[span]]
            keep = dofs >= 0
            np.add.at(weights[:, layer], dofs[keep], model.layer_w[span][keep])
        U = sp.csc_matrix(weights)
        self._U = (U.indptr.astype(np.int64), U.indices.astype(np.int64), U.data)
        self._Z = np.asfortranarray(np.column_stack([self._ldl.solve(weights[:, layer]) for layer in range(nlayer)]))
        M = _drive_matrix(model)
        self._gain = matmul(inverse(np.eye(nlayer) + matmul(M, columns_dot_dense(*self._U, self._Z))), M)

    def solve(self, b):
        """``A^-1 b`` on the free DOFs.

        Parameters
        ----------
        b : numpy.ndarray
            [nfree].

        Returns
        -------
        numpy.ndarray
            [nfree].
        """
        y = self._ldl.solve(np.ascontiguousarray(b, dtype=np.float64))
        woodbury_correct(y, self._gain, *self._U, self._Z)
        return y

    def move_to_equilibrium(self, backend, tol):
        """Move the backend's state to the equilibrium of its current wells, if it keeps every point in its well.

        From the state at rest (``v = a = 0``) with every Gauss point held in its well, the
        modified Newton iterations of the module docstring, one exchange with the backend each
        (:meth:`.backends.base.Backend.correct`).

        Parameters
        ----------
        backend : stickslip.fem.backends.base.Backend
            Its model may be any with this one's linear parts (e.g. the elastic model of the linear response).
        tol : float
            The minimisation tolerance; the solve ends below ``tol^2``.

        Returns
        -------
        bool
            True if the state is now the equilibrium (``v = a = 0``, forces, strain and stress
            evaluated at it, wells unchanged); False if the iterations did not converge or some Gauss
            point of the equilibrium lies outside its current well: the state is then as before, bit for bit.
        """
        before = backend.checkpoint()
        backend.rest_in_wells()
        best = backend.residual()
        bests = [best]  # the smallest residual after each iteration
        stalled = 0  # consecutive iterations that did not halve it
        stuck = False
        for _ in range(MAX_NEWTON):
            # stalled: no iteration halved the residual in the last STALL; stuck: not even all of them
            # together, or the residual is below tol already (a round-off floor, accepted below)
            stuck = stalled >= STALL and (best < tol or best > 0.5 * bests[-1 - STALL])
            if best <= tol * tol or stuck:
                break
            current = backend.correct(self.free, self.solve)
            stalled = 0 if current <= 0.5 * best else stalled + 1
            best = min(best, current)
            bests.append(best)
        final = backend.residual()
        if (final <= tol * tol or (stuck and final < tol)) and backend.wells_hold():
            return True
        backend.rollback(before)
        return False
