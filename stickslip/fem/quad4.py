"""Bilinear quadrilateral (Quad4) elements: shape functions, gradients, integration volumes.

Conventions (as GooseFEM): nodes counter-clockwise from the bottom-left corner,
local coordinates ``xi = (-1, -1), (1, -1), (1, 1), (-1, 1)``; 2 x 2 Gauss
quadrature with points ``(-1, -1), (1, -1), (1, 1), (-1, 1) / sqrt(3)`` and unit
weights; "nodal" quadrature with the four corners as points and unit weights
(it makes the lumped mass matrix diagonal). Plane problem, unit out-of-plane
thickness: "volume" is an area [length^2].
"""

import numpy as np

from ..numba_options import njit

__all__ = ["GAUSS_XI", "NODAL_XI", "shape_functions", "shape_gradients", "element_coordinates", "element_strain"]

_CORNERS = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])

#: Local coordinates of the 2 x 2 Gauss points [4, 2] (weights are 1).
GAUSS_XI = _CORNERS / np.sqrt(3.0)

#: Local coordinates of the nodal quadrature points [4, 2] (weights are 1).
NODAL_XI = _CORNERS.copy()


def shape_functions(xi):
    """Shape functions at local points.

    Parameters
    ----------
    xi : numpy.ndarray
        [nip, 2] local coordinates.

    Returns
    -------
    numpy.ndarray
        [nip, 4]: ``N[q, m]`` of node ``m`` at point ``q``.
    """
    return 0.25 * (1.0 + xi[:, None, 0] * _CORNERS[None, :, 0]) * (1.0 + xi[:, None, 1] * _CORNERS[None, :, 1])


def _local_gradients(xi):
    """dN/dxi [nip, 4, 2]."""
    d = np.empty((xi.shape[0], 4, 2))
    d[:, :, 0] = 0.25 * _CORNERS[None, :, 0] * (1.0 + xi[:, None, 1] * _CORNERS[None, :, 1])
    d[:, :, 1] = 0.25 * _CORNERS[None, :, 1] * (1.0 + xi[:, None, 0] * _CORNERS[None, :, 0])
    return d


def element_coordinates(coor, conn):
    """Nodal coordinates per element.

    Parameters
    ----------
    coor : numpy.ndarray
        [nnode, 2] [length].
    conn : numpy.ndarray
        int [nelem, 4].

    Returns
    -------
    numpy.ndarray
        [nelem, 4, 2] [length].
    """
    return np.asarray(coor, dtype=np.float64)[np.asarray(conn)]


def shape_gradients(xe, xi=GAUSS_XI):
    """Global shape-function gradients and integration volumes.

    Parameters
    ----------
    xe : numpy.ndarray
        [nelem, 4, 2] nodal coordinates per element [length].
    xi : numpy.ndarray, optional
        [nip, 2] local points (default: Gauss points; unit weights).

    Returns
    -------
    dNdx : numpy.ndarray
        [nelem, nip, 4, 2]: ``dN_m / dx_i`` [1/length].
    dV : numpy.ndarray
        [nelem, nip]: ``w_q det(J)`` [length^2].

    Raises
    ------
    ValueError
        If an element is inverted or degenerate (``det(J) <= 0``).
    """
    dNdxi = _local_gradients(xi)  # [nip, 4, 2]
    J = np.einsum("qmj,emi->eqij", dNdxi, xe)  # J[i, j] = dx_i / dxi_j
    det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    if np.any(det <= 0.0):
        bad = int(np.argwhere(det <= 0.0)[0, 0])
        raise ValueError(f"element {bad} is inverted or degenerate (det J <= 0); expected counter-clockwise nodes")
    inv = np.empty_like(J)
    inv[..., 0, 0] = J[..., 1, 1] / det
    inv[..., 1, 1] = J[..., 0, 0] / det
    inv[..., 0, 1] = -J[..., 0, 1] / det
    inv[..., 1, 0] = -J[..., 1, 0] / det
    dNdx = np.einsum("qmj,eqji->eqmi", dNdxi, inv)
    return dNdx, det


@njit
def element_strain(dNdx, ue, out):
    """Strain ``(xx, yy, xy)`` at the 4 Gauss points of one element (small strain, symmetric gradient).

    Parameters
    ----------
    dNdx : numpy.ndarray
        [4, 4, 2] gradients of the element [1/length].
    ue : numpy.ndarray
        [8] element displacement (node-major, x then y) [length].
    out : numpy.ndarray
        [4, 3] written.
    """
    for q in range(4):
        xx = 0.0
        yy = 0.0
        xy = 0.0
        for m in range(4):
            gx = dNdx[q, m, 0]
            gy = dNdx[q, m, 1]
            ux = ue[2 * m]
            uy = ue[2 * m + 1]
            xx += gx * ux
            yy += gy * uy
            xy += gy * ux + gx * uy
        out[q, 0] = xx
        out[q, 1] = yy
        out[q, 2] = 0.5 * xy
