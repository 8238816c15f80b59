"""Small dense linear algebra in a fixed order of operations, with no BLAS.

numpy's ``@``, :func:`numpy.linalg.solve` and :func:`numpy.linalg.inv` call the BLAS and LAPACK
that numpy was built with (OpenBLAS), which picks a kernel for the CPU at run time (SkylakeX on
AVX-512, Haswell on AVX2 and Zen, SandyBridge...): the same product sums in another order, and its
last bits differ from host to host (``benchmarks/host_bytes.py``). Every product and solve whose
result reaches a solver's output is computed here instead (the exact relaxation's drive correction,
:mod:`stickslip.fem.equilibrium`; the virtual lever's coupling matrices,
:mod:`stickslip.experiment.virtual`), with plain loops whose order is fixed in the source; numba's
``fastmath`` stays off (:mod:`stickslip.numba_options`), so LLVM neither reorders nor fuses them, and
the result is the same bit for bit on every x86-64 host. The matrices are small (a few rows) or
the products sparse: the loops cost no more than the BLAS call.

The drive's layer weights ``U`` [n, m] are passed as columns of a sparse matrix: ``ptr``
int64 [m + 1], and for column ``l`` the rows ``rows[ptr[l]:ptr[l + 1]]`` with the weights
``weights[ptr[l]:ptr[l + 1]]``.
"""

import numpy as np

from .numba_options import njit

__all__ = ["dot", "solve", "matmul", "inverse", "columns_dot", "columns_dot_dense", "woodbury_correct"]


def dot(a, b):
    """``a @ b`` (:func:`matmul`) for ``a`` [..., k] or [k] and ``b`` [k, m] or [k], with numpy's shapes.

    Parameters
    ----------
    a, b : array_like
        float64.

    Returns
    -------
    numpy.ndarray or float
        The shape of ``a @ b`` (a float for two vectors).
    """
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    left = np.ascontiguousarray(a.reshape(-1, a.shape[-1]))
    right = np.ascontiguousarray(b.reshape(b.shape[0], -1))
    out = matmul(left, right)
    shape = a.shape[:-1] + b.shape[1:]
    return float(out[0, 0]) if not shape else out.reshape(shape)


def solve(a, b):
    """``a^-1 b`` for a small non-singular ``a`` [n, n] and ``b`` [n], by :func:`inverse` then :func:`dot`."""
    return dot(inverse(np.ascontiguousarray(a, dtype=np.float64)), b)


@njit
def matmul(a, b):
    """``a @ b``, every entry summed over ``k`` in increasing order.

    Parameters
    ----------
    a : numpy.ndarray
        float64 [n, k].
    b : numpy.ndarray
        float64 [k, m].

    Returns
    -------
    numpy.ndarray
        float64 [n, m].
    """
    n, inner = a.shape
    out = np.zeros((n, b.shape[1]))
    for i in range(n):
        for j in range(b.shape[1]):
            total = 0.0
            for k in range(inner):
                total += a[i, k] * b[k, j]
            out[i, j] = total
    return out


@njit
def inverse(a):
    """Inverse of a small square matrix by Gauss-Jordan elimination with partial pivoting.

    Parameters
    ----------
    a : numpy.ndarray
        float64 [n, n], non-singular (not modified).

    Returns
    -------
    numpy.ndarray
        float64 [n, n].

    Raises
    ------
    ValueError
        If a pivot is zero (the matrix is singular).
    """
    n = a.shape[0]
    work = a.copy()
    out = np.eye(n)
    for col in range(n):
        pivot = col
        for row in range(col + 1, n):
            if abs(work[row, col]) > abs(work[pivot, col]):
                pivot = row
        if work[pivot, col] == 0.0:
            raise ValueError("singular matrix")
        if pivot != col:
            for k in range(n):
                work[col, k], work[pivot, k] = work[pivot, k], work[col, k]
                out[col, k], out[pivot, k] = out[pivot, k], out[col, k]
        scale = 1.0 / work[col, col]
        for k in range(n):
            work[col, k] *= scale
            out[col, k] *= scale
        for row in range(n):
            if row != col and work[row, col] != 0.0:
                factor = work[row, col]
                for k in range(n):
                    work[row, k] -= factor * work[col, k]
                    out[row, k] -= factor * out[col, k]
    return out


@njit
def columns_dot(ptr, rows, weights, y, out):
    """``out = U^T y``, each column's sum in the order of its stored rows.

    Parameters
    ----------
    ptr, rows, weights : numpy.ndarray
        ``U`` [n, m] by columns (module docstring).
    y : numpy.ndarray
        float64 [n].
    out : numpy.ndarray
        float64 [m], written.
    """
    for col in range(ptr.size - 1):
        total = 0.0
        for k in range(ptr[col], ptr[col + 1]):
            total += weights[k] * y[rows[k]]
        out[col] = total


@njit
def columns_dot_dense(ptr, rows, weights, Z):
    """``U^T Z`` [m, m'] for a dense ``Z`` [n, m'] (:func:`columns_dot` on each column of ``Z``)."""
    out = np.empty((ptr.size - 1, Z.shape[1]))
    column = np.empty(ptr.size - 1)
    for j in range(Z.shape[1]):
        columns_dot(ptr, rows, weights, np.ascontiguousarray(Z[:, j]), column)
        out[:, j] = column
    return out


@njit
def woodbury_correct(y, gain, ptr, rows, weights, Z):
    """``y <- y - Z (gain (U^T y))``: the drive's correction of a solve, in place.

    Parameters
    ----------
    y : numpy.ndarray
        float64 [n]: ``(K_p + K_i)^-1 b``; overwritten by ``A^-1 b``.
    gain : numpy.ndarray
        float64 [m, m]: ``(I + M U^T Z)^-1 M``.
    ptr, rows, weights : numpy.ndarray
        ``U`` [n, m] by columns (module docstring).
    Z : numpy.ndarray
        float64 [n, m] (Fortran order: columns contiguous): ``(K_p + K_i)^-1 U``.
    """
    m = ptr.size - 1
    w = np.empty(m)
    columns_dot(ptr, rows, weights, y, w)
    for l in range(m):
        c = 0.0
        for k in range(m):
            c += gain[l, k] * w[k]
        if c != 0.0:
            for i in range(y.size):
                y[i] -= c * Z[i, l]
