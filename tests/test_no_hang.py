"""No job hangs: parameters that make a loop endless are refused at parse time, every sampling loop has a bound that
turns into an error naming the parameters, and SIGTERM stops a run inside its longest kernel call within seconds.

The audit: an aging run with ``junction_glass_temperature`` at or below ``temperature`` (or
``junction_attempt_rate=1e100``) never left its first increment, looping inside the numba kernel
``sample_with_redraws``, and ignored Ctrl-C and SIGTERM (only SIGKILL stopped it).
"""

import math
import os
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest
from conftest import time_to_stop

from stickslip.fem.errors import SolverError
from stickslip.fem.laws import Cusp
from stickslip.fem.parameters import FemParams
from stickslip.fem.random import pcg32_seed
from stickslip.fem.thermal import redraws as redraws_module
from stickslip.fem.thermal import sampler
from stickslip.fem.thermal.junctions import renew, widen
from stickslip.fem.trap_model import expected_redraws
from stickslip.fem.thermal.redraws import PAUSED, redraw_loop, sample_with_redraws
from stickslip.fem.thermal.sampler import HOP, NONE, STALLED, THRESHOLD, draw_event, sample_event
from stickslip.formats.fem_run import read_run_attrs
from stickslip.plugin_params import ParameterError, ParameterWarning, parse_params

AGING = {"N": "9", "plates": "2", "temperature": "1e-3", "drive_rate": "2e-8", "junction_strengthening": "5"}


def _params(**changes):
    return parse_params(FemParams, {**AGING, **changes})


@pytest.mark.parametrize("changes, message", [
    # the audit's run: T_g = 5e-4 below T = 1e-3, every junction redrawn ~nu_j t_cycle = 1e7 times a cycle
    ({"junction_glass_temperature": "5e-4"}, "parameter 'junction_glass_temperature': 0.0005 at temperature 0.001 "
                                             "and junction_attempt_rate 1/time has every junction redrawn ~1e+07 "
                                             "times in a stick-slip cycle"),
    ({"junction_glass_temperature": "1e-3"}, "parameter 'junction_glass_temperature': 0.001 at temperature 0.001"),
    ({"junction_attempt_rate": "1e100"}, "parameter 'junction_attempt_rate': 1e+100/time makes 1e+107 attempts in "
                                         "a stick-slip cycle"),
    ({"junction_attempt_rate": "1e9"}, "parameter 'junction_attempt_rate': 1e+09/time makes 1e+16 attempts"),
    ({"attempt_rate": "1e100"}, "parameter 'attempt_rate': 1e+100/time makes 1e+107 attempts"),
    # a hold longer than a cycle is the longest stretch
    ({"junction_glass_temperature": "1.1e-3", "junction_attempt_rate": "1e-3", "hold_times": "1e13"},
     "parameter 'junction_glass_temperature': 0.0011 at temperature 0.001 and junction_attempt_rate 0.001/time has "
     "every junction redrawn ~1.23e+09 times in a hold of 1e+13 time"),
])
def test_parameters_that_make_the_sampling_endless_are_refused_in_one_line(changes, message):
    with pytest.raises(ParameterError) as refused:
        _params(**changes)
    text = str(refused.value)
    assert text.startswith(message) and "\n" not in text, text
    assert "expected" in text


def test_the_glass_temperature_at_or_below_the_temperature_is_warned_where_the_run_ends():
    # T >= T_g with few attempts in a cycle: the junctions do not age, the run ends (a warning, one line)
    with pytest.warns(ParameterWarning, match=r"T_g = 0.0009 <= T = 0.001: the junctions do not age") as warned:
        _params(junction_glass_temperature="9e-4", junction_attempt_rate="1e-6")
    assert len(warned) == 1 and "\n" not in str(warned[0].message)
    # the shipped aging study's junctions pass without a word (T = 1e-3, T_g = 8e-3, nu_j = 1, its drive rates)
    for values in ({"drive_rate": "2e-8"}, {"drive_rate": "2e-11"}, {"drive_rate": "2e-5"},
                   {"junction_strengthening": "10"}):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            _params(**values)


def test_the_trap_model_s_count_of_redraws():
    assert expected_redraws(1.0, 1e-3, 8e-3, 1e8) == pytest.approx(1e8 ** 0.125)
    assert expected_redraws(1.0, 2e-3, 1e-3, 1e7) == pytest.approx(1e7)  # at and above T_g: nu_j t
    assert expected_redraws(1.0, 1e-3, 8e-3, 0.5) == 1.0
    assert expected_redraws(1.0, 1e-3, 8e-3, math.inf) == math.inf


# ---------------------------------------------------------------------------------------- bounds in the kernels

LAW = Cusp(4.5, 1.0)


class Block:
    """One interface block in pure shear in its well (3e-4, 6e-4], with a junction (tests/test_fem_aging.py)."""

    def __init__(self, strain_rate=0.0):
        self.base = np.array([[-3e-4, 3e-4, 6e-4, 9e-4, 1.2e-3]])
        self.idx = np.full((1, 4), 1, dtype=np.int64)
        self.eps = np.zeros((1, 4, 3))
        self.eps[..., 2] = 4.5e-4
        self.deps = np.zeros((1, 4, 3))
        self.deps[..., 2] = strain_rate
        self.dV = np.full((1, 4), math.pi ** 2 / 4)
        self.offset = np.zeros(1, dtype=np.int64)

    def junction(self, Tg, seed):
        stream = pcg32_seed(np.array([seed], dtype=np.uint64), np.array([7], dtype=np.uint64))
        well, depth = np.full(1, -1, dtype=np.int64), np.zeros(1)
        renew(well, depth, self.idx, Tg, *stream)
        epsy = np.empty_like(self.base)
        widen(self.base, self.offset, well, depth, 5e-5, epsy)
        return well, depth, epsy, stream

    def arguments(self, Tg, nu_j, T, duration, seed, allowed=False, speed=0.0):
        well, depth, epsy, stream = self.junction(Tg, seed)
        return (LAW, epsy, self.base, self.offset, well, depth, 5e-5, Tg, nu_j, 1 / T, self.idx, self.eps, self.deps,
                self.dV, np.full((1, 2), allowed), 1 / T, 1.0, speed, duration, *stream)


def test_the_redraw_loop_in_chunks_draws_what_one_call_draws():
    block = Block()
    one = block.arguments(8e-3, 1.0, 4e-3, 1e8, seed=3)
    whole = redraw_loop(*one, 0.0, 0.0, 0, 10**9)
    assert whole[0] == NONE and whole[5] > 3000  # ~(nu_j t)^(T/T_g) = 10^4
    chunked = block.arguments(8e-3, 1.0, 4e-3, 1e8, seed=3)
    t, ds, count, calls = 0.0, 0.0, 0, 0
    while True:
        kind, b, d, t, ds, count, depth = redraw_loop(*chunked, t, ds, count, 997)
        calls += 1
        if kind != PAUSED:
            break
    assert calls > 5 and (kind, b, d, t, ds, count) == whole[:6]
    assert np.array_equal(one[1], chunked[1]) and np.array_equal(one[5], chunked[5])  # yield strains, depths
    assert np.array_equal(one[-2], chunked[-2])  # the generator: the same draws


def test_redraws_beyond_the_trap_model_s_bound_stop_with_an_error_naming_the_parameters(monkeypatch):
    # T > T_g at rest for 10^12: ~10^12 redraws of one block; the bound (here lowered) stops the sampling
    monkeypatch.setattr(redraws_module, "REDRAW_MARGIN", 1e-9)
    monkeypatch.setattr(redraws_module, "REDRAW_FLOOR", 50_000)
    monkeypatch.setattr(redraws_module, "REDRAWS_PER_CALL", 10_000)
    with pytest.raises(SolverError) as stopped:
        sample_with_redraws(*Block().arguments(1e-3, 1.0, 2e-3, 1e12, seed=5))
    text = str(stopped.value)
    assert text.startswith("junction aging: 60000 junction redraws before the next event, more than 1e-09 times the "
                           "trap model's 1e+12 per block (1 blocks)"), text
    assert "(temperature = 0.002, junction_glass_temperature = 0.001, junction_attempt_rate = 1)" in text
    assert "\n" not in text


def test_a_hop_draw_gives_up_after_its_bound_with_an_error_naming_the_parameters(monkeypatch):
    # a rising load with hops allowed: each window and candidate counts; at a bound of 3 the draw gives up
    block = Block(strain_rate=1e-4)
    args = block.arguments(8e-3, 1.0, 1e-3, math.inf, seed=1, allowed=True, speed=1.0)
    law, epsy, _, _, _, _, _, _, _, _, idx, eps, deps, dV, allowed, beta, nu, speed, duration, state, inc = args
    draw = (law, epsy, idx, eps, deps, dV, allowed, beta, nu, 0.0, speed, duration, 1.5, state, inc)
    kind = draw_event(*draw)[0]
    assert kind in (HOP, THRESHOLD)
    monkeypatch.setattr(sampler, "draw_event", lambda *_: (STALLED, -1, -1, 0.5))
    with pytest.raises(SolverError) as stopped:
        sample_event(*draw)
    text = str(stopped.value)
    assert text.startswith(f"the thermal sampling made {sampler.MAX_DRAWS} windows and candidate hops without finding "
                           "the next event (attempt_rate = 1/time, 1/T = 1000 per energy unit")
    assert "\n" not in text


def test_the_kernel_gives_up_at_its_bound(monkeypatch):
    # the kernel's own source (numba's py_func, reading the module's MAX_DRAWS at call time) draws what the compiled
    # kernel draws; with a bound of 1 window or candidate, a draw that needs more comes back STALLED
    block = Block(strain_rate=1e-4)
    args = block.arguments(8e-3, 1.0, 1e-3, math.inf, seed=1, allowed=True, speed=1.0)
    law, epsy, _, _, _, _, _, _, _, _, idx, eps, deps, dV, allowed, beta, nu, speed, duration, state, inc = args
    draw = (law, epsy, idx, eps, deps, dV, allowed, beta, nu, 0.0, speed, duration, 1.5)
    compiled = draw_event(*draw, state.copy(), inc.copy())
    assert compiled[0] in (HOP, THRESHOLD) and draw_event.py_func(*draw, state.copy(), inc.copy()) == compiled
    monkeypatch.setattr(sampler, "MAX_DRAWS", 1)
    assert draw_event.py_func(*draw, state.copy(), inc.copy())[0] == STALLED


# ---------------------------------------------------------------------------------------- SIGTERM in a kernel call

def _simulate(path, *params):
    command = [sys.executable, "-m", "stickslip", "simulate", "--solver", "fem", "-o", str(path)]
    for value in params:
        command += ["--param", value]
    return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "NUMBA_NUM_THREADS": "1"})


def _stored(path):
    try:
        return read_run_attrs(path)["nstored"]
    except Exception:  # not yet written, or being written
        return 0


def _terminate_inside(process, path, stored, settle):
    """Wait until ``path`` holds ``stored`` increments (the next one is the long kernel call; ``stored`` 0: until the
    run holds the writer's lock of ``path``, the linear response being the long call), SIGTERM the run ``settle``
    seconds later; return the seconds it took to end."""
    deadline = time.monotonic() + 600  # a cold numba cache compiles first
    lock = path.parent / f".{path.name}.lock"
    while (_stored(path) < stored) if stored else not lock.exists():
        assert process.poll() is None, process.stderr.read()
        assert time.monotonic() < deadline, f"the run did not reach the long call in 10 minutes"
        time.sleep(0.2)
    time.sleep(settle)
    assert process.poll() is None, "the run ended before the signal"
    return time_to_stop(process, signal.SIGTERM, 30, "the run (inside a kernel call that does not return)")


@pytest.mark.slow
@pytest.mark.parametrize("case, params, stored", [
    # an aging run whose first load draws ~10^7 junction redraws (~40 s in one kernel call before): allowed
    # parameters (~1e6 redraws of a junction in a cycle), no hops (attempt_rate 1e-6), T / T_g = 1/2
    ("redraws", ("N=9", "plates=2", "temperature=4e-3", "attempt_rate=1e-6", "drive_rate=2e-8",
                 "junction_strengthening=5", "junction_attempt_rate=9e4", "max_increments=4"), 1),
    # a minimisation that never converges (tol 1e-300): the linear response's, 10^8 time steps in one kernel call
    # before; nothing is stored yet (the run file is written once the linear response is known)
    ("minimisation", ("N=9", "plates=2", "tol=1e-300", "max_iter=100000000", "max_increments=4"), 0),
])
def test_sigterm_stops_a_run_inside_its_longest_kernel_call_within_5_s(tmp_path, case, params, stored):
    path = tmp_path / f"{case}.h5"
    warm = _simulate(tmp_path / "warm.h5", *params[:2], "max_increments=2")  # the kernels compiled (numba's cache)
    assert warm.wait(timeout=600) == 0, warm.stderr.read()
    process = _simulate(path, *params)
    took = _terminate_inside(process, path, stored, settle=3.0)
    error = process.stderr.read().strip().splitlines()
    print(f"{case}: ended {took:.2f} s after SIGTERM")
    assert took < 5.0 and process.returncode == 143, (took, process.returncode, error[-3:])
    assert any(line.startswith("stickslip: terminated by SIGTERM; what was stored is kept") for line in error), error
    if stored:
        assert read_run_attrs(path)["nstored"] == stored  # nothing stored is lost; the file reads
    else:
        left = [p.name for p in tmp_path.iterdir() if path.name in p.name]
        assert left == [], left  # no partial run file, temporary file or lock left behind
