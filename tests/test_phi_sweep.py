"""Phi-sweep statistics: counting errors, pooling by (n, Phi), the crossover."""

import math

import numpy as np
import pandas as pd
import pytest

from stickslip.summaries.phi_sweep import crossover, sweep_table, wilson_interval
from stickslip.events.analysis_files import AnalysisFile


def test_wilson_interval_brackets_the_fraction_and_shrinks_as_one_over_root_m():
    low, high = wilson_interval(50, 100)
    assert low < 0.5 < high and high - low == pytest.approx(2 * math.sqrt(0.25 / 100), rel=0.01)
    low, high = wilson_interval(0, 20)
    assert low == pytest.approx(0.0, abs=1e-15) and 0 < high < 0.1  # not empty at k = 0
    width100 = np.subtract(*wilson_interval(50, 100)[::-1])
    assert np.subtract(*wilson_interval(200, 400)[::-1]) == pytest.approx(width100 / 2, rel=0.01)
    assert all(math.isnan(v) for v in wilson_interval(0, 0))


def _file(n, phi, seed, s, dmu):
    slips = pd.DataFrame({"increment": np.arange(len(s)), "s": s})
    rows = [(i, a, d) for i, (k, d) in enumerate(zip(s, dmu)) for a in range(k)]
    per = pd.DataFrame(rows, columns=["increment", "interface", "dmu_sig0"])
    return AnalysisFile(path=f"{n}-{phi}-{seed}", attrs={"n_interfaces": n, "phi": phi, "N": 27, "seed": seed},
                        tables={"slips": slips, "slip_interfaces": per})


def test_sweep_pools_seeds_and_counts_multi_slips():
    files = [_file(2, 1e-6, 1, [1, 1, 1, 2], [1.0, 2.0, 3.0, 4.0]), _file(2, 1.0000001e-6, 2, [1, 1], [1.0, 1.0]),
             _file(2, 1e-4, 1, [2, 2, 2, 1], [1.0] * 4), _file(2, 1e-3, 1, [2, 2, 2, 2], [1.0] * 4)]
    table = sweep_table(files, lambda attrs: attrs["phi"])
    assert table["phi"].tolist() == [1e-6, 1e-4, 1e-3]
    first = table.iloc[0]
    assert first["seeds"] == 2 and first["slips"] == 6 and first["multi"] == 1
    assert first["multi_fraction"] == pytest.approx(1 / 6)
    dmu = [1.0, 2.0, 3.0, 4.0, 4.0, 1.0, 1.0]  # one row per slipping interface (the multi-slip twice)
    assert first["dmu_count"] == 7 and first["dmu_mean"] == pytest.approx(np.mean(dmu))
    assert first["dmu_width"] == pytest.approx(np.std(dmu, ddof=1))
    assert first["dmu_mean_error"] == pytest.approx(np.std(dmu, ddof=1) / math.sqrt(7))
    # 1/6 at 1e-6, 3/4 at 1e-4: 0.5 is passed at log10 Phi = -6 + (0.5 - 1/6) / (3/4 - 1/6) * 2
    assert crossover(table, 2) == pytest.approx(10 ** (-6 + (1 / 3) / (7 / 12) * 2))
    assert math.isnan(crossover(table, 3)) and math.isnan(crossover(table, 2, level=1.01))
