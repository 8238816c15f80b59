"""The structured plate kernel equals the assembled product, for every mesh shape."""

import dataclasses

import numpy as np
import pytest

from stickslip.fem.assembly import assemble_csr, elastic_element_stiffness, element_dofs
from stickslip.fem.backends import make_backend
from stickslip.fem.backends.cpu.plates import plate_force
from stickslip.fem.backends.cpu.stencils import balanced_blocks, build_stencils, plan_product, plate_product
from stickslip.fem.constants import derived_constants
from stickslip.fem.parameters import FemParams
from stickslip.fem.quad4 import element_coordinates, shape_gradients
from stickslip.fem.stack import stack_model
from stickslip.mesh import MeshParams, build_stack_mesh


def _backend(mesh, name, threads=1):
    """A CPU backend ``name`` prepared for the stack of ``mesh``."""
    params = FemParams(N=mesh.N, plates=mesh.plates, nchunk=20)
    model, wells = stack_model(params, mesh, derived_constants(params, mesh))
    return make_backend(name, threads).prepare(model, mesh, wells.epsy)


@pytest.mark.parametrize("plates_", [2, 3, 4, 5, 6])
@pytest.mark.parametrize("N", [4, 9, 10, 54, 162])
def test_stencils_equal_the_assembled_product_on_random_displacements(N, plates_):
    # n = plates - 1 = 1..5 interfaces; random displacements reach every row, the periodic wrap included
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates_))
    backends = [_backend(mesh, name) for name in ("structured", "assembled")]
    rng = np.random.default_rng(N * 10 + plates_)
    u = rng.standard_normal(backends[0].model.ndof)
    forces = []
    for backend in backends:
        backend.set_state(u, np.zeros(mesh.nlayer), 0.0, 0.0)
        forces.append(backend.read("f")[0])
    np.testing.assert_allclose(forces[0], forces[1], rtol=0, atol=1e-12 * np.abs(forces[1]).max())
    model, work = backends[0].model, backends[0].work
    # the plates alone, and a displacement that differs between the first and the last node of every
    # line (the wrap couples them): equal row by row to the CSR product
    ramp = np.full(model.ndof // 2, np.inf)  # x of each node (periodic images share the first node's DOFs)
    np.minimum.at(ramp, np.asarray(mesh.dofs)[:, 0] // 2, np.asarray(mesh.coor)[:, 0])
    for displacement in (u, np.repeat(ramp, 2) * np.tile([1.0, -0.5], model.ndof // 2)):
        expected = np.array([model.k_val[model.k_ptr[i]:model.k_ptr[i + 1]] @ displacement[model.k_col[
            model.k_ptr[i]:model.k_ptr[i + 1]]] for i in range(model.ndof)])
        f = np.full(model.ndof, np.nan)  # every entry must be written
        plate_force(work.plates, work.nblock, displacement, f)
        np.testing.assert_allclose(f, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    # a rigid translation in x is force free (the periodic wrap included)
    plates_only = np.full(model.ndof, np.nan)
    plate_force(work.plates, work.nblock, np.tile([1.0, 0.0], model.ndof // 2), plates_only)
    assert np.abs(plates_only).max() < 1e-12


def _element_stiffness(mesh):
    """The element dofs [nelem, 8], the elements' elastic stiffness [nelem, 8, 8] and the dofs of ``mesh``."""
    dNdx, dV = shape_gradients(element_coordinates(mesh.coor, mesh.conn))
    return element_dofs(mesh.conn, mesh.dofs), elastic_element_stiffness(dNdx, dV, 4.5, 1.0), int(np.max(mesh.dofs)) + 1


def _stencil_and_dense_products(mesh):
    """The stencil product and the dense matrix's product of the plates of ``mesh`` on random displacements."""
    edofs, ke, ndof = _element_stiffness(mesh)
    plan = plan_product(build_stencils(mesh, *assemble_csr(edofs, ke, ndof)), ndof)
    u = np.random.default_rng(0).standard_normal(ndof)
    f = np.zeros(ndof)
    plate_product(plan.views, plan.groups, plan.triplet_ptr, plan.triplet_view, plan.triplet_coef, plan.empty_dofs,
                  np.zeros((4, max(plan.view_size, plan.output_size))), u, f)
    dense = np.zeros((ndof, ndof))
    np.add.at(dense, (np.repeat(edofs, 8, axis=1), np.tile(edofs, (1, 8))), ke.reshape(edofs.shape[0], 64))
    return f, dense @ u


def test_stencils_of_a_single_row_pair_are_the_element_stiffness():
    # one regular row of N squares between two node lines: the stencil of a node is the sum of its
    # two elements' blocks, whatever N (the wrap joins the last element to the first node)
    f, expected = _stencil_and_dense_products(build_stack_mesh(MeshParams(N=4, plates=2)))
    np.testing.assert_allclose(f, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_stencils_of_far_coordinates_allow_their_round_off_and_still_see_another_element():
    # N = 13 122 (x up to 4.1e4) was a ValueError traceback of `stickslip simulate` ("rows differ between blocks"):
    # coordinates far from 0 make the coefficients of equal elements differ by eps |x| / h. The same mesh at
    # N = 54 shifted to x ~ 1e5 has that round-off (3e-12 of the largest coefficient), cheaply
    mesh = build_stack_mesh(MeshParams(N=54, plates=2))
    far = dataclasses.replace(mesh, coor=np.asarray(mesh.coor) + [1e5, 0.0])
    f, expected = _stencil_and_dense_products(far)
    np.testing.assert_allclose(f, expected, rtol=0, atol=1e-10 * np.abs(expected).max())
    edofs, ke, ndof = _element_stiffness(far)
    ke[7] *= 1 + 1e-6  # one element a little stiffer: no longer one stencil block after block
    with pytest.raises(ValueError, match="rows differ between blocks"):
        build_stencils(far, *assemble_csr(edofs, ke, ndof))


@pytest.mark.parametrize("threads", [2, 3])
def test_parallel_product_has_the_serial_bits(threads):
    mesh = build_stack_mesh(MeshParams(N=54, plates=3))
    for name in ("structured", "assembled"):
        serial = _backend(mesh, name).work
        parallel = _backend(mesh, name, threads).work
        assert parallel.nblock > 1
        u = np.random.default_rng(1).standard_normal(mesh.dofs.max() + 1)
        f_serial, f_parallel = np.zeros(u.size), np.zeros(u.size)
        plate_force(serial.plates, serial.nblock, u, f_serial)
        plate_force(parallel.plates, parallel.nblock, u, f_parallel)
        assert f_serial.tobytes() == f_parallel.tobytes()


def test_balanced_blocks_split_the_work_evenly():
    work = np.array([1, 1, 10, 1, 1, 1, 1, 1, 1, 1, 1, 10])
    bounds = balanced_blocks(work, 3)
    assert bounds[0] == 0 and bounds[-1] == work.size and np.all(np.diff(bounds) >= 0)
    totals = [work[a:b].sum() for a, b in zip(bounds[:-1], bounds[1:])]
    assert max(totals) <= work.sum() / 3 + work.max()
    assert list(balanced_blocks(work, 100)[[0, -1]]) == [0, work.size]
