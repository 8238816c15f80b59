"""The aging trials of the thermal-events analysis and their summaries: known answers and a small real run (N = 9).

- Omori-Utsu by maximum likelihood: sequences drawn from a known law give back its p and c within their
  bootstrap errors; too few events give no fit.
- Paired slopes: states with known slopes give back their mean; failed holds are left out; the curvature
  finds a quadratic term and none in a line.
- Driven aftershocks: the time and drive to the next event on each interface in a scripted table.
- Through the solver: the aging trials of a small aging run (holds at two loads with two slips each,
  aftershock holds with their controls at the post-slip stress), and the figure on them.
"""

import math

import numpy as np
import pandas as pd
import pytest

from stickslip import registry
from stickslip.summaries.aging_summary import curvature, driven_aftershocks, paired_slopes
from stickslip.statistics.omori import bootstrap_omori, fit_omori, omori_rate_integral
from stickslip.h5io import open_file, read_table
from stickslip.lineage import Artifact
from stickslip.plugin_params import parse_params


def _omori_sequences(K, c, p, T, M, seed):
    rng = np.random.default_rng(seed)
    q = 1.0 - p
    out = []
    for _ in range(M):
        u = rng.random(rng.poisson(K * omori_rate_integral(c, p, 0.0, T)))
        out.append(np.sort((c ** q + u * ((T + c) ** q - c ** q)) ** (1.0 / q) - c))
    return out


@pytest.mark.parametrize("p", [0.7, 1.2])
def test_omori_utsu_maximum_likelihood_recovers_the_law(p):
    K, c, T = 2.0, 50.0, 1e8
    fit = bootstrap_omori(_omori_sequences(K, c, p, T, 40, seed=int(10 * p)), 0.0, T, samples=40)
    assert fit.n_mainshocks == 40 and fit.n_events > 100
    assert abs(fit.p - p) < 4 * fit.p_error and fit.p_error < 0.1
    assert abs(math.log(fit.c / c)) < 4 * fit.c_error / fit.c
    # the integral is exact at p = 1 too
    assert omori_rate_integral(3.0, 1.0, 2.0, 10.0) == pytest.approx(math.log(13.0 / 5.0), rel=1e-12)
    assert omori_rate_integral(3.0, 1.0 + 1e-10, 2.0, 10.0) == pytest.approx(math.log(13.0 / 5.0), rel=1e-8)


def test_too_few_aftershocks_give_no_fit():
    fit = fit_omori([np.array([1.0, 2.0]), np.array([])], 0.0, 10.0)
    assert math.isnan(fit.p) and fit.n_events == 2 and fit.n_mainshocks == 2


def _holds(slopes, noise=0.0, seed=0):
    rng = np.random.default_rng(seed)
    times = np.array([0.0, 1e6, 1e8, 1e10, 1e12])
    rows = []
    for state, slope in enumerate(slopes):
        for t in times:
            x = math.log(t) if t > 0 else 0.0
            rows.append({"state": state, "hold_time": t, "below": 0.02, "interface": 1, "failed_in_hold": False,
                         "peak": 0.5 + slope * x + noise * rng.normal() + 1e-3 * state})
    return pd.DataFrame(rows)


def test_paired_slopes_are_the_mean_of_the_states_slopes_without_failed_holds():
    peaks = _holds([0.004, 0.006, 0.005])
    slope, error, states = paired_slopes(peaks)
    assert slope == pytest.approx(0.005, rel=1e-9) and states == 3
    assert error == pytest.approx(np.std([0.004, 0.006, 0.005], ddof=1) / math.sqrt(3), rel=1e-9)
    failed = peaks.copy()
    failed.loc[(failed["state"] == 0) & (failed["hold_time"] >= 1e10), "failed_in_hold"] = True
    failed.loc[(failed["state"] == 0) & (failed["hold_time"] >= 1e10), "peak"] = 9.0  # the held stress: left out
    assert paired_slopes(failed)[2] == 2  # state 0 keeps 2 points < 3
    twice = peaks[peaks["hold_time"].isin([1e6, 1e12])]  # a study that holds every state twice: a slope from both
    assert paired_slopes(twice)[0] == pytest.approx(0.005, rel=1e-9) and paired_slopes(twice)[2] == 3
    line = _holds([0.005] * 4, noise=1e-4)
    bend, bend_error = curvature(line)
    assert abs(bend) < 3 * bend_error
    curved = line.assign(peak=line["peak"] + 1e-4 * np.log(np.maximum(line["hold_time"], 1.0)) ** 2)
    bend, bend_error = curvature(curved)
    assert bend == pytest.approx(1e-4, rel=0.1) and bend > 10 * bend_error


def test_driven_aftershocks_take_the_next_event_on_each_interface():
    N = 4
    table = pd.DataFrame({"t": [0.0, 1.0, 1.0, 3.0, 3.0, 7.0, 7.0, 9.0, 9.0],
                          "kick": [True, False, True, False, True, False, True, False, True],
                          "A_a1": [0, 0, 4, 0, 0, 0, 1, 0, 4], "A_a2": [0, 0, 1, 0, 2, 0, 0, 0, 0]})
    out = driven_aftershocks(table, N, rate=0.5).set_index(["a", "b"])
    assert out.loc[(1, 1), "t"] == 6.0 and out.loc[(1, 2), "t"] == 2.0  # from the slip at t = 1
    assert out.loc[(1, 2), "drive"] == 1.0
    assert len(out) == 2  # one mainshock with a following slip, two interfaces


# --- through the solver ------------------------------------------------------------------------

RUN = {"N": 9, "plates": 3, "seed": 1, "k_drive": 1e-3, "relaxation": "exact", "dt_scale": 4.0, "max_increments": 160,
       "temperature": 2e-3, "drive_rate": 1e-5, "attempt_rate": 1.0, "junction_strengthening": 5.0}
TRIALS = {"states": 2, "hold_times": (0.0, 1e4, 1e7), "below": 0.02, "hold_loads": (0.05,), "each": 2,
          "hold_interfaces": 0, "aftershock_states": 1, "aftershock_time": 1e8}


@pytest.fixture(scope="module")
def trials(tmp_path_factory):
    root = tmp_path_factory.mktemp("aging-trials")
    solver, analysis = registry.get("solver", "fem"), registry.get("analysis", "thermal-events")
    params = parse_params(solver.params, RUN)
    raw = Artifact(root / "run.h5", registry.run_id(solver, params), solver.name, solver.produces)
    solver.run(params, raw.path, threads=1, inputs={})
    analysis_params = parse_params(analysis.params, TRIALS)
    events = Artifact(root / "events.h5", registry.derived_run_id(analysis, analysis_params, [raw.run_id]),
                      analysis.name, analysis.produces, raw)
    analysis.run(analysis_params, raw, events.path)
    with open_file(events.path) as file:
        tables = {name: read_table(file, name) for name in ("holds", "trial_slips", "aftershock_trials", "aftershocks")}
    return events, tables


@pytest.mark.slow
def test_hold_trials_at_two_loads_record_two_slips_of_every_interface(trials):
    _, tables = trials
    holds, slips = tables["holds"], tables["trial_slips"]
    assert len(holds) == 2 * 3 * 2 and set(holds["below"]) == {0.02, 0.05}
    for _, group in holds.groupby(["state", "below"]):  # paired: every hold of a state starts alike
        assert group["mu_start"].nunique() == 1
    higher = holds.groupby("state").apply(lambda g: g.loc[g["below"] == 0.02, "mu_start"].iloc[0]
                                          - g.loc[g["below"] == 0.05, "mu_start"].iloc[0])
    assert np.all(higher > 0)  # the hold nearer the threshold is at a higher stress
    complete = holds["events"] < 2000
    for trial in holds.loc[complete, "trial"]:
        mine = slips[slips["trial"] == trial]
        assert set(mine["interface"]) == {1, 2} and mine.groupby("interface")["slip"].max().min() >= 2
        assert np.all(np.diff(mine["t"]) >= 0)
        assert np.all((mine["precursors"] >= 0) & (mine["precursors"] <= 1))
        assert np.all(mine["widening"] > 0) and np.all(mine["depth"] > 0)
    first = slips[slips["slip"] == 1].merge(holds, on="trial")
    first = first[first["interface_x"] == first["interface_y"]]
    assert np.allclose(first["peak_x"], first["peak_y"])  # the holds table's peak is its first slip's


@pytest.mark.slow
def test_aftershock_holds_and_their_controls_at_the_post_slip_stress(trials):
    _, tables = trials
    shocks, events = tables["aftershock_trials"], tables["aftershocks"]
    assert len(shocks) >= 2 and set(shocks["kind"]) == {0, 1}
    for _, pair in shocks.groupby("mainshock"):
        post, control = pair[pair["kind"] == 0].iloc[0], pair[pair["kind"] == 1].iloc[0]
        a = post["a"]
        assert post["state"] == post["mainshock"] and control["state"] > post["mainshock"]
        assert control[f"stress_{a}"] == pytest.approx(post[f"stress_{a}"], abs=2e-3)
    for _, trial in shocks.iterrows():
        mine = events[events["trial"] == trial["trial"]]
        assert len(mine) == trial["events"] and np.all(mine["t"] < 1e8) and np.all(np.diff(mine["t"]) >= 0)


@pytest.mark.slow
def test_the_aging_figure_draws_the_trials(trials, tmp_path):
    events, _ = trials
    figure = registry.get("figure", "figS-aging")
    params = parse_params(figure.params, {"drive_rate": 1e-5, "temperature": 2e-3})
    figure.run(params, {"analysis:thermal-events": [events]}, tmp_path / "figS-aging.pdf")
    assert (tmp_path / "figS-aging.pdf").stat().st_size > 0 and (tmp_path / "figS-aging.png").stat().st_size > 0
