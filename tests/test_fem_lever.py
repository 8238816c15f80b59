"""Free-lever drive (moment balance) and compliant driving of the fem solver."""

import numpy as np
import pytest

from stickslip import registry
from stickslip.formats.fem_run import read_increments, read_run_attrs
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.plugin_params import parse_params

pytestmark = pytest.mark.slow


def _run(path, **values):
    plugin = registry.get("solver", "fem")
    params = parse_params(plugin.params, {"N": 9, "nchunk": 30, "max_increments": 30, **values})
    plugin.run(params, path, threads=1, inputs={})
    return read_increments(path), read_run_attrs(path)


def test_free_lever_moment_balance_holds_at_every_increment(tmp_path):
    table, attrs = _run(tmp_path / "free.h5", plates=3, drive="free-lever")
    heights = build_stack_mesh(MeshParams(N=9, plates=3)).layer_mid_height
    driven = [2, 4]
    H = attrs["H"]
    assert H == pytest.approx(10 * (heights[1] - heights[0]))
    x_target = table["lever_target"].to_numpy()
    x_lever = table["lever_position"].to_numpy()
    # massless lever: drive spring at H balances the layer springs at h_l (all of stiffness k)
    moment_drive = H * (x_target - x_lever)
    moment_layers = sum(heights[layer] * table[f"fxdrive_{layer}"].to_numpy() for layer in driven)
    np.testing.assert_allclose(moment_drive, moment_layers, rtol=1e-10, atol=1e-12 * np.abs(moment_drive).max())
    for layer in driven:  # the layer targets sit on the rigid lever
        target = table[f"fxdrive_{layer}"] + table[f"ubar_{layer}"]
        np.testing.assert_allclose(target, heights[layer] / H * x_lever, rtol=1e-12, atol=1e-18)
    assert (x_target[1:] > 0).all() and np.all(np.diff(x_target) >= 0)
    assert table[["A_a1", "A_a2"]].to_numpy().sum() > 0  # blocks yield on both drives' interfaces


@pytest.mark.parametrize("drive", ["fixed-lever", "free-lever"])
def test_compliant_driving_runs(tmp_path, drive):
    # Phi = 3e-11: slips of thousands of wells per block; the paper code's margin stop ends the run
    table, attrs = _run(tmp_path / "compliant.h5", plates=2, k_drive=1e-6, drive=drive, yield_strains="stop")
    assert attrs["completed"]
    assert len(table) > 5
    assert table["A_a1"].sum() > 0
    # compliant spring: the elongation, not the layer's displacement, carries the load
    loaded = table["kick"] & (table.index > 0)
    assert (table.loc[loaded, "fxdrive_2"] > 0).all()
