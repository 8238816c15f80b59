"""The device kernels' work items as plain functions: one node's rows, one interface element, one DOF's update.

Every function here is plain Python over arrays and indices, built for a target by :func:`build`
with that target's decorator (``numba.cuda.jit(device=True, inline="always")`` for the device,
``numba.njit`` for checks on the CPU): the kernels only deal the items to threads and
synchronise. The scalar physics comes from the package's own reference functions (their plain
Python ``py_func``): the element strain (:func:`...quad4.element_strain`), the well search
(:func:`...laws.wells.well_index`), the equivalent strain, the velocity-Verlet update of one DOF
(:mod:`..cpu.dynamics`) and the law's stress factor, so a new law runs on the device without device
code of its own. Each item computes what the CPU kernels compute for it, in the same order of
operations (the plates' rows in the ``structured`` backend's order); the device compiler may fuse a
multiply and an add (FMA), so the results agree with the CPU's to round-off, not bit for bit.
"""

from types import SimpleNamespace

from ...laws.wells import well_index
from ...materials import equivalent_strain
from ...quad4 import element_strain
from ..cpu.dynamics import _verlet_velocity

__all__ = ["build"]


def _python(function):
    """The plain Python function of a numba-compiled ``function`` (itself where numba's JIT is off:
    ``NUMBA_DISABLE_JIT=1``, as in the GPU check's smoke mode)."""
    return getattr(function, "py_func", function)


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
        ``plate_rows``, ``interface_element``, ``gathered``, ``predict``, ``verlet``, ``residual_terms``,
        and the scalar references ``equivalent`` (strain) and ``well`` (search).
    """
    equivalent = jit(_python(equivalent_strain))
    strain_of = jit(_python(element_strain))
    well = jit(_python(well_index))
    verlet = jit(_python(_verlet_velocity))
    factor = jit(_python(law_class.deviatoric_factor))

    def plate_rows(coef, target, b, nb, lo, hi, u):
        """The node's two rows of ``K_p u`` from its stencil triplets ``lo:hi`` (the CPU's ``_triplet`` order).

        ``coef`` [., 12] the triplets' blocks, ``target`` [., 3, 4] per entry the target line's first node, its
        nodes per block, class and block offset; ``b``, ``nb`` the node's block and the line's blocks.
        """
        fx = 0.0
        fy = 0.0
        for j in range(lo, hi):
            k, tg = coef[j], target[j]
            n1 = tg[0, 0] + ((b + tg[0, 3] + nb) % nb) * tg[0, 1] + tg[0, 2]
            n2 = tg[1, 0] + ((b + tg[1, 3] + nb) % nb) * tg[1, 1] + tg[1, 2]
            n3 = tg[2, 0] + ((b + tg[2, 3] + nb) % nb) * tg[2, 1] + tg[2, 2]
            x1, y1, x2, y2, x3, y3 = u[2 * n1], u[2 * n1 + 1], u[2 * n2], u[2 * n2 + 1], u[2 * n3], u[2 * n3 + 1]
            gx = ((k[0] * x1 + k[1] * y1) + (k[4] * x2 + k[5] * y2)) + (k[8] * x3 + k[9] * y3)
            gy = ((k[2] * x1 + k[3] * y1) + (k[6] * x2 + k[7] * y2)) + (k[10] * x3 + k[11] * y3)
            if j == lo:
                fx, fy = gx, gy
            else:
                fx += gx
                fy += gy
        return fx, fy

    def interface_element(law, e, u, dofs, dNdx, dV, epsy, ny, idx, eps, sig, fe, owner, update_wells, store, ue,
                          strain):
        """Strain, well, stress and element force of interface element ``e`` (:mod:`..cpu.interface_elements`).

        ``epsy`` [ni, >= ny] the held yield strains; ``fe`` [8] receives the element force; the element's
        well is written if ``owner``, its strain and stress if ``owner`` and ``store`` (another tile may compute
        the same element: the well search does not depend on where it starts, so both find the same wells).
        ``ue`` [8], ``strain`` [4, 3] scratch. Returns ``(moved, top)``: 1 if a Gauss point changed well, and the
        largest well of the element.
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
                    i = j
                    moved = 1
                    if owner:
                        idx[e, q] = j
            top = max(top, i)
            m = 0.5 * (xx + yy)
            g = factor(law, eq, epsy[e, i], epsy[e, i + 1])
            strain[q, 0] = law.K * m + g * (xx - m)  # the strain's row now holds the stress
            strain[q, 1] = law.K * m + g * (yy - m)
            strain[q, 2] = g * xy
            if owner and store:
                eps[e, q, 0] = xx
                eps[e, q, 1] = yy
                eps[e, q, 2] = xy
                sig[e, q, 0] = strain[q, 0]
                sig[e, q, 1] = strain[q, 1]
                sig[e, q, 2] = strain[q, 2]
        g, w, s = dNdx[e], dV[e], strain
        for n in range(4):  # the Gauss points' terms summed in order, as the CPU kernel
            fe[2 * n] = (((w[0] * (g[0, n, 0] * s[0, 0] + g[0, n, 1] * s[0, 2]))
                          + w[1] * (g[1, n, 0] * s[1, 0] + g[1, n, 1] * s[1, 2]))
                         + w[2] * (g[2, n, 0] * s[2, 0] + g[2, n, 1] * s[2, 2])) \
                + w[3] * (g[3, n, 0] * s[3, 0] + g[3, n, 1] * s[3, 2])
            fe[2 * n + 1] = (((w[0] * (g[0, n, 0] * s[0, 2] + g[0, n, 1] * s[0, 1]))
                              + w[1] * (g[1, n, 0] * s[1, 2] + g[1, n, 1] * s[1, 1]))
                             + w[2] * (g[2, n, 0] * s[2, 2] + g[2, n, 1] * s[2, 1])) \
                + w[3] * (g[3, n, 0] * s[3, 2] + g[3, n, 1] * s[3, 1])
        return moved, top

    def gathered(f, gather, fe):
        """``f`` plus the DOF's interface terms ``fe[g // 8, g % 8]`` for ``g`` in ``gather`` (in order; -1: none)."""
        for g in gather:
            if g >= 0:
                f += fe[g // 8, g % 8]
        return f

    def predict(u, v, a, dt):
        """Step 1 of velocity Verlet for one DOF (:mod:`..cpu.dynamics`): the next displacement."""
        return u + (dt * v + 0.5 * dt * dt * a)

    def residual_terms(free, multiplicity, damping, f, v):
        """A DOF's terms of the residual's two norms: ``(|f + D v|^2 if free, |f|^2 if prescribed)``, weighted."""
        if free:
            r = f + damping * v
            return multiplicity * r * r, 0.0
        return 0.0, multiplicity * f * f

    return SimpleNamespace(plate_rows=jit(plate_rows), interface_element=jit(interface_element),
                           gathered=jit(gathered), predict=jit(predict), verlet=verlet,
                           residual_terms=jit(residual_terms), equivalent=equivalent, well=well)
