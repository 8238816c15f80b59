"""Assembled operators of the linear parts of the model, built once per mesh.

All operators act on DOF vectors (periodic images share a DOF):

- the elastic stiffness of the plates as a CSR matrix (rows summed in a fixed
  order, so the matrix is the same bit for bit on every run);
- the lumped (nodal-quadrature) diagonal of a density field, used for the
  mass and the background damping;
- per layer, the weights that turn the DOF vector into the volume-averaged
  x-displacement of the layer, ``ubar_x = w . u``; the uniform body force
  ``f`` per unit volume on the layer has the nodal equivalent ``f V w``.
"""

import numpy as np

from .quad4 import GAUSS_XI, NODAL_XI, shape_functions, shape_gradients

__all__ = ["element_dofs", "elastic_element_stiffness", "assemble_csr", "lumped_diagonal", "layer_average_weights"]


def element_dofs(conn, dofs):
    """DOF indices of each element, ordered ``(node 0 x, node 0 y, node 1 x, ...)``.

    Parameters
    ----------
    conn : numpy.ndarray
        int [nelem, 4].
    dofs : numpy.ndarray
        int [nnode, 2].

    Returns
    -------
    numpy.ndarray
        int64 [nelem, 8].
    """
    return np.asarray(dofs, dtype=np.int64)[np.asarray(conn)].reshape(-1, 8)


def elastic_element_stiffness(dNdx, dV, K, G):
    """Element stiffness matrices of the linear elastic law (``sigma = K eps_m I + G eps_d``).

    Parameters
    ----------
    dNdx : numpy.ndarray
        [nelem, nip, 4, 2] shape-function gradients [1/length].
    dV : numpy.ndarray
        [nelem, nip] integration volumes [length^2].
    K, G : float
        Moduli [stress].

    Returns
    -------
    numpy.ndarray
        [nelem, 8, 8] [stress]: ``f_e = K_e u_e`` in :func:`element_dofs` order.
    """
    nelem, nip = dV.shape
    # strain (xx, yy, xy) from u_e, and nodal force from stress (xx, yy, xy)
    B = np.zeros((nelem, nip, 3, 8))
    B[:, :, 0, 0::2] = dNdx[..., 0]
    B[:, :, 1, 1::2] = dNdx[..., 1]
    B[:, :, 2, 0::2] = 0.5 * dNdx[..., 1]
    B[:, :, 2, 1::2] = 0.5 * dNdx[..., 0]
    F = B.copy()
    F[:, :, 2, :] *= 2.0
    D = np.array([[0.5 * (K + G), 0.5 * (K - G), 0.0],
                  [0.5 * (K - G), 0.5 * (K + G), 0.0],
                  [0.0, 0.0, G]])
    return np.einsum("eq,eqia,ij,eqjb->eab", dV, F, D, B)


def assemble_csr(edofs, Ke, ndof):
    """Assemble element matrices into a CSR matrix, summing duplicates in a fixed order.

    Parameters
    ----------
    edofs : numpy.ndarray
        int64 [nelem, 8].
    Ke : numpy.ndarray
        [nelem, 8, 8].
    ndof : int

    Returns
    -------
    indptr : numpy.ndarray
        int64 [ndof + 1].
    indices : numpy.ndarray
        int64 [nnz], column of each entry (sorted within a row).
    data : numpy.ndarray
        float64 [nnz].
    """
    rows = np.repeat(edofs, 8, axis=1).ravel()
    cols = np.tile(edofs, (1, 8)).ravel()
    vals = Ke.reshape(-1)
    key = rows * np.int64(ndof) + cols
    order = np.argsort(key, kind="stable")
    key = key[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    data = np.add.reduceat(vals[order], starts) if key.size else np.zeros(0)
    unique = key[starts]
    indices = (unique % ndof).astype(np.int64)
    counts = np.bincount((unique // ndof).astype(np.int64), minlength=ndof)
    indptr = np.zeros(ndof + 1, dtype=np.int64)
    np.cumsum(counts, out=indptr[1:])
    return indptr, indices, data


def lumped_diagonal(xe, edofs, density, ndof):
    """Diagonal matrix of ``int N^T density N dV`` with nodal quadrature (lumped mass).

    Each node of an element receives ``density * det(J)`` evaluated at that node,
    i.e. a quarter of the area for a parallelogram.

    Parameters
    ----------
    xe : numpy.ndarray
        [nelem, 4, 2] element nodal coordinates [length].
    edofs : numpy.ndarray
        int64 [nelem, 8].
    density : numpy.ndarray
        [nelem] density per element (e.g. rho [mass/length^2], alpha [mass/(length^2 time)]).
    ndof : int

    Returns
    -------
    numpy.ndarray
        float64 [ndof].
    """
    _, dV_nodal = shape_gradients(xe, NODAL_XI)  # [nelem, 4], node q <-> point q
    values = (np.asarray(density, dtype=np.float64)[:, None] * dV_nodal)
    out = np.zeros(ndof)
    np.add.at(out, edofs[:, 0::2].ravel(), values.ravel())
    np.add.at(out, edofs[:, 1::2].ravel(), values.ravel())
    return out


def layer_average_weights(edofs, dV, elements, ndof):
    """Weights of the volume-averaged x-displacement of a set of elements.

    ``ubar_x = sum_{e, q} u_x(x_q) dV_q / V = w . u``.

    Parameters
    ----------
    edofs : numpy.ndarray
        int64 [nelem, 8] (all elements).
    dV : numpy.ndarray
        [nelem, nip] Gauss-point volumes [length^2] (all elements).
    elements : numpy.ndarray
        int [n] the elements of the layer.
    ndof : int

    Returns
    -------
    xdofs : numpy.ndarray
        int64 [m], the x-DOFs involved (sorted).
    weights : numpy.ndarray
        float64 [m] [1].
    volume : float
        ``V`` [length^2].
    """
    N = shape_functions(GAUSS_XI)  # [nip, 4]
    nodal = np.einsum("qm,eq->em", N, dV[elements])  # [n, 4]
    dense = np.zeros(ndof)
    np.add.at(dense, edofs[elements][:, 0::2].ravel(), nodal.ravel())
    volume = float(dV[elements].sum())
    xdofs = np.unique(edofs[elements][:, 0::2])
    return xdofs.astype(np.int64), dense[xdofs] / volume, volume
