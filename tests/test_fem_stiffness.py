"""The rigidity ratio Phi = K / K_s against the paper's statements, and its place in the run file."""

import math

import pytest

from stickslip import registry
from stickslip.fem.stiffness import PHI_STIFF, at_paper_phi, driving_regime, stiffness_ratio
from stickslip.formats.fem_run import describe, read_run_attrs
from stickslip.mesh.rows import plate_target_height
from stickslip.plugin_params import parse_params


def test_phi_of_the_paper_runs_is_the_paper_number():
    # "A = n_x l0, such that K_s = 4G for our geometry; we use K = 1e-3 and 1e-6 and G = 1/2"
    # (the paper's G is mu = G_fe / 2): A / h = N / M at N = 1458 is the paper's 4
    assert 1458 / plate_target_height(1458) == pytest.approx(4.0, rel=2e-3)
    mu = 0.5
    assert stiffness_ratio(1e-3, 1458) == pytest.approx(1e-3 / (4 * mu))
    assert stiffness_ratio(1e-6, 1458) == pytest.approx(1e-6 / (4 * mu))
    # "Phi ~ 1e-3 (stiff) and 1e-6 (compliant)": the same decade (5e-4, 5e-7)
    assert round(math.log10(stiffness_ratio(1e-3, 1458))) == -3
    assert round(math.log10(stiffness_ratio(1e-6, 1458))) == -6
    assert driving_regime(stiffness_ratio(1e-3, 1458)) == "stiff"
    assert driving_regime(stiffness_ratio(1e-6, 1458)) == "compliant"
    assert driving_regime(PHI_STIFF) == "stiff" and driving_regime(0.99 * PHI_STIFF) == "compliant"


def test_phi_grows_as_the_square_of_the_plate_height_and_scales_with_the_modulus():
    # spring k L h_p against plate rigidity mu L / h_p: Phi ~ k h_p^2 / mu
    for N in (9, 54, 162, 486):
        M = plate_target_height(N)
        assert stiffness_ratio(1.0, N) / stiffness_ratio(1.0, 1458) == pytest.approx((M / 364) ** 2)
    assert stiffness_ratio(1e-3, 162, G=2.0) == pytest.approx(stiffness_ratio(1e-3, 162) / 2)
    # equal Phi at another N needs k scaled by (M_paper / M)^2
    assert stiffness_ratio(1e-3 * (364 / 40) ** 2, 162) == pytest.approx(stiffness_ratio(1e-3, 1458))
    assert at_paper_phi(stiffness_ratio(1e-3 * (364 / 40) ** 2, 162))
    assert not at_paper_phi(1e-5) and not at_paper_phi(1e-2)
    # plates M = N // 4 blocks thick: k = 1e-3 at N = 54 (M = 13) drives far more compliantly than at N = 1458
    assert driving_regime(stiffness_ratio(1e-3, 54)) == "compliant"
    assert driving_regime(stiffness_ratio(1e-3 * (364 / 13) ** 2, 54)) == "stiff"


def test_the_run_file_states_phi_and_regime(tmp_path):
    plugin = registry.get("solver", "fem")
    params = parse_params(plugin.params, {"N": 9, "plates": 2, "k_drive": 2.0, "max_increments": 2})
    plugin.run(params, tmp_path / "run.h5", threads=1, inputs={})
    attrs = read_run_attrs(tmp_path / "run.h5")
    assert attrs["phi"] == stiffness_ratio(2.0, 9) == pytest.approx(2.0 / 2 * (3 / 364) ** 2)
    assert attrs["regime"] == "stiff"
    described = describe(tmp_path / "run.h5")  # the database's simulation columns
    assert (described["phi"], described["regime"]) == (attrs["phi"], "stiff")
