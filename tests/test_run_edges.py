"""Runs at their edges (issue 45, items 1, 8, 9, 10, 15): an aging run's state, arguments of the wrong type, a thermal
run's failures, and the GPU in what decides a run's bits.

The audit of c47ca12: ``FemRun.state()`` raised "too many values to unpack" on every junction-aging run;
``simulate(..., overwrite="no")`` replaced the run (a truthy string); ``threads="2"`` was a TypeError that did not
name ``threads``; ``failures()`` of a thermal run was an AssertionError; a ``cuda`` run recorded neither its GPU nor
whether numba's CUDA simulator ran it, so a resume could not compare them and simulator runs took the GPU's run ids.
"""

import importlib.util
import os
import subprocess
import sys

import numpy as np
import pytest

import stickslip
from stickslip.arithmetic import ArithmeticMismatchError
from stickslip.fem.backends import backend_arithmetic
from stickslip.formats.fem_run import check_arithmetic
from stickslip.h5io import FileFormatError
from stickslip.plugin_params import ParameterError

AGING = {"N": 9, "plates": 2, "temperature": 1e-3, "drive_rate": 2e-8, "junction_strengthening": 5.0}


@pytest.fixture(scope="module")
def aging_run(tmp_path_factory):
    return stickslip.simulate("fem", tmp_path_factory.mktemp("aging") / "a.h5", max_increments=5, **AGING)


def test_the_state_of_a_junction_aging_run_has_its_junctions(aging_run):
    for increment in range(aging_run.increments["increment"].size):
        state = aging_run.state(increment)
        assert set(state.further) == {"junction_depth", "junction_well"}
        assert state.further["junction_depth"].shape == state.further["junction_well"].shape == (9,)
        blocks_with_a_junction = state.further["junction_well"] >= 0
        assert blocks_with_a_junction.any() and np.all(state.further["junction_depth"][blocks_with_a_junction] >= 0)


def test_failures_of_a_thermal_run_are_a_file_format_error(aging_run):
    event = int(aging_run.increments["increment"][aging_run.increments["kick"]].iloc[1])
    with pytest.raises(FileFormatError, match="thermal"):
        aging_run.failures(event)


@pytest.mark.parametrize("argument, value", [("overwrite", "no"), ("overwrite", 1), ("threads", "2"),
                                             ("threads", 0), ("threads", True), ("threads", 1.5)])
def test_arguments_of_the_wrong_type_are_refused_naming_them(tmp_path, argument, value):
    output = tmp_path / "run.h5"
    stickslip.simulate("fem", output, N=9, plates=2, max_increments=2)
    before = output.read_bytes()
    with pytest.raises(ParameterError, match=f"parameter '{argument}'"):
        stickslip.simulate("fem", output, N=9, plates=2, max_increments=3, **{argument: value})
    assert output.read_bytes() == before


def test_the_cpu_backends_add_nothing_to_the_arithmetic():
    assert backend_arithmetic("structured") == {} and backend_arithmetic("assembled") == {}


def test_a_resume_under_another_gpu_is_refused_naming_it(tmp_path):
    output = tmp_path / "run.h5"
    stickslip.simulate("fem", output, N=9, plates=2, max_increments=2)
    assert check_arithmetic(output) == {}
    gpu = {"gpu": "NVIDIA H200", "gpu_compute_capability": "9.0", "gpu_driver": "CUDA 13.0", "numba_cuda": "0.30.4",
           "cuda_simulator": False}
    with pytest.raises(ArithmeticMismatchError, match="gpu") as refused:
        check_arithmetic(output, gpu)
    assert "\n" not in str(refused.value)


CUDA_TOOLS = importlib.util.find_spec("numba_cuda") is not None


@pytest.mark.skipif(not CUDA_TOOLS, reason="numba-cuda is not installed (CI installs it: .ci/requirements.txt)")
def test_a_simulated_cuda_run_says_so_and_is_refused_outside_the_tests():
    script = ("from stickslip.fem.backends import backend_arithmetic, make_backend\n"
              "print(backend_arithmetic('cuda'))\n"
              "make_backend('cuda')\n")
    environment = {name: value for name, value in os.environ.items() if name != "PYTEST_CURRENT_TEST"}
    environment["NUMBA_ENABLE_CUDASIM"] = "1"
    done = subprocess.run([sys.executable, "-c", script], env=environment, capture_output=True, text=True, timeout=300)
    assert "'cuda_simulator': True" in done.stdout and "'gpu': 'none'" in done.stdout, done.stdout
    assert done.returncode == 1 and "STICKSLIP_CUDA_SIMULATOR=1" in done.stderr.strip().splitlines()[-1]
    environment["STICKSLIP_CUDA_SIMULATOR"] = "1"
    done = subprocess.run([sys.executable, "-c", script], env=environment, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
