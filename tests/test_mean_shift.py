"""The two-sample test of Fig. 2f: its level, its power and its resolution."""

import math

import numpy as np

from stickslip.statistics.mean_shift import detectable_shift, shift_test


def _samples(rng, shift, m, repeats):
    """``repeats`` pairs of Weibull(2) samples (mean 1) of size ``m``, the second moved by ``shift``."""
    base = rng.weibull(2.0, size=(repeats, 2, m)) / math.gamma(1.5)
    base[:, 1] += shift
    return base


def test_equal_samples_are_rejected_at_the_level_alpha():
    rng = np.random.default_rng(1)
    p = [shift_test(a, b)["p_value"] for a, b in _samples(rng, 0.0, 60, 2000)]
    rejected = np.mean(np.array(p) < 0.05)
    assert abs(rejected - 0.05) < 0.015  # 2000 tries: counting error 0.005


def test_the_detectable_shift_is_detected_with_the_stated_power():
    rng = np.random.default_rng(2)
    m = 80
    # Weibull(2) has the coefficient of variation sqrt(4 / pi - 1): the normal approximation
    # of Welch's statistic detects 2.80 cv sqrt(2 / m) = 0.23 at alpha = 0.05 with power 0.8
    expected = (1.959964 + 0.841621) * math.sqrt(4 / math.pi - 1) * math.sqrt(2 / m)
    estimates = [detectable_shift(a, b) for a, b in _samples(rng, 0.0, m, 400)]
    assert abs(np.mean(estimates) - expected) < 0.01
    p = [shift_test(a, b)["p_value"] for a, b in _samples(rng, expected, m, 4000)]
    detected = np.mean(np.array(p) < 0.05)
    assert abs(detected - 0.8) < 0.025  # 4000 tries: counting error 0.006


def test_the_measured_shift_and_too_small_samples():
    result = shift_test([1.0, 2.0, 3.0], [2.2, 2.0, 1.8])
    assert math.isclose(result["shift"], 0.0, abs_tol=1e-12)
    assert result["count_1"] == result["count_2"] == 3
    assert result["p_value"] > 0.9
    short = shift_test([1.0], [1.0, 2.0])
    assert math.isnan(short["p_value"]) and math.isnan(short["detectable_shift"])
    assert math.isclose(short["shift"], 0.5)
