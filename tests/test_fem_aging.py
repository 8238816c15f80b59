"""Junction aging in the thermal fem model (stickslip.fem.thermal.junctions, .redraws, .aging): verification.

(a) One block at rest: the mean depth of its junction grows as T ln t (slope T within 5 %) for
    T < T_g, and saturates at the equilibrium T T_g / (T - T_g) for T > T_g (the trap model).
(b) A change of well renews the junction: every block whose Gauss points share a well holds a junction
    on that well, a block that changed well has a new depth, the new depths are exponential of mean
    T_g (Kolmogorov-Smirnov), and the yield strains the backend holds are the window widened by them.
(c) Redraw times follow their exact law: exponential with the rate nu_j exp(-E / T) (Kolmogorov-Smirnov),
    the redrawn block picked in proportion to its rate (binomial), and under a rising load the
    athermal threshold comes first with the probability exp(-r t_c).
(d) Aging off gives the thermal run of before junction aging bit for bit; same seed, same bytes; a run
    killed, or cut at a pending redraw, a pending hop or an event, resumes to the bytes of an
    uninterrupted one.
(e) Bad input: every new parameter checked with one line naming it.
"""

import hashlib
import math
import os
import signal
import subprocess
import sys

import h5py
import numpy as np
import pytest
from scipy import stats

from conftest import kill_when_stored
from stickslip.fem.backends import make_backend
from stickslip.fem.laws import Cusp
from stickslip.fem.random import pcg32_seed
from stickslip.fem.simulation import Simulation
from stickslip.fem.thermal.junctions import CAP, renew, widen
from stickslip.fem.thermal.redraws import REDRAW, sample_with_redraws
from stickslip.fem.thermal.sampler import NONE, THRESHOLD
from stickslip.formats.fem_run import RunFile, describe, read_increments, read_run_attrs
from stickslip.h5io import write_attrs
from stickslip.plugin_params import ParameterError, parse_params
from stickslip.registry import get, run_id
from stickslip.solvers.fem import stack_mesh

H = math.pi
LAW = Cusp(4.5, 1.0)
EPS0 = 5e-5


class OneBlock:
    """A block in pure shear at the centre of its well (3e-4, 6e-4], its hops switched off, with a junction."""

    def __init__(self, strain_rate=0.0, scale=EPS0):
        self.base = np.array([[-3e-4, 3e-4, 6e-4, 9e-4, 1.2e-3]])
        self.idx = np.full((1, 4), 1, dtype=np.int64)
        self.eps = np.zeros((1, 4, 3))
        self.eps[..., 2] = 4.5e-4
        self.deps = np.zeros((1, 4, 3))
        self.deps[..., 2] = strain_rate
        self.dV = np.full((1, 4), H * H / 4)
        self.allowed = np.zeros((1, 2), dtype=bool)
        self.offset = np.zeros(1, dtype=np.int64)
        self.scale = scale

    def sample(self, well, depth, epsy, T, Tg, speed, duration, stream, nu_j=1.0):
        return sample_with_redraws(LAW, epsy, self.base, self.offset, well, depth, self.scale, Tg, nu_j, 1 / T,
                                   self.idx, self.eps, self.deps, self.dV, self.allowed, 1.0, 1.0, speed, duration,
                                   *stream)

    def aged(self, well, depth):
        epsy = np.empty_like(self.base)
        widen(self.base, self.offset, well, depth, self.scale, epsy)
        return epsy


def _stream(seed, k):
    return pcg32_seed(np.array([seed], dtype=np.uint64), np.array([k], dtype=np.uint64))


def _depths_at(T, Tg, times, count, seed=3):
    """Depth of one block's junction at ``times`` (from its renewal at t = 0), ``count`` samples: [count, len(times)]."""
    block = OneBlock()
    out = np.empty((count, len(times)))
    for k in range(count):
        stream = _stream(seed, k)
        well, depth = np.full(1, -1, dtype=np.int64), np.zeros(1)
        assert renew(well, depth, block.idx, Tg, *stream) == 1 and well[0] == 1
        epsy = block.aged(well, depth)
        now = 0.0
        for i, t in enumerate(times):
            kind = block.sample(well, depth, epsy, T, Tg, 0.0, t - now, stream)[0]
            assert kind == NONE
            now = t
            out[k, i] = depth[0]
        assert np.array_equal(epsy, block.aged(well, depth))  # the redraws applied to the held yield strains
    return out


@pytest.mark.parametrize("T", [1e-3, 2e-3])
def test_a_junction_at_rest_deepens_as_T_ln_t_below_the_glass_temperature(T):
    Tg = 8e-3
    times = np.logspace(2, 12, 11)
    depths = _depths_at(T, Tg, times, 4000)
    slope = np.polyfit(np.log(times), depths.mean(axis=0), 1)[0]
    assert slope == pytest.approx(T, rel=0.05)
    # the depth of a fresh junction is T_g on average: aging starts from there
    assert depths[:, 0].mean() > Tg


def test_a_junction_at_rest_saturates_above_the_glass_temperature():
    Tg, T = 8e-3, 1.6e-2
    equilibrium = 1 / (1 / Tg - 1 / T)  # the Boltzmann-weighted trap density exp(-E / T_g + E / T)
    times = np.array([1e2, 1e3, 1e4])
    depths = _depths_at(T, Tg, times, 1000)
    mean, error = depths.mean(axis=0), depths.std(axis=0) / math.sqrt(depths.shape[0])
    assert abs(mean[-1] - equilibrium) < 3 * error[-1]
    assert abs(np.polyfit(np.log(times), mean, 1)[0]) < 0.1 * T  # against T when it ages


def test_redraw_times_are_exponential_with_the_arrhenius_rate_of_the_depth():
    # the Gauss points sit just inside the widest well a junction can make (capped): almost every redraw
    # (a depth below ~100 T_g) narrows the well past them, so the sampler stops at the first redraw (REDRAW)
    T, Tg, E = 1e-3, 1e-5, 1e-2
    block = OneBlock(scale=1.0)
    w_cap = CAP * (9e-4 - 6e-4)
    block.eps[..., 2] = 6e-4 + 0.99 * w_cap
    rate = math.exp(-E / T)
    times, depths = [], []
    for k in range(4000):
        well, depth = np.array([1]), np.array([E])
        epsy = block.aged(well, depth)
        assert epsy[0, 2] == 6e-4 + w_cap
        kind, b, _, dt, _, redraws, new_depth = block.sample(well, depth, epsy, T, Tg, 0.0, math.inf, _stream(5, k))
        assert (kind, b, redraws) == (REDRAW, 0, 0) and depth[0] == E  # the yielding redraw is left to the event
        times.append(dt)
        depths.append(new_depth)
    times = np.asarray(times)
    assert stats.kstest(times, stats.expon(scale=1 / rate).cdf).pvalue > 0.01
    assert times.mean() == pytest.approx(1 / rate, rel=5 / math.sqrt(times.size))
    assert stats.kstest(depths, stats.expon(scale=Tg).cdf).pvalue > 0.01


def test_the_redrawn_block_is_picked_in_proportion_to_its_rate_and_a_rising_load_competes():
    T, Tg = 1e-3, 1e-5
    block = OneBlock(scale=1.0)
    block.base = np.repeat(block.base, 2, axis=0)
    block.idx = np.repeat(block.idx, 2, axis=0)
    block.eps = np.repeat(block.eps, 2, axis=0)
    block.eps[..., 2] = 6e-4 + 0.99 * CAP * 3e-4
    block.deps = np.zeros((2, 4, 3))
    block.dV = np.repeat(block.dV, 2, axis=0)
    block.allowed = np.zeros((2, 2), dtype=bool)
    block.offset = np.zeros(2, dtype=np.int64)
    depths = np.array([1e-2, 1.1e-2])
    rates = np.exp(-depths / T)
    picked = [block.sample(np.array([1, 1]), depths.copy(), block.aged(np.array([1, 1]), depths), T, Tg, 0.0,
                           math.inf, _stream(6, k))[1] for k in range(2000)]
    assert stats.binomtest(int(np.sum(np.asarray(picked) == 1)), 2000, rates[1] / rates.sum()).pvalue > 0.01
    # a rising load: the threshold (the forward yield strain widened by the junction) comes at t_c unless a
    # redraw comes first, with probability exp(-r t_c)
    block = OneBlock(strain_rate=1.0, scale=EPS0)
    E, Tg = 1e-2, 8e-3
    well, depth = np.array([1]), np.array([E])
    epsy = block.aged(well, depth)
    speed = 1e-8
    rate = math.exp(-E / T)
    t_c = (epsy[0, 2] - 4.5e-4) / speed
    assert rate * t_c == pytest.approx(1.0, rel=0.7)  # both outcomes frequent
    kinds, times = [], []
    for k in range(2000):
        w, d = well.copy(), depth.copy()
        kind, _, _, dt, _, redraws, _ = block.sample(w, d, epsy.copy(), T, Tg, speed, math.inf, _stream(7, k))
        kinds.append(kind == THRESHOLD and redraws == 0)
        if kind == THRESHOLD and redraws == 0:
            assert dt == pytest.approx(t_c, rel=1e-12)
    assert stats.binomtest(int(np.sum(kinds)), 2000, math.exp(-rate * t_c)).pvalue > 0.01


def test_renew_draws_a_junction_for_a_whole_block_that_changed_well_and_removes_a_split_one():
    well = np.array([4, 4, -1, 6], dtype=np.int64)
    depth = np.array([0.5, 0.7, 0.0, 0.2])
    idx = np.array([[4, 4, 4, 4], [5, 5, 5, 5], [2, 2, 2, 2], [6, 6, 7, 6]], dtype=np.int64)
    assert renew(well, depth, idx, 1.0, *_stream(1, 0)) == 3
    assert list(well) == [4, 5, 2, -1]
    assert depth[0] == 0.5 and depth[1] != 0.7 and depth[2] > 0 and depth[3] == 0


# --- through the solver ------------------------------------------------------------------------

CASE = {"N": 9, "plates": 2, "seed": 1, "k_drive": 1e-3, "relaxation": "exact", "dt_scale": 4.0,
        "max_increments": 60}
THERMAL = {"temperature": 2e-3, "drive_rate": 1e-5, "attempt_rate": 1.0, "hold_times": (1e4, 1e7), "hold_delay": 0.05}
AGING = {**THERMAL, "junction_strengthening": 5.0, "junction_glass_temperature": 8e-3, "junction_attempt_rate": 1.0}

#: sha256 of the state and increment datasets of the thermal run CASE + THERMAL made by main at ee6f300, before
#: junction aging (the file itself also stores the package version, so its bytes are not compared across versions).
#: (At f068ff9, before the BLAS-free factorisation of the exact relaxation, it was c8d356a9...)
THERMAL_DIGEST = "189c945a84f540b4005e639c9f9e33339f675ee2dc5072d9305fd1a7a116691c"


def _params(**params):
    return parse_params(get("solver", "fem").params, {**CASE, **params})


def _run(path, **params):
    get("solver", "fem").run(_params(**params), path, threads=1, inputs={})
    return path


def _digest(path):
    digest = hashlib.sha256()
    with h5py.File(path) as file:
        for group in ("state", "increments"):
            for name in sorted(file[group]):
                digest.update(name.encode())
                digest.update(np.ascontiguousarray(file[group][name][...]).tobytes())
    return digest.hexdigest()


def test_aging_off_gives_the_thermal_run_of_before_bit_for_bit(tmp_path):
    plain = _run(tmp_path / "plain.h5", **THERMAL)
    off = _run(tmp_path / "off.h5", **THERMAL, junction_strengthening=0.0)
    assert _digest(plain) == THERMAL_DIGEST
    assert off.read_bytes() == plain.read_bytes()
    plugin = get("solver", "fem")
    assert run_id(plugin, _params(**THERMAL, junction_strengthening=0.0)) == run_id(plugin, _params(**THERMAL))
    assert "junction_strengthening" not in read_run_attrs(plain)["params"]
    # the database's columns: no aging in a thermal run, none at all in an athermal one
    described = describe(plain)
    assert described["junction_strengthening"] == 0.0 and described["junction_glass_temperature"] is None


@pytest.fixture(scope="module")
def aging_run(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("aging") / "aging.h5", **AGING, max_increments=120)


def test_every_event_renews_the_junctions_of_the_blocks_that_changed_well(aging_run):
    table = read_increments(aging_run)
    params = _params(**AGING, max_increments=120)
    simulation = Simulation(params, stack_mesh(params, {}), make_backend(params.backend, 1))
    stack = simulation.stack
    fresh, renewed, kept = [], 0, 0
    with h5py.File(aging_run) as file:
        run = RunFile(file)
        previous = None
        for increment in range(run.nstored):
            state = run.state(increment)
            junctions = state.further
            stack.restore(state)
            wells = stack.well_index()
            whole = np.all(wells == wells[:, :1], axis=1)
            assert np.array_equal(junctions["junction_well"], np.where(whole, wells[:, 0], -1))
            assert np.all((junctions["junction_depth"] > 0) == whole)
            # the backend holds the window widened by the junctions, each about its well's centre
            epsy, base = stack.yield_strains, stack.wells.epsy
            for e in np.flatnonzero(whole):
                j = junctions["junction_well"][e] - stack.wells.offset[e]
                neighbours = [base[e, j + 2] - base[e, j + 1]] + ([base[e, j] - base[e, j - 1]] if j > 0 else [])
                w = min(params.junction_strengthening * params.eps0 * junctions["junction_depth"][e],
                        CAP * min(neighbours))
                assert epsy[e, j] == base[e, j] - w and epsy[e, j + 1] == base[e, j + 1] + w
                assert np.array_equal(np.delete(epsy[e], [j, j + 1]), np.delete(base[e], [j, j + 1]))
            if previous is not None and table["kick"][increment]:
                moved = np.any(wells != previous[0], axis=1) & whole
                changed = junctions["junction_depth"] != previous[1]
                assert np.all(changed[moved])  # a block that changed well has a new junction ...
                fresh += list(junctions["junction_depth"][moved])
                renewed += int(moved.sum())
                # ... and one that kept its well and was not redrawn in the load before kept it
                redrawn = table["redraws"][increment - 1] > 0 or table["redraw_block"][increment - 1] >= 0
                if not redrawn:
                    assert np.all(~changed[~moved & whole])
                    kept += 1
            previous = (wells, junctions["junction_depth"])
    assert renewed > 50 and kept > 0
    assert stats.kstest(fresh, stats.expon(scale=params.junction_glass_temperature).cdf).pvalue > 0.01


def test_an_aging_run_redraws_its_junctions_and_states_its_parameters(aging_run):
    attrs = read_run_attrs(aging_run)
    assert (attrs["junction_strengthening"], attrs["junction_glass_temperature"], attrs["junction_attempt_rate"]) == \
        (5.0, 8e-3, 1.0)
    described = describe(aging_run)  # the database's typed columns
    assert (described["junction_strengthening"], described["junction_glass_temperature"],
            described["junction_attempt_rate"]) == (5.0, 8e-3, 1.0)
    table = read_increments(aging_run)
    loads = table[~table["kick"]]
    assert loads["redraws"].sum() > 100  # junctions redrawn at rest
    assert np.all(table.loc[table["kick"], "redraws"] == 0)


def _cut(path, nstored, target):
    """A copy of run ``path`` with its first ``nstored`` increments, as a run killed there leaves it."""
    target.write_bytes(path.read_bytes())
    with h5py.File(target, "r+") as file:
        write_attrs(file, {"nstored": nstored, "completed": False, "stop_reason": ""})
    return target


def test_same_seed_same_bytes_and_a_cut_or_killed_aging_run_resumes_to_them(tmp_path, aging_run):
    first = _run(tmp_path / "first.h5", **AGING, max_increments=120)
    assert first.read_bytes() == aging_run.read_bytes()
    table = read_increments(first)
    loads = ~table["kick"].to_numpy()
    redraw = int(np.flatnonzero(loads & (table["redraw_block"] >= 0))[0])
    hop = int(np.flatnonzero(loads & (table["hop_block"] >= 0))[2])
    event = hop + 1
    for cut in (redraw, hop, event):  # the last stored increment: a load with a pending redraw, with a hop, an event
        resumed = _run(_cut(first, cut + 1, tmp_path / f"cut{cut}.h5"), **AGING, max_increments=120)
        assert resumed.read_bytes() == first.read_bytes(), cut
    killed = tmp_path / "killed.h5"
    params = [arg for key, value in {**CASE, **AGING, "max_increments": 120}.items()
              for arg in ("--param", f"{key}={','.join(map(str, value)) if isinstance(value, tuple) else value}")]
    command = [sys.executable, "-m", "stickslip", "simulate", "--solver", "fem", *params, "-o", str(killed)]
    status, err, stored = kill_when_stored(command, killed, 40, signal.SIGKILL, timeout=300)
    assert status == -signal.SIGKILL, err  # killed, not ended by itself
    attrs = read_run_attrs(killed)
    assert not attrs["completed"] and attrs["nstored"] >= stored >= 40
    done = subprocess.run(command, capture_output=True, text=True, env=os.environ)
    assert done.returncode == 0, done.stderr
    assert killed.read_bytes() == first.read_bytes()


@pytest.mark.parametrize("values, message", [
    ({"junction_strengthening": -1.0}, "parameter 'junction_strengthening': expected a value >= 0.0"),
    ({"junction_strengthening": "nan"}, "parameter 'junction_strengthening': expected a finite number"),
    ({**THERMAL, "junction_strengthening": 1.0, "junction_glass_temperature": 0.0},
     "parameter 'junction_glass_temperature': expected a value > 0.0"),
    ({**THERMAL, "junction_strengthening": 1.0, "junction_glass_temperature": -1e-3},
     "parameter 'junction_glass_temperature': expected a value > 0.0"),
    ({**THERMAL, "junction_strengthening": 1.0, "junction_attempt_rate": "inf"},
     "parameter 'junction_attempt_rate': expected a finite number"),
    ({**THERMAL, "junction_strengthening": 1.0, "junction_attempt_rate": 0.0},
     "parameter 'junction_attempt_rate': expected a value > 0.0"),
    ({"junction_strengthening": 1.0}, "parameter 'junction_strengthening': junction aging needs thermal activation"),
    ({"junction_glass_temperature": 1e-2}, "parameter 'junction_glass_temperature': used only with "
                                           "junction_strengthening > 0"),
    ({**THERMAL, "junction_attempt_rate": 2.0}, "parameter 'junction_attempt_rate': used only with "
                                                "junction_strengthening > 0"),
    ({**THERMAL, "junction_strengthening": 1.0, "interface_law": "smooth", "relaxation": "dynamic"},
     "parameter 'junction_strengthening': law 'smooth' has a stress that depends on the well's width"),
])
def test_bad_junction_parameters_are_refused_with_one_line_naming_them(values, message):
    with pytest.raises(ParameterError, match=message.replace("(", r"\(").replace(")", r"\)")) as error:
        parse_params(get("solver", "fem").params, values)
    assert "\n" not in str(error.value)
