"""Backend ``assembled`` (the reference): the plates' product by the assembled CSR matrix.

The same kernels as the default backend but for the plates' product, row by row from the
assembled stiffness (:func:`stickslip.fem.assembly.assemble_csr`): its sums run in another order than
the stencils', so its results differ from the default's by round-off, and a run with it has
its own run id (the ``backend`` parameter of ``fem``).
"""

from collections import namedtuple

from numba import prange

from ....numba_options import njit
from .plates import register_plate_operator
from ..base import register_backend
from .backend import CpuBackend

__all__ = ["AssembledBackend", "CsrPlates"]


@njit
def _rows(lo, hi, ptr, col, val, u, f):
    for i in range(lo, hi):
        s = 0.0
        for j in range(ptr[i], ptr[i + 1]):
            s += val[j] * u[col[j]]
        f[i] = s


@njit(parallel=True)
def _rows_parallel(nblock, ptr, col, val, u, f):
    n = f.size
    for b in prange(nblock):
        _rows(b * n // nblock, (b + 1) * n // nblock, ptr, col, val, u, f)


@njit(inline="always")
def _product(plates, nblock, u, f):
    if nblock > 1:
        _rows_parallel(nblock, plates.ptr, plates.col, plates.val, u, f)
    else:
        _rows(0, f.size, plates.ptr, plates.col, plates.val, u, f)


@register_plate_operator
class CsrPlates(namedtuple("CsrPlates", [
        "ptr",   # int64 [ndof + 1]
        "col",   # int32 [nnz]
        "val",   # float64 [nnz] [stress]
])):
    """The assembled CSR stiffness of the plates [ndof, ndof]."""

    __slots__ = ()
    product = staticmethod(_product)


@register_backend
class AssembledBackend(CpuBackend):
    """Numba CPU kernels with the assembled CSR product of the plates (the reference)."""

    name = "assembled"
    summary = "numba CPU kernels, plates by the assembled CSR matrix (reference; round-off differs)"

    def plate_operator(self, model, mesh, nblock):
        return CsrPlates(ptr=model.k_ptr, col=model.k_col, val=model.k_val)
