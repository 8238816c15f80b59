"""The discretised model as arrays: ``Model``, physics and discretisation, fixed for a run.

A named tuple of numpy arrays and scalars, so that numba kernels take it whole: operators,
masses, the interfaces' geometry and law, the drive. How its products are
computed (threads, plate kernels, scratch) and the state it acts on are a backend's
(:mod:`.backends`). The yield strains are not the model's: they are state, which the backend holds (its copy the
only one), given to it by the window of held yield strains (:meth:`.backends.base.Backend.set_yield_strains`).
Units are the FE model's own: length (block size ``h = pi``), stress (``G = 1``),
mass density (``rho = 1``), time (``dt = 0.05``; shear-wave speed ``c_s = sqrt(G / 2 / rho)``).
"""

from collections import namedtuple

import numpy as np

from .assembly import (assemble_csr, elastic_element_stiffness, element_dofs, layer_average_weights,
                       lumped_diagonal)
from .quad4 import element_coordinates, shape_gradients

__all__ = ["Model", "build_model"]

Model = namedtuple("Model", [
    "ndof",           # int: number of DOFs
    "dt",             # float: time step [time]
    "k_ptr", "k_col", "k_val",  # CSR [ndof, ndof] elastic stiffness of the plates [stress] (k_col int32)
    "mass_inv",       # float64 [ndof]: 1 / lumped mass on free DOFs, 0 on prescribed DOFs
    "damping",        # float64 [ndof]: lumped background damping [mass / time]
    "prescribed",     # bool [ndof]
    "multiplicity",   # float64 [ndof]: nodes sharing the DOF (for node-vector norms)
    "iface_dofs",     # int64 [ni, 8]: DOFs of the interface elements (interface by interface, blocks left to right)
    "iface_dNdx",     # float64 [ni, 4, 4, 2] [1/length]
    "iface_dV",       # float64 [ni, 4] [length^2]
    "law",            # the interface law (:mod:`.laws`), e.g. Cusp(K, G)
    "layer_ptr",      # int64 [nlayer + 1]: slices of layer_xdofs / layer_w
    "layer_xdofs",    # int64 [sum m_l]
    "layer_w",        # float64 [sum m_l]: ubar_x = sum w u [1]
    "layer_volume",   # float64 [nlayer] [length^2]
    "drive_active",   # bool [nlayer]: layer has a drive spring in x
    "k_drive",        # float: spring stiffness per unit volume [stress / length^2]
    "free_lever",     # bool: targets follow the moment balance of a free lever
    "lever_ratio",    # float64 [nlayer]: h_l / H (free lever), layer height over drive height
])

def build_model(mesh, *, law, rho, alpha, dt, k_drive, drive_active, free_lever, lever_height):
    """Assemble the model arrays of a layered mesh.

    Parameters
    ----------
    mesh : stickslip.mesh.LayeredMesh
        Needs ``coor``, ``conn``, ``dofs``, ``iip``, ``elem_layer``, ``nlayer``,
        ``layer_is_plastic``, ``layer_mid_height``, ``interface_elements``.
    law : tuple
        The interface law (:mod:`.laws`); the plates are elastic with its moduli ``law.K``,
        ``law.G`` [stress].
    rho, alpha : float
        Mass density and background damping density.
    dt : float
        Time step.
    k_drive : float
        Drive spring stiffness per unit volume.
    drive_active : numpy.ndarray
        bool [nlayer].
    free_lever : bool
    lever_height : float
        Height ``H`` of the drive spring on the lever (free lever only; > 0).

    Returns
    -------
    Model
    """
    conn = np.asarray(mesh.conn, dtype=np.int64)
    dofs = np.asarray(mesh.dofs, dtype=np.int64)
    ndof = int(dofs.max()) + 1
    xe = element_coordinates(mesh.coor, conn)
    dNdx, dV = shape_gradients(xe)
    edofs = element_dofs(conn, dofs)
    plastic_layer = np.asarray(mesh.layer_is_plastic, dtype=bool)
    elem_layer = np.asarray(mesh.elem_layer, dtype=np.int64)
    elastic = np.flatnonzero(~plastic_layer[elem_layer])
    iface = np.asarray(mesh.interface_elements, dtype=np.int64).ravel()

    k_ptr, k_col, k_val = assemble_csr(edofs[elastic], elastic_element_stiffness(dNdx[elastic], dV[elastic], law.K,
                                                                                 law.G), ndof)
    k_col = k_col.astype(np.int32)  # less memory traffic in the sparse product
    nelem = conn.shape[0]
    mass = lumped_diagonal(xe, edofs, np.full(nelem, rho), ndof)
    damping = lumped_diagonal(xe, edofs, np.full(nelem, alpha), ndof)
    prescribed = np.zeros(ndof, dtype=bool)
    prescribed[np.asarray(mesh.iip, dtype=np.int64)] = True
    mass_inv = np.where(prescribed, 0.0, 1.0 / mass)
    multiplicity = np.bincount(dofs.ravel(), minlength=ndof).astype(np.float64)

    ptr, xdofs, weights, volume = [0], [], [], []
    for layer in range(mesh.nlayer):
        d, w, v = layer_average_weights(edofs, dV, np.flatnonzero(elem_layer == layer), ndof)
        xdofs.append(d)
        weights.append(w)
        volume.append(v)
        ptr.append(ptr[-1] + d.size)
    heights = np.asarray(mesh.layer_mid_height, dtype=np.float64)
    return Model(
        ndof=ndof, dt=float(dt), k_ptr=k_ptr, k_col=k_col, k_val=k_val, mass_inv=mass_inv, damping=damping,
        prescribed=prescribed, multiplicity=multiplicity, iface_dofs=edofs[iface], iface_dNdx=dNdx[iface],
        iface_dV=dV[iface], law=law,
        layer_ptr=np.asarray(ptr, dtype=np.int64), layer_xdofs=np.concatenate(xdofs),
        layer_w=np.concatenate(weights), layer_volume=np.asarray(volume),
        drive_active=np.asarray(drive_active, dtype=bool), k_drive=float(k_drive), free_lever=bool(free_lever),
        lever_ratio=heights / float(lever_height))

