"""Damaged data is refused with one line naming the file and dataset, never used.

Bytes inside a data chunk are overwritten, as a failing disk or a bad copy would: every
numeric dataset carries HDF5's fletcher32 checksum (:func:`stickslip.h5io.write_dataset`),
and readers go through :func:`stickslip.h5io.read_array`. Before, ``stickslip increments``
on such a fem run file exited 0 writing values like 2.4e+288.
"""

import h5py
import numpy as np
import pytest

from stickslip import h5io
from stickslip.cli import main
from stickslip.provenance.record import record_path, recording

FEM = ["simulate", "--solver", "fem", "--param", "N=9", "--param", "plates=2", "--param", "nchunk=200",
       "--param", "yield_strains=stop"]


def damage(path, dataset, nbytes=100):
    """Invert ``nbytes`` bytes near the start of the first stored chunk of ``dataset`` (in its first rows)."""
    with h5py.File(path, "r") as file:
        info = file[dataset].id.get_chunk_info(0)
    start = info.byte_offset + 8
    with open(path, "r+b") as stream:
        stream.seek(start)
        original = np.frombuffer(stream.read(nbytes), np.uint8)
        stream.seek(start)
        stream.write((original ^ 0xFF).tobytes())


def one_error(capsys):
    lines = [line for line in capsys.readouterr().err.splitlines() if "elapsed" not in line]  # progress lines
    assert len(lines) == 1, lines
    return lines[0]


def test_numeric_datasets_carry_checksums_strings_and_scalars_cannot(tmp_path):
    with h5io.open_file(tmp_path / "x.h5", "w") as file:
        h5io.write_dataset(file, "floats", np.arange(5.0))
        h5io.write_dataset(file, "flags", np.zeros(3, bool))
        h5io.write_dataset(file, "growing", None, shape=(0, 4), dtype=np.float64, maxshape=(None, 4), chunks=(1, 4))
        h5io.write_dataset(file, "scalar", 1.5)
        h5io.write_dataset(file, "names", np.asarray(["a", "b"], dtype=h5py.string_dtype()))
        assert [file[name].fletcher32 for name in ("floats", "flags", "growing", "scalar", "names")] == [
            True, True, True, False, False]


@pytest.mark.slow
def test_a_damaged_fem_run_is_refused_by_its_readers_and_by_resume(tmp_path, capsys):
    run = tmp_path / "run.h5"
    assert main(FEM + ["--param", "max_increments=20", "-o", str(run)]) == 0
    sane = tmp_path / "sane.csv"
    assert main(["increments", str(run), "-o", str(sane)]) == 0
    capsys.readouterr()
    damage(run, "increments/sigd")
    assert main(["increments", str(run), "-o", str(tmp_path / "bad.csv")]) == 2
    error = one_error(capsys)
    assert error.startswith(f"stickslip: error: {run}: dataset /increments/sigd is damaged and cannot be read")
    assert not (tmp_path / "bad.csv").exists()

    partial = tmp_path / "partial.h5"  # a run to resume, damaged in a stored state
    assert main(FEM + ["--param", "max_increments=20", "-o", str(partial)]) == 0
    with h5io.open_file(partial, "r+") as file:
        file.attrs["completed"] = False
    damage(partial, "state/u")
    capsys.readouterr()
    assert main(FEM + ["--param", "max_increments=20", "-o", str(partial)]) == 2
    assert f"{partial}: dataset /state/u is damaged" in one_error(capsys)


@pytest.mark.slow
def test_a_damaged_lab_file_is_a_one_line_error(tmp_path, capsys):
    lab = tmp_path / "lab.h5"
    assert main(["simulate", "--solver", "lever", "--param", "n=2", "--param", "duration=600", "-o", str(lab)]) == 0
    damage(lab, "F")
    capsys.readouterr()
    assert main(["analyze-experiment", str(lab), "-o", str(tmp_path / "slips.csv")]) == 2
    error = one_error(capsys)
    assert error.startswith(f"stickslip: error: {lab}: dataset /F is damaged and cannot be read")


def job(record, outputs, inputs=()):
    """A workflow job's provenance recording (what :mod:`stickslip.workflow_api` wraps every job in)."""
    return recording(record, outputs, run_id="r", kind="analysis", plugin="p", plugin_version="1", code_hash="c",
                     params={}, inputs=inputs)


def test_a_job_refuses_an_input_whose_bytes_differ_from_its_record(tmp_path):
    upstream = tmp_path / "sim.h5"
    with job(record_path(upstream), [("output", upstream)]):
        with h5io.open_file(upstream, "w") as file:
            h5io.write_dataset(file, "x", np.arange(100.0))
    with job(tmp_path / "a.provenance.json", [("output", tmp_path / "a.h5")], inputs=[("simulation", upstream)]):
        (tmp_path / "a.h5").touch()  # the intact input is accepted
    damage(upstream, "x", nbytes=8)
    with pytest.raises(h5io.FileFormatError, match=f"{upstream}: sha256 .* differs from .* recorded in "
                                                   f"{record_path(upstream)}"):
        with job(tmp_path / "b.provenance.json", [("output", tmp_path / "b.h5")], inputs=[("simulation", upstream)]):
            pass
    assert not (tmp_path / "b.provenance.json").exists()
