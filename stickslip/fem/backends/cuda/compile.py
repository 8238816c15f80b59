"""Compile every kernel of the ``cuda`` backend to PTX for a given GPU, on a machine without one, and read it.

numba-cuda compiles a kernel to PTX with the NVVM library alone (its wheel, no driver) when every
device function is inlined, as all of :mod:`.items`, :mod:`.sync`, :mod:`.tiles` and :mod:`.minimise`
are. The arguments' types are those of a real launch: the same argument lists
(:meth:`.launch.Launcher.arguments`), built from host arrays of the same dtypes and shapes. Typing
errors, which numba's simulator does not catch, thus show up in CI rather than in the few minutes a
GPU is lent (tests/test_fem_cuda.py). :func:`ptx_figures` reads what the kernels' design promises off
the PTX: the grid barriers of the minimisation kernels, their block barriers, shared memory, and no
floating-point atomics (``atom.`` or ``red.`` on ``.f16/.f32/.f64``); and off the machine code that
ptxas makes of it for the PTX's target (through nvJitLink, the ``nvidia-nvjitlink`` wheel, no driver):
registers per thread, the stack frame and the spills, under the register cap of the launch
(:data:`.kernels.MAX_REGISTERS` for the minimisation kernels).

``python -m stickslip.fem.backends.cuda.compile [LAW]`` prints these figures of every kernel for the
paper's mesh at N = 9 (the code does not depend on the mesh's size).
"""

import json
import re
import sys

import numba
import numpy as np
from numba import cuda

from ...laws import LAWS
from .device import DeviceMesh
from .kernels import KERNELS, MAX_REGISTERS, MINIMISERS, python_kernels
from .launch import Launcher
from .state import DeviceState

__all__ = ["ptx", "ptx_figures", "machine_figures", "KERNELS"]


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


#: A grid barrier's arrival in PTX: the tiles kernel's atomic add, the resident kernel's release reduction.
ARRIVAL = re.compile(r"\b(atom\.global\.add\.u32|red\.release\.gpu\.add\.u32)\b")
#: A poll of a grid barrier's counter: an atomic or, or an acquire load.
POLL = re.compile(r"\b(atom\.global\.or\.b32|ld\.acquire\.gpu\.u32)\b")
#: A block barrier (``cuda.syncthreads``) in PTX.
BLOCK_BARRIER = re.compile(r"\b(bar\.sync|barrier\.sync)\b")


def ptx_figures(text, max_registers=None):
    """What a kernel's PTX says, and the machine code ptxas makes of it (:func:`machine_figures`).

    From the PTX: ``grid_barriers`` (arrivals at a barrier counter), ``barrier_spins`` (polls of it),
    ``block_barriers`` (``bar.sync`` sites; a site in a loop counts once), ``float_atomics``, ``shared_bytes``
    (static shared memory), ``target``; from the machine code: ``registers``, ``stack_bytes``,
    ``spill_store_bytes``, ``spill_load_bytes``.

    Returns
    -------
    dict
    """
    lines = text.splitlines()
    shared = sum(int(size) * int(count) for size, count in
                 re.findall(r"\.shared \.align \d+ \.b(\d+) \w+\[(\d+)\]", text)) // 8
    return {"target": next((line.split()[1] for line in lines if line.startswith(".target")), ""),
            "grid_barriers": sum(1 for line in lines if ARRIVAL.search(line)),
            "barrier_spins": sum(1 for line in lines if POLL.search(line)),
            "block_barriers": sum(1 for line in lines if BLOCK_BARRIER.search(line)),
            "float_atomics": [line.strip() for line in lines if FLOAT_ATOMIC.search(line)],
            "shared_bytes": shared, **machine_figures(text, max_registers)}


def machine_figures(text, max_registers=None):
    """Registers per thread, stack frame and spills [bytes] of the one kernel of PTX ``text``, compiled by ptxas
    (nvJitLink) for the PTX's target, at most ``max_registers`` registers per thread if given.

    Returns
    -------
    dict
        ``registers``, ``stack_bytes``, ``spill_store_bytes``, ``spill_load_bytes``.
    """
    from cuda.bindings import nvjitlink

    arch = re.search(r"^\.target\s+(sm_\w+)", text, re.MULTILINE)[1]
    options = [f"-arch={arch}", "-Xptxas=-v"] + ([f"-maxrregcount={max_registers}"] if max_registers else [])
    handle = nvjitlink.create(len(options), options)
    try:
        data = text.encode()
        nvjitlink.add_data(handle, nvjitlink.InputType.PTX, data, len(data), "kernel.ptx")
        nvjitlink.complete(handle)
        log = bytearray(nvjitlink.get_info_log_size(handle))
        nvjitlink.get_info_log(handle, log)
    finally:
        nvjitlink.destroy(handle)
    log = log.decode(errors="replace")
    frame = re.search(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads", log)
    registers = re.search(r"Used (\d+) registers", log)
    return {"registers": int(registers[1]), "stack_bytes": int(frame[1]), "spill_store_bytes": int(frame[2]),
            "spill_load_bytes": int(frame[3])}


def kernel_figures(model, mesh, kernels=KERNELS, cc=(9, 0)):
    """:func:`ptx_figures` of ``kernels`` for ``model``'s law on ``mesh`` (the minimisation kernels under
    :data:`.kernels.MAX_REGISTERS`), by kernel name."""
    return {name: ptx_figures(text, MAX_REGISTERS if name in MINIMISERS.values() else None)
            for name, text in ptx(model, mesh, cc, kernels).items()}


def main(argv=None):
    """Print every kernel's figures (module docstring) for the law named first in ``argv`` (default cusp)."""
    from ....mesh import MeshParams, build_stack_mesh
    from ...constants import derived_constants
    from ...parameters import FemParams
    from ...stack import stack_model

    law = (sys.argv[1:] if argv is None else argv)[:1] or ["cusp"]
    params = FemParams(N=9, plates=2, nchunk=30, interface_law=law[0])
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    model, _ = stack_model(params, mesh, derived_constants(params, mesh))
    for name, figures in kernel_figures(model, mesh).items():
        print(json.dumps({"kernel": name, **figures}))


if __name__ == "__main__":
    main()
