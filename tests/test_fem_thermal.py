"""Finite temperature in the fem model (stickslip.fem.thermal): verification.

(a) One block at a held load: its waiting time is exponential with the Arrhenius mean, and it
    hops forward or backward in proportion to the two rates (Kolmogorov-Smirnov, binomial).
(b) One block under a load rising linearly in time: the first passage follows the analytic
    survival function of the time-dependent rate, and the athermal threshold is reached with
    the survival probability at the threshold.
(c) T -> 0: a thermal run at a temperature far below every barrier the athermal protocol leaves
    is the athermal run, bit for bit (states and every observable but the clock).
(d) Same seed, same bytes; a thermal run killed and resumed gives the bytes of an uninterrupted one.
Plus what the exact sampling rests on: the barrier bounds bound the barrier over a stretch of drive
for both laws, and the hop's kick carries every Gauss point of the block over the edge.
"""

import math
import os
import signal
import subprocess
import sys

import numpy as np
import pytest
from scipy import special, stats

from conftest import kill_when_stored
from stickslip.fem.laws import Cusp, Smooth, backward_barrier, forward_barrier
from stickslip.formats.fem_run import RunFile, read_increments, read_run_attrs
from stickslip.fem.random import pcg32_seed
from stickslip.fem.thermal import (BACKWARD, FORWARD, HOP, NONE, THRESHOLD, barrier_bounds, block_barrier,
                                   hop_step, sample_event)
from stickslip.plugin_params import parse_params
from stickslip.registry import get

H = math.pi  # block size
DV = np.full((1, 4), H * H / 4)  # Gauss-point volumes of one square block
NU = 2.0  # attempt rate


def _block(eq, epsy, well, strain_rate=0.0):
    """One block in pure shear: every Gauss point at eps_xy = eq in ``well``, raised by ``strain_rate`` per unit drive."""
    eps = np.zeros((1, 4, 3))
    eps[..., 2] = eq
    deps = np.zeros((1, 4, 3))
    deps[..., 2] = strain_rate
    return np.asarray([epsy], dtype=np.float64), np.full((1, 4), well, dtype=np.int64), eps, deps


def _draws(law, block, beta, speed, duration, ds_c, count, seed=7):
    epsy, idx, eps, deps = block
    allowed = np.ones((1, 2), dtype=bool)
    out = []
    for k in range(count):
        state, inc = pcg32_seed(np.array([seed], dtype=np.uint64), np.array([k], dtype=np.uint64))
        out.append(sample_event(law, epsy, idx, eps, deps, DV, allowed, beta, NU, 0.0, speed, duration, ds_c,
                                state, inc))
    return out


@pytest.mark.parametrize("law, eq", [(Cusp(4.5, 1.0), 2.75e-4), (Smooth(4.5, 1.0), 2.65e-4)], ids=["cusp", "smooth"])
def test_a_block_at_a_held_load_waits_an_exponential_time_with_the_arrhenius_mean(law, eq):
    epsy = [-1e-4, 1e-4, 2e-4, 3.2e-4]  # eq in the well (2e-4, 3.2e-4], nearer its forward edge
    # the barriers by hand: cusp G x^2 h^2 on both sides; smooth from its formula via the law
    lo, hi = epsy[2], epsy[3]
    forward, backward = (4 * DV[0, 0] * f(law, eq, lo, hi) for f in (forward_barrier, backward_barrier))
    if isinstance(law, Cusp):
        assert forward == pytest.approx(law.G * (hi - eq) ** 2 * H * H, rel=1e-12)
        assert backward == pytest.approx(law.G * (eq - lo) ** 2 * H * H, rel=1e-12)
    T = forward / 3.0  # the forward rate exp(-3) nu, the backward one much smaller but not negligible
    rates = NU * np.exp(-np.array([forward, backward]) / T)
    assert 1e-3 < rates[1] / rates[0] < 0.2
    draws = _draws(law, _block(eq, epsy, 2), 1 / T, 0.0, math.inf, 1.0, 4000)
    kinds, directions, times = (np.array([d[i] for d in draws]) for i in (0, 2, 3))
    assert np.all(kinds == HOP)
    mean = 1 / rates.sum()
    assert stats.kstest(times, stats.expon(scale=mean).cdf).pvalue > 0.01
    assert times.mean() == pytest.approx(mean, rel=5 / math.sqrt(times.size))  # 5 standard errors
    backward_share = rates[1] / rates.sum()
    assert stats.binomtest(int(np.sum(directions == BACKWARD)), times.size, backward_share).pvalue > 0.01
    # a hold shorter than most waits ends first: NONE with the hold's duration, as often as exp(-R t)
    hold = 0.5 * mean
    ended = [d for d in _draws(law, _block(eq, epsy, 2), 1 / T, 0.0, hold, 1.0, 2000, seed=8) if d[0] == NONE]
    assert all(d[3] == hold for d in ended)
    assert stats.binomtest(len(ended), 2000, math.exp(-0.5)).pvalue > 0.01


def test_a_block_under_a_rising_load_hops_with_the_survival_function_of_its_time_dependent_rate():
    law = Cusp(4.5, 1.0)
    epsy = [-3e-4, 3e-4, 5e-4]
    eq0 = 1e-4  # in the first well (centred on zero strain: no back edge), x0 = 2e-4 below its yield strain
    x0 = epsy[1] - eq0
    a_energy = law.G * H * H  # barrier = a_energy x^2
    T = a_energy * (0.4 * x0) ** 2  # barrier at the start 6.25 T
    beta = 1 / T
    speed = 1.5e-4  # strain per unit time along the drive: eps_xy = eq0 + speed t (survival at threshold ~0.4)
    t_c = x0 / speed  # the athermal threshold
    a = beta * a_energy

    def hazard(t):
        """int_0^t nu exp(-a (x0 - speed t')^2) dt'."""
        return NU / speed * math.sqrt(math.pi / (4 * a)) * (special.erf(math.sqrt(a) * x0)
                                                             - special.erf(math.sqrt(a) * (x0 - speed * np.asarray(t))))

    survival_c = math.exp(-hazard(t_c))
    assert 0.1 < survival_c < 0.9  # both outcomes frequent
    draws = _draws(law, _block(eq0, epsy, 0, strain_rate=1.0), beta, speed, math.inf, x0, 4000)
    kinds, times = np.array([d[0] for d in draws]), np.array([d[3] for d in draws])
    assert set(kinds) <= {HOP, THRESHOLD}
    assert np.all(times[kinds == THRESHOLD] == t_c)
    assert stats.binomtest(int(np.sum(kinds == THRESHOLD)), kinds.size, survival_c).pvalue > 0.01
    hops = times[kinds == HOP]
    assert np.all((hops > 0) & (hops < t_c))

    def conditional_cdf(t):
        return (1 - np.exp(-hazard(t))) / (1 - survival_c)

    assert stats.kstest(hops, conditional_cdf).pvalue > 0.01
    # the same process with the rate frozen at its start would hop far later: the test sees the rise
    frozen = NU * math.exp(-a * x0 ** 2)
    assert np.median(hops) < 0.5 * math.log(2) / frozen


@pytest.mark.parametrize("law", [Cusp(4.5, 1.0), Smooth(4.5, 1.0)], ids=["cusp", "smooth"])
def test_the_barrier_bounds_bound_every_barrier_over_the_stretch_of_drive(law):
    rng = np.random.default_rng(3)
    ni = 200
    epsy = np.cumsum(rng.uniform(0.5e-4, 1.5e-4, (ni, 8)), axis=1) - 1e-4
    idx = rng.integers(1, 6, (ni, 4))
    eps = np.zeros((ni, 4, 3))
    rows = np.arange(ni)[:, None]
    lo, hi = epsy[rows, idx], epsy[rows, idx + 1]
    eps[..., 2] = lo + rng.uniform(0.05, 0.95, (ni, 4)) * (hi - lo)
    eps[..., 0] = rng.normal(0, 1e-6, (ni, 4))
    deps = rng.normal(0, 1e-6, (ni, 4, 3))  # any direction, so that eps_eq may fall and rise along the drive
    dV = np.full((ni, 4), H * H / 4)
    ds_a, ds_b = 0.0, 20.0
    bounds = np.empty((ni, 2))
    barrier_bounds(law, epsy, idx, eps, deps, dV, ds_a, ds_b, bounds)
    checked = 0
    for e in range(ni):
        # the window must keep every Gauss point in its well (as below the athermal threshold)
        grid = np.linspace(ds_a, ds_b, 101)
        strains = np.hypot(0.5 * (eps[e, :, 0, None] + grid * deps[e, :, 0, None] - eps[e, :, 1, None]
                                  - grid * deps[e, :, 1, None]), eps[e, :, 2, None] + grid * deps[e, :, 2, None])
        if np.any(strains <= lo[e][:, None]) or np.any(strains > hi[e][:, None]):
            continue
        checked += 1
        for direction in (FORWARD, BACKWARD):
            values = [block_barrier(law, epsy, idx, eps, deps, dV, s, e, direction) for s in grid]
            assert bounds[e, direction] <= min(values) * (1 + 1e-12)
    assert checked > 50
    # and over a short stretch the bound is the barrier (so that halving the windows makes them tight)
    short = np.empty((ni, 2))
    barrier_bounds(law, epsy, idx, eps, deps, dV, 5.0, 5.0 + 1e-6, short)
    for e in range(ni):
        for direction in (FORWARD, BACKWARD):
            value = block_barrier(law, epsy, idx, eps, deps, dV, 5.0, e, direction)
            assert short[e, direction] == pytest.approx(value, rel=1e-6) or value == math.inf


def test_the_hop_kick_carries_every_gauss_point_of_the_block_over_the_edge():
    from stickslip.fem.quad4 import element_strain, shape_gradients

    xe = np.array([[[0.0, 0.0], [H, 0.0], [H, H], [0.0, H]]])
    dNdx = shape_gradients(xe)[0][0]
    mode = np.array([-0.5, 0, -0.5, 0, 0.5, 0, 0.5, 0])
    epsy = np.array([-1e-4, 1e-4, 2e-4, 3.2e-4, 4e-4])
    rng = np.random.default_rng(1)
    for direction, edge in ((FORWARD, 1), (BACKWARD, 0)):
        for _ in range(20):
            eps = np.zeros((4, 3))
            eps[:, 2] = rng.uniform(2.1e-4, 3.1e-4, 4)
            eps[:, 0] = rng.normal(0, 2e-6, 4)
            idx = np.full(4, 2)
            step = hop_step(dNdx, mode, eps, epsy, idx, direction, 5e-9)
            d = np.empty((4, 3))
            element_strain(dNdx, mode, d)
            after = eps + step * d
            eq = np.hypot(0.5 * (after[:, 0] - after[:, 1]), after[:, 2])
            target = epsy[2 + edge]
            beyond = eq - target if direction == FORWARD else target - eq
            assert np.all(beyond >= 5e-9 * (1 - 1e-9)) and np.min(beyond) == pytest.approx(5e-9, rel=1e-6)


# --- through the solver ------------------------------------------------------------------------

CASE = {"N": 9, "plates": 2, "seed": 1, "k_drive": 1e-3, "relaxation": "exact", "dt_scale": 4.0,
        "max_increments": 60}


def _run(path, **params):
    plugin = get("solver", "fem")
    plugin.run(parse_params(plugin.params, {**CASE, **params}), path, threads=1, inputs={})
    return path


def test_t_to_zero_gives_the_athermal_run_bit_for_bit(tmp_path):
    athermal = read_increments(_run(tmp_path / "athermal.h5"))
    # T = 1e-12 G eps0^2 h^2: a block at the athermal brink (deps / 2 = 5e-5 eps0 from its edge) has a barrier
    # of 2.5e-9 = 2500 T, so no hop comes before the threshold at any drive rate
    cold_path = _run(tmp_path / "cold.h5", temperature=1e-12, drive_rate=1e-3)
    cold = read_increments(cold_path)
    assert np.all(cold["hop_block"] == -1)
    shared = [c for c in athermal.columns if c != "t"]
    assert cold[shared].equals(athermal[shared])
    import h5py

    with h5py.File(tmp_path / "athermal.h5") as a, h5py.File(cold_path) as c:
        for name in ("u", "target", "lever_target"):
            assert np.array_equal(a["state"][name][...], c["state"][name][...])
        # the clock runs with the drive: the imposed shear gamma = target / (2 H) [eps0] grows at drive_rate
        gamma = c["state/target"][:, -1] / (2 * 5e-5 * RunFile(c).mesh.layer_mid_height[-1])
    loads = ~cold["kick"].to_numpy()
    rate = np.diff(gamma)[loads[1:]] / np.diff(cold["t"])[loads[1:]]
    assert rate == pytest.approx(np.full(rate.size, 1e-3), rel=1e-9)
    assert np.all(np.diff(cold["t"])[~loads[1:]] == 0)  # events take no time


THERMAL = {"temperature": 2e-3, "drive_rate": 1e-5, "attempt_rate": 1.0, "hold_times": (1e4, 1e7)}


def test_a_thermal_run_states_its_temperature_and_hops(tmp_path):
    path = _run(tmp_path / "hot.h5", **THERMAL)
    attrs = read_run_attrs(path)
    assert attrs["protocol"] == "thermal"
    assert (attrs["temperature"], attrs["attempt_rate"], attrs["drive_rate"]) == (2e-3, 1.0, 1e-5)
    assert attrs["params"]["attempt_rate"] == 1.0 and attrs["params"]["hold_times"] == [1e4, 1e7]
    table = read_increments(path)
    events = table[table["kick"]].iloc[1:]
    assert (events["hop_block"] >= 0).sum() > 5  # thermally activated events
    assert np.all(np.diff(table["t"]) >= 0)


def test_same_seed_same_bytes_and_a_killed_thermal_run_resumes_to_them(tmp_path):
    first = _run(tmp_path / "first.h5", **THERMAL)
    second = _run(tmp_path / "second.h5", **THERMAL)
    assert first.read_bytes() == second.read_bytes()
    killed = tmp_path / "killed.h5"
    params = [arg for key, value in {**CASE, **THERMAL}.items()
              for arg in ("--param", f"{key}={','.join(map(str, value)) if isinstance(value, tuple) else value}")]
    command = [sys.executable, "-m", "stickslip", "simulate", "--solver", "fem", *params, "-o", str(killed)]
    for stop in (7, 20, 33):  # after a load increment and after an event increment, twice
        status, err, stored = kill_when_stored(command, killed, stop, signal.SIGKILL, timeout=300)
        assert status == -signal.SIGKILL, err  # killed, not ended by itself
        attrs = read_run_attrs(killed)
        assert not attrs["completed"] and attrs["nstored"] >= stored >= stop
    done = subprocess.run(command, capture_output=True, text=True, env=os.environ)
    assert done.returncode == 0, done.stderr
    assert killed.read_bytes() == first.read_bytes()
