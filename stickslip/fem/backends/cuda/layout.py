"""What the device kernels need of a model, arranged on the host: gathers instead of scatters, fixed-order sums.

The CPU kernels add the interface elements' forces into the DOF vector in one serial pass and sum
the layer averages and the residual serially. On a device the same must be computed by many
threads without floating-point atomics and in an order that never depends on the launch:

- every DOF **gathers** its interface contributions (element ``e``, element DOF ``a``) from a list
  in the CPU's order (element by element), and at most one drive contribution (its layer's weight);
- every sum (a layer's average, the residual's two norms) is a **fixed-order sum**
  (:func:`fixed_sum_plan`): items ``i`` of ``n`` go to ``LEAVES * R`` chunks, chunk ``c`` holding the
  items ``c, c + LEAVES R, c + 2 LEAVES R, ...`` summed in that order; leaf ``l`` sums the chunks
  ``l, l + LEAVES, ...``; a binary tree over the ``LEAVES`` leaves ends it. Only ``n`` fixes the order:
  the sums (and every result) are the same bits whatever the number of blocks and of threads per
  block, the batch or the device.
"""

from collections import namedtuple

import numpy as np

__all__ = ["LEAVES", "ITEMS_PER_CHUNK", "DeviceLayout", "device_layout", "fixed_sum_plan"]

#: Leaves of the fixed-order sums' tree (a power of 2).
LEAVES = 256

#: Items per chunk of a fixed-order sum, about (a chunk is one thread's sequential sum).
ITEMS_PER_CHUNK = 4

DeviceLayout = namedtuple("DeviceLayout", [
    "ndof", "ni", "nlayer",
    "k_ptr", "k_col", "k_val",      # int64 [ndof + 1], int32 [nnz], float64 [nnz]: the plates' CSR stiffness
    "mass_inv", "damping",          # float64 [ndof]
    "free",                         # int8 [ndof]: 1 on free DOFs, 0 on prescribed ones
    "multiplicity",                 # float64 [ndof]
    "iface_dofs",                   # int64 [ni, 8]
    "iface_dNdx", "iface_dV",       # float64 [ni, 4, 4, 2], [ni, 4]
    "gather_ptr", "gather_index",   # int64 [ndof + 1], int64 [8 ni]: DOF d adds fe.ravel()[gather_index[k]], k in its range
    "drive_layer", "drive_w",       # int64 [ndof] (-1: none), float64 [ndof]: the drive's layer and weight of a DOF
    "layer_ptr", "layer_xdofs", "layer_w",  # the layers' x-DOFs and weights (model.layer_*)
    "layer_volume", "drive_active", "lever_ratio",  # float64 [nlayer], int8 [nlayer], float64 [nlayer]
    "dof_chunks",                   # int: R of the fixed-order sums over the DOFs
    "layer_chunks",                 # int: R of the fixed-order sums over every layer's x-DOFs
])


def fixed_sum_plan(n):
    """``R`` of the fixed-order sum of ``n`` items: ``LEAVES * R`` chunks of about :data:`ITEMS_PER_CHUNK` items."""
    return max(1, -(-int(n) // (LEAVES * ITEMS_PER_CHUNK)))


def _gathers(iface_dofs, ndof):
    """Per DOF, the flat indices ``8 e + a`` of its interface contributions, in the CPU's order (by ``e``, then ``a``)."""
    flat = np.asarray(iface_dofs, dtype=np.int64).ravel()
    order = np.argsort(flat, kind="stable")  # stable: by (e, a) within a DOF
    counts = np.bincount(flat, minlength=ndof)
    return np.concatenate([[0], np.cumsum(counts)]).astype(np.int64), order.astype(np.int64)


def _drive(model):
    """Per DOF the driven layer whose average it enters (-1: none) and its weight."""
    layer_of = np.full(model.ndof, -1, dtype=np.int64)
    weight = np.zeros(model.ndof)
    for layer in np.flatnonzero(model.drive_active):
        span = slice(model.layer_ptr[layer], model.layer_ptr[layer + 1])
        dofs = model.layer_xdofs[span]
        if np.any(layer_of[dofs] >= 0):
            raise ValueError("a DOF lies in two driven layers: the device gather needs one drive term per DOF")
        layer_of[dofs] = layer
        weight[dofs] = model.layer_w[span]
    return layer_of, weight


def device_layout(model):
    """The device layout of a model (module docstring).

    Parameters
    ----------
    model : stickslip.fem.model.Model

    Returns
    -------
    DeviceLayout
        Host arrays, to be copied to the device once per mesh.
    """
    gather_ptr, gather_index = _gathers(model.iface_dofs, model.ndof)
    drive_layer, drive_w = _drive(model)
    sizes = np.diff(model.layer_ptr)
    return DeviceLayout(
        ndof=int(model.ndof), ni=int(model.iface_dofs.shape[0]), nlayer=int(model.layer_volume.size),
        k_ptr=np.asarray(model.k_ptr, dtype=np.int64), k_col=np.asarray(model.k_col, dtype=np.int32),
        k_val=np.asarray(model.k_val, dtype=np.float64), mass_inv=model.mass_inv, damping=model.damping,
        free=(~model.prescribed).astype(np.int8), multiplicity=model.multiplicity,
        iface_dofs=np.ascontiguousarray(model.iface_dofs, dtype=np.int64),
        iface_dNdx=np.ascontiguousarray(model.iface_dNdx), iface_dV=np.ascontiguousarray(model.iface_dV),
        gather_ptr=gather_ptr, gather_index=gather_index, drive_layer=drive_layer, drive_w=drive_w,
        layer_ptr=model.layer_ptr, layer_xdofs=model.layer_xdofs, layer_w=model.layer_w,
        layer_volume=model.layer_volume, drive_active=model.drive_active.astype(np.int8),
        lever_ratio=model.lever_ratio, dof_chunks=fixed_sum_plan(model.ndof),
        layer_chunks=fixed_sum_plan(int(sizes.max()) if sizes.size else 1))
