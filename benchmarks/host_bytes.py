"""Do a solver's output bytes depend on the host's CPU? One run per arithmetic setting, compared byte for byte.

Usage::

    python benchmarks/host_bytes.py                      # every case, every setting this host supports
    python benchmarks/host_bytes.py --case fem-exact     # one case
    python benchmarks/host_bytes.py --case fem-default-study --setting machine --setting avx2-host

Each case is one ``stickslip simulate`` run (a fresh process, its own output file) under each
setting of what a host chooses by its CPU, set here and nowhere else (tests and CI keep the
machine's own):

- ``OPENBLAS_CORETYPE``: the OpenBLAS kernel of numpy and scipy, every kernel this CPU can run
  (from the flags in /proc/cpuinfo; what the library really picked is read back with threadpoolctl
  in the child and printed: a kernel OpenBLAS does not know falls back silently);
- ``NUMBA_CPU_NAME=generic``: numba's code for a generic x86-64 instead of this CPU;
- ``NPY_DISABLE_CPU_FEATURES``: numpy's own SIMD loops limited to AVX2 (an AVX-512 host's
  numpy then runs as on an AVX2 host);
- ``GLIBC_TUNABLES``: glibc's libm without its FMA and AVX2 variants (``exp``, ``log``, ``pow``
  as on a CPU without FMA);
- ``avx2-host``: all of these at once, as an AVX2 (Haswell) host would choose.

Prints one line per run: the setting, the kernel OpenBLAS reported, the file's sha256, whether
its bytes equal the first run's and whether its numbers do (every dataset; the files also state
what decides their bits, :mod:`stickslip.arithmetic`, so a setting that changes that, glibc's libm
without FMA, changes an attribute even where the numbers stay); for numbers that differ, the first
dataset that differs and its largest difference. A setting that changes what decides the bits
(``arithmetic=other``: glibc's libm without FMA) may change the numbers: the documented difference
of a CPU without FMA (docs/fem.md, "The same bytes on any x86-64 host": the ``rate-state-lever``
solver's last bits), which such a host records and a resume refuses; it is shown (``expected``) and
does not fail the run. Last line ``all_equal=<bool>`` (bytes), ``numbers_equal=<bool>`` (under this host's
arithmetic) and the settings of other arithmetic whose numbers differ; the exit status is 0 when
every setting of this host's arithmetic gives equal numbers. A case takes a few seconds per setting
once numba's cache is warm (``NUMBA_CPU_NAME=generic`` compiles every kernel once: minutes).
"""

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from stickslip.h5io import read_datasets

#: One short run of each solver and relaxation: (solver, KEY=VALUE parameters).
CASES = {
    "fem-exact": ("fem", ["N=9", "plates=3", "relaxation=exact", "max_increments=60", "k_drive=0.081"]),
    "fem-exact-free-lever": ("fem", ["N=9", "plates=3", "relaxation=exact", "max_increments=40", "drive=free-lever"]),
    "fem-dynamic": ("fem", ["N=9", "plates=2", "max_increments=20"]),
    "fem-thermal": ("fem", ["N=9", "plates=2", "relaxation=exact", "max_increments=30", "temperature=0.05",
                            "drive_rate=1e-6"]),
    # one fem run of the default study (workflow/config/default.yaml), minutes per setting
    "fem-default-study": ("fem", ["N=162", "plates=3", "relaxation=exact", "dt_scale=4", "max_increments=250",
                                  "k_drive=0.08281", "seed=1"]),
    "lever": ("lever", ["n=3", "duration=600"]),
    "rate-state-lever": ("rate-state-lever", ["n=3", "duration=300"]),
}

#: OpenBLAS kernels (``OPENBLAS_CORETYPE``) and the CPU flags each needs.
KERNELS = {
    "Cooperlake": {"avx512f", "avx512bw", "avx512vl", "avx512dq", "avx512cd", "avx512_bf16"},
    "SkylakeX": {"avx512f", "avx512bw", "avx512vl", "avx512dq", "avx512cd"},
    "Haswell": {"avx2", "fma"},
    "Zen": {"avx2", "fma"},
    "SandyBridge": {"avx"},
    "Nehalem": {"sse4_2"},
    "Prescott": {"sse3"},
}

#: numpy's dispatch targets above AVX2 (numpy 2.4 names).
NUMPY_ABOVE_AVX2 = "X86_V4 AVX512_ICL AVX512_SPR"
#: glibc's libm variants chosen by these CPU features.
GLIBC_NO_FMA = "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F"

_REPORT = ("import json, numpy, scipy.linalg, threadpoolctl; from stickslip.arithmetic import decisive; "
           "print(json.dumps([sorted({i.get('architecture') or '?' for i in threadpoolctl.threadpool_info() "
           "if i['user_api'] == 'blas'}), decisive()]))")


def cpu_flags():
    """The CPU's feature flags (first processor of /proc/cpuinfo)."""
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("flags"):
            return set(line.split(":", 1)[1].split())
    return set()


def settings(flags):
    """(name, environment changes) of every setting this CPU supports; the machine's own first."""
    out = [("machine", {})]
    out += [(f"OPENBLAS_CORETYPE={name}", {"OPENBLAS_CORETYPE": name}) for name, needs in KERNELS.items()
            if needs <= flags]
    out += [("NUMBA_CPU_NAME=generic", {"NUMBA_CPU_NAME": "generic"}),
            ("NPY_DISABLE_CPU_FEATURES", {"NPY_DISABLE_CPU_FEATURES": NUMPY_ABOVE_AVX2}),
            ("GLIBC_TUNABLES", {"GLIBC_TUNABLES": GLIBC_NO_FMA}),
            ("avx2-host", {"OPENBLAS_CORETYPE": "Haswell", "NUMBA_CPU_NAME": "haswell",
                           "NPY_DISABLE_CPU_FEATURES": NUMPY_ABOVE_AVX2, "GLIBC_TUNABLES": GLIBC_NO_FMA.replace(
                               "-AVX2,-FMA,", "")})]
    return out


def first_difference(path, reference):
    """The first dataset (by name) whose values differ, with the largest absolute difference; None if none."""
    a, b = read_datasets(path), read_datasets(reference)
    for name in sorted(set(a) | set(b)):
        if name not in a or name not in b or np.shape(a[name]) != np.shape(b[name]):
            return f"{name} (missing or other shape)"
        if not np.array_equal(a[name], b[name]):
            diff = np.max(np.abs(np.asarray(a[name], dtype=float) - np.asarray(b[name], dtype=float)))
            return f"{name} (max |difference| {diff:.3g})"
    return None


def run_case(solver, assignments, environment, output):
    """Run one case in a fresh process; return the OpenBLAS kernels it reported and what decides its bits."""
    env = {**os.environ, **environment}
    report = subprocess.run([sys.executable, "-c", _REPORT], env=env, check=True, capture_output=True,
                            text=True).stdout.strip()
    command = [sys.executable, "-m", "stickslip", "simulate", "--solver", solver, "-o", str(output)]
    for assignment in assignments:
        command += ["--param", assignment]
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    kernels, arithmetic = json.loads(report)
    return ",".join(kernels), arithmetic


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=sorted(CASES), action="append",
                        help="case to run (repeat; default all but fem-default-study)")
    parser.add_argument("--setting", action="append", help="setting to run, by its printed name (repeat; default all)")
    args = parser.parse_args(argv)
    flags = cpu_flags()
    model = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                  if line.startswith("model name")), "?")
    print(f"cpu: {model}; avx512f={'avx512f' in flags} avx2={'avx2' in flags} fma={'fma' in flags}")
    all_equal = numbers_equal = True
    expected = []  # settings of another arithmetic whose numbers differ (the documented no-FMA difference)
    with tempfile.TemporaryDirectory() as tmp:
        for case in args.case or [name for name in CASES if name != "fem-default-study"]:
            solver, assignments = CASES[case]
            reference = None
            for name, environment in settings(flags):
                if args.setting and name not in args.setting:
                    continue
                output = Path(tmp) / f"{case}-{len(list(Path(tmp).iterdir()))}.h5"
                kernels, arithmetic = run_case(solver, assignments, environment, output)
                digest = sha256(output)
                if reference is None:
                    reference, first, own = digest, output, arithmetic
                equal = digest == reference
                difference = None if equal else first_difference(output, first)
                same = arithmetic == own
                all_equal &= equal
                if same:
                    numbers_equal &= difference is None
                elif difference is not None:
                    expected.append(f"{case} {name}")
                detail = f" first difference: {difference}" if difference else ""
                detail += "" if same or difference is None else " (expected: another arithmetic, docs/fem.md)"
                print(f"{case:22s} {name:26s} blas={kernels:12s} arithmetic={'same' if same else 'other'} "
                      f"sha256={digest[:16]} bytes_equal={equal!s:5s} numbers_equal={difference is None}{detail}",
                      flush=True)
    print(f"all_equal={all_equal} numbers_equal={numbers_equal} other_arithmetic_differs="
          f"{'; '.join(expected) or 'none'}")
    return 0 if numbers_equal else 1


if __name__ == "__main__":
    sys.exit(main())
