"""The device kernels' work items as plain functions: one DOF, one interface element, one chunk of a sum.

Every function here is plain Python over arrays and indices, built for a target by :func:`build`
with that target's decorator (``numba.cuda.jit(device=True, inline="always")`` for the device,
``numba.njit`` for checks on the CPU): the kernels of :mod:`.kernels` only distribute the items
over threads and synchronise. The scalar physics comes from the package's own reference functions
(their plain Python ``py_func``): the element strain (:func:`...quad4.element_strain`), the well
search (:func:`...laws.wells.well_index`), the equivalent strain, the velocity-Verlet update of one
DOF (:mod:`..cpu.dynamics`) and the law's stress factor, so a new law runs on the device without
device code of its own. Each item computes what the CPU kernels compute for it, in the same order
of operations; the device compiler may fuse a multiply and an add (FMA), so the results agree with
the CPU's to round-off, not bit for bit.
"""

from types import SimpleNamespace

from ...laws.wells import well_index
from ...materials import equivalent_strain
from ...quad4 import element_strain
from ..cpu.dynamics import _verlet_velocity

__all__ = ["build"]


def build(jit, law_class):
    """The work items compiled by ``jit`` for laws of class ``law_class``.

    Parameters
    ----------
    jit : callable
        Compiles a plain Python function for the target (a device-function decorator, or ``numba.njit``).
    law_class : type
        A registered law class (:mod:`...laws`): its ``deviatoric_factor`` gives the stress.

    Returns
    -------
    types.SimpleNamespace
        ``predict``, ``plate_row``, ``interface_element``, ``dof_force``, ``correct``, ``residual_terms``,
        ``chunk_sum_ubar``, and the scalar references ``equivalent`` (strain) and ``well`` (search).
    """
    equivalent = jit(equivalent_strain.py_func)
    strain_of = jit(element_strain.py_func)
    well = jit(well_index.py_func)
    verlet = jit(_verlet_velocity.py_func)
    factor = jit(law_class.deviatoric_factor.py_func)

    def predict(u, v, a, dt, d):
        """Step 1 of velocity Verlet for DOF ``d`` (:mod:`..cpu.dynamics`)."""
        u[d] += dt * v[d] + 0.5 * dt * dt * a[d]

    def plate_row(ptr, col, val, u, d):
        """Row ``d`` of the plates' product ``K_p u``, its entries in order (the ``assembled`` backend's sum)."""
        s = 0.0
        for j in range(ptr[d], ptr[d + 1]):
            s += val[j] * u[col[j]]
        return s

    def interface_element(law, e, u, dofs, dNdx, dV, epsy, ny, idx, eps, sig, fe, update_wells, ue, strain):
        """Strain, well, stress and element force of interface element ``e`` (:mod:`..cpu.interface_elements`).

        ``epsy`` [ni, >= ny] the held yield strains (``ny`` of them); ``fe`` [8 ni] element forces, element by
        element (DOF ``a`` of element ``e`` at ``8 e + a``); ``ue`` [8], ``strain`` [4, 3] scratch.
        Returns ``(moved, top)``: 1 if a Gauss point changed well, and the largest well index of the element.
        """
        for a in range(8):
            ue[a] = u[dofs[e, a]]
        strain_of(dNdx[e], ue, strain)
        moved = 0
        top = 0
        for q in range(4):
            xx, yy, xy = strain[q, 0], strain[q, 1], strain[q, 2]
            eq = equivalent(xx, yy, xy)
            i = idx[e, q]
            if update_wells:
                j = well(epsy[e, :ny], eq, i)
                if j != i:
                    idx[e, q] = j
                    i = j
                    moved = 1
            top = max(top, i)
            m = 0.5 * (xx + yy)
            g = factor(law, eq, epsy[e, i], epsy[e, i + 1])
            eps[e, q, 0] = xx
            eps[e, q, 1] = yy
            eps[e, q, 2] = xy
            sig[e, q, 0] = law.K * m + g * (xx - m)
            sig[e, q, 1] = law.K * m + g * (yy - m)
            sig[e, q, 2] = g * xy
        g, w = dNdx[e], dV[e]
        for n in range(4):  # the Gauss points' terms summed in order, as the CPU kernel
            fe[8 * e + 2 * n] = (((w[0] * (g[0, n, 0] * sig[e, 0, 0] + g[0, n, 1] * sig[e, 0, 2]))
                             + w[1] * (g[1, n, 0] * sig[e, 1, 0] + g[1, n, 1] * sig[e, 1, 2]))
                            + w[2] * (g[2, n, 0] * sig[e, 2, 0] + g[2, n, 1] * sig[e, 2, 2])) \
                + w[3] * (g[3, n, 0] * sig[e, 3, 0] + g[3, n, 1] * sig[e, 3, 2])
            fe[8 * e + 2 * n + 1] = (((w[0] * (g[0, n, 0] * sig[e, 0, 2] + g[0, n, 1] * sig[e, 0, 1]))
                                 + w[1] * (g[1, n, 0] * sig[e, 1, 2] + g[1, n, 1] * sig[e, 1, 1]))
                                + w[2] * (g[2, n, 0] * sig[e, 2, 2] + g[2, n, 1] * sig[e, 2, 1])) \
                + w[3] * (g[3, n, 0] * sig[e, 3, 2] + g[3, n, 1] * sig[e, 3, 1])
        return moved, top

    def dof_force(d, plates, gather_ptr, gather_index, fe, drive_layer, drive_w, scale):
        """DOF ``d``'s force: its plate row, then its interface terms in element order, then its drive term."""
        f = plates
        for k in range(gather_ptr[d], gather_ptr[d + 1]):
            f += fe[gather_index[k]]
        layer = drive_layer[d]
        if layer >= 0:
            f += scale[layer] * drive_w[d]
        return f

    def correct(dt, mass_inv, damping, f, v, a, d):
        """Steps 2-4 of velocity Verlet for DOF ``d`` (the CPU's ``_verlet_velocity``)."""
        v[d], a[d] = verlet(dt, mass_inv[d], damping[d], f[d], v[d], a[d])

    def residual_terms(free, multiplicity, damping, f, v, d):
        """DOF ``d``'s terms of the residual's two norms: ``(|f + D v|^2 if free, |f|^2 if prescribed)``, weighted."""
        if free[d]:
            r = f[d] + damping[d] * v[d]
            return multiplicity[d] * r * r, 0.0
        return 0.0, multiplicity[d] * f[d] * f[d]

    def chunk_sum_ubar(start, end, chunks, c, xdofs, w, u):
        """Chunk ``c`` of a layer's fixed-order sum ``sum_j w_j u[xdofs_j]`` (items ``start + c + k chunks``)."""
        s = 0.0
        for j in range(start + c, end, chunks):
            s += w[j] * u[xdofs[j]]
        return s

    return SimpleNamespace(predict=jit(predict), plate_row=jit(plate_row), interface_element=jit(interface_element),
                           dof_force=jit(dof_force), correct=jit(correct), residual_terms=jit(residual_terms),
                           chunk_sum_ubar=jit(chunk_sum_ubar), equivalent=equivalent, well=well)
