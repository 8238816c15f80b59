"""The L2 traffic of one realisation-step of each minimisation kernel, counted from the code and the mesh's layout.

An estimate, not a measurement (no GPU runs here): the bytes each kernel's step requests from the L2 cache, per
realisation, at N = 1458 with 2 and 6 plates. The model: every block's L1 is empty after the step's grid barrier
(its fence), so every distinct byte a block reads in a step comes from L2 once (re-reads within the step hit L1);
every store goes to L2. Counted per step (``python benchmarks/gpu/traffic.py``):

- the tile's stencil triplets (:func:`...tiles.load_stencils`: 12 coefficients, 12 targets, the triplet's index):
  every step in the tiles kernel, once per launch in the resident kernel;
- the tile's interface elements (:func:`...items.interface_element`): the element's list entries, DOFs,
  shape-function gradients, volumes, wells and the two yield strains of each Gauss point's well (both kernels);
  their strains and stresses written by the owner (the tiles kernel every step; the resident kernel at exit);
- the tile's nodes: their rows of the layout (slot node, stencil row, gathers, layers, weights) and per-DOF
  constants (inverse mass, damping, multiplicity, free), velocity and acceleration read, force, velocity and
  acceleration written (the tiles kernel every step; the resident kernel holds them in registers), the next
  displacement written (both);
- the displacements the tile's plate rows and elements read: distinct nodes, 16 bytes each (both);
- the tile's sums written, and every block reading the sums and flags of every tile of its realisation (both).

A block of the tiles kernel may hold several tiles (``G`` blocks per realisation); the resident kernel's
realisation has one block per tile.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from stickslip.fem.backends.cuda.layout import build_layout  # noqa: E402
from stickslip.fem.backends.cuda.tiles import LAYER_ROW  # noqa: E402
from stickslip.fem.constants import derived_constants  # noqa: E402
from stickslip.fem.parameters import FemParams  # noqa: E402
from stickslip.fem.stack import stack_model  # noqa: E402
from stickslip.mesh import MeshParams, build_stack_mesh  # noqa: E402

F8, I4 = 8, 4
#: Bytes of one stencil triplet: 12 coefficients, 12 targets, its index in the tile's list.
TRIPLET = 12 * F8 + 12 * I4 + I4
#: Bytes one interface element reads: list entry and owner flag, 8 DOFs, gradients [4, 4, 2], volumes [4],
#: wells [4] (int64), the yield strains bounding each Gauss point's well (2 per point).
ELEMENT_READ = I4 + 1 + 8 * I4 + 32 * F8 + 4 * F8 + 4 * F8 + 8 * F8
#: Bytes its owner writes: strain and stress [4, 3] each.
ELEMENT_WRITE = 24 * F8
#: Bytes of one node's rows of the layout besides its gathers: slot node, stencil row [4], layers [2], weights [2].
NODE_ROWS = I4 + 4 * I4 + 2 * I4 + 2 * F8
#: Bytes of one DOF's constants: inverse mass, damping, multiplicity, free.
DOF_CONSTANTS = 3 * F8 + 1


def tile_bytes(layout, k):
    """What tile ``k`` reads and writes in one step, by item (module docstring)."""
    lo, hi = layout.tile_element_ptr[k], layout.tile_element_ptr[k + 1]
    elements = layout.tile_elements[lo:hi]
    owned = int(layout.tile_owns[lo:hi].sum())
    slots = layout.slot_node[k * layout.tile:(k + 1) * layout.tile]
    nodes = slots[slots >= 0]
    read = set(np.asarray(layout.iface_dofs)[elements].ravel() // 2)
    triplets = layout.tile_triplets[layout.tile_triplet_ptr[k]:layout.tile_triplet_ptr[k + 1]]
    for n in nodes:
        b, nb, first, last = layout.slot_stencil[n]
        for j in triplets[first:last]:
            for entry in layout.triplet_target[j]:
                start, per_block, klass, offset = entry
                read.add(start + ((b + offset + nb) % nb) * per_block + klass)
    gathers = layout.slot_gather.shape[1] * layout.slot_gather.shape[2] * I4
    return {"stencils": len(triplets) * TRIPLET, "elements": len(elements) * ELEMENT_READ,
            "element_writes": owned * ELEMENT_WRITE, "node_constants": len(nodes) * (NODE_ROWS + gathers
                                                                                     + 2 * DOF_CONSTANTS),
            "motion": len(nodes) * 2 * (2 * F8 + 3 * F8), "next_u": len(nodes) * 2 * F8, "u": len(read) * 2 * F8,
            "sums_written": (LAYER_ROW + layout.nlayer + 3) * F8}


def per_realisation_step(layout, kernel, G):
    """Bytes per realisation-step of ``kernel`` ("tiles" or "resident") over ``G`` blocks, by item."""
    total = {}
    for k in range(layout.ntile):
        for item, value in tile_bytes(layout, k).items():
            if kernel == "resident" and item in ("stencils", "element_writes", "node_constants", "motion"):
                value = 0  # once per launch, or at its end
            total[item] = total.get(item, 0) + value
    total["sums_read"] = G * layout.ntile * (LAYER_ROW + layout.nlayer + 3) * F8
    return total


def main():
    for plates in (2, 6):
        params = FemParams(N=1458, plates=plates, nchunk=200, window=64)
        mesh = build_stack_mesh(MeshParams(N=1458, plates=plates))
        model, _ = stack_model(params, mesh, derived_constants(params, mesh))
        layout = build_layout(model, mesh)
        print(f"N = 1458, {plates} plates: {layout.nnode} nodes in {layout.ntile} tiles of {layout.tile}, "
              f"{layout.ni} interface elements; a tile uses at most {np.diff(layout.tile_triplet_ptr).max()} stencil "
              f"triplets and touches at most {np.diff(layout.tile_element_ptr).max()} elements")
        for kernel, G, label in (("tiles", layout.ntile, "one realisation, a block per tile"),
                                 ("tiles", 1, "batches, a block per realisation"),
                                 ("resident", layout.ntile, "a block per tile")):
            items = per_realisation_step(layout, kernel, G)
            listed = ", ".join(f"{name} {value / 1e6:.3f}" for name, value in items.items() if value)
            print(f"  {kernel:8s} G = {G:3d} ({label}): {sum(items.values()) / 1e6:.2f} MB per realisation-step "
                  f"({listed} MB)")


if __name__ == "__main__":
    main()
