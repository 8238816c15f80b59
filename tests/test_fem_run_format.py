"""The ``fem-run`` format without the solver: a producer with its own parameters writes, the readers read back.

The format stores the producer's parameters as opaque JSON and the header fields the analyses
need as typed attributes; the analyses read it without loading any module of ``stickslip.fem``.
"""

import io
import subprocess
import sys

import h5py
import numpy as np
import pytest

from stickslip import formats
from stickslip.formats import fem_run
from stickslip.h5io import FileFormatError, open_file, read_array
from stickslip.mesh import MeshParams, build_stack_mesh

#: A producer that is not the ``fem`` solver: parameters the format never interprets.
HEADER = {"solver": "other-solver", "solver_version": "7", "params": {"grid": [3, 3], "law": "smooth"},
          "N": 9, "plates": 2, "n_interfaces": 1, "k_drive": 0.5, "seed": 3, "eps0": 1e-3, "sig0": 2e-3,
          "gamma0": 0.25, "c_s": 0.7, "h": np.pi, "dt": 0.01, "phi": 5e-7, "regime": "compliant",
          "backend": "gpu-like"}


def _write(path, header=HEADER, increments=3):
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    ndof, nlayer, ni = mesh.ndof, mesh.nlayer, mesh.interface_elements.size
    rng = np.random.default_rng(0)
    response = (rng.random(ndof), rng.random((ni, 4, 3)), rng.random(nlayer), 0.5)
    with open_file(path, "w") as file:
        fem_run.create_file(file, header, mesh, response, ["t", "sigd", "S_a1", "A_a1"])
        for i in range(increments):
            fem_run.append_increment(file, *_increment(i, ndof, nlayer))
    return mesh, response


def _increment(i, ndof, nlayer):
    """The state and the row of increment ``i`` of the files written here."""
    state = fem_run.StoredState(np.full(ndof, float(i)), np.full(nlayer, 2.0 * i), 3.0 * i, 0.1 * i)
    return state, {"increment": i, "kick": i % 2 == 0, "yield_element": False, "t": 0.1 * i, "sigd": 1.5 * i,
                   "S_a1": i, "A_a1": 9 * i}


def test_a_producer_with_other_parameters_writes_a_readable_file(tmp_path):
    path = tmp_path / "run.h5"
    mesh, response = _write(path)
    attrs = fem_run.read_run_attrs(path)
    assert attrs["params"] == HEADER["params"]  # stored as written, not parsed
    assert (attrs["solver"], attrs["backend"], attrs["phi"], attrs["regime"]) == ("other-solver", "gpu-like", 5e-7,
                                                                                "compliant")
    assert attrs["nstored"] == 3 and attrs["completed"] is False and attrs["format"] == "fem-run"
    table = fem_run.read_increments(path)
    assert list(table.columns) == ["increment", "kick", "yield_element", "t", "sigd", "S_a1", "A_a1"]
    np.testing.assert_array_equal(table["sigd"], [0.0, 1.5, 3.0])
    assert table["A_a1"].dtype == np.int64 and table["kick"].tolist() == [True, False, True]
    with open_file(path) as file:
        run = fem_run.RunFile(file)
        assert run.params == HEADER["params"] and run.nstored == 3 and run.mesh.N == 9
        state = run.state(2)
        np.testing.assert_array_equal(state.u, np.full(mesh.ndof, 2.0))
        assert (state.lever_target, state.t) == (6.0, pytest.approx(0.2)) and not state.further
        stored = run.linear_response()
        for got, expected in zip(stored, response):
            np.testing.assert_array_equal(got, expected)
        with pytest.raises(FileFormatError, match="increment 3 is not stored"):
            run.state(3)
    assert formats.describe("fem-run", path) == {"n": 1, "plates": 2, "blocks": 9, "k_drive": 0.5, "phi": 5e-7,
                                                  "regime": "compliant", "seed": 3, "temperature": 0.0,
                                                  "attempt_rate": None, "drive_rate": None,
                                                  "junction_strengthening": None, "junction_glass_temperature": None,
                                                  "junction_attempt_rate": None}  # an athermal producer


def test_a_producer_stores_further_state_per_increment_and_reads_it_back(tmp_path):
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    ndof, nlayer, ni = mesh.ndof, mesh.nlayer, mesh.interface_elements.size
    response = (np.zeros(ndof), np.zeros((ni, 4, 3)), np.zeros(nlayer), 0.5)
    fields = {"depth": ((ni,), np.float64), "well": ((ni,), np.int64)}
    path = tmp_path / "further.h5"
    with open_file(path, "w") as file:
        fem_run.create_file(file, HEADER, mesh, response, ["t"], state_fields=fields)
        for i in range(3):
            further = {"depth": np.full(ni, 0.5 * i), "well": np.arange(ni) + i}
            fem_run.append_increment(file, fem_run.StoredState(np.zeros(ndof), np.zeros(nlayer), 0.0, 0.1 * i, further),
                                     {"increment": i, "kick": False, "yield_element": False, "t": 0.1 * i})
    with open_file(path) as file:
        state = fem_run.RunFile(file).state(2)
        assert state.further["well"].dtype == np.int64
        np.testing.assert_array_equal(state.further["depth"], np.full(ni, 1.0))
        np.testing.assert_array_equal(state.further["well"], np.arange(ni) + 2)
        assert file["state/depth"].chunks == (1, ni)
    # a file without further state: none read, none written
    _write(tmp_path / "plain.h5")
    with open_file(tmp_path / "plain.h5") as file:
        assert fem_run.RunFile(file).state(1).further == {}
        assert sorted(file["state"]) == ["lever_target", "t", "target", "u"]


def test_rows_beyond_nstored_are_dropped_by_rewrite(tmp_path):
    path = tmp_path / "run.h5"
    _write(path)
    with h5py.File(path, "r+") as file:
        file.attrs["nstored"] = 2  # as if the third increment was being written when the writer was killed
    fem_run.rewrite(path, completed=True, stop_reason="margin")
    attrs = fem_run.read_run_attrs(path)
    assert (attrs["nstored"], attrs["completed"], attrs["stop_reason"]) == (2, True, "margin")
    assert len(fem_run.read_increments(path)) == 2
    with h5py.File(path) as file:
        assert file["state/u"].shape[0] == 2


def test_the_writer_names_missing_or_mistyped_header_fields(tmp_path):
    without = {key: value for key, value in HEADER.items() if key not in ("phi", "c_s")}
    with pytest.raises(ValueError, match="lacks c_s, phi"):
        _write(tmp_path / "a.h5", without)
    with pytest.raises(ValueError, match=r"N \(int, got str\)"):
        _write(tmp_path / "b.h5", {**HEADER, "N": "9"})
    with pytest.raises(ValueError, match="regime must be one of stiff, compliant"):
        _write(tmp_path / "c.h5", {**HEADER, "regime": "soft"})


def test_the_readers_refuse_a_file_without_a_header_field_or_of_another_format(tmp_path):
    path = tmp_path / "run.h5"
    _write(path)
    with h5py.File(path, "r+") as file:
        del file.attrs["regime"]
    for read in (fem_run.read_run_attrs, fem_run.read_increments):
        with pytest.raises(FileFormatError, match="run.h5: fem-run header lacks regime"):
            read(path)
    with h5py.File(path, "r+") as file:
        file.attrs["format"] = "timeseries"
    with pytest.raises(FileFormatError, match="a timeseries file version 2, expected fem-run"):
        fem_run.read_run_attrs(path)


def test_the_analyses_load_no_module_of_the_solver():
    # every module of the analyses (one run's, a study's, their statistics) and the experimental analysis, in a fresh
    # interpreter
    probe = ("import importlib, pkgutil, sys\n"
             "for name in ('events', 'summaries', 'statistics'):\n"
             "    package = importlib.import_module('stickslip.' + name)\n"
             "    for module in pkgutil.iter_modules(package.__path__):\n"
             "        importlib.import_module(f'stickslip.{name}.{module.name}')\n"
             "import stickslip.experiment.analysis\n"
             "print(sorted(m for m in sys.modules if m == 'stickslip.fem' or m.startswith('stickslip.fem.')))\n"
             "print(len([m for m in sys.modules if m.startswith(('stickslip.events.', 'stickslip.summaries.', "
             "'stickslip.statistics.'))]))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    loaded, analyses = done.stdout.split("\n")[:2]
    assert loaded == "[]"
    assert int(analyses) >= 13  # the probe did import the analyses


def _append_running(path, increments, killed_at):
    """Append ``increments`` increments to ``path`` as the fem loop does (SWMR); the bytes once ``killed_at``
    increments are stored (a kill between increments) and at the end (a kill inside the next append)."""
    with open_file(path, "r+") as file:
        file.swmr_mode = True
        ndof, nlayer = file["state/u"].shape[1], file["state/target"].shape[1]
        for i in range(file["state/t"].shape[0], file["state/t"].shape[0] + increments):
            fem_run.append_increment(file, *_increment(i, ndof, nlayer))
            if i + 1 == killed_at:
                between = path.read_bytes()
    return between, path.read_bytes()


def test_a_chunk_torn_by_a_kill_keeps_its_committed_rows_and_other_damage_is_refused(tmp_path):
    """A kill inside the in-place rewrite of a chunk leaves its new bytes up to a page boundary and its
    old bytes (old checksum included) after it; the resume keeps the 5 committed rows of every such tear,
    so the rewritten file is the one of a kill between increments, byte for byte."""
    path = tmp_path / "run.h5"
    _write(path, increments=2)
    before, after = _append_running(path, 4, killed_at=5)  # the sixth increment was being written at the kill
    expected = tmp_path / "expected.h5"
    expected.write_bytes(before)
    fem_run.rewrite(expected)
    with h5py.File(expected) as file:
        growable = ["state/t", "state/target", "state/lever_target", "increments/sigd", "increments/S_a1"]
        assert all(file[name].shape[0] == 5 for name in growable)
    torn = tmp_path / "torn.h5"
    tears = 0
    for name in growable:
        with h5py.File(io.BytesIO(after), "r") as file:
            chunk = file[name].id.get_chunk_info_by_coord((0,) * file[name].ndim)
        start, stop = chunk.byte_offset, chunk.byte_offset + chunk.size
        assert before[start:stop] != after[start:stop]  # rewritten in place
        for page in range(start // 4096 + 1, (stop - 1) // 4096 + 1):
            cut = page * 4096
            torn.write_bytes(before[:start] + after[start:cut] + before[cut:])
            with open_file(torn) as file, pytest.raises(FileFormatError, match=f"{name} is damaged"):
                read_array(file[name])
            assert fem_run.read_increments(torn).equals(fem_run.read_increments(expected))  # a reader of the killed file
            fem_run.rewrite(torn)
            assert torn.read_bytes() == expected.read_bytes(), (name, cut)
            tears += 1
    assert tears >= 8  # a chunk of 1024 numbers (8 KiB) spans one or two page boundaries
    # a committed row changed, not a tear: refused, and the file is left as it was
    with h5py.File(io.BytesIO(after), "r") as file:
        offset = file["increments/sigd"].id.get_chunk_info_by_coord((0,)).byte_offset
    damaged = bytearray(before)
    damaged[offset + 8 * 2] ^= 1
    torn.write_bytes(bytes(damaged))
    with pytest.raises(FileFormatError, match="increments/sigd is damaged"):
        fem_run.rewrite(torn)
    assert torn.read_bytes() == bytes(damaged)
