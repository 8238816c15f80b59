"""What the device kernels need of a model, arranged on the host: nodes in tiles, stencils and elements per tile.

The device computes a realisation tile by tile. A **tile** is ``tile`` consecutive nodes (node ``n`` owns
the DOFs ``2 n, 2 n + 1``; the last tile is padded): the unit of work dealt whole to a block, one node
per thread. For its nodes a tile needs:

- **its stencils**: the plates' product by the periodic stencils of the ``structured`` CPU backend
  (:mod:`..cpu.stencils`): every node's rows are the triplets of its node line and class, each triplet
  three entries ``(target line, class, block offset)`` with a 2 x 2 block each, summed in the CPU's
  order. The triplets a tile uses are listed per tile (``tile_triplets``), so a block copies them
  into shared memory once per tile;
- **its interface elements**: every element touching one of its nodes (computed into shared memory;
  an element at a tile's edge is computed by both tiles, the same bits); the element's *owner*, the
  tile of its first node, alone writes its strain, stress and well;
- every DOF **gathers** its interface terms from the tile's elements in the CPU's order (element by
  element), then its drive term;
- **fixed-order sums**: a tile's sums (the residual's two norms and every layer's weighted average)
  run over its slots in a fixed binary tree; the tiles' sums are then added by :data:`LEAVES` leaves
  (leaf ``l`` sums the tiles ``l, l + LEAVES, ...`` in order) and a binary tree over the leaves. The
  order depends on the number of nodes only (:func:`tile_size`): the same bits whatever the number of
  blocks, the threads per block, the batch or the device.
"""

from collections import namedtuple

import numpy as np

from ..cpu.stencils import build_stencils, plan_product

__all__ = ["LEAVES", "MAX_LAYERS", "MAX_TILE", "MAX_TILE_TRIPLETS", "MAX_TILE_ELEMENTS", "Layout", "build_layout",
           "tile_size"]

#: Leaves of the sums over tiles (a power of 2).
LEAVES = 32
#: Layers a mesh may have (6 plates and 5 interfaces).
MAX_LAYERS = 11
#: Nodes of a tile at most (a power of 2; shared memory is sized for it).
MAX_TILE = 128
#: Stencil triplets one tile may use (shared memory; the paper's meshes use at most 28, at N = 1458).
MAX_TILE_TRIPLETS = 48
#: Interface elements one tile may touch (shared memory).
MAX_TILE_ELEMENTS = MAX_TILE + 8

Layout = namedtuple("Layout", [
    "ndof", "nnode", "ni", "nlayer", "tile", "ntile",
    "slot_node",        # int32 [ntile * tile]: the node of every slot (-1: padding)
    "slot_stencil",     # int32 [ntile * tile, 4]: block b, blocks nb, the tile's triplets lo:hi of the node's rows
    "slot_gather",      # int32 [ntile * tile, 2, width]: per DOF, 8 le + a of its interface terms (le: the tile's
                        #   element), element by element (-1: none)
    "slot_layer",       # int32 [ntile * tile, 2]: the layers whose average the node's x-DOF enters (-1: none)
    "slot_weight",      # float64 [ntile * tile, 2]: its weights there
    "tile_triplet_ptr", "tile_triplets",  # int32 [ntile + 1], [.]: the stencil triplets of every tile (sorted)
    "tile_element_ptr", "tile_elements", "tile_owns",  # int32 [ntile + 1], [.], int8 [.]: its elements; owner
    "triplet_coef",     # float64 [ntriplet, 12]: the three entries' blocks (xx, xy, yx, yy)
    "triplet_target",   # int32 [ntriplet, 3, 4]: per entry, target line's first node, nodes per block, class, offset
    "mass_inv", "damping", "multiplicity",  # float64 [ndof]
    "free",             # int8 [ndof]: 1 on free DOFs
    "iface_dofs",       # int32 [ni, 8]
    "iface_dNdx", "iface_dV",  # float64 [ni, 4, 4, 2], [ni, 4]
    "layer_volume", "drive_active", "lever_ratio",  # float64 [nlayer], int8 [nlayer], float64 [nlayer]
])


def tile_size(nnode):
    """Nodes per tile for a mesh of ``nnode`` nodes: the power of 2 nearest to ``nnode / 64``, in [32, MAX_TILE]."""
    return int(min(MAX_TILE, max(32, 2 ** round(np.log2(max(nnode, 1) / 64)))))


def _stencil_rows(mesh, model):
    """Per node (block b, blocks nb, global triplets lo:hi); the triplets' coefficients and targets."""
    plan = plan_product(build_stencils(mesh, model.k_ptr, model.k_col, model.k_val), model.ndof)
    nnode = model.ndof // 2
    rows = np.zeros((nnode, 4), dtype=np.int64)  # no group (an empty row): nb 1, no triplets
    rows[:, 1] = 1
    for g, (start, p, c, nb, _) in enumerate(plan.groups):
        nodes = start // 2 + np.arange(nb) * p + c
        rows[nodes, 0] = np.arange(nb)
        rows[nodes, 1] = nb
        rows[nodes, 2] = plan.triplet_ptr[g]
        rows[nodes, 3] = plan.triplet_ptr[g + 1]
    target = np.zeros((plan.triplet_view.shape[0], 3, 4), dtype=np.int64)
    for v, (start, q, nb, offset) in enumerate(plan.views):
        inside = (plan.triplet_view >= offset) & (plan.triplet_view < offset + q * (nb + 2))
        relative = plan.triplet_view[inside] - offset
        target[inside] = np.stack([np.full(relative.size, start // 2), np.full(relative.size, q),
                                   relative // (nb + 2), relative % (nb + 2) - 1], axis=-1)
    return rows, plan.triplet_coef, target


def _tile_lists(tiles_of_item, ntile):
    """CSR of the items each tile uses: ``tiles_of_item`` is a list of (tile, item) pairs."""
    pairs = np.unique(np.asarray(tiles_of_item, dtype=np.int64).reshape(-1, 2), axis=0)
    ptr = np.searchsorted(pairs[:, 0], np.arange(ntile + 1)).astype(np.int32)
    return ptr, pairs[:, 1].astype(np.int32)


def build_layout(model, mesh):
    """The device layout of ``model`` on ``mesh`` (module docstring).

    Returns
    -------
    Layout
        Host arrays, copied to the device once per mesh.

    Raises
    ------
    ValueError
        If the mesh has more than :data:`MAX_LAYERS` layers, a DOF lies in two driven layers, or a tile
        needs more triplets or elements than shared memory holds.
    """
    nlayer = int(model.layer_volume.size)
    if nlayer > MAX_LAYERS:
        raise ValueError(f"the cuda backend holds at most {MAX_LAYERS} layers (6 plates); got {nlayer}")
    nnode = model.ndof // 2
    tile = tile_size(nnode)
    ntile = -(-nnode // tile)
    slot_node = np.full(ntile * tile, -1, dtype=np.int64)
    slot_node[:nnode] = np.arange(nnode)
    tile_of_node = np.arange(nnode) // tile
    real = slot_node >= 0

    rows, coef, target = _stencil_rows(mesh, model)
    used = [(tile_of_node[n], t) for n in range(nnode) for t in range(rows[n, 2], rows[n, 3])]
    triplet_ptr, triplets = _tile_lists(used, ntile)
    slot_stencil = np.zeros((ntile * tile, 4), dtype=np.int64)
    slot_stencil[:, 1] = 1
    for n in range(nnode):
        mine = triplets[triplet_ptr[tile_of_node[n]]:triplet_ptr[tile_of_node[n] + 1]]
        lo = np.searchsorted(mine, rows[n, 2])
        slot_stencil[n] = rows[n, 0], rows[n, 1], lo, lo + rows[n, 3] - rows[n, 2]

    element_nodes = np.asarray(model.iface_dofs, dtype=np.int64)[:, 0::2] // 2
    touching = [(tile_of_node[n], e) for e in range(element_nodes.shape[0]) for n in element_nodes[e]]
    element_ptr, elements = _tile_lists(touching, ntile)
    owner = tile_of_node[element_nodes[:, 0]] if element_nodes.size else np.zeros(0, dtype=np.int64)
    tile_of_entry = np.repeat(np.arange(ntile), np.diff(element_ptr))
    owns = (owner[elements] == tile_of_entry).astype(np.int8)

    flat = np.asarray(model.iface_dofs, dtype=np.int64).ravel()
    order = np.argsort(flat, kind="stable")  # by DOF, then (e, a): the CPU's order of the interface terms
    counts = np.bincount(flat, minlength=model.ndof)
    width = max(1, int(counts.max()) if counts.size else 1)
    slot_gather = np.full((ntile * tile, 2, width), -1, dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(counts)])
    for d in np.flatnonzero(counts):
        n = d // 2
        mine = elements[element_ptr[tile_of_node[n]]:element_ptr[tile_of_node[n] + 1]]
        for k, j in enumerate(order[starts[d]:starts[d + 1]]):
            slot_gather[n, d % 2, k] = 8 * np.searchsorted(mine, j // 8) + j % 8

    slot_layer = np.full((ntile * tile, 2), -1, dtype=np.int64)
    slot_weight = np.zeros((ntile * tile, 2))
    for layer in range(nlayer):
        span = slice(model.layer_ptr[layer], model.layer_ptr[layer + 1])
        nodes = model.layer_xdofs[span] // 2
        column = (slot_layer[nodes, 0] >= 0).astype(np.int64)
        if np.any(slot_layer[nodes, 1] >= 0):
            raise ValueError("a DOF lies in three layers: the device holds two layer weights per node")
        if model.drive_active[layer] and np.any(model.drive_active[np.maximum(slot_layer[nodes, 0], 0)]
                                                & (slot_layer[nodes, 0] >= 0)):
            raise ValueError("a DOF lies in two driven layers: the device adds one drive term per DOF")
        slot_layer[nodes, column] = layer
        slot_weight[nodes, column] = model.layer_w[span]

    for name, ptr, capacity in (("stencil triplets", triplet_ptr, MAX_TILE_TRIPLETS),
                                ("interface elements", element_ptr, MAX_TILE_ELEMENTS)):
        if ntile and np.diff(ptr).max() > capacity:
            raise ValueError(f"a tile of this mesh uses {np.diff(ptr).max()} {name}; the device holds {capacity}")
    i32 = np.int32
    return Layout(
        ndof=int(model.ndof), nnode=int(nnode), ni=int(model.iface_dofs.shape[0]), nlayer=nlayer, tile=tile,
        ntile=int(ntile), slot_node=slot_node.astype(i32), slot_stencil=slot_stencil.astype(i32),
        slot_gather=slot_gather.astype(i32), slot_layer=np.where(real[:, None], slot_layer, -1).astype(i32),
        slot_weight=slot_weight, tile_triplet_ptr=triplet_ptr, tile_triplets=triplets,
        tile_element_ptr=element_ptr, tile_elements=elements, tile_owns=owns,
        triplet_coef=np.ascontiguousarray(coef, dtype=np.float64), triplet_target=target.astype(i32),
        mass_inv=np.asarray(model.mass_inv, dtype=np.float64), damping=np.asarray(model.damping, dtype=np.float64),
        multiplicity=np.asarray(model.multiplicity, dtype=np.float64), free=(~model.prescribed).astype(np.int8),
        iface_dofs=np.ascontiguousarray(model.iface_dofs, dtype=i32), iface_dNdx=np.ascontiguousarray(model.iface_dNdx),
        iface_dV=np.ascontiguousarray(model.iface_dV), layer_volume=np.asarray(model.layer_volume, dtype=np.float64),
        drive_active=model.drive_active.astype(np.int8), lever_ratio=np.asarray(model.lever_ratio, dtype=np.float64))
