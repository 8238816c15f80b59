"""A cached caller of a parallel kernel loads in a fresh process (stickslip.numba_options).

numba (issues #8578, #9938) caches a caller compiled in a process that loaded its
``parallel=True`` callee from the cache without the hook that starts the threading
layer; a later process whose first kernel is that caller jumps to address 0. Three
processes share one cache directory, as Snakemake jobs do: the first compiles the
parallel kernel, the second its caller, the third calls the caller first. Without
:func:`stickslip.numba_options.start_threading_layer` the third dies with SIGSEGV.
"""

import os
import subprocess
import sys
import textwrap

import pytest

KERNELS = textwrap.dedent("""
    import sys

    import numba
    import numpy as np

    from stickslip.numba_options import njit


    @njit(parallel=True)
    def doubled(x):
        out = np.empty_like(x)
        for i in numba.prange(x.size):
            out[i] = 2.0 * x[i]
        return out


    @njit
    def doubled_sum(x):
        return doubled(x).sum()


    x = np.arange(1000.0)
    print(doubled(x).sum() if sys.argv[1] == "parallel" else doubled_sum(x))
""")


def _run(tmp_path, first_kernel):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), STICKSLIP_NUMBA_CACHE="1",
               NUMBA_NUM_THREADS="2", PYTHONPATH=os.pathsep.join(sys.path))
    return subprocess.run([sys.executable, str(tmp_path / "kernels.py"), first_kernel], env=env,
                          capture_output=True, text=True, timeout=300)


@pytest.mark.slow
def test_a_cached_caller_of_a_parallel_kernel_runs_in_a_fresh_process(tmp_path):
    (tmp_path / "kernels.py").write_text(KERNELS)
    expected = str(2.0 * sum(range(1000)))
    for step, first_kernel in enumerate(["parallel", "caller", "caller"]):
        done = _run(tmp_path, first_kernel)
        assert done.returncode == 0, f"process {step + 1} ({first_kernel} first): exit {done.returncode}\n{done.stderr}"
        assert done.stdout.strip() == expected
    assert {path.name.split("-")[0] for path in (tmp_path / "cache").rglob("*.nbi")} == {
        "kernels.doubled", "kernels.doubled_sum"}
