"""The numerical-events plugin's output file: tables, attributes, reproducible bytes."""

import numpy as np
import pytest

from stickslip import registry
from stickslip.events import analysis_files, extraction, plugin
from stickslip.formats.event_table import read_slip_events
from stickslip.h5io import FileFormatError
from stickslip.hashing import sha256_file
from test_events_extraction import EVENTS, N, history, run_attrs

RUN_ATTRS = run_attrs(N, 3, 1e-6, seed=4, eps0=5e-5, c_s=0.7071)
STIFF = 1e-3 * (1458 / N) ** 2  # the paper's stiff driving, for N blocks


def write(path, events=EVENTS, attrs=RUN_ATTRS):
    tables = plugin.event_tables(history(N, events), N)
    # synthetic tables: the header's input checksum is that of this test module
    plugin.write_event_file(tables, plugin.event_attrs(attrs, tables["increments"]), path, input=__file__)
    return tables


def test_event_file_round_trip(tmp_path):
    tables = write(tmp_path / "events.h5")
    read = analysis_files.read_analysis_file(tmp_path / "events.h5", "event-table", tuple(tables))
    assert read.n == 2 and read.regime == "compliant"
    assert read.attrs["N"] == N and read.attrs["seed"] == 4 and read.attrs["steady_state"] == 8
    assert read.attrs["analysis"] == "numerical-events"
    for name, table in tables.items():
        assert list(read.tables[name].columns) == list(table.columns)
        for column in table.columns:
            expected, got = table[column].to_numpy(), read.tables[name][column].to_numpy()
            if expected.dtype.kind == "f":
                np.testing.assert_array_equal(got, expected)
            else:
                assert got.tolist() == expected.tolist()
    np.testing.assert_allclose(extraction.slip_fractions(read.tables["slips"], 2), [4 / 7, 3 / 7])
    assert read.attrs["format"] == "event-table" and read.attrs["input_sha256"] == sha256_file(__file__)


def test_slip_events_are_the_per_interface_slips_numbered_by_event(tmp_path):
    tables = write(tmp_path / "events.h5")
    table = read_slip_events(tmp_path / "events.h5")
    per = tables["slip_interfaces"]
    assert list(table.columns) == ["event", "interface", "multi", "dmu_sig0", "increment", "dgamma"]
    np.testing.assert_array_equal(table["interface"], per["interface"])
    np.testing.assert_array_equal(table["dmu_sig0"], per["dmu_sig0"])
    np.testing.assert_array_equal(table["multi"], per["multi"])
    # one event number per slipping increment, counted from 0 in increment order
    assert table.groupby("event")["increment"].nunique().eq(1).all()
    assert table["event"].tolist() == table["increment"].rank(method="dense").astype(int).sub(1).tolist()
    assert table["event"].max() + 1 == len(tables["slips"])


def test_same_input_same_bytes(tmp_path):
    write(tmp_path / "a.h5")
    write(tmp_path / "b.h5")
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()


def test_run_without_steady_state_gives_empty_slip_tables(tmp_path):
    write(tmp_path / "e.h5", events=[((3, 0), (0.0, 0.0))] * 4)
    read = analysis_files.read_analysis_file(tmp_path / "e.h5", "event-table", ("slips", "sequences", "slip_interfaces"))
    assert read.attrs["steady_state"] == -1
    assert all(table.empty for table in read.tables.values())


def test_missing_run_attributes_are_named():
    tables = plugin.event_tables(history(N, EVENTS), N)
    with pytest.raises(FileFormatError, match="run.h5: run attributes lack phi, regime"):
        plugin.event_attrs({"N": N, "plates": 3, "k_drive": 1e-3}, tables["increments"], source="run.h5")


def test_grouping_by_regime_and_n(tmp_path):
    write(tmp_path / "c.h5")
    write(tmp_path / "s.h5", attrs=run_attrs(N, 3, STIFF, seed=1))
    write(tmp_path / "s2.h5", attrs=run_attrs(N, 3, STIFF, seed=0))
    files = [analysis_files.read_analysis_file(tmp_path / f, "event-table", ("slips",)) for f in ("s.h5", "c.h5", "s2.h5")]
    groups = analysis_files.group_runs(files)
    assert list(groups) == [("compliant", 2), ("stiff", 2)]
    assert [f.attrs["seed"] for f in groups[("stiff", 2)]] == [0, 1]
    assert len(analysis_files.pooled(groups[("stiff", 2)], "slips")) == 14


def test_plugin_is_registered():
    found = registry.get("analysis", "numerical-events")
    assert (found.consumes, found.produces) == (("fem-run",), "event-table")
    assert found.version == plugin.VERSION
