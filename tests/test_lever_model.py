"""Physics of the virtual lever experiment: balances, kinematics of slips, aging law, protocols."""

import math

import numpy as np
import pytest

from stickslip.experiment.virtual import first_crossing, integrate, relative_positions
from stickslip.plugin_params import parse_params
from stickslip.experiment.virtual.model import apparatus, friction_law, simulate
from stickslip.solvers.lever import LeverParams

K, N, h, H, V = 55.0, 49.0, 10.0, 100.0, 0.01


def quiet(**changes):
    """Noise-free sensors, no creep, a short run."""
    values = dict(creep_velocity=(0.0,), position_noise=0.0, force_noise=0.0, duration=1500.0, seed=2)
    values.update(changes)
    return parse_params(LeverParams, values)


def frame_before(record, t):
    return int(np.searchsorted(record.t_x, t, side="right")) - 1


def frame_after(record, t):
    return int(np.searchsorted(record.t_x, t, side="left"))


def quiet_between(truth, t0, t1):
    """No slip of any interface overlaps [t0, t1]."""
    return not np.any((truth["t_start"] < t1) & (truth["t_end"] > t0))


@pytest.mark.parametrize("mu, rate, level, slope, T", [
    (0.1, 0.01, 0.3, 0.0, 0.0),
    (0.35, 0.0112, 0.35, 0.045, 0.2),
    (0.35, 0.0168, 0.36, 0.032, 5.0),
    (0.2, 1e-4, 0.2, 0.05, 0.0),
])
def test_first_crossing_is_the_first_root(mu, rate, level, slope, T):
    tau = first_crossing(mu, rate, level, slope, T, 1.0)

    def gap(s):
        return mu + rate * s - level - slope * math.log1p((T + s) / 1.0)

    assert abs(gap(tau)) < 1e-12
    grid = np.linspace(0.0, tau, 10001)[1:-1]
    assert max(gap(s) for s in grid) < 0.0 and gap(0.0) <= 0.0
    if slope == 0.0:
        assert tau == pytest.approx((level - mu) / rate, rel=1e-14)


def test_first_crossing_limits():
    assert first_crossing(0.5, 0.01, 0.4, 0.05, 3.0, 1.0) == 0.0
    assert first_crossing(0.3, 0.0, 0.4, 0.05, 3.0, 1.0) == math.inf
    assert first_crossing(0.3, -0.01, 0.4, 0.0, 3.0, 1.0) == math.inf


@pytest.fixture(scope="module")
def stack4():
    params = quiet(n=4)
    return params, *simulate(params)


def test_moment_balance_at_every_frame(stack4):
    params, record, truth, _ = stack4
    gamma = params.gamma_start + V / H * record.t_x
    heights = np.arange(1, 5) * h
    f = K * (heights * gamma[:, None] - record.x[:, :4])
    F_from_x = f @ heights / H
    on_frames = np.searchsorted(record.t_F, record.t_x)
    np.testing.assert_array_equal(record.t_F[on_frames], record.t_x)
    np.testing.assert_allclose(record.F[on_frames], F_from_x, rtol=1e-12, atol=1e-12)
    assert len(truth) > 30


def test_force_balance_gives_the_slip_onset_friction(stack4):
    """mu_a at slip onset, recomputed from the stuck positions, is the engine's mu_before."""
    params, record, truth, _ = stack4
    checked = 0
    for row in truth.itertuples():
        k = frame_before(record, row.t_start)
        if not quiet_between(truth, record.t_x[k], row.t_start):
            continue
        gamma = params.gamma_start + V / H * row.t_start
        f = K * (np.arange(1, 5) * h * gamma - record.x[k, :4])
        assert f[row.a - 1:].sum() / N == pytest.approx(row.mu_before, abs=1e-12)
        checked += 1
    assert checked > 0.9 * len(truth)


def test_slip_moves_the_slabs_above_rigidly_and_drops_mu(stack4):
    params, record, truth, _ = stack4
    rates = apparatus(params).loading_rates()
    checked = 0
    for row in truth.itertuples():
        before, after = frame_before(record, row.t_start), frame_after(record, row.t_end)
        if row.multi or not (quiet_between(truth.drop(row.Index), record.t_x[before], record.t_x[after])):
            continue
        dx = record.x[after] - record.x[before]
        expected = np.where(np.arange(1, 6) >= row.a, row.dR, 0.0)
        np.testing.assert_allclose(dx, expected, atol=1e-12)
        c = 4 - row.a + 1
        assert row.dmu == pytest.approx(K * c * row.dR / N, rel=1e-12)
        assert row.dF == pytest.approx(K * row.dR * h / H * sum(range(row.a, 5)), rel=1e-12)
        assert row.mu_after == pytest.approx(params.mu_d[0], abs=1e-12)
        # the same drop seen by the force balance on the positions, plus the drive in between
        gamma = params.gamma_start + V / H * record.t_x[[before, after]]
        f = K * (np.arange(1, 5) * h * gamma[:, None] - record.x[[before, after], :4])
        drop = (f[0, row.a - 1:].sum() - f[1, row.a - 1:].sum()) / N
        elapsed = record.t_x[after] - record.t_x[before]
        assert drop == pytest.approx(row.dmu - rates[row.a - 1] * elapsed, abs=1e-12)
        checked += 1
    assert checked > 0.9 * len(truth)


def test_no_motion_during_stick_without_creep(stack4):
    _, record, truth, _ = stack4
    R = record.R
    moving = np.zeros(record.t_x.size - 1, bool)
    for row in truth.itertuples():
        moving |= (record.t_x[1:] > row.t_start) & (record.t_x[:-1] < row.t_end)
    assert moving.sum() < 0.1 * moving.size
    np.testing.assert_array_equal(np.diff(R, axis=0)[~moving], 0.0)
    assert np.all(R[:, 4] == R[0, 4])  # the undriven top slab rides on slab 4


def test_aging_law_is_the_threshold_without_disorder():
    params = quiet(n=3, threshold_noise=0.0, B=(0.045, 0.03, 0.06, 0.04, 0.05))
    _, truth, _ = simulate(params)
    B = np.array(params.B)[truth["a"] - 1]
    expected = params.mu_d[0] + params.strength_offset + B * np.log1p(truth["age"] / params.T0)
    np.testing.assert_allclose(truth["mu_before"], expected, rtol=0, atol=1e-12)
    assert params.strength_offset > 0 and np.all(truth["excess"] == params.strength_offset)
    for a, rows in truth.groupby("a"):
        np.testing.assert_allclose(rows["T"].to_numpy()[1:], np.diff(rows["t_start"]), rtol=1e-12)
        assert math.isnan(rows["T"].iloc[0])
        np.testing.assert_allclose(rows["dmu"], params.strength_offset + B[rows.index] * np.log1p(rows["age"]),
                                   atol=1e-12)


@pytest.mark.parametrize("a", [1, 3])
def test_individual_protocol(a):
    params = quiet(protocol="individual", driven_slab=a, n=1)
    record, truth, _ = simulate(params)
    assert record.V == pytest.approx(V / a) and record.protocol == "individual" and record.a == a
    assert set(truth["a"]) == {a}
    R = record.R
    np.testing.assert_array_equal(record.x[:, :a - 1], 0.0)        # clamped slabs
    for i in range(a, 5):                                          # slabs above ride on slab a
        np.testing.assert_array_equal(R[:, i], R[0, i])
    np.testing.assert_allclose(truth["dF"], K * truth["dR"] * a * h / H, rtol=1e-12)
    np.testing.assert_allclose(truth["dmu"], K * truth["dR"] / N, rtol=1e-12)
    # the paper's disorder law: mu_a grows at K h gamma_dot / N whatever a, from mu_d to the threshold
    later = truth.iloc[1:]
    np.testing.assert_allclose(later["dmu"], K * later["T"] * h * (V / H) / N, rtol=1e-10)


def test_triggered_simultaneous_slips():
    params = quiet(n=3, trigger_margin=0.08)
    record, truth, _ = simulate(params)
    multi = truth[truth["multi"]]
    assert multi["event"].nunique() >= 3
    for _, rows in multi.groupby("event"):
        assert len(rows) >= 2 and rows["triggered"].sum() == len(rows) - 1
        np.testing.assert_allclose(rows["mu_after"], params.mu_d[0], atol=1e-12)
        assert np.all(rows["dR"] > 0)
        row = rows.iloc[0]
        before, after = frame_before(record, row.t_start), frame_after(record, row.t_end)
        if not quiet_between(truth[truth["event"] != row.event], record.t_x[before], record.t_x[after]):
            continue
        dx = record.x[after] - record.x[before]
        expected = [rows.loc[rows["a"] <= i, "dR"].sum() for i in range(1, 6)]
        np.testing.assert_allclose(dx, expected, atol=1e-12)
        drive = K * (V / H) * h * h / H * sum(j * j for j in range(1, 4)) * (record.t_x[after] - record.t_x[before])
        on = np.searchsorted(record.t_F, record.t_x[[before, after]])
        assert record.F[on[0]] - record.F[on[1]] == pytest.approx(rows["dF"].sum() - drive, abs=1e-10)


def test_creep_accounts_for_the_rest_of_the_sliding():
    params = quiet(n=5, creep_velocity=(0.002, 0.001, 0.0, 0.0, 0.0), duration=3000.0)
    record, truth, interfaces = simulate(params)
    law = friction_law(params)
    np.testing.assert_allclose(law.creep_velocity, [0.002, 0.001, 0, 0, 0])  # n = n_slabs: full velocity
    np.testing.assert_allclose(interfaces["slip_total"] + interfaces["creep_total"], interfaces["R_total"],
                               atol=1e-9)
    assert interfaces.loc[0, "creep_total"] > 0.1 and np.all(interfaces.loc[2:, "creep_total"] == 0.0)
    np.testing.assert_allclose(record.R[-1] - record.R[0], interfaces["R_total"], atol=1e-9)
    # creep stays far below the detection speed (0.02 mm/s)
    assert law.creep_velocity.max() < 0.02 / 5
    creep_seen = truth.groupby("a")["creep_before"].sum().reindex(range(1, 6), fill_value=0.0)
    assert creep_seen[1] > 0 and np.all(creep_seen[3:] == 0.0)


def test_creep_vanishes_for_a_single_driven_slab():
    assert np.all(friction_law(quiet(n=1, creep_velocity=(0.002,))).creep_velocity == 0.0)
    assert np.all(friction_law(quiet(protocol="individual", driven_slab=2, creep_velocity=(0.002,))).creep_velocity == 0.0)


def test_sampled_positions_follow_the_history():
    """relative_positions at the slip boundaries: nothing before the onset, all of dR after."""
    params = quiet(n=2)
    lever, law = apparatus(params), friction_law(params)
    history = integrate(lever, law, params.duration, params.slip_duration, np.random.default_rng(0))
    row = history.slips.iloc[3]
    times = np.array([row.t_start, row.t_start + params.slip_duration / 2, row.t_end])
    R = relative_positions(history, times)
    assert R[1, row.a - 1] - R[0, row.a - 1] == pytest.approx(row.dR / 2, rel=1e-12)
    assert R[2, row.a - 1] - R[0, row.a - 1] == pytest.approx(row.dR, rel=1e-12)
