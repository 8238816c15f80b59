"""Compile every kernel of the ``cuda`` backend to PTX for a given GPU, on a machine without one.

numba-cuda compiles a kernel to PTX with the NVVM library alone (its wheel, no driver) when every
device function is inlined, as all of :mod:`.items` and :mod:`.kernels` are. The arguments' types are
those of a real launch: the same argument lists (:meth:`.batch.DeviceBatch.arguments`), built from host
arrays of the same dtypes and shapes. Typing errors, which numba's simulator does not catch, thus
show up in CI rather than in the few minutes a GPU is lent (tests/test_fem_cuda.py).
"""

import numba
import numpy as np
from numba import cuda

from .batch import DeviceBatch, DeviceMesh
from .kernels import kernels_for

__all__ = ["ptx", "KERNELS"]

#: Every kernel of :func:`.kernels.kernels_for`.
KERNELS = ("minimise", "evaluate", "residual", "wells_hold", "load", "add_u", "shift_wells", "zero_motion")


def ptx(model, cc=(9, 0), kernels=KERNELS):
    """PTX of the kernels for ``model``'s law, for compute capability ``cc`` (default: the H100's, sm_90).

    Parameters
    ----------
    model : stickslip.fem.model.Model
        Its law chooses the kernels; its mesh gives the arguments' shapes (any mesh gives the same types).
    cc : tuple[int, int], optional
    kernels : Sequence[str], optional

    Returns
    -------
    dict[str, str]
        Kernel name -> PTX.
    """
    batch = DeviceBatch(DeviceMesh(model, place=np.ascontiguousarray, sm_count=1), model.law, 1)
    python = kernels_for(type(model.law).name).python
    members = np.zeros(1, dtype=np.int64)
    out = {}
    for name in kernels:
        signature = tuple(numba.typeof(argument) for argument in batch.arguments(name, members))
        out[name], _ = cuda.compile(python[name], signature, device=False, cc=cc, abi="numba", output="ptx")
    return out
