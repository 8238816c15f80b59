"""Slip detection and force drops on synthetic recordings of the lever apparatus with known slips."""

import numpy as np
import pytest

from stickslip.experiment import detection, kinematics

K, N, h, H, V = 55.0, 49.0, 10.0, 100.0, 0.01
RESOLUTION = 0.005  # camera position resolution [mm]
FORCE_NOISE = 0.01  # force sensor noise [N]


def _record(slips, n, *, duration=400.0, frame_dt=0.2, force_dt=0.02, slip_time=0.05, seed=0):
    """Synthetic recording: rigid slabs, springs to a lever, slips ramped over ``slip_time``.

    ``slips``: list of (t0 [s], a, dR [mm]). Positions are rounded to the camera resolution, the
    force gets Gaussian sensor noise.
    """
    rng = np.random.default_rng(seed)

    def positions(t):
        x = np.zeros((t.size, 5))
        for t0, a, dR in slips:
            x[:, a - 1:] += dR * np.clip((t - t0) / slip_time, 0.0, 1.0)[:, None]
        return x

    t_x = np.arange(0.0, duration, frame_dt) + 0.013
    t_F = np.arange(0.0, duration, force_dt)
    x_F = positions(t_F)
    j = np.arange(1, n + 1)
    f = K * (j * h * V / H * t_F[:, None] - x_F[:, :n]) + 2.0
    F = f @ (j * h / H) + rng.normal(0.0, FORCE_NOISE, t_F.size)
    x = np.round(positions(t_x) / RESOLUTION) * RESOLUTION
    R = np.diff(x, axis=1, prepend=0.0)
    return t_x, R, t_F, F


def _analyse(t_x, R, t_F, F, n):
    slips = detection.detect_slips(t_x, R)
    events = slips.groupby("event").agg(t_start=("t_start", "min"), t_end=("t_end", "max"))
    previous = np.concatenate([[-np.inf], events["t_end"].to_numpy()[:-1]])
    following = np.concatenate([events["t_start"].to_numpy()[1:], [np.inf]])
    dF = detection.force_drop(t_F, F, events["t_start"], events["t_end"], window=1.0,
                              t_previous=previous, t_next=following)
    slips["dF"] = dF[slips["event"].to_numpy()]
    slips["dmu"] = kinematics.dmu_from_dF(slips["dF"], slips["a"], n, "stack", normal_force=N, h=h, H=H)
    return slips


def test_running_average_and_clusters():
    values = np.arange(10.0)[:, None]
    smooth = detection.running_average(values, 5)
    assert np.all(np.isnan(smooth[:2])) and np.all(np.isnan(smooth[-2:]))
    np.testing.assert_allclose(smooth[2:-2, 0], np.arange(2.0, 8.0))
    mask = np.array([0, 1, 1, 1, 0, 1, 1, 0, 1, 1, 1, 1], dtype=bool)
    np.testing.assert_array_equal(detection.clusters(mask, 3), [[1, 3], [8, 11]])


def test_every_slip_found_with_its_interface_and_amplitude():
    n = 4
    truth = [(20.3, 1, 0.060), (55.1, 3, 0.040), (90.7, 2, 0.050), (130.0, 4, 0.100),
             (170.45, 1, 0.030), (211.9, 2, 0.025), (260.2, 3, 0.070), (300.0, 1, 0.120)]
    t_x, R, t_F, F = _record(truth, n)
    slips = _analyse(t_x, R, t_F, F, n)
    assert len(slips) == len(truth)
    assert not slips["multi"].any()
    for (t0, a, dR), (_, row) in zip(truth, slips.iterrows()):
        assert row["a"] == a
        assert row["t_start"] <= t0 and t0 + 0.05 <= row["t_end"]
        assert abs(row["t"] - t0) < 0.2
        # dR: two rounded positions per R, so at most two resolution steps off.
        assert abs(row["dR"] - dR) <= 2 * RESOLUTION + 1e-12
        dmu_true = kinematics.dmu_from_dR(dR, a, n, "stack", k_spring=K, normal_force=N)
        dF_true = K * dR * h / H * (n + a) * (n - a + 1) / 2
        # Force drop from two lines fitted on 1 s at 50 Hz: error ~ 0.005 N; 5 sigma.
        assert abs(row["dF"] - dF_true) < 0.025
        assert row["dmu"] == pytest.approx(dmu_true, abs=0.025 * 2 * H / (h * (n + a) * N))


def test_no_false_slip_on_a_noise_only_stick():
    t_x, R, t_F, F = _record([], 5, duration=2000.0)
    assert len(detection.detect_slips(t_x, R)) == 0
    # Gaussian position noise at the resolution (smoothed velocity noise ~ 0.007 mm/s) neither.
    rng = np.random.default_rng(3)
    assert len(detection.detect_slips(t_x, R + rng.normal(0.0, RESOLUTION, R.shape))) == 0


def test_simultaneous_slips_are_flagged_not_assigned():
    n = 3
    truth = [(50.0, 1, 0.05), (50.1, 3, 0.06), (120.0, 2, 0.05)]
    slips = _analyse(*_record(truth, n), n)
    assert slips["a"].tolist() == [1, 3, 2]
    assert slips["multi"].tolist() == [True, True, False]
    assert slips["event"].tolist() == [0, 0, 1]


def test_small_slip_below_the_threshold_is_not_a_slip():
    # 0.015 mm in one frame: smoothed velocity 0.015 mm/s < 0.02 mm/s.
    slips = detection.detect_slips(*_record([(50.0, 1, 0.015)], 1)[:2])
    assert len(slips) == 0


def test_force_drop_follows_the_loading_ramp_and_a_change_of_rate():
    rate, drop = 0.3, 0.4  # loading rate [N/s] (n = 5) and drop [N], the drop lasting 0.1 s
    t_F = np.arange(0.0, 20.0, 0.02)
    ramp = np.clip((t_F - 10.0) / 0.1, 0.0, 1.0)
    F = rate * t_F - drop * ramp
    bracket = dict(t_start=[9.0], t_end=[10.8])  # a camera bracket: +-2 frames around the slip
    assert detection.force_drop(t_F, F, **bracket, window=1.0)[0] == pytest.approx(drop, abs=1e-9)
    # Creep starts 0.5 s before the slip (the force rises 0.12 N/s slower), the slip stops it: the line
    # before the drop follows the creep, so the jump is found up to the change of slope over half the
    # drop; lines fitted on the windows outside the camera bracket would be off by ~0.1 N.
    creeping = F - 0.12 * np.clip(t_F - 9.5, 0.0, 0.5)
    assert detection.force_drop(t_F, creeping, **bracket, window=0.4)[0] == pytest.approx(drop, abs=0.12 * 0.05)
    # Sensor noise: no bias, a scatter below the noise of one sample (0.5 sigma from the two fits,
    # plus the jitter of the located drop).
    rng = np.random.default_rng(1)
    noisy = [detection.force_drop(t_F, F + rng.normal(0.0, 0.01, t_F.size), **bracket, window=1.0)[0]
             for _ in range(200)]
    assert np.mean(noisy) == pytest.approx(drop, abs=0.002)
    assert np.std(noisy) < 0.008
    # A window with fewer than three samples gives NaN.
    assert np.isnan(detection.force_drop(t_F, F, **bracket, window=1.0, t_previous=[9.97])[0])
