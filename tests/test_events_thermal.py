"""The thermal-events analysis and the figS-thermal figure on small real runs (N = 9), and the figure's helpers
on tables with known answers.

The hold trials are checked against what a hold must do: after a hold of T_w no block is left with a barrier
that its rate would have crossed many times over (the depletion the figure shows), trials of one state start
alike, creep and failures happen within the hold.
"""

import math

import numpy as np
import pandas as pd
import pytest

from stickslip import registry
from stickslip.events.thermal import ThermalEventParams
from stickslip.experiment.aging import fit_aging, log_binned
from stickslip.formats.fem_run import read_increments
from stickslip.figures import figs_thermal
from stickslip.figures.experimental_data import EVENTS
from stickslip.figures.style import plt
from stickslip.fem.thermal.protocol import drive_scale
from stickslip.h5io import open_file, read_table
from stickslip.lineage import Artifact
from stickslip.plugin_params import parse_params

pytestmark = pytest.mark.slow

BASE = {"N": 9, "plates": 2, "seed": 1, "k_drive": 1e-3, "relaxation": "exact", "dt_scale": 4.0}
HOT = {"temperature": 2e-3, "attempt_rate": 1.0}
RUNS = {  # name -> parameters: the figure's kinds of run, small
    "stack1": {**BASE, **HOT, "drive_rate": 1e-5, "max_increments": 160},
    "stack2": {**BASE, **HOT, "plates": 3, "drive_rate": 1e-5, "max_increments": 120},
    "fast": {**BASE, **HOT, "drive_rate": 1e-2, "max_increments": 100},
    "shs": {**BASE, **HOT, "drive_rate": 1e-5, "max_increments": 160, "hold_times": (0.0, 1e5, 1e7),
            "hold_delay": 0.2},
    "athermal1": {**BASE, "max_increments": 100},
    "athermal2": {**BASE, "plates": 3, "max_increments": 100},
}
HOLDS = {"states": 3, "hold_times": (0.0, 1e4, 1e6), "below": 0.02}


def _analyse(root, name, values, holds=HOLDS):
    solver, analysis = registry.get("solver", "fem"), registry.get("analysis", "thermal-events")
    params = parse_params(solver.params, values)
    raw = Artifact(root / f"{name}.h5", registry.run_id(solver, params), solver.name, solver.produces)
    if not raw.path.exists():
        solver.run(params, raw.path, threads=1, inputs={})
    analysis_params = parse_params(analysis.params, holds)
    events = Artifact(root / f"{name}.events.h5", registry.derived_run_id(analysis, analysis_params, [raw.run_id]),
                      analysis.name, analysis.produces, raw)
    analysis.run(analysis_params, raw, events.path)
    return events


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """The six small fem runs analysed, and a small virtual experiment (stacks n = 1, 2, seed 1, 2000 s)."""
    root = tmp_path_factory.mktemp("thermal")
    inputs = {figs_thermal.THERMAL: [_analyse(root, name, values) for name, values in RUNS.items()], EVENTS: []}
    solver, analysis = registry.get("solver", "rate-state-lever"), registry.get("analysis", "experiment-events")
    for n in (1, 2):
        params = parse_params(solver.params, {"n": n, "seed": 1, "duration": 2000.0, "path_disorder": 0.02})
        raw = Artifact(root / f"lever{n}.h5", registry.run_id(solver, params), solver.name, solver.produces)
        solver.run(params, raw.path, threads=1, inputs={})
        events = Artifact(root / f"lever{n}.events.h5", registry.derived_run_id(analysis, analysis.params(),
                                                                                [raw.run_id]),
                          analysis.name, analysis.produces, raw)
        analysis.run(parse_params(analysis.params, {}), raw, events.path)
        inputs[EVENTS].append(events)
    return inputs


def _tables(artifact):
    with open_file(artifact.path) as f:
        return {name: read_table(f, name) for name in ("slip_events", "interfaces", "holds", "creep", "barriers")}


def test_waiting_times_are_the_clock_between_slips_of_an_interface(study):
    events = study[figs_thermal.THERMAL][0]
    slips = _tables(events)["slip_events"]
    table = read_increments(events.parent.path)
    full = table["kick"].to_numpy() & (table["A_a1"].to_numpy() == 9)
    t = table["t"].to_numpy()[full]
    rows = np.searchsorted(table["increment"].to_numpy()[full], slips["increment"].to_numpy())
    expected = np.where(rows > 0, t[rows] - t[np.maximum(rows - 1, 0)], np.nan)
    assert len(slips) >= 3
    np.testing.assert_array_equal(slips["T_fe"].to_numpy(), expected)
    np.testing.assert_array_equal(slips["B_a_sig0"].to_numpy()[rows > 0],
                                  slips["dmu_sig0"].to_numpy()[rows > 0] / np.log(expected[rows > 0]))
    assert np.all(slips["hold"].to_numpy()[rows > 0] == 0.0)  # this run has no holds of its own


def test_an_athermal_run_has_no_clock_and_no_hold_trials(study):
    tables = _tables(study[figs_thermal.THERMAL][4])
    assert np.all(np.isnan(tables["slip_events"]["T_fe"])) and np.all(np.isnan(tables["slip_events"]["t"]))
    assert tables["holds"].empty and tables["barriers"].empty
    assert 0.0 <= tables["interfaces"]["R_slow"].iloc[0] < 1.0


def test_hold_trials_deplete_the_barriers_they_cross_and_start_alike(study):
    tables = _tables(study[figs_thermal.THERMAL][0])
    holds, creep, barriers = tables["holds"], tables["creep"], tables["barriers"]
    assert len(holds) == 3 * 3 and set(holds["hold_time"]) == {0.0, 1e4, 1e6}
    assert np.all(holds.loc[holds["hold_time"] == 0.0, "hold_hops"] == 0)
    for _, group in holds.groupby("state"):  # paired: every hold of a state starts from the same state
        assert group["mu_start"].nunique() == 1
        starts = [barriers.loc[barriers["trial"] == trial, "start"].to_numpy() for trial in group["trial"]]
        assert all(np.array_equal(starts[0], other) for other in starts[1:])
    for _, trial in holds[holds["hold_time"] > 0].iterrows():
        steps = creep[creep["trial"] == trial["trial"]]
        assert len(steps) == trial["hold_hops"] and np.all(steps["t"] < trial["hold_time"])
        if trial["failed_in_hold"]:
            continue  # the slip ended the hold
        last = steps["t"].max() if len(steps) else 0.0
        quiet = trial["hold_time"] - last  # no hop in this time: every barrier below ln(nu quiet) would have hopped
        end = barriers.loc[barriers["trial"] == trial["trial"], "end"].to_numpy()
        assert np.sum(end < math.log(quiet) - 5.0) == 0  # survival probability < exp(-e^5) per block
    assert holds["hold_hops"].sum() > 0


def test_the_analysis_writes_the_same_bytes_twice(study, tmp_path):
    first = study[figs_thermal.THERMAL][0]
    again = _analyse(tmp_path, "again", RUNS["stack1"])
    with open_file(first.path) as a, open_file(again.path) as b:
        for name in ("slip_events", "holds", "creep", "barriers"):
            pd.testing.assert_frame_equal(read_table(a, name), read_table(b, name))


def test_hold_differences_barrier_counts_and_creep_on_known_tables():
    holds = pd.DataFrame({"trial": range(6), "state": [5, 5, 5, 9, 9, 9], "hold_time": [0.0, 10.0, 100.0] * 2,
                          "peak": [0.40, 0.43, 0.47, 0.50, 0.51, 0.57], "failed_in_hold": [False, False, True] * 2,
                          "t_slip": [1.0, 20.0, 50.0, 1.0, 20.0, 60.0]})
    table = figs_thermal.hold_differences(holds).set_index("hold_time")
    assert table.loc[10.0, "mean"] == pytest.approx(0.02) and table.loc[100.0, "mean"] == pytest.approx(0.07)
    assert table.loc[10.0, "sem"] == pytest.approx(np.std([0.03, 0.01], ddof=1) / np.sqrt(2))
    assert table.loc[100.0, "failed"] == 1.0 and table.loc[10.0, "failed"] == 0.0
    barriers = pd.DataFrame({"trial": np.repeat(range(6), 3), "block": np.tile(range(3), 6),
                             "start": np.tile([1.0, 5.0, 30.0], 6), "end": np.tile([6.0, 7.0, 30.0], 6)})
    counts = figs_thermal.barrier_counts(holds, barriers, np.array([2.0, 5.5, 40.0]))
    np.testing.assert_array_equal(counts["start"], [1, 2, 3])
    np.testing.assert_array_equal(counts[10.0], [0, 0, 3])
    creep = pd.DataFrame({"trial": [2, 2, 5], "t": [5.0, 40.0, 30.0], "R_1": [1.0, 2.0, 4.0]})
    curve = figs_thermal.creep_curve(holds, creep, np.array([1.0, 10.0, 45.0, 55.0]))
    # trial 2 slipped at 50, trial 5 at 60: at 55 only trial 5 (4.0); at 45: (2 + 4) / 2
    np.testing.assert_allclose(curve, [0.0, 0.5, 3.0, 4.0])


def test_the_figure_is_drawn_reproducibly_from_the_small_study(study, tmp_path):
    figure = registry.get("figure", "figS-thermal")
    params = parse_params(figure.params, {"drive_rate": 1e-5})
    for name in ("a", "b"):
        figure.run(params, study, tmp_path / f"{name}.pdf")
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    runs = figs_thermal.load_runs(study[figs_thermal.THERMAL])
    rates = figs_thermal.rate_table(runs)
    assert list(rates["drive_rate"][:2]) == [1e-5, 1e-2] and np.isnan(rates["drive_rate"].iloc[2])
    slow = figs_thermal.slow_slip_table(runs, params, None)
    assert set(slow["source"]) == {"thermal", "athermal"} and set(slow["n"]) == {1, 2}


def test_params_of_the_hold_trials():
    params = parse_params(ThermalEventParams, {})
    assert params.hold_times[0] == 0.0 and params.hold_interfaces == 1


def test_the_figure_plots_the_numbers_of_its_runs(study):
    params = parse_params(registry.get("figure", "figS-thermal").params, {"drive_rate": 1e-5})
    figure = figs_thermal.draw(params, study)
    shs, held = _tables(study[figs_thermal.THERMAL][3]), _tables(study[figs_thermal.THERMAL][0])
    # (a) slide-hold-slide: every single slip with a waiting time (T0 = 1 / attempt_rate = 1) and the fit through
    # the origin, dmu = B ln(nu T)
    slips = shs["slip_events"]
    slips = slips[~slips["multi"].to_numpy(dtype=bool) & np.isfinite(slips["T_fe"].to_numpy(dtype=float))]
    assert len(slips) >= 5
    a = figure.axes[0]
    [points] = [line for line in a.get_lines() if line.get_marker() == "o" and line.get_linestyle() == "None"]
    np.testing.assert_array_equal(points.get_xdata(), slips["T_fe"].to_numpy(float))
    np.testing.assert_array_equal(points.get_ydata(), slips["dmu_sig0"].to_numpy(float))
    bins = log_binned(slips["T_fe"].to_numpy(float), slips["dmu_sig0"].to_numpy(float),
                      bins_per_decade=params.bins_per_decade)
    [squares] = [line for line in a.get_lines() if line.get_marker() == "s"]  # binned means
    np.testing.assert_array_equal(squares.get_xdata(), bins["T"].to_numpy())
    np.testing.assert_array_equal(squares.get_ydata(), bins["dmu_mean"].to_numpy())
    dotted = [line for line in a.get_lines() if line.get_linestyle() == ":"]
    try:
        fit = fit_aging(slips["T_fe"].to_numpy(float), slips["dmu_sig0"].to_numpy(float), t0=1.0, fit="origin",
                        bins_per_decade=params.bins_per_decade)
    except ValueError:  # too few slips per bin in this small run: no fit drawn
        assert dotted == []
    else:
        np.testing.assert_allclose(dotted[0].get_ydata(), fit.B * np.log(dotted[0].get_xdata()), rtol=1e-12)
    # (b) paired holds of the n = 1 run at the figure's drive rate: the mean peak difference per hold time
    table = figs_thermal.hold_differences(held["holds"])
    assert len(table) == len(HOLDS["hold_times"]) - 1  # each hold time against the hold of 0
    [means] = [line for line in figure.axes[1].get_lines() if line.get_marker() == "o"]
    np.testing.assert_array_equal(means.get_xdata(), table["hold_time"].to_numpy())
    np.testing.assert_array_equal(means.get_ydata(), table["mean"].to_numpy())
    plt.close(figure)


def test_an_elastic_unload_stops_at_the_first_block_that_would_leave_its_well(study):
    """Loading.unload_size: the unload it gives keeps every well index; where it is capped, a step 1e-4 further
    changes one (the bisection's tolerance is 1e-5)."""
    replay = registry.replay("fem", study[figs_thermal.THERMAL][0].parent.path)
    simulation = replay.simulation
    increments = read_increments(replay.path)
    capped = 0
    for increment in increments["increment"].to_numpy()[increments["kick"].to_numpy()][:20]:
        state = replay._state(int(increment))
        simulation.stack.restore(state)
        wells = simulation.stack.well_index()
        wanted = 100.0 * simulation.loading.step_size(False) + 1.0
        unload = simulation.loading.unload_size(wanted)
        assert 0.0 <= unload <= wanted
        simulation.loading.load(-unload)
        assert np.array_equal(simulation.stack.well_index(), wells)
        if unload < wanted:
            capped += 1
            simulation.stack.restore(state)
            simulation.loading.load(-unload * (1.0 + 1e-4))
            assert not np.array_equal(simulation.stack.well_index(), wells)
    assert capped > 0


def test_a_hold_unloads_a_state_nearer_its_threshold_than_below(study):
    """A state ``d`` eps0 of drive under its threshold held at ``below = d + 0.1, 0.3, 0.5``: each hold says it
    reached its ``below``, and the held stresses are those of an elastic unload (linear in ``below``: their
    differences in the ratio 0.2 : 0.4). A hold that could not unload would start all three at the state's load."""
    replay = registry.replay("fem", study[figs_thermal.THERMAL][0].parent.path)
    simulation = replay.simulation
    slips = _tables(study[figs_thermal.THERMAL][0])["slip_events"]
    state = int(slips["increment"].iloc[len(slips) // 2])
    simulation.stack.restore(replay._state(state))
    scale = drive_scale(simulation.loading.response, simulation.params.eps0, simulation.mesh)
    near = simulation.loading.step_size(False) * scale
    assert simulation.loading.unload_size(0.5 / scale) == 0.5 / scale  # the unloads below are not capped
    trials = [replay.hold(state, 0.0, near + extra, 0) for extra in (0.1, 0.3, 0.5)]
    np.testing.assert_allclose([trial["held_below"] for trial in trials], near + np.array([0.1, 0.3, 0.5]),
                               rtol=1e-12)
    start = np.array([trial["mu_start"] for trial in trials])
    assert start[0] > start[1] > start[2]
    np.testing.assert_allclose((start[0] - start[1]) / (start[0] - start[2]), 0.2 / 0.4, rtol=1e-6)
