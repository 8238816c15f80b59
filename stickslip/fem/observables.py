"""Per-increment observables (shared/reference-model.md, section 10).

- ``epsd``, ``sigd``: equivalent deviatoric strain and stress of the volume-averaged
  strain and stress tensors of the whole system, in units of ``eps0`` and
  ``sig0 = 2 G eps0``; ``epsd_<l>``, ``sigd_<l>`` the same per layer ``l``;
- ``ubar_<l>``: volume-averaged x-displacement of layer ``l`` [length];
- ``fxdrive_<l>``: spring elongation ``target_x - ubar_x`` (0 for layers without a spring) [length];
- ``S_a<a>``, ``A_a<a>``: signed number of well hops and number of blocks whose well
  changed since the previous increment, at Gauss point 0, interface ``a`` (1 = lowest);
- ``gamma``: lever rotation ``90 - atan2(H_top, target_top)`` [deg] in units of
  ``gamma0 = 90 - atan2(H_1, eps0 h)`` [deg];
- free lever only: ``lever_target`` (drive target ``x_target``) and ``lever_position``
  (``x_lever``), displacements of the lever at the drive height ``H`` [length].
"""

import math

import numpy as np

from ..numba_options import njit
from .assembly import element_dofs
from .materials import elastic_stress, equivalent_strain, equivalent_stress
from .quad4 import element_coordinates, element_strain, shape_gradients

__all__ = ["Observer", "layer_strain_sums", "observable_columns"]


@njit
def layer_strain_sums(u, edofs, dNdx, dV, elem_layer, nlayer):
    """Integral of the strain over every layer.

    Parameters
    ----------
    u : numpy.ndarray
        [ndof] displacement [length].
    edofs : numpy.ndarray
        int64 [nelem, 8].
    dNdx : numpy.ndarray
        [nelem, 4, 4, 2].
    dV : numpy.ndarray
        [nelem, 4].
    elem_layer : numpy.ndarray
        int64 [nelem].
    nlayer : int

    Returns
    -------
    numpy.ndarray
        [nlayer, 3]: ``sum_{e, q} eps_(xx, yy, xy) dV`` [length^2].
    """
    out = np.zeros((nlayer, 3))
    ue = np.empty(8)
    eps = np.empty((4, 3))
    for e in range(edofs.shape[0]):
        for a in range(8):
            ue[a] = u[edofs[e, a]]
        element_strain(dNdx[e], ue, eps)
        for q in range(4):
            for c in range(3):
                out[elem_layer[e], c] += eps[q, c] * dV[e, q]
    return out


def observable_columns(nlayer, n_interfaces, free_lever):
    """Names of the observable columns, in table order (after ``increment``, ``kick``, ``yield_element``)."""
    names = ["t", "gamma", "epsd", "sigd"] + (["lever_target", "lever_position"] if free_lever else [])
    for prefix in ("epsd", "sigd", "ubar", "fxdrive"):
        names += [f"{prefix}_{layer}" for layer in range(nlayer)]
    for prefix in ("S", "A"):
        names += [f"{prefix}_a{a}" for a in range(1, n_interfaces + 1)]
    return names


class Observer:
    """Computes the observables of the state of a simulation's stack (read through its backend).

    Parameters
    ----------
    simulation : stickslip.fem.simulation.Simulation
    """

    def __init__(self, simulation):
        mesh = simulation.mesh
        self.stack = simulation.stack
        self.model = simulation.model
        self.params = simulation.params
        self.sig0 = simulation.constants["sig0"]
        xe = element_coordinates(mesh.coor, mesh.conn)
        self.dNdx, self.dV = shape_gradients(xe)
        self.edofs = element_dofs(mesh.conn, mesh.dofs)
        self.elem_layer = np.asarray(mesh.elem_layer, dtype=np.int64)
        self.nlayer = int(mesh.nlayer)
        self.n_interfaces = int(mesh.n_interfaces)
        self.N = int(mesh.N)
        self.volume = np.bincount(self.elem_layer, weights=self.dV.sum(axis=1), minlength=self.nlayer)
        self.plastic = np.asarray(mesh.layer_is_plastic, dtype=bool)
        heights = np.asarray(mesh.layer_mid_height, dtype=np.float64)
        self.gamma0 = 90.0 - math.degrees(math.atan2(heights[1], self.params.eps0 * float(mesh.h)))
        self.top_height = heights[-1]

    def well_index(self):
        """Global well index of Gauss point 0 of every interface block, int64 [n_interfaces, N]."""
        return self.stack.well_index()[:, 0].reshape(self.n_interfaces, self.N)

    def observe(self, previous_index):
        """Observables of the current state.

        Parameters
        ----------
        previous_index : numpy.ndarray
            int64 [n_interfaces, N] well index (Gauss point 0) at the previous increment.

        Returns
        -------
        dict[str, float]
            Keys :func:`observable_columns`.
        """
        u, sig, target, ubar, lever = self.stack.read("u", "sig", "target", "ubar", "lever")
        p = self.params
        model = self.model
        eps0, sig0 = p.eps0, self.sig0
        eps_sum = layer_strain_sums(u, self.edofs, self.dNdx, self.dV, self.elem_layer, self.nlayer)
        sig_sum = np.empty_like(eps_sum)
        for layer in range(self.nlayer):
            sig_sum[layer] = elastic_stress(*eps_sum[layer], p.K, p.G)
        iface_sig = (sig * model.iface_dV[:, :, None]).reshape(self.n_interfaces, -1, 3).sum(axis=1)
        sig_sum[self.plastic] = iface_sig
        row = {"t": self.stack.time}
        target_top = target[-1]
        row["gamma"] = (90.0 - math.degrees(math.atan2(self.top_height, target_top))) / self.gamma0
        total_eps = eps_sum.sum(axis=0) / self.volume.sum()
        total_sig = sig_sum.sum(axis=0) / self.volume.sum()
        row["epsd"] = equivalent_strain(*total_eps) / eps0
        row["sigd"] = equivalent_stress(*total_sig) / sig0
        if model.free_lever:
            row["lever_target"] = float(lever[0])
            row["lever_position"] = float(lever[1])
        for layer in range(self.nlayer):
            row[f"epsd_{layer}"] = equivalent_strain(*(eps_sum[layer] / self.volume[layer])) / eps0
        for layer in range(self.nlayer):
            row[f"sigd_{layer}"] = equivalent_stress(*(sig_sum[layer] / self.volume[layer])) / sig0
        for layer in range(self.nlayer):
            row[f"ubar_{layer}"] = float(ubar[layer])
        for layer in range(self.nlayer):
            active = model.drive_active[layer]
            row[f"fxdrive_{layer}"] = float(target[layer] - ubar[layer]) if active else 0.0
        index = self.well_index()
        hops = index - previous_index
        for a in range(self.n_interfaces):
            row[f"S_a{a + 1}"] = int(hops[a].sum())
        for a in range(self.n_interfaces):
            row[f"A_a{a + 1}"] = int(np.count_nonzero(hops[a]))
        return row
