"""The rate-and-state virtual experiment against rate-and-state analytics, the lever's statics, and
the experimental analysis (which must recover its ground truth)."""

import hashlib
import json
import re

import h5py

import numpy as np
import pytest

from stickslip import progress, registry
from stickslip.experiment.analysis import analyse_record
from stickslip.experiment.timeseries import read_timeseries, read_truth
from stickslip.experiment.virtual import Apparatus
from stickslip.experiment.virtual.rate_state import RateStateLaw
from stickslip.experiment.virtual import rosenbrock, slab_dynamics
from stickslip.experiment.virtual.slab_dynamics import SlabDynamics, Trajectory
from stickslip.experiment.virtual.slab_equations import rhs
from stickslip.experiment.virtual.slab_linear_system import factorize, new_factors, solve
from stickslip.params import parse_params
from stickslip.experiment.virtual import rate_state_model

N, H, h = 49.0, 100.0, 10.0
LAW = RateStateLaw(a=np.full(5, 0.013), b=np.full(5, 0.019), D_c=np.full(5, 5e-4), mu0=np.full(5, 0.35), V0=1e-3)
K_C = float(LAW.critical_stiffness(N)[0])  # 588 N/mm


def _one_slab(k_spring, V=0.01):
    """Slab 1 driven alone (the spring moves at h V / H), everything above riding on it."""
    apparatus = Apparatus.from_protocol("individual", n=1, a=1, n_slabs=5, k_spring=k_spring, normal_force=N, h=h,
                                        H=H, V=V, gamma_start=0.0)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0)
    spring_speed = h * apparatus.shear_rate
    _, y0 = dynamics.initial_state(spring_speed, LAW.D_c[0] / spring_speed, 0.0)
    return apparatus, dynamics, y0, spring_speed


def _friction(dynamics, y):
    return dynamics.friction(y[..., 1], y[..., 2])


@pytest.mark.parametrize("V", [0.01, 0.1, 1.0])
def test_steady_sliding_follows_the_rate_weakening_law(V):
    """Stiff drive (K = 100 K_c, stable): after a transient the slab slides at the spring's speed and
    the spring holds mu_ss(V) = mu0 + (a - b) ln(V/V0), read from the lever statics."""
    apparatus, dynamics, y0, spring_speed = _one_slab(100 * K_C, V)
    y0[1] *= 3.0  # start off the steady state
    t, y, _, _ = dynamics.integrate(y0, 40 * LAW.D_c[0] / spring_speed, apparatus.shear_rate)
    R = np.zeros(5)
    R[0] = y[-1, 0]
    mu_springs = apparatus.mu(t[-1], R)[0]
    expected = 0.35 + (0.013 - 0.019) * np.log(spring_speed / 1e-3)
    assert y[-1, 1] == pytest.approx(spring_speed, rel=1e-3)
    assert mu_springs == pytest.approx(expected, abs=1e-5)
    assert _friction(dynamics, y[-1]) == pytest.approx(expected, abs=1e-5)


def test_slide_hold_slide_static_friction_grows_as_b_ln_T():
    """Slide at 10 um/s, hold (drive stopped) for T, slide again: the peak friction grows by b ln(T2/T1)
    per decade of hold, within 10 % (stiff drive, K = 100 K_c)."""
    apparatus, dynamics, y0, spring_speed = _one_slab(100 * K_C, V=0.1)
    _, y, _, _ = dynamics.integrate(y0, 20.0, apparatus.shear_rate)
    slid = y[-1]
    peaks = []
    holds = np.array([10.0, 100.0, 1000.0])
    for hold in holds:
        _, held, _, _ = dynamics.integrate(slid, hold, 0.0)
        _, again, _, _ = dynamics.integrate(held[-1], 20.0, apparatus.shear_rate)
        peaks.append(_friction(dynamics, again).max())
    growth = np.diff(peaks) / np.diff(np.log(holds))
    np.testing.assert_allclose(growth, 0.019, rtol=0.1)


def _late_velocity_range(k_spring):
    apparatus, dynamics, y0, spring_speed = _one_slab(k_spring, V=0.1)
    y0[1] *= 0.5  # perturb the steady state
    t, y, _, _ = dynamics.integrate(y0, 200.0, apparatus.shear_rate)
    late = y[t > 100.0]
    mu = _friction(dynamics, late)
    return late[:, 1].min() / spring_speed, late[:, 1].max() / spring_speed, mu.max() - mu.min()


def test_stick_slip_below_the_critical_stiffness_steady_sliding_above():
    """Linear stability: K > K_c = N (b - a) / D_c slides steadily (the perturbation decays), K < K_c
    stick-slips with an amplitude that grows as K moves away from K_c."""
    low, high, amplitude = _late_velocity_range(2.0 * K_C)
    assert 0.99 < low and high < 1.01 and amplitude < 1e-4
    low, high, amplitude_half = _late_velocity_range(0.5 * K_C)
    assert low < 1e-2 and high > 10.0 and amplitude_half > 0.01
    _, _, amplitude_quarter = _late_velocity_range(0.25 * K_C)
    assert amplitude_quarter > 1.15 * amplitude_half  # measured: 0.169 against 0.134


def test_lever_moment_balance_with_inertia():
    """Stack n = 3, at every step (sticks and slips): the moment of the springs on the lever equals
    that of the interfaces' friction plus the slabs' inertia, F H = h (N sum_i mu_i + sum_k k M_k du_k/dt)
    (slab k is body k; the slabs above n ride on body n), to 1e-6 of F H."""
    apparatus = Apparatus.from_protocol("stack", n=3, a=0, n_slabs=5, k_spring=55.0, normal_force=N, h=h, H=H,
                                        V=0.01, gamma_start=-0.3)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0)
    R0, y0 = dynamics.initial_state(1e-6, 0.01, -0.3)
    t, y, dydt, _ = dynamics.integrate(y0, 600.0, apparatus.shear_rate)
    R = np.tile(R0, (t.size, 1))
    R[:, :3] = y[:, :3]
    F = apparatus.lever_force(apparatus.spring_forces(t, apparatus.positions(R)))
    mu = dynamics.friction(y[:, 3:6], y[:, 6:9])
    body_acceleration = np.cumsum(dydt[:, 3:6], axis=1) / 1000.0  # [m/s^2]
    inertia = body_acceleration @ (np.arange(1, 4) * dynamics.masses)
    assert np.abs(y[:, 3:6]).max() > 1.0  # slips happened
    np.testing.assert_allclose(F * H, h * (N * mu.sum(axis=1) + inertia), rtol=1e-6, atol=1e-6 * (F * H).max())


def _stack_n3(duration):
    apparatus = Apparatus.from_protocol("stack", n=3, a=0, n_slabs=5, k_spring=55.0, normal_force=N, h=h, H=H,
                                        V=0.01, gamma_start=-0.3)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0)
    _, y0 = dynamics.initial_state(1e-6, 0.01, -0.3)
    return dynamics.integrate(y0, duration, apparatus.shear_rate)


def test_integration_in_pieces_takes_the_same_steps_as_in_one(monkeypatch):
    """The pieces between two progress reports change nothing: 1, 7 and the default number of pieces
    give the same step times, states and derivatives, bit for bit (stack n = 3 over 400 s, slips
    included)."""
    results = []
    for pieces in (1, 7, slab_dynamics.PROGRESS_PIECES):
        monkeypatch.setattr(slab_dynamics, "PROGRESS_PIECES", pieces)
        results.append(_stack_n3(400.0))
    assert np.abs(results[0][1][:, 3:6]).max() > 1.0  # slips happened
    for t, y, dydt, _ in results[1:]:
        assert np.array_equal(t, results[0][0]) and np.array_equal(y, results[0][1])
        assert np.array_equal(dydt, results[0][2])
    assert np.all(np.diff(results[0][0]) > 0) and results[0][0][-1] == 400.0


def test_integration_reports_simulated_time_rate_time_left_and_steps(monkeypatch, capsys):
    """A job's log gets lines 'virtual experiment: <s done>/<s total> s simulated (<%>) [... elapsed,
    ... left, <rate> s simulated/s, <steps> steps]', the last one at the full duration with the
    number of accepted steps."""
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "1e-9")
    t, _, _, _ = _stack_n3(120.0)
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("virtual experiment:")]
    done = [int(re.match(r"virtual experiment: (\d+)/120 s simulated", line)[1]) for line in lines]
    assert len(lines) > 10 and done == sorted(done) and done[0] == 0 and done[-1] == 120
    assert re.match(rf"virtual experiment: 120/120 s simulated \(100%\) \[[0-9:]+ elapsed, [0-9:]+ left, "
                    rf"+[0-9.]+ s simulated/s, {t.size - 1} steps\]$", lines[-1])


def test_the_structured_solve_equals_a_dense_solve_of_the_whole_system():
    """(I - c J) u = r solved through the m x m Schur complement (slab_linear_system) equals LAPACK's
    dense solve of the (3 m + 1)-dimensional system, at states of sticks and slips (stack n = 3) and
    step sizes from 1e-9 s to 1 s, to 1e-9 of the solution."""
    apparatus = Apparatus.from_protocol("stack", n=3, a=0, n_slabs=5, k_spring=55.0, normal_force=N, h=h, H=H,
                                        V=0.01, gamma_start=-0.3)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0)
    t, y, _, _ = _stack_n3(300.0)
    args = (apparatus.shear_rate, *dynamics._arrays())
    rng = np.random.default_rng(0)
    states = y[np.linspace(0, t.size - 1, 40).astype(int)]
    states = np.vstack([states, y[np.abs(y[:, 3:6]).max(axis=1).argmax()]])  # the fastest slip
    assert np.abs(states[:, 3:6]).max() > 1.0 and np.abs(states[:, 3:6]).min() < 1e-4
    factors = new_factors(3)
    for state in states:
        for c in (1e-9, 1e-6, 1e-3, 1.0):
            r = rng.standard_normal(state.size)
            u = np.empty(state.size)
            factorize(state, c, factors, *args)
            solve(r, u, c, factors, *args)
            dense = np.linalg.solve(np.eye(state.size) - c * dynamics.jacobian(state, apparatus.shear_rate), r)
            np.testing.assert_allclose(u, dense, rtol=0, atol=1e-9 * np.abs(dense).max())


def test_rodas4_has_order_four_and_an_order_three_error_estimate():
    """One step of size h = 0.03 s and h/3 on a slab in stick-slip (K = K_c/2, mid-oscillation): the
    local error against a Radau reference falls as h^5 and the embedded error estimate as h^4
    (measured exponents 5.3 and 4.2, asserted within 0.4); a wrong tableau coefficient breaks the order."""
    apparatus, dynamics, y0, spring_speed = _one_slab(0.5 * K_C, V=0.1)
    y0[1] *= 0.5
    _, y, _, _ = dynamics.integrate(y0, 1.0, apparatus.shear_rate, rtol=1e-10)
    start = y[-1]
    args = (apparatus.shear_rate, *dynamics._arrays())
    tableau = rosenbrock.TABLEAUX["RODAS4"]
    errors, estimates = [], []
    for step in (0.03, 0.01):
        _, exact, _, _ = dynamics.integrate(start, step, apparatus.shear_rate, method="Radau", rtol=1e-13)
        y_new, error = np.empty(start.size), np.empty(start.size)
        rosenbrock.step(start, rhs(start, *args), step, *tableau.arrays()[:5], np.empty((tableau.weights.size, 4)),
                        y_new, error, np.empty((2, 4)), new_factors(1), args)
        errors.append(abs(y_new[1] - exact[-1, 1]))
        estimates.append(abs(error[1]))
    assert np.log(errors[0] / errors[1]) / np.log(3) == pytest.approx(5, abs=0.4)
    assert np.log(estimates[0] / estimates[1]) / np.log(3) == pytest.approx(4, abs=0.4)


def test_the_default_tolerance_resolves_the_slips_to_the_sensor_resolution():
    """Individual protocol (periodic): the default integration (RODAS4, rtol 1e-4) and a reference at
    rtol 1e-8 have the same slips, onsets within one force sample (0.02 s) and dmu, dR within 1e-4
    (force noise: 0.002 in mu; camera noise: 0.002 mm)."""
    plugin = registry.get("solver", "rate-state-lever")
    values = {"protocol": "individual", "n": 1, "a": 1, "duration": 1500.0}
    default, reference = (rate_state_model.simulate(parse_params(plugin.params, dict(values, rtol=rtol)))[1]
                          for rtol in (1e-4, 1e-8))
    assert len(default) == len(reference) >= 5
    for column, tolerance in (("t_start", 0.02), ("dmu", 1e-4), ("dR", 1e-4)):
        np.testing.assert_allclose(default[column], reference[column], rtol=0, atol=tolerance)


def _simulate(tmp_path, name, **values):
    plugin = registry.get("solver", "rate-state-lever")
    path = tmp_path / f"{name}.h5"
    plugin.run(parse_params(plugin.params, values), path, threads=1, inputs={})
    return path


def test_same_parameters_same_bytes_and_seeds_differ(tmp_path):
    paths = [_simulate(tmp_path, name, protocol="individual", n=1, a=2, duration=500.0, seed=seed)
             for name, seed in (("a", 1), ("b", 1), ("c", 2))]
    digests = [hashlib.sha256(p.read_bytes()).hexdigest() for p in paths]
    assert digests[0] == digests[1] != digests[2]
    truth = read_truth(paths[0])
    assert len(truth) >= 2 and (truth["a"] == 2).all()


def test_the_fallback_deep_in_a_stick_keeps_the_slips_of_a_tight_reference(tmp_path):
    """Stack n = 5, seed 5 (the default study's run, cut at 700 s): at t = 670.23 s, deep in a stick
    (slip rates 5e-15 to 2e-13 mm/s), RODAS4's step size underflows and ROS2 integrates 10 s, the run's
    only fallback; the run file records it. Against a reference from the state where it starts (BDF
    at rtol 1e-8; Radau and LSODA at 1e-8 agree with it to 1e-11 mm and 1e-6 in mu over the span):

    - the stick holds through the span: every slip rate stays in (0, 1e-6 mm/s) (no slip, no sign flip),
      and the slips R end within 1e-6 mm of the reference's (camera noise: 0.002 mm);
    - 10 ms after the span, the interfaces' friction mu(V, psi) balances the springs again (the
      apparatus's statics mu_a) to 1e-5, as in the reference: ROS2's loose slip-rate tolerance leaves the
      slip rates off the force balance during the span (mu off by up to 0.004, measured), and nothing after;
    - the slips after it (a = 1 at 688.5 s and 699.6 s) have the reference's onsets within one force
      sample (0.02 s; measured 5e-4 s) and its dmu, dR within 1e-4 (force noise: 0.002 in mu).

    The run errors if the fallback is gone (step-size underflow)."""
    path = _simulate(tmp_path, "fallback", n=5, seed=5, duration=700.0)
    with h5py.File(path) as f:
        integration = json.loads(f.attrs["integration"])
    assert integration["method"] == "RODAS4" and integration["fallback"] == "ROS2"
    assert len(integration["fallback_spans"]) == 1
    start, end = integration["fallback_spans"][0]
    assert start == pytest.approx(670.23, abs=0.01) and end == start + slab_dynamics.FALLBACK_SPAN

    plugin = registry.get("solver", "rate-state-lever")
    params = parse_params(plugin.params, {"n": 5, "seed": 5, "duration": 700.0})
    dynamics, R0, y0 = rate_state_model.dynamics_of(params)
    apparatus = dynamics.apparatus
    run = dynamics.integrate(y0, 700.0, apparatus.shear_rate)
    assert run.fallback_spans.tolist() == [[start, end]] and run.t.size - 1 == integration["steps"]
    first = np.searchsorted(run.t, start)
    pieces = [Trajectory(run.t[:first + 1], run.y[:first + 1], run.dydt[:first + 1], None)]
    for t0, t1 in ((start, end), (end, 700.0)):
        piece = dynamics.integrate(pieces[-1].y[-1], t1 - t0, apparatus.shear_rate, method="BDF", rtol=1e-8)
        pieces.append(piece._replace(t=t0 + piece.t))
    t, y, dydt = (np.concatenate([pieces[0][k]] + [piece[k][1:] for piece in pieces[1:]]) for k in range(3))
    later = np.concatenate([[True], np.diff(t) > 0])  # BDF's first steps (~1e-14 s) vanish in t0 + t
    reference = Trajectory(t[later], y[later], dydt[later], None)

    for trajectory in (run, reference):
        span = (trajectory.t >= start) & (trajectory.t <= end)
        assert 0.0 < trajectory.y[span, 5:10].min() and trajectory.y[span, 5:10].max() < 1e-6
    np.testing.assert_allclose(run.y[run.t == end, :5], reference.y[reference.t == end, :5], rtol=0, atol=1e-6)

    for trajectory in (run, reference):
        after = (trajectory.t > end + 0.01) & (trajectory.t < 688.0)
        statics = [apparatus.mu(t, np.concatenate([y[:5], R0[5:]]))[:5] for t, y in zip(trajectory.t[after],
                                                                                       trajectory.y[after])]
        friction = dynamics.friction(trajectory.y[after, 5:10], trajectory.y[after, 10:15], trajectory.y[after, :5])
        np.testing.assert_allclose(friction, statics, rtol=0, atol=1e-5)

    slips, expected = (rate_state_model.ground_truth(params, dynamics, R0, trajectory)[0] for trajectory in
                       (run, reference))
    slips, expected = slips[slips["t_start"] > start], expected[expected["t_start"] > start]
    assert len(slips) == len(expected) >= 2 and list(slips["a"]) == list(expected["a"])
    for column, tolerance in (("t_start", 0.02), ("dmu", 1e-4), ("dR", 1e-4)):
        np.testing.assert_allclose(slips[column], expected[column], rtol=0, atol=tolerance)


@pytest.mark.slow
def test_experimental_analysis_recovers_the_ground_truth(tmp_path):
    """Stack n = 3, default sensors: the unchanged analysis finds >= 95 % of the true slips above the
    detection limit (dR > 0.02 mm) after the transient, and the median |dmu error| of the single
    slips is at most 0.005."""
    path = _simulate(tmp_path, "stack", n=3, seed=1, duration=3000.0)
    detected, _ = analyse_record(read_timeseries(path))
    truth = read_truth(path)
    truth = truth[(truth["t_start"] > 300.5) & (truth["dR"] > 0.02)]
    assert len(truth) > 30
    found, errors = 0, []
    for row in truth.itertuples():
        same = detected[(detected["a"] == row.a) & ((detected["t"] - row.t_start).abs() < 1.5)]
        if len(same):
            found += 1
            if not row.multi and not same["multi"].iloc[0]:
                errors.append(abs(same["dmu"].iloc[0] - row.dmu))
    assert found >= 0.95 * len(truth)
    assert np.median(errors) <= 0.005
