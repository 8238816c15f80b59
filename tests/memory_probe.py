"""A fem run's peak resident memory and its estimate, measured in a fresh process.

Used by tests/test_fem_memory.py (one small size) and benchmarks/fem_memory.py (the sizes of docs/fem.md).
"""

import json
import subprocess
import sys
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
    output.unlink(missing_ok=True)  # a run file already there would be resumed, not built: no model, no peak
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(values), str(output)], capture_output=True,
                          text=True, check=True, preexec_fn=preexec_fn)
    return json.loads(done.stdout.splitlines()[-1])
