"""Aging fit, aging rate per slip, its spread with n, slow slip: against known synthetic laws."""

import numpy as np
import pandas as pd
import pytest

from stickslip.experiment import aging


def _aging_sample(B, scatter, size, seed):
    rng = np.random.default_rng(seed)
    T = 10.0 ** rng.uniform(0.5, 3.0, size)
    return T, B * np.log(T) + rng.normal(0.0, scatter, size)


def test_log_binned_means_and_edges():
    T = np.array([1.5, 2.0, 2.5, 15.0, 20.0, 25.0, 150.0])
    values = np.array([1.0, 2.0, 3.0, 10.0, 20.0, 30.0, 7.0])
    bins = aging.log_binned(T, values, bins_per_decade=1, min_count=2)
    assert bins["count"].tolist() == [3, 3]
    np.testing.assert_allclose(bins["T_low"], [1.0, 10.0])
    np.testing.assert_allclose(bins["dmu_mean"], [2.0, 20.0])
    np.testing.assert_allclose(bins["dmu_std"], [1.0, 10.0])
    np.testing.assert_allclose(bins["T"], [np.cbrt(1.5 * 2.0 * 2.5), np.cbrt(15.0 * 20.0 * 25.0)])


@pytest.mark.parametrize("B, seed", [(0.053, 1), (0.02, 2), (0.1, 3)])
def test_fit_recovers_B_with_an_honest_error(B, seed):
    T, dmu = _aging_sample(B, 0.03, 600, seed)
    fit = aging.fit_aging(T, dmu)
    assert fit.B == pytest.approx(B, rel=0.05)
    assert abs(fit.B - B) < 4 * fit.B_error
    assert fit.B_error < 0.05 * B
    assert fit.n_slips == 600


def test_fit_error_shrinks_with_more_slips():
    small = aging.fit_aging(*_aging_sample(0.05, 0.03, 200, 5))
    large = aging.fit_aging(*_aging_sample(0.05, 0.03, 3200, 5))
    assert large.B_error < small.B_error / 2.5  # ~ 1/sqrt(16) = 1/4


def test_fit_needs_two_bins():
    with pytest.raises(ValueError, match="at least two bins"):
        aging.fit_aging([10.0, 11.0, 12.0], [0.1, 0.1, 0.1])


def test_aging_rate_per_slip():
    rate = aging.aging_rate([0.1, 0.2, 0.3, 0.1], [np.e, np.e ** 2, 0.5, np.nan])
    np.testing.assert_allclose(rate[:2], [0.1, 0.1])
    assert np.isnan(rate[2]) and np.isnan(rate[3])


def test_spread_of_aging_rate_is_normalised_by_the_interface_alone():
    rng = np.random.default_rng(0)
    rows = []
    for protocol, n, a, spread in [("individual", 1, 1, 0.01), ("individual", 1, 2, 0.02),
                                   ("stack", 1, 1, 0.5), ("stack", 3, 1, 0.03), ("stack", 3, 2, 0.02)]:
        for b in 0.05 + spread * rng.standard_normal(4000):
            rows.append((protocol, n, a, b))
    table = aging.spread_of_aging_rate(pd.DataFrame(rows, columns=["protocol", "n", "interface", "B_a"]))
    table = table.set_index(["interface", "n"])
    assert table.loc[(1, 1), "std"] == pytest.approx(0.01, rel=0.05)  # individual, not stack n = 1
    assert table.loc[(1, 3), "std_normalised"] == pytest.approx(3.0, rel=0.05)
    assert table.loc[(2, 3), "std_normalised"] == pytest.approx(1.0, rel=0.05)
    assert table.loc[(2, 1), "std_normalised"] == 1.0


def test_slow_slip_fraction_and_subset():
    np.testing.assert_allclose(aging.slow_slip_fraction([6.0, 4.0, 0.0], [4.5, 4.0, 0.0]), [0.25, 0.0, np.nan])
    slips = pd.DataFrame({"drift": [0.0, 0.0029, 0.003, 0.01, np.nan]})
    assert aging.without_slow_slip(slips).index.tolist() == [0, 1]


def test_intercept_fit_recovers_an_offset_that_the_origin_fit_reads_as_aging():
    """dmu = c + B ln T: the intercept fit finds B and c within their errors; the paper's fit through
    the origin returns B + c / <ln T> (here 0.03 + 0.08 / ~4 = ~0.05)."""
    B, c = 0.03, 0.08
    T, dmu = _aging_sample(B, 0.02, 2000, 7)
    dmu = dmu + c
    free = aging.fit_aging(T, dmu, fit="intercept")
    assert abs(free.B - B) < 4 * free.B_error and free.B_error < 0.05 * B
    assert abs(free.c - c) < 4 * free.c_error and free.c_error < 0.05 * c
    origin = aging.fit_aging(T, dmu, fit="origin")
    assert origin.c == 0.0 and origin.c_error == 0.0
    x = np.log(T).mean()
    assert origin.B == pytest.approx(B + c / x, rel=0.1)
    assert origin.B > 1.5 * B
    np.testing.assert_allclose(free([1.0, np.e]), [free.c, free.c + free.B])


def test_intercept_fit_needs_three_bins_and_a_known_kind():
    T = np.repeat([2.0, 20.0], 10)
    with pytest.raises(ValueError, match="at least three bins"):
        aging.fit_aging(T, 0.05 * np.log(T) + 0.01 * np.arange(20) % 3, fit="intercept")
    with pytest.raises(ValueError, match="fit must be one of origin, intercept"):
        aging.fit_aging(T, T, fit="free")


def test_per_interface_fits_recover_each_rate():
    rng = np.random.default_rng(3)
    rates = {1: 0.02, 2: 0.05}
    rows = []
    for a, B in rates.items():
        T = 10.0 ** rng.uniform(0.5, 3.0, 800)
        rows.append(pd.DataFrame({"interface": a, "T": T, "dmu": 0.1 + B * np.log(T) + rng.normal(0, 0.01, T.size)}))
    fits = aging.fit_aging_per_interface(pd.concat(rows), fit="intercept")
    assert sorted(fits) == [1, 2]
    for a, B in rates.items():
        assert abs(fits[a].B - B) < 4 * fits[a].B_error
        assert abs(fits[a].c - 0.1) < 4 * fits[a].c_error
