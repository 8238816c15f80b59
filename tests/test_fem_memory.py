"""The fem run's memory estimate against its measured peak, and a command that runs out of memory is one line."""

import resource
import subprocess
import sys

from memory_probe import measure

#: The estimate's band against the peak measured (VmHWM): a lower bound, at most this far under it.
BAND = 0.2


def test_the_estimate_is_a_lower_bound_within_the_band_of_the_measured_peak(tmp_path):
    measure(9, 2, tmp_path)  # numba compiles the kernels not yet cached (a peak the estimate does not count)
    result = measure(486, 3, tmp_path)
    estimate = sum(result["estimate"].values())
    assert (1 - BAND) * result["peak"] <= estimate <= result["peak"], (estimate, result)


def _address_space(limit):
    def preexec():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return preexec


def test_a_command_that_runs_out_of_memory_says_so_in_one_line(tmp_path):
    # the preflight passes (its estimate is 0.9 GiB) but the address space of numba's process runs out
    done = subprocess.run([sys.executable, "-m", "stickslip", "simulate", "--solver", "fem", "--param", "N=13122",
                           "--param", "max_increments=1", "-o", str(tmp_path / "run.h5")],
                          capture_output=True, text=True, preexec_fn=_address_space(int(1.2 * 2**30)))
    error = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(error) == 1, done.stderr[-2000:]
    assert error[0].startswith("stickslip: error: simulate: out of memory") and "smaller N, plates, window" in error[0]
