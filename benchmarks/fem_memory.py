"""The fem run's peak memory against its estimate (:func:`stickslip.fem.memory.run_memory`): docs/fem.md, "Memory".

    nice -n 10 python benchmarks/fem_memory.py --sizes 486:2 486:3 1458:2 1458:3 4374:2

Each size runs ``stickslip simulate``'s solver (``max_increments = 1``, other parameters the defaults) in a fresh
process, which computes the estimate as the preflight does (after the imports), runs, then reads its peak resident
memory (``VmHWM`` of /proc/self/status: ``ru_maxrss`` would keep a forking parent's across exec). Prints per size:
blocks, the peak, the estimate and its terms, estimate / peak.
"""

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from memory_probe import measure  # noqa: E402

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
