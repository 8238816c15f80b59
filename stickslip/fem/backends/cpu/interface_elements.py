"""Interface elements' force, vectorised over elements, for any interface law.

The interface elements (one row of ``ni`` Quad4 elements per interface) are computed
Gauss point by Gauss point as :func:`stickslip.fem.quad4.element_strain`, :func:`stickslip.fem.laws.well_index`
and :func:`stickslip.fem.laws.well_stress` (the law's scalar reference) prescribe, in the same order of
operations (so the bits equal those of that scalar formulation), but with the elements as the
inner, contiguous loop: the element data are stored field by field (:func:`interface_layout`)
and one pass per Gauss point runs over the elements with loop-invariant rows, which LLVM
vectorises. The law (:mod:`stickslip.fem.laws`) is an argument: the kernels are compiled for its type, with
its stress factor inlined into the pass.

A pass assumes that every Gauss point stays in its current well (the well's bounds are
gathered first); the few elements where one leaves it get their well index updated and are
recomputed, alone, by the same pass (:func:`interface_force`).
Reference: shared/reference-model.md, sections 2 and 4.
"""

import numpy as np

from ....numba_options import njit
from ...laws import deviatoric_factor, well_index
from ...materials import equivalent_strain

__all__ = ["interface_layout", "interface_force", "NIN", "NOUT"]

#: Rows of the input work array: element displacement (8), lower (4) and upper (4) well bounds.
_U, _LO, _HI, NIN = 0, 8, 12, 16
#: Rows of the output work array: strain (4 x 3), stress (4 x 3), element force (8), outside flags (4).
_EPS, _SIG, _FE, _OUT, NOUT = 0, 12, 24, 32, 36


def interface_layout(dNdx, dV):
    """Field-by-field element data of the interface elements.

    Parameters
    ----------
    dNdx : numpy.ndarray
        [ni, 4, 4, 2] shape-function gradients at the Gauss points [1/length].
    dV : numpy.ndarray
        [ni, 4] integration volumes [length^2].

    Returns
    -------
    grad : numpy.ndarray
        [32, ni]: row ``(q * 4 + m) * 2 + k`` is ``dNdx[:, q, m, k]``.
    volume : numpy.ndarray
        [4, ni]: row ``q`` is ``dV[:, q]``.
    """
    ni = dNdx.shape[0]
    return (np.ascontiguousarray(np.asarray(dNdx, dtype=np.float64).reshape(ni, 32).T),
            np.ascontiguousarray(np.asarray(dV, dtype=np.float64).T))


@njit
def _gather(lo, hi, iface_dofs, epsy, u, idx, inp):
    for e in range(lo, hi):
        for a in range(8):
            inp[_U + a, e] = u[iface_dofs[e, a]]
        for q in range(4):
            i = idx[e, q]
            inp[_LO + q, e] = epsy[e, i]
            inp[_HI + q, e] = epsy[e, i + 1]


@njit
def _pass(lo, hi, grad, volume, law, inp, out):
    # elements lo:hi; every row a slice (contiguous, non-negative index), few rows written per loop
    # (LLVM vectorises a loop only if it can check the overlaps of what it writes at run time)
    u0, u1, u2, u3 = inp[_U, lo:hi], inp[_U + 1, lo:hi], inp[_U + 2, lo:hi], inp[_U + 3, lo:hi]
    u4, u5, u6, u7 = inp[_U + 4, lo:hi], inp[_U + 5, lo:hi], inp[_U + 6, lo:hi], inp[_U + 7, lo:hi]
    for q in range(4):
        r = 8 * q
        x0, y0, x1, y1 = grad[r, lo:hi], grad[r + 1, lo:hi], grad[r + 2, lo:hi], grad[r + 3, lo:hi]
        x2, y2, x3, y3 = grad[r + 4, lo:hi], grad[r + 5, lo:hi], grad[r + 6, lo:hi], grad[r + 7, lo:hi]
        exx, eyy, exy = out[_EPS + 3 * q, lo:hi], out[_EPS + 3 * q + 1, lo:hi], out[_EPS + 3 * q + 2, lo:hi]
        for e in range(hi - lo):  # strain (quad4.element_strain)
            exx[e] = (((x0[e] * u0[e]) + x1[e] * u2[e]) + x2[e] * u4[e]) + x3[e] * u6[e]
            eyy[e] = (((y0[e] * u1[e]) + y1[e] * u3[e]) + y2[e] * u5[e]) + y3[e] * u7[e]
            exy[e] = 0.5 * ((((y0[e] * u0[e] + x0[e] * u1[e]) + (y1[e] * u2[e] + x1[e] * u3[e]))
                             + (y2[e] * u4[e] + x2[e] * u5[e])) + (y3[e] * u6[e] + x3[e] * u7[e]))
        bottom, top = inp[_LO + q, lo:hi], inp[_HI + q, lo:hi]
        sxx, syy, sxy = out[_SIG + 3 * q, lo:hi], out[_SIG + 3 * q + 1, lo:hi], out[_SIG + 3 * q + 2, lo:hi]
        outside = out[_OUT + q, lo:hi]
        for e in range(hi - lo):  # stress in the current well (laws.well_stress)
            xx, yy, xy = exx[e], eyy[e], exy[e]
            m = 0.5 * (xx + yy)
            eq = equivalent_strain(xx, yy, xy)
            factor = deviatoric_factor(law, eq, bottom[e], top[e])
            sxx[e] = law.K * m + factor * (xx - m)
            syy[e] = law.K * m + factor * (yy - m)
            sxy[e] = factor * xy
            outside[e] = 0.0 if (bottom[e] < eq and eq <= top[e]) else 1.0
    w0, w1, w2, w3 = volume[0, lo:hi], volume[1, lo:hi], volume[2, lo:hi], volume[3, lo:hi]
    a0, b0, c0 = out[_SIG, lo:hi], out[_SIG + 1, lo:hi], out[_SIG + 2, lo:hi]
    a1, b1, c1 = out[_SIG + 3, lo:hi], out[_SIG + 4, lo:hi], out[_SIG + 5, lo:hi]
    a2, b2, c2 = out[_SIG + 6, lo:hi], out[_SIG + 7, lo:hi], out[_SIG + 8, lo:hi]
    a3, b3, c3 = out[_SIG + 9, lo:hi], out[_SIG + 10, lo:hi], out[_SIG + 11, lo:hi]
    for n in range(4):  # element force of node n: the Gauss points' terms summed in order
        gx0, gy0 = grad[2 * n, lo:hi], grad[2 * n + 1, lo:hi]
        gx1, gy1 = grad[8 + 2 * n, lo:hi], grad[9 + 2 * n, lo:hi]
        gx2, gy2 = grad[16 + 2 * n, lo:hi], grad[17 + 2 * n, lo:hi]
        gx3, gy3 = grad[24 + 2 * n, lo:hi], grad[25 + 2 * n, lo:hi]
        fx, fy = out[_FE + 2 * n, lo:hi], out[_FE + 2 * n + 1, lo:hi]
        for e in range(hi - lo):
            fx[e] = (((w0[e] * (gx0[e] * a0[e] + gy0[e] * c0[e])) + w1[e] * (gx1[e] * a1[e] + gy1[e] * c1[e]))
                     + w2[e] * (gx2[e] * a2[e] + gy2[e] * c2[e])) + w3[e] * (gx3[e] * a3[e] + gy3[e] * c3[e])
            fy[e] = (((w0[e] * (gx0[e] * c0[e] + gy0[e] * b0[e])) + w1[e] * (gx1[e] * c1[e] + gy1[e] * b1[e]))
                     + w2[e] * (gx2[e] * c2[e] + gy2[e] * b2[e])) + w3[e] * (gx3[e] * c3[e] + gy3[e] * b3[e])


@njit
def interface_force(lo, hi, law, iface_dofs, grad, volume, epsy, u, idx, inp, out, update_wells):
    """Strain, stress and element force of the interface elements ``lo:hi`` (into ``out``).

    Parameters
    ----------
    lo, hi : int
        Element range.
    law : tuple
        The interface law (:mod:`stickslip.fem.laws`), e.g. ``Cusp(K, G)``.
    iface_dofs : numpy.ndarray
        int64 [ni, 8] DOFs of the elements.
    grad, volume : numpy.ndarray
        [32, ni], [4, ni] (:func:`interface_layout`).
    epsy : numpy.ndarray
        [ni, ny] yield strains.
    u : numpy.ndarray
        [ndof] displacement [length].
    idx : numpy.ndarray
        int64 [ni, 4] current wells; updated (Gauss points that left their well) if ``update_wells``.
    inp, out : numpy.ndarray
        [NIN, ni], [NOUT, ni] work arrays; ``out`` rows: strain ``3 q + c``, stress ``12 + 3 q + c``,
        element force ``24 + a`` (DOF ``a`` of the element), then flags.
    update_wells : bool
        Move a Gauss point to the well of its strain (else it keeps its well whatever its strain).
    """
    _gather(lo, hi, iface_dofs, epsy, u, idx, inp)
    _pass(lo, hi, grad, volume, law, inp, out)
    if not update_wells:
        return
    for e in range(lo, hi):
        moved = False
        for q in range(4):
            if out[_OUT + q, e] != 0.0:
                xx, yy, xy = out[_EPS + 3 * q, e], out[_EPS + 3 * q + 1, e], out[_EPS + 3 * q + 2, e]
                i = well_index(epsy[e], equivalent_strain(xx, yy, xy), idx[e, q])
                if i != idx[e, q]:
                    idx[e, q] = i
                    inp[_LO + q, e] = epsy[e, i]
                    inp[_HI + q, e] = epsy[e, i + 1]
                    moved = True
        if moved:
            _pass(e, e + 1, grad, volume, law, inp, out)
