"""The fixed-order dense algebra (:mod:`stickslip.fixed_order`) against numpy."""

import numpy as np
import pytest
import scipy.sparse as sp

from stickslip.fixed_order import columns_dot_dense, dot, inverse, matmul, solve, woodbury_correct


def test_products_and_inverse_equal_numpy_to_round_off():
    rng = np.random.default_rng(3)
    a, b = rng.standard_normal((5, 4)), rng.standard_normal((4, 3))
    np.testing.assert_allclose(matmul(a, b), a @ b, rtol=0, atol=1e-14)
    square = rng.standard_normal((6, 6)) + 6.0 * np.eye(6)
    square[[0, 3]] = square[[3, 0]]  # a small leading pivot: needs the row exchange
    square[0, 0] = 1e-12
    np.testing.assert_allclose(inverse(square) @ square, np.eye(6), rtol=0, atol=1e-12)
    vector = rng.standard_normal(6)
    np.testing.assert_allclose(solve(square, vector), np.linalg.solve(square, vector), rtol=1e-12)
    batch = rng.standard_normal((2, 3, 4))
    np.testing.assert_allclose(dot(batch, b), batch @ b, rtol=0, atol=1e-14)
    np.testing.assert_allclose(dot(a, b[:, 0]), a @ b[:, 0], rtol=0, atol=1e-14)
    assert dot(b[:, 0], b[:, 0]) == pytest.approx(b[:, 0] @ b[:, 0], rel=1e-15)
    with pytest.raises(ValueError, match="singular"):
        inverse(np.zeros((2, 2)))


def test_woodbury_correction_is_the_inverse_of_the_rank_m_update():
    # A = K + U M U^T: y = K^-1 b corrected by -Z (I + M U^T Z)^-1 M U^T y must be A^-1 b
    rng = np.random.default_rng(4)
    n, m = 30, 3
    R = rng.standard_normal((n, n))
    K = R @ R.T + n * np.eye(n)
    weights = np.where(rng.random((n, m)) < 0.4, rng.random((n, m)), 0.0)
    M = np.diag(rng.random(m)) + 0.1
    U = sp.csc_matrix(weights)
    ptr, rows, data = U.indptr.astype(np.int64), U.indices.astype(np.int64), U.data
    Z = np.asfortranarray(np.linalg.solve(K, weights))
    np.testing.assert_allclose(columns_dot_dense(ptr, rows, data, Z), weights.T @ Z, rtol=1e-13)
    gain = matmul(inverse(np.eye(m) + matmul(M, columns_dot_dense(ptr, rows, data, Z))), M)
    b = rng.standard_normal(n)
    y = np.linalg.solve(K, b)
    woodbury_correct(y, gain, ptr, rows, data, Z)
    np.testing.assert_allclose(y, np.linalg.solve(K + weights @ M @ weights.T, b), rtol=1e-11, atol=1e-14)
