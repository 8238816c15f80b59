"""``stickslip mesh``: writes the mesh of the given parameters, one-line errors for bad input."""

import numpy as np

from stickslip.cli import main
from stickslip.mesh import MeshParams, build_stack_mesh, read_mesh


def test_cli_writes_the_mesh(tmp_path, capsys):
    output = tmp_path / "mesh.h5"
    assert main(["mesh", "--param", "N=54", "--param", "plates=3", "-o", str(output)]) == 0
    mesh = read_mesh(output)
    assert np.array_equal(mesh.coor, build_stack_mesh(MeshParams(N=54, plates=3)).coor)
    assert "972 elements" in capsys.readouterr().out


def test_cli_bad_parameter_is_one_line(tmp_path, capsys):
    assert main(["mesh", "--param", "plates=9", "-o", str(tmp_path / "m.h5")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'plates'" in err
    assert not (tmp_path / "m.h5").exists()
