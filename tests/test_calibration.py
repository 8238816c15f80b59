"""The estimator's calibration against the truth (issue 56), on data with known answers.

- The lab's eye: slips of one interface closer than the resolution are merged, exactly (drop from the first peak to
  the last post-slip stress, the next waiting time from the merged slip's time).
- The lab's clock: the T0 it returns makes the resolved single slips' <ln(T / T0)> the lab's 4.6.
- The spread of ln T: its normal-theory error is right for normal logs and too small for heavy tails, where the
  bootstrap sees it; the robust spread is a normal sample's sigma and ignores the tails.
- Errors over seeds and the calibration line: exact on known numbers, the line's 95 % intervals cover the truth.
- The loading contrast (the estimator beside the paper's): it recovers a known B from slips pooled over interfaces
  of different strengths and stacks of different loading rates, where the paper's pooled fits read the strengths as
  aging; a direct dependence of the peak on the loading rate enters as predicted; with one loading path per
  interface (n = 1) there is no estimate, because every slip lies on the disorder law whatever B is.
"""

import math

import numpy as np
import pandas as pd
import pytest

from stickslip.statistics.calibration import (LAB_MEAN_LN, calibration_line, lab_clock, log_spread,
                                              merge_unresolved, over_seeds)
from stickslip.statistics.estimator import estimator_table, lab_slips
from stickslip.statistics.loading_contrast import loading_contrast, slips_needed


def _slip_table(times, peaks, drops, multi=None, interface=1):
    times = np.asarray(times, dtype=float)
    return pd.DataFrame({"run": 0, "interface": interface, "t": times,
                         "T": np.concatenate([[np.nan], np.diff(times)]), "mu_before": peaks, "dmu": drops,
                         "multi": np.zeros(times.size, bool) if multi is None else multi})


def test_slips_closer_than_the_resolution_are_one_slip_to_the_lab():
    slips = _slip_table([0.0, 10.0, 10.5, 10.7, 30.0, 30.2], [0.5, 0.6, 0.58, 0.57, 0.62, 0.6],
                        [0.2, 0.05, 0.03, 0.04, 0.1, 0.02], multi=[False, False, True, False, False, False])
    merged = merge_unresolved(slips, 1.0)
    assert merged["t"].tolist() == [0.0, 10.0, 30.0]
    assert merged["merged"].tolist() == [1, 3, 2]
    # from the first peak to the last post-slip stress: 0.6 - (0.57 - 0.04), and 0.62 - (0.6 - 0.02)
    assert merged["dmu"].tolist() == pytest.approx([0.2, 0.07, 0.04])
    assert merged["T"].iloc[1:].tolist() == pytest.approx([10.0, 20.0])
    assert merged["multi"].tolist() == [False, True, False]
    assert merge_unresolved(slips, 0.0)[["t", "dmu", "T"]].equals(slips[["t", "dmu", "T"]])  # nothing merged
    # interfaces are merged apart; the first slip of an interface keeps its own waiting time
    other = _slip_table([5.0, 5.5], [0.4, 0.41], [0.1, 0.1], interface=2).assign(T=[0.3, 0.5])
    both = merge_unresolved(pd.concat([slips, other]), 1.0)
    assert both.loc[both["interface"] == 2, "T"].tolist() == [0.3] and len(both) == 4


def test_the_lab_clock_gives_the_resolved_slips_the_papers_mean_log_wait():
    rng = np.random.default_rng(5)
    rows = []
    for run in range(4):  # cycles of ~1e7 with thermal re-slips ~1e4 after some slips
        t = 0.0
        for _ in range(200):
            t += float(np.exp(rng.normal(math.log(1e7), 0.3)))
            rows.append((run, t, 0.5, 0.1))
            if rng.random() < 0.5:
                t += float(np.exp(rng.normal(math.log(1e4), 1.0)))
                rows.append((run, t, 0.42, 0.02))
    slips = pd.DataFrame(rows, columns=["run", "t", "mu_before", "dmu"]).assign(interface=1, multi=False)
    slips["T"] = slips.groupby("run")["t"].diff()
    t0 = lab_clock(slips)
    resolved = merge_unresolved(slips, t0)
    assert np.nanmean(np.log(resolved["T"] / t0)) == pytest.approx(LAB_MEAN_LN, abs=1e-6)
    assert 1e4 < t0 < 1e6 and len(resolved) < len(slips)  # the re-slips are below the lab's second
    raw = lab_clock(slips, merge=False)
    assert np.nanmean(np.log(slips["T"] / raw)) == pytest.approx(LAB_MEAN_LN, abs=1e-9)


def test_the_spread_of_ln_T_and_its_errors():
    rng = np.random.default_rng(2)
    normal = log_spread(np.exp(0.8 * rng.standard_normal(400)))
    assert normal["std"] == pytest.approx(0.8, abs=3 * normal["std_error"])
    assert normal["robust"] == pytest.approx(0.8, abs=3 * normal["robust_error_bootstrap"])
    assert normal["std_error_bootstrap"] == pytest.approx(normal["std_error"], rel=0.3)
    heavy = log_spread(np.exp(rng.standard_t(2.5, 400)))  # heavy tails: the normal theory is too optimistic
    assert heavy["std_error_bootstrap"] > 1.5 * heavy["std_error"]
    assert heavy["robust"] < 0.8 * heavy["std"]
    assert log_spread(np.exp(rng.standard_t(2.5, 400)), seed=3) != log_spread(np.exp(rng.standard_t(2.5, 400)))
    again = np.exp(np.random.default_rng(7).standard_normal(50))
    assert log_spread(again) == log_spread(again)  # a fixed bootstrap seed: the same numbers every time
    assert math.isnan(log_spread([1.0, 2.0])["std"])


def test_errors_over_seeds_beside_the_within_seed_errors():
    result = over_seeds([1.0, 2.0, 3.0, np.nan], [0.3, 0.4, 0.5, 0.1])
    assert result["seeds"] == 3 and result["mean"] == 2.0 and result["sd"] == 1.0
    assert result["error"] == pytest.approx(1.0 / math.sqrt(3))
    assert result["high"] - result["mean"] == pytest.approx(4.302653 / math.sqrt(3), rel=1e-6)
    assert result["within"] == pytest.approx(math.sqrt((0.09 + 0.16 + 0.25) / 3) / math.sqrt(3))


def test_the_calibration_lines_95_percent_intervals_cover_a_known_line():
    rng = np.random.default_rng(11)
    covered = {"slope": 0, "intercept": 0}
    for _ in range(200):  # settings x seeds; the truth and the estimate both measured with errors
        exact = np.repeat([0.001, 0.002, 0.005, 0.009], 5)
        truth = exact + 0.0004 * rng.standard_normal(20)
        estimate = 0.002 + 0.7 * exact + 0.0006 * rng.standard_normal(20)
        line = calibration_line(truth, np.full(20, 0.0004), estimate, np.full(20, 0.0006))
        covered["slope"] += line["slope_low"] < 0.7 < line["slope_high"]
        covered["intercept"] += line["intercept_low"] < 0.002 < line["intercept_high"]
    assert line["points"] == 20 and line["slope_high"] < 1.0  # the miscalibration is resolved
    assert 0.90 <= covered["slope"] / 200 <= 0.99 and 0.90 <= covered["intercept"] / 200 <= 0.99
    exact = calibration_line([1.0, 2.0, 3.0, 4.0], [0.1] * 4, [1.0, 2.0, 3.0, 4.0], [0.1] * 4)
    assert exact["slope"] == pytest.approx(1.0) and exact["intercept"] == pytest.approx(0.0, abs=1e-9)


STRENGTHS = np.linspace(0.15, 0.3, 5)  # the paper's interfaces driven alone: mean drops 0.15 to 0.3


def _lab(B, direct=0.0, seed=1, count=300):
    return lab_slips(np.random.default_rng(seed), count, B=B, strengths=STRENGTHS, disorder=0.1, path_spread=0.5,
                     direct=direct)


@pytest.mark.parametrize("B", [0.0, 0.02])
def test_the_loading_contrast_recovers_B_where_pooling_reads_the_strengths(B):
    slips = _lab(B)
    contrast = loading_contrast(slips, t0=1.0)
    assert contrast["interfaces"] == 4 and contrast["groups"] == 14  # interface 5 slips in one stack only
    assert abs(contrast["B"] - B) < 3 * contrast["B_error"] and contrast["B_error"] < 0.002
    pooled = estimator_table(slips, t0=1.0).set_index("fit")
    if B == 0.0:  # the strengths and the disorder law pooled: an aging rate where there is none
        assert pooled.loc["origin", "B_low"] > 0.04 and pooled.loc["intercept", "B_low"] > 0.0


def test_a_direct_rate_dependence_of_the_peak_enters_the_contrast_as_predicted():
    B, direct = 0.02, 0.013
    contrast = loading_contrast(_lab(B, direct=direct), t0=1.0)
    # the loading rate raises the peak by direct ln(rate) while <ln T> falls by ~ln(rate): B - direct
    assert contrast["B"] == pytest.approx(B - direct, abs=0.003)
    assert contrast["B"] < B - 5 * contrast["B_error"]


def test_one_loading_path_per_interface_identifies_nothing():
    for B in (0.0, 0.03):
        alone = _lab(B, seed=3)
        alone = alone[alone["n"] == 1]
        rate = 55.0 * 10.0 * 1e-4 / 49.0
        # every slip on the disorder law, T = dmu / rate, whatever B: the records of any B are those of some
        # thresholds without aging (drawn as these drops), so no function of them can tell B
        assert np.allclose(alone["T"] * rate, alone["dmu"], rtol=1e-9)
        result = loading_contrast(alone, t0=1.0)
        assert math.isnan(result["B"]) and "two loading paths" in result["reason"]


def test_the_slips_a_loading_contrast_needs_follow_its_error():
    B, shift, sd = 0.005, 0.4, 0.03
    m = int(round(slips_needed(sd, B, shift)))
    assert m == int(round(2 * (sd / (0.25 * B * shift)) ** 2))
    rng = np.random.default_rng(5)
    estimates = []
    for _ in range(200):  # two paths of one interface, <ln T> apart by `shift`, drops B ln T + scatter `sd`
        lnT = np.concatenate([np.full(m, 10.0), np.full(m, 10.0 + shift)]) + 0.01 * rng.standard_normal(2 * m)
        slips = pd.DataFrame({"interface": 1, "n": np.repeat([1, 2], m), "T": np.exp(lnT), "multi": False,
                              "dmu": B * lnT + sd * rng.standard_normal(2 * m)})
        estimates.append(loading_contrast(slips, t0=1.0)["B"])
    assert np.std(estimates) == pytest.approx(0.25 * B, rel=0.15)
    assert slips_needed(sd, B, 0.0) == math.inf
