"""The structured plate kernel equals the assembled product, for every mesh shape."""

import numpy as np
import pytest

from stickslip.fem.assembly import assemble_csr, elastic_element_stiffness, element_dofs
from stickslip.fem.forces import compute_force
from stickslip.fem.model import new_state
from stickslip.fem.parameters import FemParams
from stickslip.fem.quad4 import element_coordinates, shape_gradients
from stickslip.fem.structured import apply_stencils, build_stencils, line_blocks
from stickslip.fem.system import System
from stickslip.mesh import MeshParams, build_stack_mesh


@pytest.mark.parametrize("plates", [2, 3, 4, 5, 6])
@pytest.mark.parametrize("N", [4, 9, 10, 54, 162])
def test_stencils_equal_the_assembled_product_on_random_displacements(N, plates):
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    systems = [System(FemParams(N=N, plates=plates, nchunk=20), mesh, plate_kernel=kernel)
               for kernel in ("structured", "assembled")]
    rng = np.random.default_rng(N * 10 + plates)
    u = rng.standard_normal(systems[0].model.ndof)
    forces = []
    for system in systems:
        state = new_state(system.model)
        state.u[:] = u
        compute_force(system.model, state, system._fe)
        forces.append(state.f)
    np.testing.assert_allclose(forces[0], forces[1], rtol=0, atol=1e-12 * np.abs(forces[1]).max())
    # a rigid translation in x is force free (the periodic wrap included)
    plates_only = np.zeros_like(u)
    model = systems[0].model
    apply_stencils(model.stencil_index, model.stencil_coef, 0, model.stencil_index.shape[0],
                   np.tile([1.0, 0.0], model.ndof // 2), plates_only)
    assert np.abs(plates_only).max() < 1e-12


def test_stencils_of_a_single_row_pair_are_the_element_stiffness():
    # one regular row of N squares between two node lines: the stencil of a node is the sum of its
    # two elements' blocks, whatever N (the wrap joins the last element to the first node)
    mesh = build_stack_mesh(MeshParams(N=4, plates=2))
    edofs = element_dofs(mesh.conn, mesh.dofs)
    dNdx, dV = shape_gradients(element_coordinates(mesh.coor, mesh.conn))
    ndof = int(np.max(mesh.dofs)) + 1
    ptr, col, val = assemble_csr(edofs, elastic_element_stiffness(dNdx, dV, 4.5, 1.0), ndof)
    stencils = build_stencils(mesh, ptr, col, val)
    u = np.random.default_rng(0).standard_normal(ndof)
    f = np.zeros(ndof)
    apply_stencils(stencils.index, stencils.coef, 0, stencils.index.shape[0], u, f)
    dense = np.zeros((ndof, ndof))
    np.add.at(dense, (np.repeat(edofs, 8, axis=1), np.tile(edofs, (1, 8))),
              elastic_element_stiffness(dNdx, dV, 4.5, 1.0).reshape(edofs.shape[0], 64))
    np.testing.assert_allclose(f, dense @ u, rtol=0, atol=1e-12 * np.abs(dense @ u).max())


def test_parallel_blocks_hold_whole_lines():
    mesh = build_stack_mesh(MeshParams(N=54, plates=3))
    model = System(FemParams(N=54, plates=3, nchunk=20), mesh).model
    index = model.stencil_index
    for nblock in (1, 2, 8, 1000):
        bounds = line_blocks(index, nblock)
        assert bounds[0] == 0 and bounds[-1] == index.shape[0] and np.all(np.diff(bounds) >= 0)
        inner = bounds[1:-1][(bounds[1:-1] > 0) & (bounds[1:-1] < index.shape[0])]
        assert np.all(index[inner, 0] != index[inner - 1, 0])  # a boundary never splits a line
