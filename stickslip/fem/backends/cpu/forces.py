"""Internal force of the model: elastic plates, interface laws and drive springs (numba CPU kernels).

``f(u) = K_plates u + sum_interface int B^T sigma_law dV + f_drive`` on DOF vectors.
The drive adds, on every layer ``l`` with an active spring, the uniform body
force ``k (ubar_l - target_l)`` per unit volume (nodal equivalent
``k (ubar_l - target_l) V_l w_l``, :mod:`stickslip.fem.assembly`). With a free lever the
targets follow the lever's moment balance at every evaluation
(``x_lever = (x_target + sum_l r_l ubar_l) / (1 + sum_l r_l^2)``,
``target_l = r_l x_lever``, ``r_l = h_l / H``, sums over driven layers).

The kernels take the physics (``model``, :class:`stickslip.fem.model.Model`, with its law) and the
workspace of a CPU backend (``work``, :class:`.backend.CpuWork`: the plate operator,
which :func:`.plates.plate_force` applies, the interface elements' layout and scratch,
the number of parallel blocks); they are compiled for the types of the law and of the plate
operator. Deterministic whatever the number of threads: interface elements are computed
independently (serially, or in ``work.nblock`` parallel blocks); their forces are added to the
DOF vector in one serial pass in element order.
Reference: shared/reference-model.md, sections 2, 6 and 7.
"""

from numba import prange

from ....numba_options import njit
from .plates import plate_force
from .interface_elements import interface_force
from ...laws import well_index
from ...materials import equivalent_strain

__all__ = ["interface_forces", "drive_force", "compute_force", "wells_hold", "layer_ubar"]


# The parallel variant takes plain arrays: numba loses writes to named-tuple fields inside prange.
@njit(parallel=True)
def _interface_force_parallel(nblock, law, iface_dofs, grad, volume, epsy, u, idx, inp, out, update_wells):
    n = iface_dofs.shape[0]
    for b in prange(nblock):
        interface_force(b * n // nblock, (b + 1) * n // nblock, law, iface_dofs, grad, volume, epsy, u, idx, inp,
                        out, update_wells)


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
def interface_forces(model, work, state, update_wells):
    """Add the interface elements' force to ``state.f``; write ``state.eps``, ``state.sig`` (and ``state.idx``).

    Parameters
    ----------
    model : Model
    work : CpuWork
        ``work.iface.fe`` [ni, 8] is written: the element forces, added to ``state.f`` in element order.
    state : State
    update_wells : bool
        Move Gauss points to the well of their strain (else they keep ``state.idx``).
    """
    m, w = model, work.iface
    if work.nblock > 1:
        _interface_force_parallel(work.nblock, m.law, m.iface_dofs, w.grad, w.volume, state.epsy, state.u, state.idx,
                                  w.inp, w.out, update_wells)
    else:
        interface_force(0, m.iface_dofs.shape[0], m.law, m.iface_dofs, w.grad, w.volume, state.epsy, state.u, state.idx,
                        w.inp, w.out, update_wells)
    out, fe = w.out, w.fe
    for e in range(m.iface_dofs.shape[0]):
        for q in range(4):
            for c in range(3):
                state.eps[e, q, c] = out[3 * q + c, e]
                state.sig[e, q, c] = out[12 + 3 * q + c, e]
        for a in range(8):
            fe[e, a] = out[24 + a, e]
            state.f[m.iface_dofs[e, a]] += fe[e, a]


@njit
def compute_force(model, work, state, update_wells):
    """Evaluate ``state.f`` (and interface strain, stress, well index, ubar, drive targets) from ``state.u``.

    Parameters
    ----------
    model : Model
    work : CpuWork
    state : State
        ``u``, ``target`` and ``lever[0]`` are read; ``f``, ``eps``, ``sig``, ``ubar`` (and with a
        free lever ``target``, ``lever[1]``) are written, and ``idx`` if ``update_wells``.
    update_wells : bool
        Move every Gauss point to the well of its strain. False: every Gauss point keeps its
        well ``state.idx`` whatever its strain, so that the force is the gradient of the energy of
        the current wells (:mod:`stickslip.fem.equilibrium`).
    """
    plate_force(work.plates, work.nblock, state.u, state.f)
    interface_forces(model, work, state, update_wells)
    drive_force(model, state)


@njit
def wells_hold(model, state):
    """True if every interface Gauss point's strain ``state.eps`` lies in its well ``state.idx``.

    Uses :func:`stickslip.fem.laws.well_index` on the stored strain, i.e. exactly the test that
    :func:`compute_force` would apply to the same displacement.
    """
    for e in range(state.idx.shape[0]):
        for q in range(4):
            i = state.idx[e, q]
            x = equivalent_strain(state.eps[e, q, 0], state.eps[e, q, 1], state.eps[e, q, 2])
            if well_index(state.epsy[e], x, i) != i:
                return False
    return True
