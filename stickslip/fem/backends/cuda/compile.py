"""Compile every kernel of the ``cuda`` backend to PTX for a given GPU, on a machine without one, and read it.

numba-cuda compiles a kernel to PTX with the NVVM library alone (its wheel, no driver) when every
device function is inlined, as all of :mod:`.items`, :mod:`.sync`, :mod:`.tiles` and :mod:`.minimise`
are. The arguments' types are those of a real launch: the same argument lists
(:meth:`.launch.Launcher.arguments`), built from host arrays of the same dtypes and shapes. Typing
errors, which numba's simulator does not catch, thus show up in CI rather than in the few minutes a
GPU is lent (tests/test_fem_cuda.py). :func:`ptx_figures` reads what the kernels' design promises off
the PTX: the grid barriers of the minimisation kernel, its shared memory, and no floating-point
atomics (``atom.`` or ``red.`` on ``.f16/.f32/.f64``).
"""

import re

import numba
import numpy as np
from numba import cuda

from ...laws import LAWS
from .device import DeviceMesh
from .kernels import KERNELS, python_kernels
from .launch import Launcher
from .state import DeviceState

__all__ = ["ptx", "ptx_figures", "KERNELS"]


def ptx(model, mesh, cc=(9, 0), kernels=KERNELS):
    """PTX of the kernels for ``model``'s law on ``mesh``, for compute capability ``cc`` (default sm_90).

    Returns
    -------
    dict[str, str]
        Kernel name -> PTX.
    """
    device_mesh = DeviceMesh(model, mesh, place=np.ascontiguousarray)
    state = DeviceState(device_mesh, 1)
    launcher = Launcher.__new__(Launcher)  # its argument lists only (no kernels: they would be jitted for a device)
    launcher.mesh, launcher.law, launcher.deadline = device_mesh, model.law, 1
    python = python_kernels(LAWS[type(model.law).name])
    extra = {"load": (0.0,), "add_u": (np.zeros(1, np.int64), np.zeros(1)), "shift_wells": (np.zeros(1, np.int64),)}
    out = {}
    for name in kernels:
        arguments = launcher.arguments(name, [0], state, extra=extra.get(name, ()))
        signature = tuple(numba.typeof(argument) for argument in arguments)
        out[name], _ = cuda.compile(python[name], signature, device=False, cc=cc, abi="numba", output="ptx")
    return out


#: A floating-point atomic or reduction in PTX.
FLOAT_ATOMIC = re.compile(r"\b(atom|red)\.[\w.]*\.f(16|32|64)\b")


def ptx_figures(text):
    """What a kernel's PTX says: grid barriers (arrivals at a barrier counter: ``atom.global.add``), the spins on it,
    floating-point atomics, shared memory [bytes], the target.

    Returns
    -------
    dict
    """
    lines = text.splitlines()
    shared = sum(int(size) * int(count) for size, count in
                 re.findall(r"\.shared \.align \d+ \.b(\d+) \w+\[(\d+)\]", text)) // 8
    return {"target": next((line.split()[1] for line in lines if line.startswith(".target")), ""),
            "grid_barriers": sum(1 for line in lines if "atom.global.add.u32" in line),
            "barrier_spins": sum(1 for line in lines if "atom.global.or.b32" in line),
            "float_atomics": [line.strip() for line in lines if FLOAT_ATOMIC.search(line)],
            "shared_bytes": shared}
