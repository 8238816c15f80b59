"""HDF5 helpers: reproducible bytes, table round trip, atomic output."""

import hashlib
import time

import numpy as np
import pandas as pd
import pytest

from stickslip.h5io import FileFormatError, open_file, read_table, write_dataset, write_table
from stickslip.output_safety.atomic import atomic_output


def _write(path, table):
    with open_file(path, "w") as f:
        write_dataset(f, "x", np.arange(4.0))
        write_table(f, "events", table, attrs={"n": 3, "config": {"a": 1}})


def test_same_content_gives_same_bytes(tmp_path):
    table = pd.DataFrame({"a": [1, 2], "mu": [0.1, 0.2], "flag": [True, False], "name": ["x", "y"]})
    _write(tmp_path / "1.h5", table)
    time.sleep(1.1)  # HDF5 would record a different modification time
    _write(tmp_path / "2.h5", table)
    digest = [hashlib.sha256((tmp_path / f"{i}.h5").read_bytes()).hexdigest() for i in (1, 2)]
    assert digest[0] == digest[1]
    with open_file(tmp_path / "1.h5") as f:
        back = read_table(f, "events")
        assert f["events"].attrs["n"] == 3
    pd.testing.assert_frame_equal(back, table, check_dtype=False)
    assert back["flag"].dtype == bool


def test_missing_file_and_table_are_clear_errors(tmp_path):
    with pytest.raises(FileFormatError, match="no such file"):
        open_file(tmp_path / "none.h5")
    (tmp_path / "bad.h5").write_text("not hdf5")
    with pytest.raises(FileFormatError, match="not a readable HDF5"):
        open_file(tmp_path / "bad.h5")
    _write(tmp_path / "ok.h5", pd.DataFrame({"a": [1]}))
    with open_file(tmp_path / "ok.h5") as f, pytest.raises(FileFormatError, match="no table 'slips'"):
        read_table(f, "slips")


def test_atomic_output_keeps_previous_file_on_failure(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_output(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]
    with atomic_output(target) as tmp:
        tmp.write_text("new")
    assert target.read_text() == "new"
