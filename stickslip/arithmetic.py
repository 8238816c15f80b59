"""What decides the bits of a run's numbers, and what the host chose: recorded, and checked at a resume.

Two descriptions:

- :func:`decisive`: what a solver's numbers depend on beyond its parameters and the package's
  code: the versions of Python and of the libraries that compute or write them (numpy, scipy,
  numba, llvmlite, qdldl, h5py) and the C library whose libm numba's ``math`` functions call
  (glibc picks an FMA variant of ``exp``, ``log``, ``pow`` on CPUs with FMA and AVX2; on a CPU
  without them the rate-and-state lever's last bits differ, ``benchmarks/host_bytes.py``). The
  same on every host of one environment (environment.txt) with FMA, i.e. every x86-64 CPU since
  2013. A ``fem`` run file stores it (:mod:`stickslip.formats.fem_run`, attribute ``arithmetic``) and
  a resume under another refuses (:func:`check_resume`), unless told to continue
  (:data:`CONTINUE_VARIABLE`, or ``stickslip simulate --resume-other-arithmetic``): then the file
  records from which increment the other arithmetic holds.
- :func:`host`: what the host chose: CPU model and SIMD features, the BLAS libraries and the kernel
  OpenBLAS picked for the CPU (threadpoolctl), numba's target CPU, numpy's SIMD targets. None of it
  changes a solver's bits (``benchmarks/host_bytes.py`` runs each solver under every OpenBLAS kernel
  of a host, numba's generic target and numpy without AVX-512: the files are equal; docs/benchmarks.md).
  It goes into the provenance record beside every output (:mod:`stickslip.provenance.record`), not
  into the files, whose bytes would then differ from host to host.
"""

import json
import os
import platform
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import threadpoolctl
from llvmlite import binding as llvm
from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

from .h5io import FileFormatError

__all__ = ["DECISIVE_LIBRARIES", "CONTINUE_VARIABLE", "ArithmeticMismatchError", "decisive", "host", "segments",
           "differences", "check_resume"]

#: Libraries whose versions decide a solver's bits (computing or writing them).
DECISIVE_LIBRARIES = ("numpy", "scipy", "numba", "llvmlite", "qdldl", "h5py")

#: Set to 1 to resume a run under another arithmetic than the one it was started with (recorded).
CONTINUE_VARIABLE = "STICKSLIP_RESUME_OTHER_ARITHMETIC"

#: The SIMD flags of /proc/cpuinfo that a host's choice of kernels depends on.
_SIMD = ("sse2", "pni", "ssse3", "sse4_1", "sse4_2", "avx", "fma", "avx2", "avx512f", "avx512dq", "avx512cd",
         "avx512bw", "avx512vl", "avx512_bf16", "avx512_fp16", "amx_tile")


class ArithmeticMismatchError(FileFormatError):
    """A run would be resumed under another arithmetic than the one its stored increments were computed with."""


def _cpuinfo():
    """(model name, set of flags) of the first processor in /proc/cpuinfo (empty where there is none)."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return platform.processor(), set()
    fields = dict(line.split(":", 1) for line in lines if ":" in line)
    fields = {key.strip(): value.strip() for key, value in fields.items()}
    return fields.get("model name", platform.processor()), set(fields.get("flags", "").split())


def _libm():
    """The C library and whether glibc's libm uses its FMA variants (FMA and AVX2 usable, not masked)."""
    name, release = platform.libc_ver()
    _, flags = _cpuinfo()
    tunables = os.environ.get("GLIBC_TUNABLES", "")
    fma = {"fma", "avx2"} <= flags and "-FMA" not in tunables and "-AVX2" not in tunables
    return f"{name or 'unknown'} {release}".strip() + (" fma" if fma else "")


def decisive():
    """What decides a run's bits beyond its parameters (module docstring).

    Returns
    -------
    dict[str, str]
        ``python``, each of :data:`DECISIVE_LIBRARIES` (``"absent"`` if not installed) and ``libm``.
    """
    out = {"python": platform.python_version()}
    for name in DECISIVE_LIBRARIES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "absent"
    out["libm"] = _libm()
    return out


def host():
    """What this host chose (module docstring): recorded, never checked.

    Returns
    -------
    dict
        ``cpu_model``, ``cpu_simd`` (the SIMD flags of /proc/cpuinfo it has), ``blas`` (one entry per
        loaded BLAS: ``library``, ``version``, ``kernel``, ``threads``), ``numba_target`` (CPU name
        and features of numba's code; ``NUMBA_CPU_NAME`` if set), ``numpy_simd`` (numpy's dispatched
        SIMD targets this CPU runs).
    """
    model, flags = _cpuinfo()
    blas = [{"library": info.get("internal_api"), "version": info.get("version"),
             "kernel": info.get("architecture"), "threads": info.get("num_threads")}
            for info in threadpoolctl.threadpool_info() if info.get("user_api") == "blas"]
    # numba's own variables (read here, not through numba.config: a workflow job records this before it
    # may import numba, stickslip.workflow_api.prepare_environment)
    target = os.environ.get("NUMBA_CPU_NAME") or llvm.get_host_cpu_name()
    return {"cpu_model": model, "cpu_simd": [flag for flag in _SIMD if flag in flags], "blas": blas,
            "numba_target": {"cpu_name": target, "features": os.environ.get("NUMBA_CPU_FEATURES") or "host"},
            "numpy_simd": [name for name in __cpu_dispatch__ if __cpu_features__.get(name)]}


def segments(text, path="the run file"):
    """The arithmetic segments stored in a run file's ``arithmetic`` attribute (JSON list; [] if absent).

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the attribute is not a JSON list of objects (the message names ``path``).
    """
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    if not isinstance(text, str):
        raise FileFormatError(f"{path}: attribute 'arithmetic' is a {type(text).__name__}, expected JSON text")
    try:
        found = json.loads(text) if text else []
    except ValueError as error:
        raise FileFormatError(f"{path}: attribute 'arithmetic' is not JSON ({error})") from None
    if not isinstance(found, list) or not all(isinstance(item, dict) for item in found):
        raise FileFormatError(f"{path}: attribute 'arithmetic' is {text[:80]!r}, expected a JSON list of objects "
                              "(one per segment of arithmetic)")
    return found


def differences(stored, current):
    """``"name stored -> current"`` for every field of two :func:`decisive` mappings that differs."""
    return [f"{name} {stored.get(name, 'unrecorded')} -> {current.get(name, 'unrecorded')}"
            for name in sorted(set(stored) | set(current)) if name != "from_increment"
            and stored.get(name) != current.get(name)]


def check_resume(path, stored_text, nstored, allow=None, extra=None):
    """Check that a run can resume under this process's arithmetic; return the attribute to store.

    Parameters
    ----------
    path : str or pathlib.Path
        The run file (for the message).
    stored_text : str
        Its ``arithmetic`` attribute: a JSON list of segments, each :func:`decisive` with the
        ``from_increment`` it holds from.
    nstored : int
        Increments stored: a new segment would hold from this one.
    allow : bool, optional
        Continue under another arithmetic (default: :data:`CONTINUE_VARIABLE` is ``1``).
    extra : Mapping[str, object], optional
        What else decides the run's bits beside :func:`decisive` (a backend's device:
        :func:`stickslip.fem.backends.backend_arithmetic`), compared as well.

    Returns
    -------
    str or None
        None if the arithmetic is the stored one; else the attribute with a new segment appended.

    Raises
    ------
    ArithmeticMismatchError
        If it differs and continuing was not allowed: one line naming every field that differs
        and how to continue anyway.
    """
    allow = os.environ.get(CONTINUE_VARIABLE) == "1" if allow is None else allow
    stored = segments(stored_text, path)
    current = {**decisive(), **(extra or {})}
    changed = differences(stored[-1] if stored else {}, current)
    if not changed:
        return None
    if not allow:
        raise ArithmeticMismatchError(
            f"{path}: its {nstored} increments were computed with other arithmetic ({'; '.join(changed)}), so "
            f"resuming here would continue another trajectory; resume with the same packages, or continue anyway "
            f"with `stickslip simulate --resume-other-arithmetic` ({CONTINUE_VARIABLE}=1), which the file records")
    return json.dumps(stored + [{"from_increment": int(nstored), **current}], sort_keys=True)
