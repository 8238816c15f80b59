"""Lever kinematics: the closed forms against an explicit force and moment balance."""

import numpy as np
import pytest

from stickslip.experiment import kinematics

K, N, h, H, V = 55.0, 49.0, 10.0, 100.0, 0.01


def _balance(forces, driven):
    """mu_i for i = 1..5 and the lever force F from the spring forces of the driven slabs."""
    mu = np.array([sum(forces[j] for j in driven if j >= i) / N for i in range(1, 6)])
    F = sum(forces[j] * j * h / H for j in driven)
    return mu, F


def _slip(forces, driven, a, dR):
    """Spring forces after interface a slips by dR: every driven slab j >= a moves by dR."""
    return {j: forces[j] - (K * dR if j >= a else 0.0) for j in driven}


CASES = [("stack", n, a) for n in range(1, 6) for a in range(1, n + 1)] + [("individual", 1, a) for a in range(1, 6)]


@pytest.mark.parametrize("protocol, n, a", CASES)
def test_closed_forms_follow_from_force_and_moment_balance(protocol, n, a):
    driven = list(range(1, n + 1)) if protocol == "stack" else [a]
    rng = np.random.default_rng(n * 10 + a)
    forces = {j: rng.uniform(1.0, 5.0) for j in driven}
    dR = 0.037
    mu0, F0 = _balance(forces, driven)
    mu1, F1 = _balance(_slip(forces, driven, a, dR), driven)
    dF, dmu = F0 - F1, mu0[a - 1] - mu1[a - 1]
    assert kinematics.dmu_from_dF(dF, a, n, protocol, normal_force=N, h=h, H=H) == pytest.approx(dmu, rel=1e-12)
    assert kinematics.dR_from_dF(dF, a, n, protocol, k_spring=K, h=h, H=H) == pytest.approx(dR, rel=1e-12)
    assert kinematics.dmu_from_dR(dR, a, n, protocol, k_spring=K, normal_force=N) == pytest.approx(dmu, rel=1e-12)
    # Loading: after dt of drive every driven spring gains K j h (V/H) dt.
    dt = 3.0
    loaded = {j: forces[j] + K * j * h * V / H * dt for j in driven}
    rate = (_balance(loaded, driven)[0][a - 1] - mu0[a - 1]) / dt
    assert kinematics.mu_loading_rate(a, n, protocol, k_spring=K, h=h, H=H, V=V, normal_force=N) == pytest.approx(rate)


@pytest.mark.parametrize("n, a", [(n, a) for n in range(1, 6) for a in range(1, n + 1)])
def test_stack_matches_corrected_paper_formulas(n, a):
    dF = 0.8
    # eq. (DR_DF_multi): dF = K dR (h/H) (n+a)(n-a+1)/2; eq. (mu_a) without the spurious U.
    assert kinematics.dR_from_dF(dF, a, n, "stack", k_spring=K, h=h, H=H) == pytest.approx(
        dF / (K * h / H * (n + a) * (n - a + 1) / 2))
    assert kinematics.dmu_from_dF(dF, a, n, "stack", normal_force=N, h=h, H=H) == pytest.approx(
        H / h * 2 / (n + a) * dF / N)
    # Loading rate in the text: K gamma_dot h (n+a)(n-a+1) / (2N).
    assert kinematics.mu_loading_rate(a, n, "stack", k_spring=K, h=h, H=H, V=V, normal_force=N) == pytest.approx(
        K * V / H * h * (n + a) * (n - a + 1) / (2 * N))


@pytest.mark.parametrize("a", range(1, 6))
def test_individual_matches_appendix(a):
    dF = 0.5
    # eq. (SI:DR_DF_single) and (SI:Dmu_DF_single); disorder law with gamma_dot_a = gamma_dot / a.
    assert kinematics.dR_from_dF(dF, a, 1, "individual", k_spring=K, h=h, H=H) == pytest.approx(dF * H / (K * a * h))
    assert kinematics.dmu_from_dF(dF, a, 1, "individual", normal_force=N, h=h, H=H) == pytest.approx(dF * H / (N * a * h))
    T = 37.0
    rate = kinematics.mu_loading_rate(a, 1, "individual", k_spring=K, h=h, H=H, V=V / a, normal_force=N)
    assert rate * T == pytest.approx(K * T * h * (V / H) / N)


def test_vectorised_and_bad_input():
    a = np.array([1, 2, 3])
    count, moment = kinematics.driven_sums(a, 3, "stack")
    np.testing.assert_array_equal(count, [3, 2, 1])
    np.testing.assert_array_equal(moment, [6, 5, 3])
    with pytest.raises(ValueError, match="protocol"):
        kinematics.driven_sums(1, 3, "lever")
    with pytest.raises(ValueError, match="a must be >= 1"):
        kinematics.driven_sums(0, 3, "stack")
