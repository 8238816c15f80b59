"""Layered Quad4 mesh: GooseFEM FineLayer geometry, paper numbers, conformity, periodicity, HDF5."""

import math
import time
from collections import Counter

import h5py
import numpy as np
import pytest

from stickslip.h5io import FileFormatError
from stickslip.mesh import (MeshParams, build_stack_mesh, load_mesh, mesh_id, read_mesh, save_mesh,
                            write_mesh)
from stickslip.mesh.rows import FINE_ABOVE, fine_layer_half, plate_target_height
from stickslip.plugin_params import ParameterError, parse_params


@pytest.fixture(scope="module")
def paper_meshes():
    """Default-size meshes (N = 1458) for 2 ... 6 plates."""
    return {plates: build_stack_mesh(MeshParams(N=1458, plates=plates)) for plates in range(2, 7)}


def element_areas(mesh):
    """Shoelace area of every element [nelem]; positive when counter-clockwise."""
    xy = mesh.coor[mesh.conn]
    x, y = xy[..., 0], xy[..., 1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)


def in_units(mesh, values):
    """Values divided by h, rounded to integers (positions are integer multiples of h)."""
    scaled = np.asarray(values) / mesh.h
    assert np.allclose(scaled, np.round(scaled), rtol=0, atol=1e-9)
    return np.round(scaled).astype(int)


# --- the paper's numbers (reference-model.md section 3, from GooseFEM's FineLayer rule) -------------

def test_fine_layer_half_for_the_paper_size():
    assert plate_target_height(1458) == 364
    rows = [(row.width, row.height, row.is_transition) for row in fine_layer_half(1458, 364)]
    assert rows == [(1, 1, False), (1, 1, False), (3, 2, True), (3, 3, False), (3, 3, False),
                    (9, 6, True), (9, 9, False), (9, 9, False), (27, 18, True), (27, 27, False),
                    (27, 27, False), (81, 54, True), (81, 81, False)]
    assert sum(height for _, height, _ in rows) == 241
    assert sum((4 if transition else 1) * 1458 // width for width, _, transition in rows) == 7218


@pytest.mark.parametrize("plates, nelem", [(2, 15966), (3, 31860), (4, 47754), (5, 63648), (6, 79542)])
def test_paper_element_counts(paper_meshes, plates, nelem):
    mesh = paper_meshes[plates]
    assert mesh.nelem == nelem
    counts = [len(mesh.layer_elements(layer)) for layer in range(mesh.nlayer)]
    assert counts == [7254] + [1458, 14436] * (plates - 2) + [1458, 7254]


def test_paper_layer_heights(paper_meshes):
    two, three = paper_meshes[2], paper_meshes[3]
    assert np.allclose(two.layer_mid_height / two.h, [201.5, 403.5, 605.5], rtol=0, atol=1e-9)
    assert np.allclose(three.layer_mid_height[:3] / three.h, [201.5, 403.5, 645.0], rtol=0, atol=1e-9)
    thickness = in_units(three, np.diff(three.layer_y, axis=1).ravel())
    assert thickness.tolist() == [403, 1, 482, 1, 403]


def test_small_reference_case_N9():
    """N = 9, 2 plates (the regression file's system), derived by hand from GooseFEM's rule.

    M = max(3, int(9 / 4)) = 3, target half height ceil(3 / 2) = 2: the FineLayer half
    is the middle row (height 1) plus one fine row, so half height = 1 h, coarse width
    1 h, and ceil((3 - 1) / 1) = 2 extra rows: bottom and top plates are 3 rows of 9
    square elements (3 h thick); with the interface: 63 elements, 8 node lines of 10
    nodes (80 nodes), height 7 h, 9 independent nodes per line (144 DOFs).
    """
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    assert [(row.width, row.height) for row in fine_layer_half(9, 3)] == [(1, 1)]
    assert (mesh.nelem, mesh.nnode, mesh.ndof) == (63, 80, 144)
    assert in_units(mesh, mesh.layer_y).tolist() == [[0, 3], [3, 4], [4, 7]]
    assert np.allclose(element_areas(mesh), math.pi**2)
    assert np.allclose(mesh.layer_mid_height, [1.5 * math.pi, 3.5 * math.pi, 5.5 * math.pi])
    assert mesh.iip.tolist() == list(range(18)) + [2 * (63 + k) + 1 for k in range(9)]


def test_transition_row_geometry_is_goosefem():
    """N = 54, M = 13: half rows (1,1) (1,1) (3,2)* (3,3); check the refinement row of the bottom plate.

    GooseFEM (refinement below the middle row): a coarse block [x0, x0 + 3] at y0 holds a bottom
    element (x0, y0) (x0+3, y0) (x0+2, y0+1) (x0+1, y0+1), top-right (x0+3, y0) (x0+3, y0+2)
    (x0+2, y0+2) (x0+2, y0+1), top-centre (x0+1, y0+1) (x0+2, y0+1) (x0+2, y0+2) (x0+1, y0+2) and
    top-left (x0, y0) (x0+1, y0+1) (x0+1, y0+2) (x0, y0+2), in units of h.
    """
    assert [(row.width, row.height, row.kind == FINE_ABOVE) for row in fine_layer_half(54, 13)][2] == (3, 2, False)
    mesh = build_stack_mesh(MeshParams(N=54, plates=2, h=1.0))
    # bottom plate: ceil((13 - 7) / 3) = 2 coarse rows (y 0...6), (3,3) row (6...9), refinement (9...11), 2 fine rows
    assert mesh.layer_y[0].tolist() == [0.0, 13.0]
    corners = mesh.coor[mesh.conn]
    in_row = np.flatnonzero((corners[:, :, 1].min(axis=1) >= 9) & (corners[:, :, 1].max(axis=1) <= 11))
    assert len(in_row) == 4 * 18
    block = [[(x + x0, y + 9) for x, y in quad] for x0 in (0, 3, 51) for quad in (
        [(0, 0), (3, 0), (2, 1), (1, 1)], [(3, 0), (3, 2), (2, 2), (2, 1)],
        [(1, 1), (2, 1), (2, 2), (1, 2)], [(0, 0), (1, 1), (1, 2), (0, 2)])]
    got = {tuple(map(tuple, corners[e].astype(int))) for e in in_row}
    assert {tuple(quad) for quad in block} <= got
    middle = mesh.coor[mesh.coor[:, 1] == 10]
    assert sorted(middle[:, 0].astype(int).tolist()) == [x for x in range(54) if x % 3]


# --- invariants ----------------------------------------------------------------------------------

@pytest.mark.parametrize("N, plates", [(9, 2), (54, 3), (162, 4), (20, 3), (1458, 6)])
def test_area_orientation_and_layers(N, plates):
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    areas = element_areas(mesh)
    assert areas.min() > 0
    assert np.isclose(areas.sum(), mesh.length * mesh.height, rtol=1e-12)
    # layers tile the height without gaps, every element lies inside its layer
    assert mesh.layer_y[0, 0] == 0
    assert np.array_equal(mesh.layer_y[1:, 0], mesh.layer_y[:-1, 1])
    y = mesh.coor[mesh.conn, 1]
    bounds = mesh.layer_y[mesh.elem_layer]
    assert np.all(y.min(axis=1) >= bounds[:, 0]) and np.all(y.max(axis=1) <= bounds[:, 1])
    for layer in range(mesh.nlayer):
        layer_area = areas[mesh.layer_elements(layer)].sum()
        assert np.isclose(layer_area, mesh.length * np.diff(mesh.layer_y[layer])[0], rtol=1e-12)


@pytest.mark.parametrize("N, plates", [(9, 2), (54, 3), (20, 3), (1458, 4)])
def test_mesh_is_conforming_with_periodic_images(N, plates):
    """Every edge is shared by two elements in opposite directions, except on the bottom and top."""
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    image = mesh.dofs[:, 0] // 2  # one id per periodic node class
    start = image[mesh.conn]
    end = image[np.roll(mesh.conn, -1, axis=1)]
    directed = Counter(zip(start.ravel().tolist(), end.ravel().tolist()))
    assert max(directed.values()) == 1
    unmatched = [edge for edge in directed if (edge[1], edge[0]) not in directed]
    y = {}
    for node, cls in enumerate(image):
        y.setdefault(int(cls), mesh.coor[node, 1])
    on_boundary = [y[a] == y[b] and y[a] in (0.0, mesh.height) for a, b in unmatched]
    assert all(on_boundary)
    bottom_top = np.sum(np.isin(mesh.coor[:, 1], [0.0, mesh.height]) & (mesh.coor[:, 0] < mesh.length))
    assert len(unmatched) == bottom_top  # a closed periodic line of k nodes has k edges
    assert np.array_equal(np.unique(mesh.conn), np.arange(mesh.nnode))


def test_periodic_dofs_and_prescribed(paper_meshes):
    mesh = paper_meshes[3]
    x, y = mesh.coor[:, 0], mesh.coor[:, 1]
    left, right = np.flatnonzero(x == 0.0), np.flatnonzero(np.isclose(x, mesh.length))
    assert np.array_equal(y[left], y[right])
    assert np.array_equal(mesh.dofs[left], mesh.dofs[right])
    assert mesh.ndof == 2 * (mesh.nnode - len(right))
    assert np.array_equal(np.unique(mesh.dofs), np.arange(mesh.ndof))
    bottom = np.flatnonzero(y == 0.0)
    top = np.flatnonzero(y == mesh.height)
    expected = np.unique(np.concatenate([mesh.dofs[bottom].ravel(), mesh.dofs[top, 1]]))
    assert np.array_equal(mesh.iip, expected)
    # outer rows have the coarsest (81 h) elements: 18 independent nodes on each face
    assert len(mesh.iip) == 2 * 18 + 18


def test_interface_blocks(paper_meshes):
    mesh = paper_meshes[4]
    assert mesh.interface_elements.shape == (3, 1458)
    for a in range(1, mesh.plates):
        elements = mesh.interface_elements[a - 1]
        assert np.array_equal(np.sort(elements), mesh.layer_elements(2 * a - 1))
        corners = mesh.coor[mesh.conn[elements]]
        b = np.arange(mesh.N)[:, None]
        expected_x = (b + np.array([0, 1, 1, 0])) * mesh.h
        expected_y = mesh.layer_y[2 * a - 1, 0] + np.array([0, 0, 1, 1]) * mesh.h
        assert np.allclose(corners[..., 0], expected_x, rtol=0, atol=1e-9)
        assert np.allclose(corners[..., 1], np.broadcast_to(expected_y, (mesh.N, 4)), rtol=0, atol=1e-9)
    assert mesh.layer_is_plastic.tolist() == [False, True] * 3 + [False]
    nodes = mesh.layer_nodes(1)
    assert len(nodes) == 2 * (mesh.N + 1)


def test_build_is_fast():
    start = time.perf_counter()
    build_stack_mesh(MeshParams(N=1458, plates=6))
    assert time.perf_counter() - start < 1.0


# --- parameters and files ------------------------------------------------------------------------

@pytest.mark.parametrize("values, field", [({"plates": 7}, "plates"), ({"plates": 1}, "plates"),
                                           ({"N": 1}, "N"), ({"h": 0}, "h"), ({"N": "many"}, "N")])
def test_invalid_params_name_the_field(values, field):
    with pytest.raises(ParameterError, match=f"'{field}'"):
        parse_params(MeshParams, values)


def test_file_roundtrip_is_exact_and_reproducible(tmp_path):
    params = MeshParams(N=54, plates=3)
    write_mesh(params, tmp_path / "a.h5")
    write_mesh(params, tmp_path / "b.h5")
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()
    mesh, built = read_mesh(tmp_path / "a.h5"), build_stack_mesh(params)
    for name in ("coor", "conn", "dofs", "iip", "elem_layer", "layer_y", "interface_elements"):
        assert np.array_equal(getattr(mesh, name), getattr(built, name))
    assert (mesh.N, mesh.plates, mesh.h) == (54, 3, params.h)
    with h5py.File(tmp_path / "a.h5") as file:
        assert file.attrs["mesh_id"] == mesh_id(params)


def test_mesh_id_depends_on_every_parameter():
    ids = {mesh_id(MeshParams()), mesh_id(MeshParams(N=54)), mesh_id(MeshParams(plates=3)),
           mesh_id(MeshParams(h=1.0))}
    assert len(ids) == 4
    assert mesh_id(MeshParams()) == mesh_id(MeshParams(N=1458, plates=2, h=math.pi))


def test_embedded_mesh_and_missing_data(tmp_path):
    mesh = build_stack_mesh(MeshParams(N=9, plates=3))
    with h5py.File(tmp_path / "sim.h5", "w") as file:
        save_mesh(mesh, file.create_group("mesh"))
        assert np.array_equal(load_mesh(file["mesh"]).conn, mesh.conn)
        del file["mesh/dofs"]
        with pytest.raises(FileFormatError, match=r"sim\.h5:/mesh: .*missing dofs"):
            load_mesh(file["mesh"])
    with pytest.raises(FileFormatError, match="no such file"):
        read_mesh(tmp_path / "absent.h5")
