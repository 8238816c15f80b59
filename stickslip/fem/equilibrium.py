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
positive definite (the bottom edge is fixed): it is factorised once with SuperLU
(:func:`scipy.sparse.linalg.splu`); the drive is added by the Woodbury identity
(``A^-1 b = y - Z (I + M U^T Z)^-1 M U^T y``, ``y = (K_p + K_i)^-1 b``,
``Z = (K_p + K_i)^-1 U``). For an all-elastic model (the linear response) ``A`` is
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
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from .assembly import assemble_csr, elastic_element_stiffness

__all__ = ["WellEquilibrium", "MAX_NEWTON", "STALL"]

#: Maximum number of modified Newton iterations of one solve.
MAX_NEWTON = 200
#: Give up when the residual has not halved in this many consecutive iterations.
STALL = 10


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
        self._lu = splu(self.matrix, permc_spec="MMD_AT_PLUS_A")
        position = np.full(ndof, -1, dtype=np.int64)
        position[self.free] = np.arange(self.free.size)
        nlayer = model.layer_volume.size
        rows, cols, vals = [], [], []
        for layer in range(nlayer):
            if not model.drive_active[layer]:
                continue
            span = slice(model.layer_ptr[layer], model.layer_ptr[layer + 1])
            dofs = position[model.layer_xdofs[span]]
            keep = dofs >= 0
            rows.append(dofs[keep])
            cols.append(np.full(int(keep.sum()), layer))
            vals.append(model.layer_w[span][keep])
        self._U = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                shape=(self.free.size, nlayer)) if rows else sp.csr_matrix((self.free.size, nlayer))
        stiffness = np.where(model.drive_active, model.k_drive * model.layer_volume, 0.0)
        M = np.diag(stiffness)
        if model.free_lever:
            r = np.where(model.drive_active, model.lever_ratio, 0.0)
            M = M @ (np.eye(nlayer) - np.outer(r, r) / (1.0 + r @ r))
        self._M = M
        self._Z = self._lu.solve(self._U.toarray())
        self._capacitance = np.linalg.inv(np.eye(nlayer) + M @ (self._U.T @ self._Z))

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
        y = self._lu.solve(b)
        c = self._capacitance @ (self._M @ (self._U.T @ y))
        for layer in range(c.size):
            if c[layer] != 0.0:
                y -= c[layer] * self._Z[:, layer]
        return y

    def relax(self, backend, tol):
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
