"""Figure plugin 'figS-mesh': picks the requested mesh among its inputs, writes PDF and PNG."""

import pytest

from stickslip import registry
from stickslip.h5io import FileFormatError
from stickslip.mesh import MeshParams, write_mesh
from stickslip.params import parse_params


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


def test_plugin_writes_pdf_and_png(meshes, tmp_path):
    plugin = registry.get("figure", "figS-mesh")
    assert plugin.inputs == ("format:mesh",)
    params = parse_params(plugin.params, {"plates": 3, "zoom_width": 20})
    output = tmp_path / "figS-mesh.pdf"
    plugin.run(params, {"format:mesh": list(meshes.values())}, output)
    assert output.stat().st_size > 0 and output.with_suffix(".png").stat().st_size > 0
