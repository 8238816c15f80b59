"""The work of one tile (:mod:`.layout`) in a block: its stencils and elements on chip, its nodes, its sums.

Every function is called by all threads of a block (``t`` of ``bd``), for tile ``k`` of realisation
``m``; shared-memory arrays are the caller's (:mod:`.kernels`). A tile's sums go to the realisation's
*partials* ``[tile, row]``: row 0 the residual's free norm, row 1 its prescribed norm, rows ``2 + l``
layer ``l``'s weighted average; its *flags* ``[tile, 3]``: a well changed, a Gauss point within the
margin, the well changes of Gauss point 0 (hops, for the recording), over the elements it owns.
"""

from types import SimpleNamespace

from numba import cuda

__all__ = ["build"]

#: Rows of a tile's sums before the layers' averages (the residual's two norms).
LAYER_ROW = 2


def build(device, items, sync):
    """The tile device functions for the work ``items`` (:func:`.items.build`) and ``sync`` (:func:`.sync.build`)."""
    plate_rows, interface_element, gathered = items.plate_rows, items.interface_element, items.gathered
    predict, verlet, residual_terms = items.predict, items.verlet, items.residual_terms
    tile_tree = sync.tile_tree

    @device
    def clear(rows, nrows, s):
        for r in range(nrows):
            rows[r, s] = 0.0

    @device
    def layer_rows(mesh, n, ux, rows, s):
        """Slot ``s``'s terms of the layers' averages (its x-displacement ``ux``)."""
        for j in range(2):
            layer = mesh.slot_layer[n, j]
            if layer >= 0:
                rows[LAYER_ROW + layer, s] = mesh.slot_weight[n, j] * ux

    def load_stencils(mesh, k, coef, target, t, bd):
        """Copy tile ``k``'s stencil triplets into shared memory (``coef`` [., 12], ``target`` [., 3, 4])."""
        lo = mesh.tile_triplet_ptr[k]
        for item in range(t, (mesh.tile_triplet_ptr[k + 1] - lo) * 12, bd):
            j, c = item // 12, item % 12
            triplet = mesh.tile_triplets[lo + j]
            coef[j, c] = mesh.triplet_coef[triplet, c]
            target[j, c // 4, c % 4] = mesh.triplet_target[triplet, c // 4, c % 4]

    def elements(law, mesh, k, u, state, m, fe, flags, update_wells, limit, record, store, t, bd, ue, strain):
        """Tile ``k``'s interface elements into ``fe`` [., 8]; its flags (owned elements) into ``flags`` [3]; the
        strain and stress of the elements it owns into the state if ``store``."""
        if t == 0:
            flags[0] = 0
            flags[1] = 0
            flags[2] = 0
        cuda.syncthreads()
        lo = mesh.tile_element_ptr[k]
        ny = state.ny[m]
        for j in range(t, mesh.tile_element_ptr[k + 1] - lo, bd):
            e = mesh.tile_elements[lo + j]
            owner = mesh.tile_owns[lo + j]
            moved, top = interface_element(law, e, u, mesh.iface_dofs, mesh.iface_dNdx, mesh.iface_dV, state.epsy[m],
                                           ny, state.idx[m], state.eps[m], state.sig[m], fe[j], owner, update_wells,
                                           store, ue, strain)
            if owner:
                if moved:
                    cuda.atomic.max(flags, 0, 1)
                if top >= limit:
                    cuda.atomic.max(flags, 1, 1)
                if record:
                    cuda.atomic.add(flags, 2, abs(state.idx[m, e, 0] - state.previous[m, e]))
        cuda.syncthreads()

    @device
    def node_force(mesh, n, u, coef, target, fe, scale):
        """Node ``n``'s force ``(x, y)``: its plate rows, its interface terms in element order, its drive term."""
        return stencil_force(mesh, n, mesh.slot_stencil[n, 0], mesh.slot_stencil[n, 1], mesh.slot_stencil[n, 2],
                             mesh.slot_stencil[n, 3], u, coef, target, fe, scale)

    @device
    def stencil_force(mesh, n, b, nb, lo, hi, u, coef, target, fe, scale):
        """:func:`node_force` with the node's stencil row ``(b, nb, lo, hi)`` (``slot_stencil[n]``) given."""
        fx, fy = plate_rows(coef, target, b, nb, lo, hi, u)
        fx = gathered(fx, mesh.slot_gather[n, 0], fe)
        fy = gathered(fy, mesh.slot_gather[n, 1], fe)
        for j in range(2):
            layer = mesh.slot_layer[n, j]
            if layer >= 0 and mesh.drive_active[layer]:
                fx += scale[layer] * mesh.slot_weight[n, j]
        return fx, fy

    @device
    def publish(rows, nrows, tile, partials, t, bd):
        """Sum the slots' rows by the tile's tree into ``partials`` [nrows] (the tile's row of the realisation)."""
        tile_tree(rows, nrows, tile, t, bd)
        for r in range(t, nrows, bd):
            partials[r] = rows[r, 0]
        cuda.syncthreads()  # the rows are read before the next tile writes them

    def step_nodes(mesh, k, m, u, u_next, state, dt, coef, target, fe, scale, rows, nrows, t, bd):
        """One time step of tile ``k``'s nodes, fused: force, velocity Verlet, residual terms, next displacement."""
        for s in range(t, mesh.tile, bd):
            clear(rows, nrows, s)
            n = mesh.slot_node[k * mesh.tile + s]
            if n >= 0:
                fx, fy = node_force(mesh, n, u, coef, target, fe, scale)
                for c in range(2):
                    d = 2 * n + c
                    f = fx if c == 0 else fy
                    v, a = verlet(dt, mesh.mass_inv[d], mesh.damping[d], f, state.v[m, d], state.a[m, d])
                    state.f[m, d] = f
                    state.v[m, d] = v
                    state.a[m, d] = a
                    res, ext = residual_terms(mesh.free[d], mesh.multiplicity[d], mesh.damping[d], f, v)
                    rows[0, s] += res
                    rows[1, s] += ext
                    u_next[d] = predict(u[d], v, a, dt)
                layer_rows(mesh, n, u_next[2 * n], rows, s)

    def force_nodes(mesh, k, m, u, state, coef, target, fe, scale, rows, t, bd):
        """Tile ``k``'s nodes' force at rest (no motion) and their residual terms (rows 0, 1)."""
        for s in range(t, mesh.tile, bd):
            clear(rows, LAYER_ROW, s)
            n = mesh.slot_node[k * mesh.tile + s]
            if n >= 0:
                fx, fy = node_force(mesh, n, u, coef, target, fe, scale)
                for c in range(2):
                    d = 2 * n + c
                    f = fx if c == 0 else fy
                    state.f[m, d] = f
                    res, ext = residual_terms(mesh.free[d], mesh.multiplicity[d], mesh.damping[d], f, state.v[m, d])
                    rows[0, s] += res
                    rows[1, s] += ext

    def state_rows(mesh, k, m, u, u_next, state, dt, predicted, rows, nrows, t, bd):
        """Tile ``k``'s rows of the state as it is: its residual terms and (``predicted``: of the displacement
        ``u_next`` predicted from it, else of ``u``) its layers' averages."""
        for s in range(t, mesh.tile, bd):
            clear(rows, nrows, s)
            n = mesh.slot_node[k * mesh.tile + s]
            if n >= 0:
                for c in range(2):
                    d = 2 * n + c
                    v = state.v[m, d]
                    res, ext = residual_terms(mesh.free[d], mesh.multiplicity[d], mesh.damping[d], state.f[m, d], v)
                    rows[0, s] += res
                    rows[1, s] += ext
                    if predicted:
                        u_next[d] = predict(u[d], v, state.a[m, d], dt)
                layer_rows(mesh, n, u_next[2 * n] if predicted else u[2 * n], rows, s)

    return SimpleNamespace(load_stencils=device(load_stencils), elements=device(elements), publish=publish,
                           clear=clear, layer_rows=layer_rows, stencil_force=stencil_force,
                           step_nodes=device(step_nodes), force_nodes=device(force_nodes),
                           state_rows=device(state_rows))
