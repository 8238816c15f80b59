"""Rupture-front speed of multi-slip events: time step, fit window and system size (issue 23).

Usage::

    python benchmarks/front_speed.py RUN.h5 [RUN.h5 ...] [--scales 4 1] [--max-events 10]
        [--windows 0.3:0.9 0.2:0.9 0.5:0.95] [--profile-width 16] [--csv fronts.csv]

Every ``fem-run`` file with n = 2 interfaces: its first ``--max-events`` steady-state multi-slips
(:mod:`stickslip.events.extraction`) are kicked again from the stored state before the kick with
each ``dt_scale`` of ``--scales`` (the run's own first), every block failure recorded as the
``front-dynamics`` analysis does, so the time steps are compared **on the same events** (the
event itself may come out differently at another time step: its slipping interfaces are
reported). The replay at the run's own ``dt_scale`` must reproduce the stored increment (checked).
Each replay is analysed by :func:`stickslip.events.fronts.analyse_event` with every fit window
``fit_from:fit_to`` of ``--windows`` (fractions of each branch's length), and its front speed is
profiled along each branch: Theil-Sen speed over consecutive windows of ``--profile-width``
blocks of distance from the nucleation block (the local speed against the distance the front
has run).

For the reconciliation with front-dynamics version 1 (the project's c_f before issue 23), every
replay is also fitted the old way (:func:`version1_speed`): one least-squares line through the
first failures of both branches against the periodic distance from the first block to fail, over
0.3 ... 0.9 of half the interface, no quality check (column ``c_f_v1``).

Printed: one line per (event, dt_scale) with both branches' speeds and qualities for every
window; then per (N, dt_scale, window) the median and the mean with its standard error of the
meaningful fits (quality "ok", :func:`~stickslip.events.fronts.analyse_event`) and how many were
flagged; then the speed profile pooled over events: median local speed [c_s] against distance
[blocks] and [plate heights]. ``--csv`` writes the per-event rows, ``--profile-csv`` the profiles.
"""

import argparse
import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from stickslip.events import fronts
from stickslip.events.extraction import classify_increments
from stickslip.fem.backends import make_backend
from stickslip.fem.parameters import stored_params
from stickslip.fem.loading import KickAlongResponse
from stickslip.fem.simulation import Simulation
from stickslip.formats.fem_run import RunFile, read_increments, read_run_attrs
from stickslip.h5io import open_file
from stickslip.mesh import interface_layer


def replays(path, scales, max_events):
    """Yield (increment, dt_scale, failures DataFrame, reproduced) for the run's multi-slips."""
    attrs = read_run_attrs(path)
    table = read_increments(path)
    N = int(attrs["N"])
    classified = classify_increments(table, N)
    chosen = fronts.multi_slip_increments(classified, max_events)
    with open_file(path) as file:
        run = RunFile(file)
        params, mesh, response = stored_params(file), run.mesh, run.linear_response()
        states = {int(i): (run.state(int(i) - 1), run.state(int(i))) for i in chosen}
    yield_element = table["yield_element"].to_numpy(dtype=bool)
    for scale in scales:
        sim = Simulation(dataclasses.replace(params, dt_scale=float(scale)), mesh, make_backend(params.backend),
                         response=response)
        for increment, (before, after) in states.items():
            sim.stack.restore(before)
            kick = KickAlongResponse(sim.loading, bool(yield_element[increment]))
            _, events = sim.protocol.perturb_and_relax(kick, params.margin, record=True)
            reproduced = bool(np.array_equal(sim.backend.read("u")[0], after.u))
            element = events[:, 0].astype(np.int64)
            failures = pd.DataFrame({"a": element // N + 1, "block": element % N, "t": events[:, 1] - before.t,
                                     "direction": events[:, 2].astype(np.int64)})
            yield increment, float(scale), failures, reproduced


def version1_speed(failures, a, N, fit_from=0.3, fit_to=0.9):
    """Front speed [blocks per FE time] as front-dynamics version 1 fitted it (module doc); NaN if not positive."""
    first = failures[failures["a"] == a].groupby("block")["t"].min()
    blocks, times = first.index.to_numpy(), first.to_numpy()
    offset = np.abs(blocks - blocks[np.argmin(times)])
    distance = np.minimum(offset, N - offset).astype(float)
    fitted = (distance >= fit_from * N / 2) & (distance <= fit_to * N / 2)
    if fitted.sum() < 3:
        return math.nan
    slope = np.polyfit(distance[fitted], times[fitted], 1)[0]
    return 1.0 / slope if slope > 0 else math.nan


def profile(failures, a, N, nucleation, meeting, width):
    """Local front speed [blocks per FE time] along both branches: (branch, distance centre, speed) rows."""
    first = failures[failures["a"] == a].groupby("block")["t"].min()
    blocks, times = first.index.to_numpy(), first.to_numpy()
    offset = np.mod(blocks - nucleation, N)
    right = int(np.mod(meeting - nucleation, N)) or N // 2
    rows = []
    for side, inside, distance, length in (("right", (offset > 0) & (offset <= right), offset, right),
                                           ("left", offset >= right, np.mod(N - offset, N), N - right)):
        d, t = distance[inside].astype(float), times[inside]
        for start in np.arange(0, length - width + 1, width / 2):
            window = (d >= start) & (d < start + width)
            if window.sum() >= max(3, width // 2):
                slope = stats.theilslopes(t[window], d[window])[0]
                rows.append({"branch": side, "distance": start + width / 2,
                             "speed": 1.0 / slope if slope > 0 else math.nan})
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--scales", nargs="+", type=float, default=None,
                        help="dt_scale of the replays (default: the run's own only)")
    parser.add_argument("--max-events", type=int, default=10)
    parser.add_argument("--windows", nargs="+", default=["0.3:0.9"])
    parser.add_argument("--profile-width", type=int, default=16)
    parser.add_argument("--csv", type=Path)
    parser.add_argument("--profile-csv", type=Path)
    args = parser.parse_args(argv)
    windows = [tuple(float(x) for x in w.split(":")) for w in args.windows]
    rows, profiles = [], []
    for path in args.runs:
        attrs = read_run_attrs(path)
        if int(attrs["plates"]) != 3:
            continue
        N, h, c_s, params = int(attrs["N"]), float(attrs["h"]), float(attrs["c_s"]), attrs["params"]
        own = float(params["dt_scale"])
        scales = [own] + [s for s in (args.scales or []) if s != own]
        with open_file(path) as file:
            heights = RunFile(file).mesh.layer_mid_height
        spacing = fronts.interface_spacing([heights[interface_layer(a)] for a in (1, 2)])
        c_d = fronts.p_wave_speed(params["K"], params["G"], params["rho"])
        plate = float(heights[2] - heights[0]) / h  # plate plus interface, in blocks
        for increment, scale, failures, reproduced in replays(path, scales, args.max_events):
            if scale == own and not reproduced:
                raise SystemExit(f"{path}: the replay of increment {increment} did not reproduce the stored state")
            line = [f"N={N} seed={attrs['seed']} run dt_scale={own:g} increment={increment} replay dt_scale={scale:g}"]
            for fit_from, fit_to in windows:
                row = fronts.analyse_event(failures, N, h=h, c_s=c_s, spacing=spacing, c_d=c_d, fit_from=fit_from,
                                           fit_to=fit_to)
                old = version1_speed(failures, row["a_first"], N) * h / c_s if row["s"] else math.nan
                rows.append({"run": path.stem, "N": N, "seed": attrs["seed"], "phi": attrs["phi"], "run_dt": own,
                             "increment": increment, "dt_scale": scale, "window": f"{fit_from:g}:{fit_to:g}",
                             **row, "c_f_v1": old})
                line.append(f"[{fit_from:g}:{fit_to:g}] s={row['s']} c_f={row['c_f']:.2f} "
                            f"(right {row['c_f_right']:.2f} {row['quality_right']}, left {row['c_f_left']:.2f} "
                            f"{row['quality_left']}) v1={old:.2f} tau={row['tau']:.2f}")
            if row["s"] >= 1:
                for item in profile(failures, row["a_first"], N, row["nucleation"], row["meeting"],
                                    args.profile_width):
                    profiles.append({"N": N, "dt_scale": scale, "increment": increment, "run": path.stem, **item,
                                     "speed": item["speed"] * h / c_s, "plate_heights": item["distance"] / plate})
            print(" ".join(line), flush=True)
    table = pd.DataFrame(rows)
    if table.empty:
        raise SystemExit("no multi-slip with n = 2 in the given runs")
    print("\nmeaningful fits (quality ok) per (N, run dt_scale, replay dt_scale, window):")
    for key, group in table.groupby(["N", "run_dt", "dt_scale", "window"]):
        ok = group["c_f"].to_numpy(dtype=float)
        ok = ok[np.isfinite(ok)]
        error = ok.std(ddof=1) / math.sqrt(ok.size) if ok.size > 1 else math.nan
        print(f"N={key[0]} run_dt={key[1]:g} dt_scale={key[2]:g} window={key[3]}: events={len(group)} ok={ok.size} "
              f"flagged={len(group) - ok.size} median={np.median(ok) if ok.size else math.nan:.3f} "
              f"mean={ok.mean() if ok.size else math.nan:.3f}+-{error:.3f} c_s "
              f"(multi-slip in the replay: {int((group['s'] >= 2).sum())}); version 1 fit, every event: median "
              f"{group['c_f_v1'].median():.3f}, range {group['c_f_v1'].min():.2f}-{group['c_f_v1'].max():.2f}")
    if profiles:
        local = pd.DataFrame(profiles)
        print(f"\nlocal front speed [c_s] against distance from the nucleation block (windows of "
              f"{args.profile_width} blocks, both branches, events pooled; median, quartiles):")
        for (N, scale), group in local.groupby(["N", "dt_scale"]):
            for distance, at in group.groupby("distance"):
                speed = at["speed"].dropna()
                if speed.size:
                    print(f"N={N} dt_scale={scale:g} distance={distance:.0f} blocks "
                          f"({at['plate_heights'].iloc[0]:.2f} H): median {speed.median():.2f} "
                          f"[{speed.quantile(0.25):.2f}, {speed.quantile(0.75):.2f}] ({speed.size} branches)")
        if args.profile_csv:
            local.to_csv(args.profile_csv, index=False)
    if args.csv:
        table.to_csv(args.csv, index=False)


if __name__ == "__main__":
    main()
