"""Two-sample comparison of slip statistics: the tests detect what they claim, and not more."""

import math

import numpy as np
import pytest
from scipy import stats

from stickslip.statistics.sample_comparison import (SlipSample, compare_distributions, compare_slip_samples,
                                                 ks_resolution, multi_slip_resolution)


def _sample(rng, m, multi_fraction, scale=1.0):
    """A run with ``m`` slip events (n = 2), Weibull drops and geometric event sizes."""
    multi = rng.binomial(m, multi_fraction)
    drops = scale * rng.weibull(2.0, size=m - multi + 2 * multi)
    sizes = rng.geometric(0.05 / scale, size=10 * m)
    return SlipSample(np.array([m - multi, multi]), drops, sizes)


def test_ks_resolution_is_the_asymptotic_critical_distance():
    # the tabulated c(0.05) = 1.358 of the two-sample KS test
    assert ks_resolution(100, 100) == pytest.approx(1.3581 * math.sqrt(2 / 100), rel=1e-4)
    assert math.isnan(ks_resolution(0, 10))


def test_ks_resolution_is_where_the_exact_test_becomes_significant():
    m = 400
    d = ks_resolution(m, m)
    p = stats.ks_2samp(np.arange(m), np.arange(m) + d * m).pvalue
    assert 0.03 < p < 0.07


def test_multi_slip_resolution_matches_the_two_proportion_formula():
    # pooled fraction 0.3, 100 events each: 2.8016 sqrt(0.21 * 0.02)
    assert multi_slip_resolution([70, 30], [70, 30]) == pytest.approx(2.80159 * math.sqrt(0.21 * 0.02), rel=1e-4)
    # no multi-slip at all still gets a finite figure (fraction floored at 1 / m)
    assert 0 < multi_slip_resolution([50, 0], [50, 0]) < 0.2
    assert math.isnan(multi_slip_resolution([0, 0], [10, 2]))


def test_same_distribution_is_not_told_apart():
    rng = np.random.default_rng(3)
    r = compare_slip_samples(_sample(rng, 300, 0.3), _sample(rng, 300, 0.3), n_resamples=500)
    assert r["rho_p"] > 0.05 and r["dmu"]["ks_p"] > 0.05 and r["dmu"]["ad_p"] > 0.05
    assert r["size"]["ad_p"] > 0.05 and r["dmu"]["shift_p"] > 0.05
    assert abs(r["multi_1"] - r["multi_2"]) < r["multi_resolution"]
    assert r["dmu"]["ks"] < r["dmu"]["ks_resolution"]


def test_differences_larger_than_the_resolution_are_detected():
    rng = np.random.default_rng(4)
    first, second = _sample(rng, 300, 0.2), _sample(rng, 300, 0.45, scale=1.3)
    r = compare_slip_samples(first, second, n_resamples=500)
    assert r["rho_p"] < 1e-3 and r["multi_2"] - r["multi_1"] > r["multi_resolution"]
    assert r["dmu"]["ks_p"] < 1e-3 and r["dmu"]["ad_p"] < 0.01 and r["dmu"]["ks"] > r["dmu"]["ks_resolution"]
    assert r["dmu"]["shift"] == pytest.approx(0.3, abs=0.1) and r["dmu"]["shift_p"] < 1e-3
    assert r["size"]["ks_p"] < 1e-3 and r["size"]["ad_p"] < 0.01


def test_rho_of_one_kind_of_event_only_cannot_differ():
    r = compare_slip_samples(SlipSample(np.array([40, 0]), np.linspace(0.1, 0.3, 40), np.ones(40)),
                             SlipSample(np.array([25, 0]), np.linspace(0.1, 0.3, 25), np.ones(25)))
    assert r["rho_p"] == 1.0 and r["rho_1"] == [1.0, 0.0] and r["multi_2"] == 0.0
    assert r["size"]["ad_p"] == 1.0


def test_too_small_samples_give_nan_not_an_error():
    out = compare_distributions([1.0], [1.0, 2.0])
    assert math.isnan(out["ks_p"]) and math.isnan(out["ad_p"]) and out["count_1"] == 1
