"""Heterogeneity of the rate-and-state interfaces along their slip path (``path_disorder``): the
profiles' statistics, the analytic Jacobian, steady sliding over a heterogeneous path, and the
individual protocol's spread; with ``path_disorder = 0`` the runs are those from before."""

import hashlib

import h5py
import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from jacobian_check import central_differences
from stickslip import registry
from stickslip.experiment.virtual import Apparatus
from stickslip.experiment.virtual.rate_state import RateStateLaw
from stickslip.experiment.virtual.slab_dynamics import SlabDynamics
from stickslip.experiment.virtual.slip_path import PathProfiles, level, path_stream, random_profiles
from stickslip.plugin_params import parse_params
from stickslip.experiment.virtual import rate_state_model

N, H, h = 49.0, 100.0, 10.0
ELL = 0.025  # [mm]
LAW = RateStateLaw(a=np.full(5, 0.013), b=np.full(5, 0.019), D_c=np.full(5, 5e-4), mu0=np.full(5, 0.35), V0=1e-3)
PLUGIN = registry.get("solver", "rate-state-lever")


def _dataset_digest(path):
    """sha256 of every dataset of a file (names and bytes; the attributes, which list the parameters, left out)."""
    digest = hashlib.sha256()
    with h5py.File(path) as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                digest.update(name.encode())
                digest.update(obj[()].tobytes())
        f.visititems(visit)
    return digest.hexdigest()


def _run(tmp_path, name, **values):
    path = tmp_path / f"{name}.h5"
    PLUGIN.run(parse_params(PLUGIN.params, values), path, threads=1, inputs={})
    return path


def test_without_path_disorder_the_correlation_length_changes_nothing(tmp_path):
    """path_disorder = 0 (the default) leaves mu0 exactly constant: any correlation length writes the
    same signals and ground truth, bit for bit (individual protocol a = 2, 500 s, seed 1)."""
    values = dict(protocol="individual", n=1, driven_slab=2, duration=500.0, seed=1)
    assert (_dataset_digest(_run(tmp_path, "default", **values))
            == _dataset_digest(_run(tmp_path, "zero", path_disorder=0.0, path_correlation_length=0.1, **values)))


def test_the_profiles_have_zero_mean_unit_variance_and_a_gaussian_correlation():
    """Over a period the profiles have mean 0 and variance 1 (exactly), their autocorrelation at lags
    ell/2, ell, 2 ell is exp(-s^2 / (2 ell^2)) = 0.882, 0.607, 0.135 (to 0.03, averaged over 5
    interfaces x 2 seeds), the Hermite interpolant between the nodes equals the Fourier sum's
    spectral interpolation to 1e-5, its slope is the derivative of its value and its curvature that of
    its slope (mid-cell), and the streams
    are deterministic per seed."""
    values, slopes, spacing = random_profiles(path_stream(1), 5, ELL)
    again, _, _ = random_profiles(path_stream(1), 5, ELL)
    other, _, _ = random_profiles(path_stream(2), 5, ELL)
    assert np.array_equal(values, again) and not np.array_equal(values, other)
    np.testing.assert_allclose(values.mean(axis=1), 0.0, atol=1e-12)
    np.testing.assert_allclose(values.var(axis=1), 1.0, rtol=1e-12)
    both = np.vstack([values, other])
    for lag in (0.5 * ELL, ELL, 2 * ELL):
        shift = int(round(lag / spacing))
        correlation = np.mean(both * np.roll(both, -shift, axis=1))
        assert correlation == pytest.approx(np.exp(-0.5 * (shift * spacing / ELL) ** 2), abs=0.03)
    # between the nodes: the band-limited (Fourier) interpolation of row 0 at a half-node shift
    nodes = values.shape[1]
    spectrum = np.fft.rfft(values[0])
    half = np.fft.irfft(spectrum * np.exp(1j * np.pi * np.fft.rfftfreq(nodes, d=1.0 / nodes) / nodes * 2 * 0.5),
                        n=nodes)
    path = PathProfiles(1.0, values, slopes, spacing).arguments(np.arange(5), np.ones(5), np.zeros(5))
    mids = (np.arange(0, nodes, 97) + 0.5) * spacing
    interpolated = np.array([level(0, x, np.zeros(5), path)[0] for x in mids])
    np.testing.assert_allclose(interpolated, half[np.arange(0, nodes, 97)], atol=1e-5)
    step = 1e-7
    for x in mids[:50]:
        numeric = (level(0, x + step, np.zeros(5), path)[0] - level(0, x - step, np.zeros(5), path)[0]) / (2 * step)
        assert level(0, x, np.zeros(5), path)[1] == pytest.approx(numeric, rel=1e-5, abs=1e-3)
        slope = (level(0, x + step, np.zeros(5), path)[1] - level(0, x - step, np.zeros(5), path)[1]) / (2 * step)
        assert level(0, x, np.zeros(5), path)[2] == pytest.approx(slope, rel=1e-4, abs=1e-1)


def _stack_n3(path_disorder, duration=300.0, seed=1):
    apparatus = Apparatus.from_protocol("stack", n=3, a=0, n_slabs=5, k_spring=55.0, normal_force=N, h=h, H=H,
                                        V=0.01, gamma_start=-0.3)
    path = PathProfiles.draw(seed, 5, path_disorder, ELL)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0, path=path)
    R0, y0 = dynamics.initial_state(1e-6, 0.01, -0.3)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0, path=path, path_origin=y0[:3])
    return apparatus, dynamics, R0, dynamics.integrate(y0, duration, apparatus.shear_rate)


def test_the_analytic_jacobian_includes_the_slope_and_curvature_along_the_path():
    """Stack n = 3 with path_disorder = 0.05: at states of sticks and slips the analytic Jacobian
    equals central differences of the right-hand side (to 1e-6 of each column's largest entry; the
    slip columns carry the slope and curvature of mu0 along the path, through the slip rates' dependence
    on mu0(R)), and they differ from the Jacobian without the path."""
    apparatus, dynamics, _, (t, y, dydt) = _stack_n3(0.05)
    rate = apparatus.shear_rate
    states = y[np.linspace(0, t.size - 1, 25).astype(int)]
    states = np.vstack([states, y[np.abs(dydt[:, :3]).max(axis=1).argmax()]])  # the fastest slip
    rates = np.abs(dynamics.slip_rates(states[:, 3:6], states[:, 6:9], states[:, :3]))
    assert rates.max() > 1.0 and rates.min() < 1e-4
    without = SlabDynamics(dynamics.apparatus, LAW, 0.143, 5.0)
    for state in states:
        J = dynamics.jacobian(state, rate)
        numeric = central_differences(dynamics, state, rate)
        scale = np.abs(J).max(axis=0)
        assert np.all(np.abs(J - numeric) <= 1e-6 * scale + 1e-12)
        assert np.abs(J[:, :3] - without.jacobian(state, rate)[:, :3]).max() > 0.0


def test_steady_sliding_over_a_heterogeneous_path_averages_to_mu_ss_with_the_imposed_fluctuations():
    """One slab on a stiff spring (K = 100 K_c) sliding steadily at 0.25 mm/s over 40 mm (1600 ell),
    path_disorder = 0.02: at every step the friction is mu_ss(V) + epsilon mu0 g(delta) (to 1 % of
    epsilon mu0: the state relaxes over D_c << ell, the spring holds V); along the path (the steps'
    states interpolated every ell/16) its mean is mu_ss(V) within 3 standard errors of a path average
    (sqrt(sqrt(2 pi) ell / L) epsilon mu0), its relative fluctuation std / mu0 is epsilon within 15 %,
    and its autocorrelation at lags ell/2, ell, 2 ell is 0.882, 0.607, 0.135 within 0.07. (At 2.5
    mm/s the slab's inertia would make steady sliding unstable: K_c (1 + M V^2 / (N a D_c)) > K.)"""
    epsilon, speed, distance = 0.02, 0.25, 40.0
    K_c = float(LAW.critical_stiffness(N)[0])
    apparatus = Apparatus.from_protocol("individual", n=1, a=1, n_slabs=5, k_spring=100 * K_c, normal_force=N, h=h,
                                        H=H, V=speed * H / h, gamma_start=0.0)
    path = PathProfiles.draw(3, 5, epsilon, ELL)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0, path=path)
    _, y0 = dynamics.initial_state(speed, LAW.D_c[0] / speed, 0.0)
    dynamics = SlabDynamics(apparatus, LAW, 0.143, 5.0, path=path, path_origin=y0[:1])
    t, y, dydt = dynamics.integrate(y0, distance / speed, apparatus.shear_rate)
    mu_ss, amplitude = float(LAW.steady_state(speed)[0]), epsilon * 0.35
    delta = y[:, 0] - y0[0]
    profile = np.array([level(0, R, dynamics._mu0, dynamics._path)[0] for R in y[:, 0]]) - 0.35
    late = delta > 0.2                                    # after the start's transient
    assert np.abs(y[:, 1] - mu_ss - profile)[late].max() < 0.01 * amplitude
    state = CubicHermiteSpline(delta, y[:, :3], dydt[:, :3] / dydt[:, :1], axis=0)   # along the path
    grid = np.arange(0.2, delta[-1], ELL / 16)
    fluctuation = state(grid)[:, 1] - mu_ss
    assert abs(fluctuation.mean()) < 3 * np.sqrt(np.sqrt(2 * np.pi) * ELL / (grid[-1] - grid[0])) * amplitude
    assert fluctuation.std() / 0.35 == pytest.approx(epsilon, rel=0.15)
    centred = fluctuation - fluctuation.mean()
    for lag, expected in ((8, 0.882), (16, 0.607), (32, 0.135)):
        correlation = np.mean(centred[:-lag] * centred[lag:]) / centred.var()
        assert correlation == pytest.approx(expected, abs=0.07)


def _individual(epsilon, seed=1, duration=3000.0):
    values = dict(protocol="individual", n=1, driven_slab=1, duration=duration, seed=seed, path_disorder=epsilon)
    _, truth, _, _ = rate_state_model.simulate(parse_params(PLUGIN.params, values))
    return truth[truth["t_start"] > 300.0]


def test_path_disorder_spreads_the_individual_protocols_slips():
    """Individual protocol a = 1, 3000 s: without path disorder the slips are periodic (std of T below
    0.5 s, of dmu below 1e-4); with path_disorder = 0.02 (the recommended value) std(T) > 4 s and
    std(dmu) > 0.006 (measured over 6000 s: 9.6 s and 0.012) while the means stay within 5 % of the
    periodic ones."""
    periodic, spread = _individual(0.0), _individual(0.02)
    assert periodic["T"].std() < 0.5 and periodic["dmu"].std() < 1e-4
    assert spread["T"].std() > 4.0 and spread["dmu"].std() > 0.006
    assert spread["T"].mean() == pytest.approx(periodic["T"].mean(), rel=0.05)
    assert spread["dmu"].mean() == pytest.approx(periodic["dmu"].mean(), rel=0.05)


def test_with_path_disorder_runs_stay_deterministic_and_the_lever_balances(tmp_path):
    """path_disorder = 0.02: the same seed gives the same bytes, another seed (another path) other ones;
    and in the stack n = 3 the moment of the springs on the lever equals that of the friction (taken
    at each interface's place on its path) plus the slabs' inertia at every step, to 1e-6 of F H."""
    paths = [_run(tmp_path, name, protocol="individual", n=1, driven_slab=2, duration=500.0, seed=seed, path_disorder=0.02)
             for name, seed in (("a", 1), ("b", 1), ("c", 2))]
    digests = [hashlib.sha256(p.read_bytes()).hexdigest() for p in paths]
    assert digests[0] == digests[1] != digests[2]
    apparatus, dynamics, R0, (t, y, dydt) = _stack_n3(0.02, duration=600.0)
    R = np.tile(R0, (t.size, 1))
    R[:, :3] = y[:, :3]
    F = apparatus.lever_force(apparatus.spring_forces(t, apparatus.positions(R)))
    mu = y[:, 3:6]
    inertia = np.cumsum(dynamics.accelerations(y), axis=1) / 1000.0 @ (np.arange(1, 4) * dynamics.masses)
    V = dydt[:, :3]
    assert np.abs(V).max() > 1.0
    # the path matters: at the same friction and state, the slip rate at the start of the path differs
    assert (np.abs(V - dynamics.slip_rates(mu, y[:, 6:9])) > 0.1 * np.abs(V)).any()
    np.testing.assert_allclose(F * H, h * (N * mu.sum(axis=1) + inertia), rtol=1e-6, atol=1e-6 * (F * H).max())
