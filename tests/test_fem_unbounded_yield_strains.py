"""Unbounded yield-strain sequences: windows held in memory give the numbers of a sequence generated up front."""

import h5py
import numpy as np
import pytest

from stickslip import registry
from stickslip.fem.yield_strains import HeldYieldStrains, interface_initstate, narrowest_well, yield_strains
from stickslip.formats.fem_run import read_run_attrs
from stickslip.h5io import read_table
from stickslip.plugin_params import describe, parse_params


def test_slid_and_widened_windows_hold_the_values_of_the_long_sequence():
    initstate = interface_initstate(seed=2, N=27, n_interfaces=2)
    full = yield_strains(initstate, 700, 5e-5, 1e-6, 2.0)
    held = HeldYieldStrains(initstate, 100, 5e-5, 1e-6, 2.0)
    shifts = [np.full(initstate.size, 60), np.arange(initstate.size) % 70, np.zeros(initstate.size, dtype=int)]
    for shift, extra in zip(shifts, (0, 150, 40)):
        held.slide(shift)
        held.widen(extra)
        ny = held.epsy.shape[1]
        for e in range(initstate.size):
            np.testing.assert_array_equal(held.epsy[e], full[e, held.offset[e]:held.offset[e] + ny])
    np.testing.assert_array_equal(held.offset, sum(shifts))  # the windows start where they were slid to
    assert narrowest_well(initstate, 700, 5e-5, 1e-6, 2.0) == np.diff(full, axis=1).min()


def _run(path, **values):
    plugin = registry.get("solver", "fem")
    case = {"N": 9, "plates": 2, "seed": 0, "k_drive": 1e-3, "relaxation": "exact", "max_increments": 160}
    plugin.run(parse_params(plugin.params, {**case, **values}), path, threads=1, inputs={})


@pytest.mark.slow
def test_a_run_holding_few_wells_is_bit_identical_to_one_holding_many(tmp_path):
    _run(tmp_path / "few.h5", window=20)
    _run(tmp_path / "many.h5", window=6000)
    with h5py.File(tmp_path / "few.h5") as few, h5py.File(tmp_path / "many.h5") as many:
        for name in ("state/u", "state/target", "state/t", "event/delta_u", "event/delta_eps"):
            np.testing.assert_array_equal(few[name][...], many[name][...], err_msg=name)
        table = read_table(few, "increments")
        assert table.equals(read_table(many, "increments"))
    assert len(table) == 161 and read_run_attrs(tmp_path / "few.h5")["stop_reason"] == "max_increments"
    # every block went through the 20 held wells several times (global index = sum of hops)
    assert table["S_a1"].sum() / 9 > 3 * 20


@pytest.mark.slow
def test_the_margin_stop_remains_for_the_paper_runs_and_is_the_default_bound(tmp_path):
    """max_increments 0 stops where the paper's code stops, with or without unbounded yield strains."""
    _run(tmp_path / "stop.h5", yield_strains="stop", nchunk=30, max_increments=0)
    attrs = read_run_attrs(tmp_path / "stop.h5")
    assert attrs["completed"] and attrs["stop_reason"] == "margin"
    with h5py.File(tmp_path / "stop.h5") as file:
        hops = read_table(file, "increments")["S_a1"].to_numpy()
    assert hops.sum() <= 9 * (30 - 5)  # no block went past its last 5 wells
    _run(tmp_path / "extend.h5", nchunk=30, max_increments=0)  # the defaults: yield_strains 'extend'
    assert read_run_attrs(tmp_path / "extend.h5")["stop_reason"] == "margin"
    with h5py.File(tmp_path / "stop.h5") as stop, h5py.File(tmp_path / "extend.h5") as extend:
        assert read_table(extend, "increments").equals(read_table(stop, "increments"))
        for name in ("state/u", "state/target", "state/t", "event/delta_u", "event/delta_eps"):
            np.testing.assert_array_equal(extend[name][...], stop[name][...], err_msg=name)


def test_the_default_parameters_are_valid_and_say_what_they_do():
    params = parse_params(registry.get("solver", "fem").params, {})  # `stickslip simulate --solver fem -o run.h5`
    assert (params.yield_strains, params.max_increments) == ("extend", 0)
    doc = {name: text for name, _, _, _, text in describe(type(params))}["max_increments"]
    assert "0: stop where the paper's code does" in doc and "nchunk" in doc
