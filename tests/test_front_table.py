"""The ``front-table`` format: what front-dynamics writes, its reader gives back; other files are refused."""

import h5py
import numpy as np
import pandas as pd
import pytest

from stickslip.events import fronts, plugin
from stickslip.formats import front_table
from stickslip.h5io import FileFormatError, read_table, write_table
from test_events_extraction import EVENTS, history, run_attrs
from test_fronts import C_S, H_BLOCK, SPACING, rupture

N = 9


def _write(path):
    classified = plugin.event_tables(history(N, EVENTS), N)["increments"]

    def rerun(increment):
        rng = np.random.default_rng(increment)
        return pd.concat([rupture(N, 1, c_f=2.0, nucleation=4, start=0.0, rng=rng),
                          rupture(N, 2, c_f=2.0, nucleation=1, start=float(increment), rng=rng)])

    failures, table = fronts.front_tables(classified, rerun, N=N, h=H_BLOCK, c_s=C_S, spacing=SPACING,
                                          params=fronts.FrontParams())
    attrs = {**plugin.event_attrs(run_attrs(N, 3, 1e-3), classified), "interface_spacing": SPACING}
    fronts.write_front_file(failures, table, attrs, path, input=__file__)
    return failures, table


def test_the_reader_gives_back_the_written_tables(tmp_path):
    failures, table = _write(tmp_path / "fronts.h5")
    read = front_table.read_front_tables(tmp_path / "fronts.h5")
    pd.testing.assert_frame_equal(read["failures"], failures)
    pd.testing.assert_frame_equal(read["fronts"], table)
    np.testing.assert_allclose(read["fronts"]["tau"], read["fronts"]["increment"] * C_S / SPACING)
    assert dict(read["fronts"].dtypes.astype(str)) == front_table.FRONT_DTYPES


def test_the_reader_refuses_other_files_and_names_what_is_missing(tmp_path):
    tables = plugin.event_tables(history(N, EVENTS), N)
    plugin.write_event_file(tables, plugin.event_attrs(run_attrs(N, 3, 1e-3), tables["increments"]),
                            tmp_path / "events.h5", input=__file__)
    with pytest.raises(FileFormatError, match="a event-table file version 2, expected front-table"):
        front_table.read_front_tables(tmp_path / "events.h5")
    _write(tmp_path / "fronts.h5")
    with h5py.File(tmp_path / "fronts.h5", "r+") as file:
        file.attrs["format_version"] = 0
    with pytest.raises(FileFormatError, match="version 0, expected front-table version 2"):
        front_table.read_front_tables(tmp_path / "fronts.h5")
    with h5py.File(tmp_path / "fronts.h5", "r+") as file:
        file.attrs["format_version"] = 2
        write_table(file, "fronts", read_table(file, "fronts").drop(columns="tau"))
    with pytest.raises(FileFormatError, match="table 'fronts' lacks column"):
        front_table.read_front_tables(tmp_path / "fronts.h5")
