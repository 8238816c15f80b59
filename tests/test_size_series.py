"""The size-series tables on synthetic event and front files with known answers."""

import math

import numpy as np
import pandas as pd
import pytest

from stickslip.events import fronts, plugin
from stickslip.summaries import size_series
from stickslip.events.analysis_files import read_analysis_file
from stickslip.statistics.mean_shift import shift_test
from stickslip.plugin_params import parse_params
from test_events_extraction import history, run_attrs
from test_fronts import C_D, C_S, H_BLOCK, SPACING, rupture

K_DRIVE = {"stiff": 1e-3, "compliant": 1e-6}  # the paper's, at N = 1458


def single_slips(n, N, drops):
    """The interfaces slip alone in turn with ``drops``: the steady state starts with the n-th (``drops[n - 1:]``)."""
    events = []
    for i, drop in enumerate(drops):
        a = i % n
        events.append((tuple(N if b == a else 0 for b in range(n)), tuple(drop if b == a else 0.0 for b in range(n))))
    return events


def write_events(path, N, n, regime, seed, dt_scale, events):
    attrs = run_attrs(N, n + 1, K_DRIVE[regime] * (1458 / N) ** 2, seed=seed, params={"dt_scale": dt_scale})
    tables = plugin.event_tables(history(N, events), N)
    plugin.write_event_file(tables, plugin.event_attrs(attrs, tables["increments"]), path, input=__file__)
    return read_analysis_file(path, "event-table", ("slip_interfaces", "periodicity"))


@pytest.fixture(scope="module")
def compliant(tmp_path_factory):
    """N = 27 and 54 at dt_scale 4, N = 54 at dt_scale 1; n = 1, 2; two seeds; n = 2 drops 10 % larger."""
    root = tmp_path_factory.mktemp("sizes")
    rng = np.random.default_rng(11)
    files, drops = [], {}
    for N, dt_scale in ((27, 4.0), (54, 4.0), (54, 1.0)):
        for n in (1, 2):
            for seed in (1, 2):
                sample = rng.uniform(0.5, 1.5, 40) * (1.1 if n == 2 else 1.0)
                drops.setdefault((N, dt_scale, n), []).append(sample[n - 1:])
                files.append(write_events(root / f"{N}-{dt_scale}-{n}-{seed}.h5", N, n, "compliant", seed, dt_scale,
                                          single_slips(n, N, sample)))
    return files, drops


def test_the_shift_of_the_drops_against_n_1_per_size_and_time_step(compliant):
    files, drops = compliant
    table = size_series.drop_shift_by_size(files)
    assert len(table) == 6 and set(table["seeds"]) == {2}
    for _, row in table.iterrows():
        sample = np.concatenate(drops[(row["N"], row["dt_scale"], row["n"])])
        assert row["count"] == sample.size == 82 - 2 * row["n"] and row["mean"] == pytest.approx(sample.mean())
        means = [part.mean() for part in drops[(row["N"], row["dt_scale"], row["n"])]]
        assert row["run_mean_error"] == pytest.approx(np.std(means, ddof=1) / math.sqrt(2))
        if row["n"] == 1:
            assert math.isnan(row["shift"]) and math.isnan(row["p_runs"])
            continue
        test = shift_test(np.concatenate(drops[(row["N"], row["dt_scale"], 1)]), sample)
        assert row["shift"] == pytest.approx(test["shift"]) and row["p_value"] == pytest.approx(test["p_value"])
        assert row["detectable_shift"] == pytest.approx(test["detectable_shift"])
        assert 0.0 < row["p_runs"] <= 1.0


def test_periodicity_is_averaged_over_the_seeds_of_each_size(compliant):
    files, _ = compliant
    table = size_series.periodicity_by_size(files)
    assert list(table[["N", "dt_scale", "n"]].itertuples(index=False, name=None)) == [
        (27, 4.0, 1), (27, 4.0, 2), (54, 1.0, 1), (54, 1.0, 2), (54, 4.0, 1), (54, 4.0, 2)]
    assert (table["runs"] == 2).all() and (table["multi_fraction"] == 0).all()
    assert (table["interval_cv"] == 0).all()  # one load step between consecutive slips: periodic in gamma
    rows = [f.tables["periodicity"].iloc[0] for f in files if f.attrs["N"] == 27 and f.n == 2]
    assert table.loc[1, "drop_cv"] == pytest.approx(np.mean([r["drop_cv"] for r in rows]))


def test_front_speeds_count_only_meaningful_fits(tmp_path):
    N = 162
    rng = np.random.default_rng(12)
    attrs = run_attrs(N, 3, K_DRIVE["stiff"] * (1458 / N) ** 2, seed=1, c_s=C_S, h=H_BLOCK, params={"dt_scale": 4.0})
    speeds = {14: 1.5, 16: 1.9, 24: None}  # None: every block fails at once, no front

    def rerun(increment):
        second = rupture(N, 2, c_f=1.0, nucleation=5, start=80.0, rng=rng)
        if speeds[increment] is None:
            first = pd.DataFrame({"a": 1, "block": np.arange(N), "t": rng.uniform(0, 1, N), "direction": 1})
        else:
            first = rupture(N, 1, c_f=speeds[increment], nucleation=30, start=0.0, rng=rng)
        return pd.concat([first, second], ignore_index=True)

    from test_events_extraction import EVENTS
    tables = plugin.event_tables(history(9, EVENTS), 9)  # steady-state multi-slips at 14, 16, 24
    failures, table = fronts.front_tables(tables["increments"], rerun, N=N, h=H_BLOCK, c_s=C_S, spacing=SPACING,
                                          params=parse_params(fronts.FrontParams, {}), c_d=C_D)
    path = tmp_path / "fronts.h5"
    fronts.write_front_file(failures, table, {**plugin.event_attrs(attrs, tables["increments"]),
                                              "interface_spacing": SPACING}, path, input=__file__)
    row = size_series.front_speed_by_size([read_analysis_file(path, "front-table", ("fronts",))]).iloc[0]
    assert (row["N"], row["dt_scale"], row["regime"], row["n"]) == (N, 4.0, "stiff", 2)
    assert (row["events"], row["ok"], row["flagged"]) == (3, 2, 1)
    assert row["c_f_mean"] == pytest.approx(1.7, rel=1e-3) and row["c_f_median"] == pytest.approx(1.7, rel=1e-3)
    assert row["c_f_error"] == pytest.approx(0.2, rel=1e-2)  # std of (1.5, 1.9) over sqrt(2)
    assert row["tau_median"] == pytest.approx(80.0 * C_S / SPACING)
