"""Cost of a thermal fem run against an athermal one of the same size and number of increments.

Usage::

    python benchmarks/bench_thermal.py [--N 162] [--plates 2] [--increments 400] [--temperature 1e-3]
                                       [--drive-rate 2e-8] [--draws 200]

Runs, in one process after a warm-up that compiles every kernel, the same ``fem`` model (exact
relaxation, dt_scale 4, the paper's compliant Phi carried to ``N``, seed 1) with the athermal
protocol and with the thermal one, ``--increments`` increments each, and prints for both: wall and
CPU time, time per increment and per event, events and slip events; then the thermal run's split:
hops, athermal kicks, failed hops, and the cost of one draw of the next event
(:func:`stickslip.fem.thermal.sample_event`, timed ``--draws`` times on a stored state of the run)
against the cost of an event. Load on the machine distorts the times; the ratios less so.
"""

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from stickslip.events.extraction import classify_increments
from stickslip.formats.fem_run import RunFile, read_increments
from stickslip.h5io import open_file
from stickslip.fem.random import pcg32_seed
from stickslip.fem.replay import EventReplay
from stickslip.fem.thermal import drive_scale, energy_unit, sample_event
from stickslip.plugin_params import parse_params
from stickslip.registry import get


def simulate(path, values):
    plugin = get("solver", "fem")
    start, cpu = time.perf_counter(), time.process_time()
    plugin.run(parse_params(plugin.params, values), path, threads=1, inputs={})
    return time.perf_counter() - start, time.process_time() - cpu


def describe(label, path, wall, cpu, N):
    table = read_increments(path)
    events = int(table["kick"].sum()) - 1
    classified = classify_increments(table, N)
    slips = int(classified["kind"].isin(("single", "multi")).sum())
    print(f"{label:9s} wall {wall:7.2f} s  cpu {cpu:7.2f} s  increments {len(table) - 1}  events {events}  "
          f"slip events {slips}  per increment {1e3 * cpu / (len(table) - 1):6.1f} ms cpu  "
          f"per event {1e3 * cpu / events:6.1f} ms cpu")
    return table, events


def draw_cost(path, draws):
    """Median cost of one :func:`sample_event` from the last stored state of a thermal run [s]."""
    replay = EventReplay(path)
    sim = replay.simulation
    with open_file(path) as file:
        sim.stack.restore(RunFile(file).state(replay.nstored - 1))
    p, model = sim.params, sim.model
    idx, eps = sim.backend.read("idx", "eps")
    beta = 1.0 / (p.temperature * energy_unit(p, sim.constants["h"]))
    speed = p.drive_rate / drive_scale(sim.loading.response, p.eps0, sim.mesh)
    ds_c = sim.loading.step_size(False)
    allowed = np.ones((model.iface_dofs.shape[0], 2), dtype=bool)
    times = []
    for k in range(draws):
        stream = pcg32_seed(np.array([1], dtype=np.uint64), np.array([k], dtype=np.uint64))
        start = time.perf_counter()
        sample_event(model.law, sim.stack.yield_strains, idx, eps, sim.loading.response.delta_eps, model.iface_dV, allowed, beta,
                     p.attempt_rate, 0.0, speed, np.inf, ds_c, *stream)
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--N", type=int, default=162)
    parser.add_argument("--plates", type=int, default=2)
    parser.add_argument("--increments", type=int, default=400)
    parser.add_argument("--temperature", type=float, default=1e-3)
    parser.add_argument("--drive-rate", type=float, default=2e-8)
    parser.add_argument("--draws", type=int, default=200)
    args = parser.parse_args()
    M = max(3, args.N // 4)
    base = {"N": args.N, "plates": args.plates, "seed": 1, "relaxation": "exact", "dt_scale": 4.0,
            "k_drive": 2 * 5e-7 * (364 / M) ** 2}
    thermal = {"temperature": args.temperature, "attempt_rate": 1.0, "drive_rate": args.drive_rate}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        simulate(folder / "warm-a.h5", {**base, "max_increments": 4})  # compile every kernel
        simulate(folder / "warm-t.h5", {**base, **thermal, "max_increments": 4})
        wall_a, cpu_a = simulate(folder / "athermal.h5", {**base, "max_increments": args.increments})
        wall_t, cpu_t = simulate(folder / "thermal.h5", {**base, **thermal, "max_increments": args.increments})
        print(f"N = {args.N}, plates = {args.plates}, {args.increments} increments; thermal: T = {args.temperature:g}, "
              f"drive rate {args.drive_rate:g}")
        _, events_a = describe("athermal", folder / "athermal.h5", wall_a, cpu_a, args.N)
        table, events_t = describe("thermal", folder / "thermal.h5", wall_t, cpu_t, args.N)
        kicks = table[table["kick"]].iloc[1:]
        print(f"thermal events: {int((kicks['hop_block'] >= 0).sum())} hops, {int((kicks['hop_block'] < 0).sum())} "
              f"athermal kicks, {int(table['failed_hops'].sum())} failed hops")
        draw = draw_cost(folder / "thermal.h5", args.draws)
        print(f"one draw of the next event: {1e3 * draw:.3f} ms (median of {args.draws}), "
              f"{draw / (cpu_t / events_t):.2%} of a thermal event's cpu")
        print(f"ratio thermal/athermal: per increment {cpu_t / cpu_a:.2f}, per event "
              f"{(cpu_t / events_t) / (cpu_a / events_a):.2f}")


if __name__ == "__main__":
    main()
