"""Quad4 elements of a stack of rows, on an integer grid, with coincident nodes merged.

Every element is first written as four integer corner points (units of h);
identical points are then merged into one node, which stitches the rows
together exactly as GooseFEM's ``Vstack`` does (it merges the bottom node line of
each pushed mesh with the top node line below it).
"""

import numpy as np

from .rows import FINE_ABOVE, FINE_BELOW, REGULAR

__all__ = ["stack_rows"]

# Corner offsets (x, y) of the elements of one block, counter-clockwise from the
# bottom-left corner (GooseFEM order), in units of (x_unit, y_unit) per row kind:
# regular rows: (width, height); transition rows: (width / 3, height / 2).
_TEMPLATES = {
    REGULAR: np.array([[[0, 0], [1, 0], [1, 1], [0, 1]]]),
    # GooseFEM FineLayer, refinement below the middle row: bottom, top-right, top-centre, top-left.
    FINE_ABOVE: np.array([
        [[0, 0], [3, 0], [2, 1], [1, 1]],
        [[3, 0], [3, 2], [2, 2], [2, 1]],
        [[1, 1], [2, 1], [2, 2], [1, 2]],
        [[0, 0], [1, 1], [1, 2], [0, 2]],
    ]),
    # GooseFEM FineLayer, coarsening above the middle row: lower-left, lower-centre, lower-right, upper.
    FINE_BELOW: np.array([
        [[0, 0], [1, 0], [1, 1], [0, 2]],
        [[1, 0], [2, 0], [2, 1], [1, 1]],
        [[2, 0], [3, 0], [3, 2], [2, 1]],
        [[1, 1], [2, 1], [3, 2], [0, 2]],
    ]),
}


def _row_corners(row, N, y0):
    """Integer corner points of the elements of one row.

    Parameters
    ----------
    row : Row
    N : int
        Periodic length in units of h.
    y0 : int
        Bottom of the row in units of h.

    Returns
    -------
    numpy.ndarray
        int64 [nelem_row, 4, 2]: blocks left to right, within a block the
        template order.
    """
    if N % row.width != 0:
        raise ValueError(f"row width {row.width} does not divide the length N = {N}")
    if row.is_transition:
        unit = np.array([row.width // 3, row.height // 2])
    else:
        unit = np.array([row.width, row.height])
    template = _TEMPLATES[row.kind] * unit  # [nquad, 4, 2]
    origins = np.zeros((N // row.width, 2), dtype=np.int64)
    origins[:, 0] = np.arange(0, N, row.width)
    origins[:, 1] = y0
    return (origins[:, None, None, :] + template[None, :, :, :]).reshape(-1, 4, 2)


def stack_rows(rows, N):
    """Build the Quad4 mesh of rows stacked bottom to top.

    Parameters
    ----------
    rows : Sequence[Row]
        Bottom-to-top order; consecutive rows must share their node line
        spacing (checked by the caller's tests, not here).
    N : int
        Periodic length in units of h.

    Returns
    -------
    grid : numpy.ndarray
        int64 [nnode, 2] node positions (x, y) in units of h, sorted by y, then x.
    conn : numpy.ndarray
        int64 [nelem, 4] element nodes, counter-clockwise from the bottom-left.
    row_of_element : numpy.ndarray
        int64 [nelem] index of the row (in ``rows``) of every element.
    """
    tops = np.cumsum([row.height for row in rows])
    bottoms = tops - np.array([row.height for row in rows])
    corners = [_row_corners(row, N, int(y0)) for row, y0 in zip(rows, bottoms)]
    row_of_element = np.repeat(np.arange(len(rows)), [len(c) for c in corners])
    corners = np.concatenate(corners)  # [nelem, 4, 2]
    keys = corners[..., 1] * (N + 1) + corners[..., 0]
    unique, inverse = np.unique(keys.ravel(), return_inverse=True)
    grid = np.stack([unique % (N + 1), unique // (N + 1)], axis=1)
    return grid, inverse.reshape(-1, 4).astype(np.int64), row_of_element
