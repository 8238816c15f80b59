"""Figure plugin 'figS-mesh': picks the requested mesh among its inputs and draws every element of it."""

import numpy as np
import pytest

from stickslip import registry
from stickslip.h5io import FileFormatError
from stickslip.mesh import MeshParams, read_mesh, write_mesh
from stickslip.plugin_params import parse_params


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    folder = tmp_path_factory.mktemp("meshes")
    paths = {}
    for N, plates in [(54, 3), (81, 3), (18, 5)]:
        paths[(N, plates)] = folder / f"N{N}_p{plates}.h5"
        write_mesh(MeshParams(N=N, plates=plates), paths[(N, plates)])
    return paths


def test_selects_the_mesh_by_plates_and_N(meshes):
    from stickslip.figures.mesh import MeshFigureParams, select_mesh

    everything = list(meshes.values())
    assert select_mesh(everything, MeshFigureParams(plates=3)) == meshes[(81, 3)]  # largest N
    assert select_mesh(everything, MeshFigureParams(plates=3, N=54)) == meshes[(54, 3)]
    with pytest.raises(FileFormatError, match=r"no mesh with plates=4 .*available: plates=3 N=54"):
        select_mesh(everything, MeshFigureParams(plates=4))


def test_plugin_draws_every_element_of_the_chosen_mesh(meshes, tmp_path, drawn_figures):
    plugin = registry.get("figure", "figS-mesh")
    assert plugin.inputs == ("format:mesh",)
    params = parse_params(plugin.params, {"plates": 3, "zoom_width": 20})
    output = tmp_path / "figS-mesh.pdf"
    plugin.run(params, {"format:mesh": list(meshes.values())}, output)
    assert output.is_file() and output.with_suffix(".png").is_file()
    mesh = read_mesh(meshes[(81, 3)])  # plates = 3: the largest N
    full, zoom = drawn_figures[0].axes
    elements = full.collections[0]
    assert len(elements.get_paths()) == mesh.nelem
    np.testing.assert_allclose(elements.get_paths()[0].vertices[:4], mesh.coor[mesh.conn[0]])
    assert zoom.get_xlim() == pytest.approx((0.0, 20 * mesh.h))
