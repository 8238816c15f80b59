"""Experimental time-series format: round trip, ground-truth tables, every validation error."""

import dataclasses
import hashlib
import re

import h5py
import numpy as np
import pandas as pd
import pytest

from stickslip.experiment.timeseries import ExperimentRecord, read_timeseries, read_truth, write_timeseries
from stickslip.h5io import FileFormatError


def make_record(**changes):
    t_F = np.arange(11) * 0.02
    t_x = np.arange(3) * 0.2
    x = np.array([[0.0, 1.0, 3.0], [0.5, 1.5, 3.5], [0.5, 2.0, 4.0]])
    values = dict(t_F=t_F, F=np.linspace(1.0, 2.0, 11), t_x=t_x, x=x, n=2, n_slabs=3, protocol="stack",
                  a=0, normal_force=49.0, k_spring=55.0, h=10.0, H=100.0, V=0.01)
    values.update(changes)
    return ExperimentRecord(**values)


def test_relative_positions():
    record = make_record()
    np.testing.assert_array_equal(record.R, [[0.0, 1.0, 2.0], [0.5, 1.0, 2.0], [0.5, 1.5, 2.0]])


def test_round_trip_with_truth_and_attrs(tmp_path):
    record = make_record()
    truth = pd.DataFrame({"t_start": [0.1], "a": [1], "dR": [0.02], "multi": [False]})
    write_timeseries(tmp_path / "run.h5", record, attrs={"seed": 3, "params": {"n": 2}}, tables={"truth": truth})
    back = read_timeseries(tmp_path / "run.h5")
    for field in dataclasses.fields(ExperimentRecord):
        np.testing.assert_array_equal(getattr(back, field.name), getattr(record, field.name))
    pd.testing.assert_frame_equal(read_truth(tmp_path / "run.h5"), truth, check_dtype=False)
    with h5py.File(tmp_path / "run.h5") as f:
        assert f.attrs["seed"] == 3 and f.attrs["params"] == '{"n": 2}'


def test_lab_file_has_no_truth_and_bytes_are_reproducible(tmp_path):
    for name in ("1.h5", "2.h5"):
        write_timeseries(tmp_path / name, make_record())
    assert read_truth(tmp_path / "1.h5") is None
    digests = {hashlib.sha256((tmp_path / name).read_bytes()).hexdigest() for name in ("1.h5", "2.h5")}
    assert len(digests) == 1


def test_individual_protocol_accepted(tmp_path):
    write_timeseries(tmp_path / "i.h5", make_record(protocol="individual", a=3, n=1))
    assert read_timeseries(tmp_path / "i.h5").a == 3


BAD_RECORDS = [
    (dict(protocol="sideways"), "'protocol' must be one of"),
    (dict(n=4), "'n' must be in 1..n_slabs=3"),
    (dict(n=0), "'n' must be in 1..n_slabs=3"),
    (dict(a=1), "'a' must be 0 for the stack protocol"),
    (dict(protocol="individual", a=4, n=1), "'a' must be in 1..n_slabs=3"),
    (dict(protocol="individual", a=2, n=2), "'n' must be 1 for the individual protocol"),
    (dict(k_spring=-1.0), "'k_spring' must be a finite number > 0"),
    (dict(V=float("nan")), "'V' must be a finite number > 0"),
    (dict(t_F=np.r_[0.0, 0.02, 0.01, np.arange(3, 11) * 0.02]), "'t_F' must be strictly increasing"),
    (dict(t_x=np.array([0.0, 0.2, 0.2])), "'t_x' must be strictly increasing"),
    (dict(t_x=np.array([0.0, np.nan, 0.4])), "'t_x' must be finite"),
    (dict(F=np.r_[np.ones(10), np.nan]), "'F' must be finite"),
    (dict(F=np.ones(10)), "'F' must have the shape of t_F"),
    (dict(x=np.zeros((3, 2))), "'x' must have shape (n_frames, n_slabs) = (3, 3)"),
    (dict(x=np.full((3, 3), np.inf)), "'x' must be finite"),
]


@pytest.mark.parametrize("changes, message", BAD_RECORDS)
def test_writer_rejects_inconsistent_records(tmp_path, changes, message):
    with pytest.raises(FileFormatError, match=re.escape(message)):
        write_timeseries(tmp_path / "bad.h5", make_record(**changes))
    assert not (tmp_path / "bad.h5").exists()


def _corrupt(path, edit):
    write_timeseries(path, make_record())
    with h5py.File(path, "r+") as f:
        edit(f)


CORRUPTIONS = [
    (lambda f: f.__delitem__("x"), "'x' is missing (required dataset)"),
    (lambda f: f.attrs.__delitem__("k_spring"), "'k_spring' is missing (required attribute)"),
    (lambda f: f.attrs.__setitem__("n", 39.6), "'n' must be an integer, got 39.6"),  # not np.float64(39.6)
    (lambda f: (f.attrs.__setitem__("protocol", "individual"), f.attrs.__delitem__("a")),
     "'a' is missing (required attribute of the individual protocol: the driven slab)"),
    (lambda f: f.attrs.__setitem__("h", "ten"), "'h' must be a number"),
    (lambda f: f.attrs.__setitem__("protocol", "free"), "'protocol' must be one of"),
    (lambda f: f["t_F"].__setitem__(3, 0.0), "'t_F' must be strictly increasing; sample 3 (0 s) does not follow"),
    (lambda f: f["x"].__setitem__((1, 1), np.nan), "'x' must be finite"),
]


@pytest.mark.parametrize("edit, message", CORRUPTIONS)
def test_reader_names_the_bad_item(tmp_path, edit, message):
    _corrupt(tmp_path / "run.h5", edit)
    with pytest.raises(FileFormatError, match=re.escape(message)) as error:
        read_timeseries(tmp_path / "run.h5")
    assert str(tmp_path / "run.h5") in str(error.value)


def test_a_stack_recording_without_a_is_read_and_analysed(tmp_path):
    """Lab exports of the stack protocol carry no driven-slab attribute: read as a = 0, analysed as with it."""
    from stickslip.cli import main
    from stickslip.experiment.virtual.model import simulate
    from stickslip.solvers.lever import LeverParams

    with_a, without_a = tmp_path / "with_a.h5", tmp_path / "without_a.h5"
    signals, _, _ = simulate(LeverParams(n=2, duration=600.0, seed=1))
    for path in (with_a, without_a):
        write_timeseries(path, signals)
    with h5py.File(without_a, "r+") as f:
        del f.attrs["a"]
    read = [read_timeseries(path) for path in (with_a, without_a)]
    assert read[1].a == 0
    for field in dataclasses.fields(ExperimentRecord):
        np.testing.assert_array_equal(getattr(read[1], field.name), getattr(read[0], field.name))
    for path in (with_a, without_a):
        assert main(["analyze-experiment", str(path), "-o", str(path.with_suffix(".csv"))]) == 0
    slips = [pd.read_csv(path.with_suffix(".csv")).drop(columns="path") for path in (with_a, without_a)]
    assert len(slips[0]) > 0
    pd.testing.assert_frame_equal(slips[0], slips[1])


def test_reader_rejects_missing_and_non_hdf5_files(tmp_path):
    with pytest.raises(FileFormatError, match="no such file"):
        read_timeseries(tmp_path / "absent.h5")
    (tmp_path / "text.h5").write_text("not hdf5")
    with pytest.raises(FileFormatError, match="not a readable HDF5 file"):
        read_timeseries(tmp_path / "text.h5")


def test_extra_items_cannot_overwrite_the_format(tmp_path):
    with pytest.raises(ValueError, match="must not reuse the format's names: n"):
        write_timeseries(tmp_path / "run.h5", make_record(), attrs={"n": 5})


#: The items of a recording in shared/design.md ("Experimental time-series format"), the layout a lab script writes.
DOCUMENTED_ATTRS = ("n", "n_slabs", "protocol", "a", "normal_force", "k_spring", "h", "H", "V")


def _lab_file(path, record, **units):
    """A lab script's file: the documented layout only, written by plain h5py (no stickslip attribute)."""
    with h5py.File(path, "w") as f:
        for name in ("t_F", "F", "t_x", "x"):
            f[name] = getattr(record, name)
            if name in units:
                f[name].attrs["unit"] = units[name]
        for name in DOCUMENTED_ATTRS:
            f.attrs[name] = getattr(record, name)


def test_a_lab_file_in_the_documented_layout_is_read_as_version_1(tmp_path, capsys):
    from stickslip.cli import main
    from stickslip.experiment.virtual.model import simulate
    from stickslip.solvers.lever import LeverParams

    signals, _, _ = simulate(LeverParams(n=2, duration=600.0, seed=1))
    ours, lab = tmp_path / "stickslip.h5", tmp_path / "lab.h5"
    write_timeseries(ours, signals)
    _lab_file(lab, signals, t_F="s", x="mm")  # a unit attribute, where present, is the documented one
    capsys.readouterr()
    back = read_timeseries(lab)
    assert capsys.readouterr().err == (f"stickslip: note: {lab}: no 'format' attribute; read as a lab recording in "
                                       f"the documented layout (timeseries version 1), checked by its content\n")
    for field in dataclasses.fields(ExperimentRecord):
        np.testing.assert_array_equal(getattr(back, field.name), getattr(signals, field.name))
    for path in (ours, lab):
        assert main(["analyze-experiment", str(path), "-o", str(path.with_suffix(".csv"))]) == 0
    slips = [pd.read_csv(path.with_suffix(".csv")).drop(columns="path") for path in (ours, lab)]
    assert len(slips[0]) > 0
    pd.testing.assert_frame_equal(slips[0], slips[1])


LAB_FILE_FAULTS = [
    (lambda f: f["x"].attrs.__setitem__("unit", "m"), "'x' is in [m]; the format stores it in [mm]"),
    (lambda f: f.__delitem__("t_x"), "'t_x' is missing (required dataset) (a file without a 'format' attribute is "
                                     "read as a lab recording in the documented layout"),
    (lambda f: f["t_F"].__setitem__(3, 0.0), "'t_F' must be strictly increasing"),
    (lambda f: f.attrs.__setitem__("format", "fem-run"), "a fem-run file version -1, expected timeseries version 1"),
]


@pytest.mark.parametrize("edit, message", LAB_FILE_FAULTS)
def test_a_lab_file_is_checked_by_its_content(tmp_path, edit, message):
    _lab_file(tmp_path / "lab.h5", make_record())
    with h5py.File(tmp_path / "lab.h5", "r+") as f:
        edit(f)
    with pytest.raises(FileFormatError, match=re.escape(message)):
        read_timeseries(tmp_path / "lab.h5")
