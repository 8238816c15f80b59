"""Import time of the package, of the command line and of the workflow's job module, each in a fresh interpreter.

Every command and every workflow job imports ``stickslip`` (and with it the public API,
:mod:`stickslip.api`) first, so what the package's ``__init__`` imports is paid once per process.

    python benchmarks/bench_import.py [--repeat 7] [--source DIR]

``--source DIR`` times the package found in DIR (e.g. an older checkout's tree, ``git archive REV
stickslip | tar -x -C DIR``) instead of the installed one. Prints the best of ``--repeat`` runs per module
[ms] and the heavy libraries each import loads.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

MODULES = ("stickslip", "stickslip.cli", "stickslip.workflow_api")
HEAVY = ("pandas", "h5py", "sqlalchemy", "scipy", "numba", "matplotlib")

PROBE = ("import sys, time, json\n"
         "start = time.perf_counter()\n"
         "import {module}\n"
         "print(json.dumps([time.perf_counter() - start, sys.modules['stickslip'].__file__,\n"
         "                  [m for m in {heavy!r} if m in sys.modules]]))")


def time_import(module, source=None):
    """(seconds, the package's file, heavy libraries loaded) of one import in a fresh interpreter."""
    environment = dict(os.environ, PYTHONPATH=source) if source else None
    # run outside any checkout: `python -c` puts the working directory first on the path
    done = subprocess.run([sys.executable, "-c", PROBE.format(module=module, heavy=HEAVY)], env=environment,
                          cwd=tempfile.gettempdir(), capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="runs per module; the best is shown (default 7)")
    parser.add_argument("--source", help="directory holding the stickslip package to time")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f}")
    for module in MODULES:
        runs = [time_import(module, args.source) for _ in range(args.repeat)]
        best = min(seconds for seconds, _, _ in runs)
        print(f"{module:24} {best * 1000:6.0f} ms  ({runs[0][1]}; loads {', '.join(runs[0][2]) or 'none of them'})")


if __name__ == "__main__":
    main()
