"""A file's word is checked against its bytes before a row is read: a lying file is refused in one line, at once.

The audit of 575c37a (issue 59, item 1): with h5py, every ``increments/*`` and ``state/*`` dataset of a fem run
resized to 5 000 000 rows and ``nstored`` set to 5 000 000: ``stickslip.open_run(f).increments`` returned a
5e6-row table (zeros after row 41) at 2.5 GB and ``stickslip increments`` wrote 5 000 001 lines, exit 0; with 1e9
rows the reader grew for 2 minutes to 3.75 GB; with a gzip column of 2.5e8 zeros (a 2.2 MB file) it ended in a
MemoryError traceback. HDF5 reads a chunk that was never written as the fill value, the torn-chunk fallback read
chunk by chunk below the block budget, and ``nstored`` was compared only with declared shapes. Item 6: a flipped
bit in a run's stored parameters read as the user's wrong parameter without the file's name, and at a resume as
"another run".
"""

import math
import subprocess
import sys
import textwrap
import zlib

import h5py
import numpy as np
import pytest

import stickslip
from stickslip import h5io
from stickslip.cli import main
from stickslip.formats import fem_run
from stickslip.h5io import CorruptFileError, FileFormatError, ReadBudgetError, open_file, read_array
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.stored_rows import first_unstored_row

#: The audit's lie: rows every growable dataset declares, and nstored.
LIE = 5_000_000


def write_fem_run(path, N=9, plates=2, increments=41):
    """A small valid ``fem-run`` file of synthetic numbers (the format's writer, no solver)."""
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    params = {"N": N, "plates": plates, "seed": 0, "max_increments": increments - 1}
    header = {"solver": "fem", "solver_version": "4", "params": params, "N": N, "plates": plates,
              "n_interfaces": plates - 1, "k_drive": 1e-3, "seed": 0, "eps0": 5e-5, "sig0": 1e-4, "gamma0": 8e-4,
              "c_s": 0.707, "h": math.pi, "dt": 0.05, "phi": 3.4e-8, "regime": "compliant"}
    ndof, nlayer, ni = mesh.ndof, mesh.nlayer, N * (plates - 1)
    columns = ["t", "sigd", *(f"{name}_a{a}" for name in ("S", "A") for a in range(1, plates))]
    response = (np.linspace(0, 1, ndof), np.full((ni, 4, 3), 1e-3), np.arange(nlayer, dtype=float), 0.0)
    rng = np.random.default_rng(1)
    with open_file(path, "w") as file:
        fem_run.create_file(file, header, mesh, response, columns)
        for i in range(increments):
            row = {"increment": i, "kick": i % 2 == 0, "yield_element": False, "t": float(i), "sigd": rng.random(),
                   **{name: i for name in columns[2:]}}
            state = fem_run.StoredState(rng.random(ndof), np.arange(nlayer, dtype=float), 0.0, float(i))
            fem_run.append_increment(file, state, row)
    return path


def lie(path, rows):
    """Resize every growable dataset of ``/increments`` and ``/state`` to ``rows`` and set ``nstored`` (the audit)."""
    with h5py.File(path, "r+") as file:
        for group in ("increments", "state"):
            for dataset in file[group].values():
                dataset.resize(rows, axis=0)
        file.attrs["nstored"] = rows
    return path


@pytest.fixture
def run(tmp_path):
    return write_fem_run(tmp_path / "run.h5")


def _one_line(capsys):
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


REFUSAL = textwrap.dedent(r"""
    import re, sys, time
    import stickslip
    started = time.perf_counter()
    try:
        stickslip.open_run(sys.argv[1]).increments
    except stickslip.h5io.CorruptFileError as error:
        # the peak resident memory of this process's image (VmHWM: ru_maxrss keeps the forking worker's across exec)
        peak_kib = int(re.search(r"VmHWM:\s+(\d+) kB", open("/proc/self/status").read())[1])
        print(time.perf_counter() - started, peak_kib / 1024, error)
""")


@pytest.mark.parametrize("rows", [LIE, 10**9])
def test_the_nstored_lie_is_refused_before_a_row_is_read_in_a_second_and_300_mb(run, rows, tmp_path, capsys):
    lie(run, rows)
    done = subprocess.run([sys.executable, "-c", REFUSAL, str(run)], capture_output=True, text=True, check=True)
    seconds, peak_mib, message = done.stdout.split(" ", 2)
    assert message.startswith(f"{run}: attribute 'nstored' is {rows}, but /state/u stores 41 rows at most")
    assert float(seconds) < 1.0 and float(peak_mib) < 300, done.stdout  # the whole process: imports included
    assert main(["increments", str(run), "-o", str(tmp_path / "run.csv")]) == 2
    assert "attribute 'nstored'" in _one_line(capsys) and not (tmp_path / "run.csv").exists()
    with pytest.raises(CorruptFileError, match="attribute 'nstored'"):
        fem_run.rewrite(run)  # the resume's copy: refused before it copies a row


def test_a_gzip_bomb_column_with_its_nstored_is_refused(run, capsys):
    rows, chunk = 250_000_000, 10**6
    with h5py.File(run, "r+") as file:
        del file["increments/sigd"]
        bomb = file.create_dataset("increments/sigd", shape=(rows,), maxshape=(None,), chunks=(chunk,), dtype="f8",
                                   compression="gzip")
        zeros = zlib.compress(np.zeros(chunk).tobytes(), 9)
        for start in range(0, rows, chunk):
            bomb.id.write_direct_chunk((start,), zeros)
        file.attrs["nstored"] = rows
        for dataset in file["state"].values():
            dataset.resize(rows, axis=0)
    assert run.stat().st_size < 3 * 2**20  # 2 GB of zeros in a file of 2 MB
    with pytest.raises(CorruptFileError, match=f"attribute 'nstored' is {rows}, but /state/"):
        stickslip.open_run(run).increments


def test_a_stored_table_beyond_the_memory_budget_is_refused_before_a_column_is_read(run, monkeypatch):
    monkeypatch.setenv(h5io.READ_LIMIT_VARIABLE, "0.001")  # 1 kB: the table of 41 rows takes 1.7 kB
    with pytest.raises(ReadBudgetError, match=r"run.h5: table 'increments' of 41 rows would take 1.68 KiB, beyond"):
        fem_run.read_increments(run)


def test_rows_in_a_chunk_never_written_are_refused_not_read_as_zeros(tmp_path):
    path = tmp_path / "holes.h5"
    with h5py.File(path, "w") as file:
        holed = file.create_dataset("holed", shape=(40, 3), maxshape=(None, 3), chunks=(4, 3), dtype="f8")
        holed[:12] = 1.0
        holed[16:] = 2.0  # rows 12 ... 15: never written
        file.create_dataset("unwritten", shape=(10,), dtype="f8")  # contiguous, never allocated
        file.create_dataset("written", data=np.arange(10.0))
        many = file.create_dataset("many", shape=(100, 2), maxshape=(None, 2), chunks=(1, 2), dtype="f8")
        many[:99] = 3.0  # row 99: never written (more chunks than are looked up one by one)
        many.resize(200, axis=0)
    with h5py.File(path, "r") as file:
        assert [first_unstored_row(file["holed"], *rows) for rows in ((0, 12), (0, 40), (13, 14), (16, 40))] == \
            [None, 12, 13, None]
        assert first_unstored_row(file["unwritten"]) == 0 and first_unstored_row(file["written"]) is None
        assert first_unstored_row(file["many"], 0, 99) is None and first_unstored_row(file["many"], 0, 150) == 99
        np.testing.assert_array_equal(read_array(file["holed"], slice(16, 40)), 2.0)
        for name, selection in (("holed", ()), ("holed", 13), ("unwritten", ()), ("many", slice(50, 120))):
            with pytest.raises(CorruptFileError, match=f"holes.h5: dataset /{name} declares .* rows but stores none "
                                                       r"from row \d+ on \(a chunk never written reads as zeros\)"):
                read_array(file[name], selection)


def test_a_virtual_or_external_dataset_is_refused(tmp_path):
    source = tmp_path / "source.h5"
    with h5py.File(source, "w") as file:
        file.create_dataset("x", data=np.arange(5.0))
    path = tmp_path / "pointing.h5"
    layout = h5py.VirtualLayout(shape=(5,), dtype="f8")
    layout[:] = h5py.VirtualSource(str(source), "x", shape=(5,))
    (tmp_path / "raw.bin").write_bytes(np.arange(5.0).tobytes())
    with h5py.File(path, "w") as file:
        file.create_virtual_dataset("virtual", layout)
        file.create_dataset("external", shape=(5,), dtype="f8", external=[(str(tmp_path / "raw.bin"), 0, 40)])
    with h5py.File(path, "r") as file:
        for name, what in (("virtual", "is a virtual dataset"), ("external", "stores its data in external files")):
            with pytest.raises(CorruptFileError, match=f"dataset /{name} {what}"):
                read_array(file[name])


def test_a_hole_in_a_stored_state_is_refused_where_it_is_read(run):
    with h5py.File(run, "r+") as file:
        u = file["state/u"]
        data, options = u[()], {"maxshape": u.maxshape, "chunks": u.chunks, "fletcher32": True}
        del file["state/u"]
        holed = file.create_dataset("state/u", shape=data.shape, dtype=data.dtype, **options)
        holed[:20] = data[:20]
        holed[21:] = data[21:]
    with open_file(run) as file:
        stored = fem_run.RunFile(file)
        np.testing.assert_array_equal(stored.state(19)[0], data[19])
        with pytest.raises(CorruptFileError, match="dataset /state/u declares 41 rows but stores none from row 20"):
            stored.state(20)
    with pytest.raises(CorruptFileError, match="/state/u declares 41 rows but stores none from row 20"):
        fem_run.rewrite(run)


def test_a_table_is_written_in_pieces_as_it_was_whole(run, tmp_path, monkeypatch):
    from stickslip.cli import increments

    monkeypatch.setattr(increments, "PIECE", 7)
    assert main(["increments", str(run), "-o", str(tmp_path / "run.csv")]) == 0
    whole = fem_run.read_increments(run).to_csv(index=False, float_format="%.17g")
    assert (tmp_path / "run.csv").read_text() == whole


def test_a_damaged_stored_parameter_names_the_file_and_says_damaged(tmp_path, capsys):
    output = tmp_path / "run.h5"
    args = ["simulate", "--solver", "fem", "--param", "N=9", "--param", "max_increments=2", "-o", str(output)]
    assert main(args) == 0
    with h5py.File(output, "r+") as file:  # the run not yet complete
        file.attrs["completed"] = False
    data = bytearray(output.read_bytes())  # a flipped bit in a parameter's text: 'fixed' -> 'fix\xe5d'
    where = data.index(b'"drive": "fixed-lever"') + len('"drive": "fix')
    data[where] ^= 0x80
    output.write_bytes(bytes(data))
    output.with_suffix(".provenance.json").unlink()  # a copy of the run without its record
    capsys.readouterr()
    with open_file(output) as file:
        from stickslip.fem.parameters import stored_params

        with pytest.raises(FileFormatError, match=f"{output}: attribute 'params' holds parameters no fem run has "
                                                  r"\(parameter 'drive': .* is not allowed"):
            stored_params(file)
    with pytest.raises(FileFormatError, match=f"{output}: attribute 'params' holds parameters no fem run has "
                                              r"\(parameter 'drive': .* is not allowed"):
        stickslip.open_run(output).run_id  # no record beside it: the id from the stored parameters
    assert main(args) == 2
    error = _one_line(capsys)
    assert error.startswith(f"stickslip: error: {output}: holds a fem-run file of solver fem 4 that is damaged: its "
                            "stored parameters are not valid (parameter 'drive': ") and "pass --overwrite" in error
    assert "with other parameters" not in error


def test_the_rows_a_killed_writer_left_beyond_nstored_are_not_read(run):
    with h5py.File(run, "r+") as file:  # killed after resizing for row 41, before writing it and raising nstored
        for group in ("increments", "state"):
            for dataset in file[group].values():
                dataset.resize(42, axis=0)
    assert len(stickslip.open_run(run).increments) == 41
    with open_file(run) as file:
        assert fem_run.RunFile(file).nstored == 41


#: The command of a small real fem run (resumed by the same command).
SIMULATE = ["simulate", "--solver", "fem", "--param", "N=9", "--param", "max_increments=2"]


def _nothing_stored(file):
    for group in ("increments", "state"):
        for dataset in file[group].values():
            dataset.resize(0, axis=0)
    file.attrs["nstored"] = 0


@pytest.mark.parametrize("mutate, expected", [
    (_nothing_stored, "attribute 'nstored' is 0, but a fem run stores its increment 0 when its file is created"),
    (lambda file: file["increments"].attrs.modify("columns", "[]"), "attribute 'columns' of /increments is [], "
                                                                    "expected the names of its 21 datasets"),
    (lambda file: file["increments"].attrs.modify("columns", '["increment", "kick", "yield_element", "t"]'),
     "attribute 'columns' of /increments is ['increment', 'kick', 'yield_element', 't'], expected"),
    (lambda file: file.attrs.create("solver_version", np.arange(3)), "holds a fem-run file of solver fem [0, 1, 2] "
                                                                     "(this run: solver_version '4')"),
], ids=["nstored 0", "no columns", "fewer columns", "solver_version an array"])
def test_a_resume_of_a_lying_run_is_one_line(mutate, expected, tmp_path, capsys):
    # found by benchmarks/fuzz_files.py --seed 59: an IndexError, a KeyError ('kick') and a ValueError (an array's
    # truth value) traceback of the resume
    output = tmp_path / "run.h5"
    assert main([*SIMULATE, "-o", str(output)]) == 0
    with h5py.File(output, "r+") as file:
        file.attrs["completed"] = False
        mutate(file)
    capsys.readouterr()
    assert main([*SIMULATE, "-o", str(output)]) == 2
    error = _one_line(capsys)
    assert error.startswith(f"stickslip: error: {output}: ") and expected in error, error
