"""What decides a run's bits is stored in its file, and a resume under another arithmetic is refused.

The bytes of an exact-relaxation run once depended on the OpenBLAS kernel of the host; a run
killed on one host and resumed on another continued another trajectory without a word. The
solvers now use no BLAS (``benchmarks/host_bytes.py``), and what still decides the bits
(:func:`stickslip.arithmetic.decisive`) is stored and checked: a stored fingerprint edited here
stands for a run started on a host of other packages.
"""

import json

import h5py
import numpy as np
import pytest

from stickslip.arithmetic import CONTINUE_VARIABLE, ArithmeticMismatchError, decisive, host
from stickslip.cli import main
from stickslip.fem.backends import make_backend
from stickslip.fem.parameters import FemParams
from stickslip.fem.run import simulate_to_file
from stickslip.formats.fem_run import read_increments, read_run_attrs
from stickslip.h5io import read_datasets
from stickslip.mesh import MeshParams, build_stack_mesh

CASE = ["N=9", "plates=2", "relaxation=exact", "max_increments=6", "nchunk=100"]


def _simulate(output, *extra):
    args = ["simulate", "--solver", "fem", "-o", str(output), *extra]
    for assignment in CASE:
        args += ["--param", assignment]
    return main(args)


def _content(path):
    """Every dataset and attribute of a file (an in-place edit of attributes changes the bytes, not these)."""
    with h5py.File(path, "r") as file:
        attrs = {key: (value.tolist() if isinstance(value, np.ndarray) else value) for key, value in file.attrs.items()}
    return read_datasets(path), attrs


def _same_content(a, b):
    (data_a, attrs_a), (data_b, attrs_b) = _content(a), _content(b)
    return attrs_a == attrs_b and data_a.keys() == data_b.keys() and all(
        np.array_equal(data_a[name], data_b[name]) for name in data_a)


def _interrupt_at(path, nstored, fingerprint_edit=None):
    """Make a completed run look killed after ``nstored`` increments, its fingerprint optionally edited."""
    with h5py.File(path, "r+") as file:
        file.attrs["nstored"] = nstored
        file.attrs["completed"] = False
        if fingerprint_edit:
            segments = json.loads(file.attrs["arithmetic"])
            segments[-1].update(fingerprint_edit)
            file.attrs["arithmetic"] = json.dumps(segments, sort_keys=True)


def test_a_run_file_states_what_decides_its_bits_and_the_record_the_host():
    fingerprint = decisive()
    assert {"python", "numpy", "scipy", "numba", "llvmlite", "qdldl", "h5py", "libm"} <= set(fingerprint)
    assert all(isinstance(value, str) and value for value in fingerprint.values())
    described = host()
    assert {"cpu_model", "cpu_simd", "blas", "numba_target", "numpy_simd"} <= set(described)
    assert any(entry["kernel"] for entry in described["blas"])  # numpy's OpenBLAS is loaded


def test_resume_under_other_packages_is_refused_naming_them_and_continues_when_asked(tmp_path, monkeypatch, capsys):
    monkeypatch.delenv(CONTINUE_VARIABLE, raising=False)
    path = tmp_path / "run.h5"
    assert _simulate(path) == 0
    stored = json.loads(read_run_attrs(path)["arithmetic"])
    assert stored == [{"from_increment": 0, **decisive()}]
    reference = tmp_path / "reference.h5"
    reference.write_bytes(path.read_bytes())
    uninterrupted = read_increments(path)

    _interrupt_at(path, 3)  # same arithmetic: resumes to the same numbers
    assert _simulate(path) == 0
    assert _same_content(path, reference)

    _interrupt_at(path, 3, {"numpy": "1.26.4", "scipy": "1.11.0"})
    with pytest.raises(ArithmeticMismatchError) as refused:  # the library call refuses as the CLI does
        params = FemParams(N=9, plates=2, relaxation="exact", max_increments=6, nchunk=100)
        simulate_to_file(params, path, build_stack_mesh(MeshParams(N=9, plates=2)), make_backend("structured"),
                       producer=("fem", "4"))
    message = str(refused.value)
    assert "\n" not in message
    assert "numpy 1.26.4 -> " in message and "scipy 1.11.0 -> " in message and "numba" not in message
    assert "--resume-other-arithmetic" in message and CONTINUE_VARIABLE in message
    assert _simulate(path) == 2  # the CLI: one line, exit status 2 (bad input)
    assert "numpy 1.26.4 -> " in capsys.readouterr().err
    with h5py.File(path, "r") as file:
        assert int(file.attrs["nstored"]) == 3  # nothing appended

    assert _simulate(path, "--resume-other-arithmetic") == 0
    segments = json.loads(read_run_attrs(path)["arithmetic"])
    assert [s["from_increment"] for s in segments] == [0, 3]
    assert segments[0]["numpy"] == "1.26.4" and segments[1] == {"from_increment": 3, **decisive()}
    resumed = read_increments(path)
    assert len(resumed) == len(uninterrupted)
    np.testing.assert_array_equal(resumed["sigd"].to_numpy(), uninterrupted["sigd"].to_numpy())
