"""Periodicity and synchronisation measures on synthetic slip sequences with known answers."""

import math

import numpy as np
import pandas as pd
import pytest

from stickslip.events import periodicity as pe
from stickslip.events.plugin import event_tables

from test_events_extraction import MICRO, N, history


def slips(gamma, s, dsigma):
    return pd.DataFrame({"gamma": np.asarray(gamma, dtype=float), "s": np.asarray(s, dtype=np.int64),
                         "dsigma": np.asarray(dsigma, dtype=float)})


def test_a_perfectly_periodic_sequence():
    """Equal intervals and drops, the pattern single, single, multi (all 3 interfaces) repeated."""
    pattern = np.tile([1, 1, 3], 20)
    row = pe.periodicity(slips(np.arange(60) * 2.5, pattern, np.full(60, 0.3)), n=3)
    assert row["n_slips"] == 60 and row["n_multi"] == 20 and row["n_spanning"] == 20
    assert row["interval_cv"] == pytest.approx(0.0, abs=1e-12) and row["drop_cv"] == pytest.approx(0.0, abs=1e-12)
    assert row["multi_fraction"] == pytest.approx(1 / 3) and row["spanning_fraction"] == pytest.approx(1 / 3)
    assert row["alternation_cv"] == 0.0  # always two singles between multis
    # 40 runs against E[R] = 2 * 40 * 20 / 60 + 1 = 27.67, Var = 26.67 * 25.67 / 59
    assert row["runs_z"] == pytest.approx((40 - 27 - 2 / 3) / math.sqrt(80 / 3 * 77 / 3 / 59))


def test_multi_slips_that_do_not_span_the_stack():
    row = pe.periodicity(slips([0, 1, 2, 3], [2, 2, 3, 1], [1, 1, 1, 1]), n=3)
    assert row["multi_fraction"] == 0.75 and row["spanning_fraction"] == 0.25 and row["n_spanning"] == 1


def test_strict_alternation_and_clustering_by_the_runs_test():
    alternating = np.tile([True, False], 30)
    clustered = np.repeat([True, False], 30)
    assert pe.runs_test(alternating)["runs"] == 60 and pe.runs_test(alternating)["z"] > 7
    assert pe.runs_test(clustered)["runs"] == 2 and pe.runs_test(clustered)["z"] < -7
    assert math.isnan(pe.runs_test(np.zeros(10, dtype=bool))["z"])  # one kind only


def test_a_random_sequence():
    """Poisson slips (exponential intervals), independent multi-slips with p = 0.3, random drops."""
    rng = np.random.default_rng(7)
    m = 20000
    multi = rng.random(m) < 0.3
    row = pe.periodicity(slips(np.cumsum(rng.exponential(1.7, m)), np.where(multi, 2, 1),
                               rng.uniform(0.0, 1.0, m)), n=2)
    assert row["interval_cv"] == pytest.approx(1.0, abs=0.03)
    assert row["drop_cv"] == pytest.approx(1 / math.sqrt(3), abs=0.02)  # uniform on [0, 1]
    assert row["alternation_cv"] == pytest.approx(1 / math.sqrt(0.7), rel=0.04)
    assert row["multi_fraction"] == pytest.approx(0.3, abs=0.01)
    # the runs statistic of random orders is standard normal
    z = [pe.runs_test(rng.random(400) < 0.3)["z"] for _ in range(300)]
    assert abs(np.mean(z)) < 0.2 and np.std(z) == pytest.approx(1.0, abs=0.15)


def test_undefined_with_too_few_events():
    row = pe.periodicity(slips([1.0, 2.0], [2, 2], [0.1, 0.1]), n=2)
    assert math.isnan(row["interval_cv"]) and math.isnan(row["alternation_cv"]) and math.isnan(row["runs_z"])
    assert row["drop_cv"] == pytest.approx(0.0, abs=1e-12)
    empty = pe.periodicity(slips([], [], []), n=2)
    assert empty["n_slips"] == 0 and math.isnan(empty["multi_fraction"]) and math.isnan(empty["drop_cv"])


def test_from_an_increment_table_through_the_event_file_tables():
    """A scripted run: the steady state (from the first slip of interface 2) is single, then (single, multi) x 8."""
    slip1, slip2, multi = ((N, 2), (1.5, 0.0)), ((1, N), (0.0, 2.5)), ((N, N), (1.0, 2.0))
    events = [MICRO, slip1, slip2] + [slip1, MICRO, multi, slip2, MICRO, multi] * 4
    tables = event_tables(history(N, events), N)
    row = tables[pe.TABLE].iloc[0]
    steady = tables["slips"]
    assert row["n_slips"] == len(steady) == 17 and row["n_multi"] == 8 == row["n_spanning"]
    # gamma grows by 1 per event: intervals 2 (over a micro event) and 1 alternate in the pattern
    intervals = np.diff(steady["gamma"].to_numpy())
    assert row["interval_cv"] == pytest.approx(np.std(intervals, ddof=1) / np.mean(intervals))
    # Sigma drops by the mean drop over both interfaces: 0.75, 1.5, 1.25, 1.5, ...
    assert row["drop_cv"] == pytest.approx(pe.coefficient_of_variation(steady["dsigma"]))
    assert row["alternation_cv"] == 0.0 and row["runs_z"] > 3
    assert list(tables[pe.TABLE].columns) == list(pe.COLUMNS)


def test_seed_summary_is_the_mean_and_standard_error_over_runs():
    rows = pd.DataFrame([{"N": 162, "n": 2, **pe.periodicity(slips(np.cumsum(g), [1, 2, 1, 2], [1, 1, 1, 1]), 2)}
                         for g in ([1, 1, 1, 1], [1, 2, 1, 2], [1, 3, 1, 3])])
    summary = pe.seed_summary(rows, ["N", "n"])
    cv = rows["interval_cv"].to_numpy()
    assert summary.loc[0, "runs"] == 3 and summary.loc[0, "n_slips"] == 12
    assert summary.loc[0, "interval_cv"] == pytest.approx(cv.mean())
    assert summary.loc[0, "interval_cv_error"] == pytest.approx(cv.std(ddof=1) / math.sqrt(3))
    assert summary.loc[0, "alternation_cv_runs"] == 0  # two multis per run: undefined everywhere
    assert math.isnan(summary.loc[0, "alternation_cv"])
