"""Internal force of the model: elastic plates, cusp interfaces and drive springs.

``f(u) = K_plates u + sum_interface int B^T sigma_cusp dV + f_drive`` on DOF vectors.
The drive adds, on every layer ``l`` with an active spring, the uniform body
force ``k (ubar_l - target_l)`` per unit volume (nodal equivalent
``k (ubar_l - target_l) V_l w_l``, :mod:`.assembly`). With a free lever the
targets follow the lever's moment balance at every evaluation
(``x_lever = (x_target + sum_l r_l ubar_l) / (1 + sum_l r_l^2)``,
``target_l = r_l x_lever``, ``r_l = h_l / H``, sums over driven layers).

Deterministic whatever the number of threads: rows of the sparse product and
interface elements are computed independently (serially, or in ``model.nblock``
parallel blocks); the interface forces are added to the DOF vector in one serial
pass in element order.
Reference: shared/reference-model.md, sections 2, 6 and 7.
"""

import numpy as np
from numba import prange

from ..numba_options import njit
from .interface import interface_force
from .materials import equivalent_strain, well_index
from .structured import apply_groups, gather_views, plate_product

__all__ = ["plates", "interface_forces", "drive_force", "compute_force", "compute_force_in_wells", "wells_hold", "layer_ubar"]


@njit
def _plates_rows(lo, hi, ptr, col, val, u, f):
    for i in range(lo, hi):
        s = 0.0
        for j in range(ptr[i], ptr[i + 1]):
            s += val[j] * u[col[j]]
        f[i] = s


# Parallel variants: blocks of rows / elements, each computed exactly as serially (so the
# result does not depend on the number of threads). They take plain arrays: numba loses
# writes to named-tuple fields inside prange.

@njit(parallel=True)
def _plates_rows_parallel(nblock, ptr, col, val, u, f):
    n = f.size
    for b in prange(nblock):
        _plates_rows(b * n // nblock, (b + 1) * n // nblock, ptr, col, val, u, f)


@njit(parallel=True)
def _interface_force_parallel(nblock, iface_dofs, grad, volume, epsy, K, G, u, idx, inp, out, update_wells):
    n = iface_dofs.shape[0]
    for b in prange(nblock):
        interface_force(b * n // nblock, (b + 1) * n // nblock, iface_dofs, grad, volume, epsy, K, G, u, idx, inp,
                        out, update_wells)


@njit(parallel=True)
def _plate_product_parallel(view_blocks, group_blocks, views, groups, triplet_ptr, triplet_view, triplet_coef, empty,
                            work, u, f):
    for b in prange(view_blocks.size - 1):
        gather_views(views, view_blocks[b], view_blocks[b + 1], u, work[0], work[1])
    for b in prange(group_blocks.size - 1):
        apply_groups(groups, triplet_ptr, triplet_view, triplet_coef, group_blocks[b], group_blocks[b + 1],
                     work[0], work[1], work[2], work[3], f)
    for i in empty:
        f[i] = 0.0


@njit
def plates(model, u, f):
    """``f = K u``: the plates' elastic force, by the structured kernel or the assembled CSR product.

    Parameters
    ----------
    model : Model
    u : numpy.ndarray
        [ndof] displacement [length].
    f : numpy.ndarray
        [ndof] force, overwritten.
    """
    m = model
    if m.structured and m.nblock > 1:
        _plate_product_parallel(m.plate_view_blocks, m.plate_group_blocks, m.plate_views, m.plate_groups,
                                m.plate_triplet_ptr, m.plate_triplet_view, m.plate_triplet_coef, m.plate_empty,
                                m.plate_work, u, f)
    elif m.structured:
        plate_product(m.plate_views, m.plate_groups, m.plate_triplet_ptr, m.plate_triplet_view, m.plate_triplet_coef,
                      m.plate_empty, m.plate_work, u, f)
    elif m.nblock > 1:
        _plates_rows_parallel(m.nblock, m.k_ptr, m.k_col, m.k_val, u, f)
    else:
        _plates_rows(0, m.ndof, m.k_ptr, m.k_col, m.k_val, u, f)


@njit
def layer_ubar(model, u, out):
    """Volume-averaged x-displacement of every layer, ``out[l] = w_l . u`` [length]."""
    for layer in range(model.layer_volume.size):
        s = 0.0
        for j in range(model.layer_ptr[layer], model.layer_ptr[layer + 1]):
            s += model.layer_w[j] * u[model.layer_xdofs[j]]
        out[layer] = s


@njit
def drive_force(model, state):
    """Add the drive springs' force to ``state.f`` (layer averages ``state.ubar`` and, free lever, targets)."""
    layer_ubar(model, state.u, state.ubar)
    if model.free_lever:
        num = state.lever[0]
        den = 1.0
        for layer in range(model.layer_volume.size):
            if model.drive_active[layer]:
                num += model.lever_ratio[layer] * state.ubar[layer]
                den += model.lever_ratio[layer] ** 2
        state.lever[1] = num / den
        for layer in range(model.layer_volume.size):
            if model.drive_active[layer]:
                state.target[layer] = model.lever_ratio[layer] * state.lever[1]
    for layer in range(model.layer_volume.size):
        if model.drive_active[layer]:
            scale = model.k_drive * (state.ubar[layer] - state.target[layer]) * model.layer_volume[layer]
            for j in range(model.layer_ptr[layer], model.layer_ptr[layer + 1]):
                state.f[model.layer_xdofs[j]] += scale * model.layer_w[j]


@njit
def interface_forces(model, state, fe, update_wells):
    """Add the interface elements' force to ``state.f``; write ``state.eps``, ``state.sig`` (and ``state.idx``).

    Parameters
    ----------
    model : Model
    state : State
    fe : numpy.ndarray
        [ni, 8] written: the element forces, added to ``state.f`` in element order.
    update_wells : bool
        Move Gauss points to the well of their strain (else they keep ``state.idx``).
    """
    m = model
    if m.nblock > 1:
        _interface_force_parallel(m.nblock, m.iface_dofs, m.iface_grad, m.iface_volume, m.epsy, m.K, m.G, state.u,
                                  state.idx, m.iface_in, m.iface_out, update_wells)
    else:
        interface_force(0, m.iface_dofs.shape[0], m.iface_dofs, m.iface_grad, m.iface_volume, m.epsy, m.K, m.G,
                        state.u, state.idx, m.iface_in, m.iface_out, update_wells)
    out = m.iface_out
    for e in range(m.iface_dofs.shape[0]):
        for q in range(4):
            for c in range(3):
                state.eps[e, q, c] = out[3 * q + c, e]
                state.sig[e, q, c] = out[12 + 3 * q + c, e]
        for a in range(8):
            fe[e, a] = out[24 + a, e]
            state.f[m.iface_dofs[e, a]] += fe[e, a]


@njit
def _force(model, state, fe, update_wells):
    plates(model, state.u, state.f)
    interface_forces(model, state, fe, update_wells)
    drive_force(model, state)


@njit
def compute_force(model, state, fe):
    """Evaluate ``state.f`` (and interface strain, stress, well index, ubar, drive targets) from ``state.u``.

    Parameters
    ----------
    model : Model
    state : State
        ``u``, ``target`` and ``lever[0]`` are read; ``f``, ``idx``, ``eps``,
        ``sig``, ``ubar`` (and with a free lever ``target``, ``lever[1]``) are written.
    fe : numpy.ndarray
        [ni, 8] work array.
    """
    _force(model, state, fe, True)


@njit
def compute_force_in_wells(model, state, fe):
    """As :func:`compute_force`, but every Gauss point keeps its well ``state.idx`` whatever its strain.

    Within fixed wells the force is the gradient of the energy of the current wells'
    parabolas (:mod:`.equilibrium`); ``state.idx`` is read, not written.
    """
    _force(model, state, fe, False)


@njit
def wells_hold(model, state):
    """True if every interface Gauss point's strain ``state.eps`` lies in its well ``state.idx``.

    Uses :func:`.materials.well_index` on the stored strain, i.e. exactly the test that
    :func:`compute_force` would apply to the same displacement.
    """
    for e in range(state.idx.shape[0]):
        for q in range(4):
            i = state.idx[e, q]
            x = equivalent_strain(state.eps[e, q, 0], state.eps[e, q, 1], state.eps[e, q, 2])
            if well_index(model.epsy[e], x, i) != i:
                return False
    return True
