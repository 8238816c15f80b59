"""The drop law at equal waiting time (stickslip.statistics.drop_law), on records with known answers.

- Holds (the waiting time set by the experimenter, not by the threshold): two records of different aging rates differ
  at equal T by the difference of the rates, which the contrast recovers within its bootstrap error.
- A constant drive (the waiting time made by the threshold, the disorder law T = dmu / rate): records of aging rate
  0.02 and 0 have one drop law, so the contrast reads no aging at equal T, and the paper's estimator reads the same
  on the aging record as on its waiting times with the aging-free record's drops.
- The drop law of a known line, and the refusals.
"""

import math

import numpy as np
import pytest

from stickslip.statistics.drop_law import at_equal_T, drop_law, drop_law_contrast
from stickslip.statistics.estimator import estimate, synthetic_slips


def _holds(B, seed, count=2000):
    rng = np.random.default_rng(seed)
    T = np.exp(rng.uniform(np.log(10.0), np.log(1e5), count))
    return T, 0.2 + B * np.log(T) + 0.02 * rng.standard_normal(count)


def _driven(B, seed, count=2000, drop=0.2, T_typical=200.0):
    """Slips of one interface at a constant drive: the typical drop ``drop`` whatever B."""
    slips = synthetic_slips(np.random.default_rng(seed), count, B=B, gap=drop - B * math.log(T_typical), drop=drop,
                            disorder=0.2, path_spread=0.0, T_typical=T_typical)
    slips = slips[slips["dmu"] > 0]  # a threshold drawn too low runs the fixed point away: no slip
    return slips["T"].to_numpy(), slips["dmu"].to_numpy()


def test_the_drop_law_of_a_line_in_ln_T():
    x = np.repeat(np.arange(0.25, 5.0, 0.5), 20) + np.tile(np.linspace(-0.2, 0.2, 20), 10)
    law = drop_law(np.exp(x), 0.1 + 0.03 * x, t0=1.0)
    assert law["x"].size == 10 and np.all(law["slips"] == 20)
    assert np.allclose(law["y"], 0.1 + 0.03 * law["x"], atol=1e-12)
    sparse = drop_law(np.exp(x[:12]), x[:12], t0=1.0, min_slips=13)
    assert sparse["x"].size == 0


def test_holds_show_the_difference_of_the_aging_rates_at_equal_T():
    T, dmu = _holds(0.02, seed=1)
    T_ref, dmu_ref = _holds(0.0, seed=2)
    contrast = drop_law_contrast(T, dmu, T_ref, dmu_ref, t0=1.0)
    assert contrast["reason"] == "" and contrast["share"] > 0.95
    assert abs(contrast["slope"] - 0.02) < 3 * contrast["slope_error"] and contrast["slope_error"] < 0.002
    same = drop_law_contrast(*_holds(0.0, seed=3), T_ref, dmu_ref, t0=1.0)
    assert abs(same["slope"]) < 3 * same["slope_error"]


def test_at_a_constant_drive_aging_leaves_the_drop_law_and_the_estimator_reads_only_the_waiting_times():
    B = 0.02
    T, dmu = _driven(B, seed=4)
    T_ref, dmu_ref = _driven(0.0, seed=5)
    assert np.allclose(dmu, 0.2 * T / 200.0) and np.allclose(dmu_ref, 0.2 * T_ref / 200.0)  # one law: the reload
    contrast = drop_law_contrast(T, dmu, T_ref, dmu_ref, t0=1.0)
    assert contrast["share"] > 0.8  # the aging record spreads wider than the reference
    assert abs(contrast["slope"]) < 0.05 * B  # no trace of the aging at equal T
    own = estimate(T, dmu, t0=1.0, fit="intercept")
    T_swapped, dmu_swapped = at_equal_T(T, T_ref, dmu_ref, t0=1.0, rng=np.random.default_rng(6))
    swapped = estimate(T_swapped, dmu_swapped, t0=1.0, fit="intercept")
    assert T_swapped.size > 0.8 * T.size
    assert swapped["B"] == pytest.approx(own["B"], rel=0.05)  # the aging-free drops read the same "aging"


def test_no_contrast_without_a_reference_law_or_overlap():
    T, dmu = _holds(0.01, seed=7, count=200)
    narrow = drop_law_contrast(T, dmu, T[:4], dmu[:4], t0=1.0)
    assert math.isnan(narrow["slope"]) and "fewer than two bins" in narrow["reason"]
    apart = drop_law_contrast(T * 1e9, dmu, T, dmu, t0=1.0)
    assert math.isnan(apart["slope"]) and "within the reference" in apart["reason"]
    assert at_equal_T(T, T[:2], dmu[:2], t0=1.0, rng=np.random.default_rng(0))[0].size == 0
