"""Execution backends of the fem model: how the numbers are computed, not what they are.

A backend is chosen once per run (:func:`make_backend`) and prepared for its model (it then owns
the state; :mod:`.base` is the seam every backend implements). Built in: ``structured`` (default)
and ``assembled`` (the reference), numba CPU backends (:mod:`.cpu`), and ``cuda`` (an NVIDIA GPU,
:mod:`.cuda`; optional dependency numba-cuda). A backend whose results are
bit-identical to the default's would be an execution option like ``threads``; both alternatives
here change the round-off, so the choice is the ``backend`` parameter of ``fem`` (recorded in the
run file and its id). A new backend: a class decorated by :func:`register_backend`, in a module of this
package (every module of it is imported) or of another package that names it in the entry-point group
:data:`ENTRY_POINT_GROUP` (docs/developing.md, "A new backend"). A run's code hash covers the backend it
chooses, not the others (:func:`stickslip.provenance.code.plugin_code_hash`).
"""

import os
from importlib.metadata import PackageNotFoundError, version

from ...discovery import import_modules, load_entry_points
from ...plugin_params import ParameterError
from .base import BACKENDS, CONVERGED, FIELDS, MARGIN, MAX_ITER_REACHED, QUIET, Backend, register_backend
from .cuda import CudaBackend

__all__ = ["BACKENDS", "DEFAULT_BACKEND", "ENTRY_POINT_GROUP", "Backend", "make_backend", "register_backend", "FIELDS",
           "CONVERGED", "MARGIN", "QUIET", "MAX_ITER_REACHED", "backend_arithmetic", "gpu_arithmetic",
           "SIMULATOR_VARIABLE"]

#: Set to 1 to run the ``cuda`` backend on numba's CUDA simulator outside the tests (which may anyway).
SIMULATOR_VARIABLE = "STICKSLIP_CUDA_SIMULATOR"

#: The entry-point group through which other packages add backends (a module registering them).
ENTRY_POINT_GROUP = "stickslip.fem.backends"

#: The backend of a run that names none.
DEFAULT_BACKEND = "structured"

import_modules(__name__)
load_entry_points(ENTRY_POINT_GROUP)


def _simulated():
    """Whether numba-cuda runs on its CUDA simulator (``NUMBA_ENABLE_CUDASIM``), read as numba-cuda reads it."""
    from numba import config

    return bool(config.ENABLE_CUDASIM)


def gpu_arithmetic():
    """What decides the bits of a ``cuda`` run beside :func:`stickslip.arithmetic.decisive`: the device and its software.

    Returns
    -------
    dict[str, object]
        ``gpu`` (the device's name), ``gpu_compute_capability``, ``gpu_driver`` (the CUDA version of its
        driver), ``numba_cuda`` (numba-cuda's version) and ``cuda_simulator`` (True: numba's CUDA simulator
        ran it, no GPU).
    """
    try:
        numba_cuda = version("numba-cuda")
    except PackageNotFoundError:
        numba_cuda = "absent"
    if _simulated():
        return {"gpu": "none", "gpu_compute_capability": "none", "gpu_driver": "none", "numba_cuda": numba_cuda,
                "cuda_simulator": True}
    from numba import cuda

    device = cuda.get_current_device()
    name = device.name.decode() if isinstance(device.name, bytes) else str(device.name)
    driver = ".".join(map(str, cuda.cudadrv.driver.driver.get_version()))
    return {"gpu": name, "gpu_compute_capability": ".".join(map(str, device.compute_capability)),
            "gpu_driver": f"CUDA {driver}", "numba_cuda": numba_cuda, "cuda_simulator": False}


#: Backends whose runs' bits depend on more than :func:`stickslip.arithmetic.decisive`: name -> what describes it.
_ARITHMETIC = {CudaBackend.name: gpu_arithmetic}


def backend_arithmetic(name):
    """What decides the bits of backend ``name``'s runs beside the host's libraries (``{}`` for the CPU backends).

    A run file records it with its arithmetic (:mod:`stickslip.formats.fem_run`, attribute ``arithmetic``) and a
    resume under another is refused (:func:`stickslip.arithmetic.check_resume`).

    Parameters
    ----------
    name : str
        A registered backend.

    Returns
    -------
    dict[str, object]
    """
    describe = _ARITHMETIC.get(name)
    return describe() if describe is not None else {}


def _refused_simulator(name):
    """Why ``name`` may not run here on numba's CUDA simulator ("" if it may): its runs would take the GPU's ids."""
    if name != CudaBackend.name or not _simulated():
        return ""
    if os.environ.get("PYTEST_CURRENT_TEST") or os.environ.get(SIMULATOR_VARIABLE) == "1":
        return ""
    return (f"NUMBA_ENABLE_CUDASIM=1 runs it on numba's CUDA simulator, whose runs would take the run ids of runs "
            f"on a GPU: unset it, or set {SIMULATOR_VARIABLE}=1 to try the backend (files not for results)")


def make_backend(name=DEFAULT_BACKEND, threads=1):
    """The backend ``name`` with ``threads`` threads (to be prepared for a model, :meth:`.base.Backend.prepare`).

    Raises
    ------
    stickslip.plugin_params.ParameterError
        If no backend of that name is registered, or it cannot run on this machine (the message says why), or
        ``cuda`` would run on numba's CUDA simulator outside the tests (and :data:`SIMULATOR_VARIABLE` is not 1).
    """
    if name not in BACKENDS:
        raise ParameterError(f"parameter 'backend': {name!r} is not a backend; expected one of "
                             f"{', '.join(sorted(BACKENDS))}")
    reason = BACKENDS[name].unavailable() or _refused_simulator(name)
    if reason:
        raise ParameterError(f"parameter 'backend': {name!r} cannot run on this machine: {reason}")
    return BACKENDS[name](threads=threads)
