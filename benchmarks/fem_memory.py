"""The fem run's peak memory against its estimate (:func:`stickslip.fem.memory.run_memory`): docs/fem.md, "Memory".

    nice -n 10 python benchmarks/fem_memory.py --sizes 486:2 486:3 1458:2 1458:3 4374:2

Each size runs ``stickslip simulate``'s solver (``max_increments = 1``, other parameters the defaults) in a fresh
process, which computes the estimate as the preflight does (after the imports), runs, then reads its peak resident
memory (``VmHWM`` of /proc/self/status: ``ru_maxrss`` would keep a forking parent's across exec). Prints per size:
blocks, the peak, the estimate and its terms, estimate / peak.
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

#: The child: estimate, run, report the peak (one JSON line on stdout).
CHILD = """
import json, sys
from stickslip.fem.memory import run_memory
from stickslip.fem.parameters import FemParams
from stickslip.plugin_params import parse_params
from stickslip.solver_run import run_solver
values = json.loads(sys.argv[1])
estimate = run_memory(parse_params(FemParams, values))
run_solver("fem", sys.argv[2], values)
peak = [int(line.split()[1]) * 1024 for line in open("/proc/self/status") if line.startswith("VmHWM:")][0]
print(json.dumps({"peak": peak, "estimate": estimate}))
"""


def measure(N, plates, directory, max_increments=1, preexec_fn=None):
    """Run one fem run of ``N`` and ``plates`` in a fresh process; return its peak and estimate.

    Returns
    -------
    dict
        ``peak`` [B] (``VmHWM``), ``estimate`` (:func:`stickslip.fem.memory.run_memory`'s terms [B]).
    """
    values = {"N": str(N), "plates": str(plates), "max_increments": str(max_increments)}
    output = Path(directory) / f"memory-{N}-{plates}.h5"
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(values), str(output)], capture_output=True,
                          text=True, check=True, preexec_fn=preexec_fn)
    return json.loads(done.stdout.splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", nargs="+", default=["486:2", "486:3", "1458:2", "1458:3", "4374:2"],
                        metavar="N:PLATES")
    args = parser.parse_args()
    print(f"{'N':>6} {'plates':>6} {'blocks':>7} {'peak MB':>8} {'estimate MB':>11} {'ratio':>6}  terms (MB)")
    with tempfile.TemporaryDirectory() as directory:
        for size in args.sizes:
            N, plates = (int(v) for v in size.split(":"))
            result = measure(N, plates, directory)
            total = sum(result["estimate"].values())
            terms = ", ".join(f"{k} {v / 1e6:.1f}" for k, v in result["estimate"].items())
            print(f"{N:6d} {plates:6d} {N * (plates - 1):7d} {result['peak'] / 1e6:8.1f} {total / 1e6:11.1f} "
                  f"{total / result['peak']:6.3f}  {terms}", flush=True)


if __name__ == "__main__":
    main()
