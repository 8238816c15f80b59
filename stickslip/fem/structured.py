"""Structured plate kernel: the plates' stiffness product as periodic stencils over node lines.

The plates are rows of elements spanning the periodic length (:mod:`stickslip.mesh.rows`):
regular rows of equal square elements and transition rows (4 quadrilaterals per coarse
block). Every node lies on a horizontal *node line* whose DOFs are contiguous (node ``k``
of a line starting at DOF ``s`` owns DOFs ``s + 2k``, ``s + 2k + 1``; the periodic image
shares the first node's DOFs). The rows touching a line repeat with a period of one block
of the coarser row, so the line's rows of the stiffness matrix are, block by block, the
same stencil: node ``k = b p + c`` (block ``b``, class ``c`` of the ``p`` nodes per block)
couples to node ``((b + db) mod nb) p_T + c_T`` of line ``T`` with one 2 x 2 block of
coefficients. A regular line between two rows of equal squares has ``p = 1`` and the
nine-point stencil of the plane-strain Q4 element; lines at transition rows have
``p = 3`` (fine), ``2`` (middle nodes) or ``1`` (coarse) with their own stencils.

The stencils are read from the assembled matrix (:func:`.assembly.assemble_csr`) at one
representative block per line and class and checked against every other block when built,
so the product equals the assembled one up to the order of the sums (round-off; tested
on random displacements for every mesh shape, periodic wrap included). The product then
needs no index array per entry: one pass per stencil entry over the blocks of a line (a
strided loop; measured 2.7x faster than the CSR product, docs/benchmarks.md).
"""

import numpy as np

from ..numba_options import njit

__all__ = ["PlateStencils", "build_stencils", "line_blocks", "apply_stencils"]

#: Stencil entry columns (int64 part): line start DOF, p, class, blocks, target start DOF, target p,
#: target class, block offset.
_START, _P, _CLASS, _NB, _TSTART, _TP, _TCLASS, _DB = range(8)


class PlateStencils:
    """The stencil entries of all node lines (arrays for :func:`apply_stencils`).

    Attributes
    ----------
    index : numpy.ndarray
        int64 [nentry, 8]: line start DOF, nodes per block ``p``, class ``c``, number of
        blocks ``nb``, target line start DOF, its ``p_T``, class ``c_T``, block offset ``db``.
    coef : numpy.ndarray
        float64 [nentry, 4]: the 2 x 2 block ``(xx, xy, yx, yy)`` [stress].
    """

    def __init__(self, index, coef):
        self.index = index
        self.coef = coef


def _node_lines(mesh):
    """Node lines: list of (start DOF, number of nodes), and per DOF its (line, node) position."""
    grid_y = np.asarray(mesh.coor)[:, 1]  # a node line: nodes of bitwise equal height
    x = np.asarray(mesh.coor)[:, 0]
    dofs = np.asarray(mesh.dofs, dtype=np.int64)
    ndof = int(dofs.max()) + 1
    line_of_dof = np.full(ndof, -1, dtype=np.int64)
    node_of_dof = np.full(ndof, -1, dtype=np.int64)
    lines = []
    for y in np.unique(grid_y):
        nodes = np.flatnonzero(grid_y == y)
        nodes = nodes[np.argsort(x[nodes], kind="stable")]
        first = dofs[nodes, 0]
        independent = np.unique(first)
        start, n = int(independent[0]), independent.size
        if not np.array_equal(independent, start + 2 * np.arange(n)) or np.any(dofs[nodes, 1] != first + 1):
            raise ValueError(f"node line at y = {y}: DOFs are not contiguous (x, y) pairs")
        line_of_dof[start:start + 2 * n] = len(lines)
        node_of_dof[start:start + 2 * n] = np.repeat(np.arange(n), 2)
        lines.append((start, n))
    return lines, line_of_dof, node_of_dof


def build_stencils(mesh, ptr, col, val):
    """Stencils of the assembled plate stiffness of a layered mesh.

    Parameters
    ----------
    mesh : stickslip.mesh.LayeredMesh
    ptr, col, val : numpy.ndarray
        The assembled CSR matrix [ndof, ndof] of the plates (:func:`.assembly.assemble_csr`).

    Returns
    -------
    PlateStencils

    Raises
    ------
    ValueError
        If a node line's rows are not the same stencil block after block (the mesh is
        not a periodic stack of rows).
    """
    lines, line_of_dof, node_of_dof = _node_lines(mesh)
    line_start = np.array([start for start, _ in lines], dtype=np.int64)
    line_n = np.array([n for _, n in lines], dtype=np.int64)
    scale = np.abs(val).max()
    index, coef = [], []
    for start, n in lines:
        first, last = ptr[start], ptr[start + 2 * n]
        if first == last:
            continue
        row = np.repeat(np.arange(start, start + 2 * n), np.diff(ptr[start:start + 2 * n + 1]))
        columns = col[first:last]
        t = line_of_dof[columns]
        nb = int(min(n, line_n[np.unique(t)].min()))
        if np.any(line_n[np.unique(t)] % nb) or n % nb:
            raise ValueError(f"node line at DOF {start}: node counts share no block period")
        p = n // nb
        k = (row - start) // 2
        block, c = k // p, k % p
        tp = line_n[t] // nb
        node = node_of_dof[columns]
        db = (node // tp - block) % nb
        tc = node % tp
        slot = 2 * ((row - start) % 2) + (columns - line_start[t]) % 2
        key = ((c * len(lines) + t) * nb + db) * (tp.max() + 1) + tc
        values = val[first:last]
        order = np.lexsort((block, slot, key))
        key, slot, block, values = key[order], slot[order], block[order], values[order]
        groups = np.flatnonzero(np.r_[True, (key[1:] != key[:-1]) | (slot[1:] != slot[:-1])])
        counts = np.diff(np.r_[groups, key.size])
        reference = values[groups]
        if np.any(counts != nb) or np.any(np.abs(values - np.repeat(reference, counts)) > 1e-12 * scale):
            raise ValueError(f"node line at DOF {start}: rows differ between blocks")
        entry_of_group = np.cumsum(np.r_[True, key[groups][1:] != key[groups][:-1]]) - 1
        blocks = np.zeros((entry_of_group[-1] + 1, 4))
        blocks[entry_of_group, slot[groups]] = reference
        firsts = groups[np.r_[True, key[groups][1:] != key[groups][:-1]]]
        for g, o in zip(firsts, order[firsts]):
            shift = int(db[o]) - nb if db[o] > nb // 2 else int(db[o])
            index.append([start, p, int(c[o]), nb, int(line_start[t[o]]), int(tp[o]), int(tc[o]), shift])
        coef.append(blocks)
    return PlateStencils(np.asarray(index, dtype=np.int64).reshape(-1, 8),
                         np.concatenate(coef) if coef else np.zeros((0, 4)))


def line_blocks(index, nblock):
    """Split the stencil entries into ``nblock`` ranges of whole node lines (for parallel kernels).

    Parameters
    ----------
    index : numpy.ndarray
        int64 [nentry, 8] (:class:`PlateStencils`), entries grouped by line.
    nblock : int

    Returns
    -------
    numpy.ndarray
        int64 [nblock + 1]: entry boundaries; entries of one line stay in one range, so the
        ranges write to disjoint DOFs.
    """
    nentry = index.shape[0]
    starts = np.r_[np.flatnonzero(np.diff(index[:, _START]) != 0) + 1, nentry]  # first entry of each next line
    bounds = [0] + [int(starts[np.searchsorted(starts, b * nentry // nblock)]) for b in range(1, nblock)] + [nentry]
    return np.asarray(bounds, dtype=np.int64)


@njit(inline="always")
def _pass(lo, hi, start, p, c, tstart, tp, tc, shift, a, b, cc, d, u, f):
    for blk in range(lo, hi):
        k = start + 2 * (blk * p + c)
        j = tstart + 2 * ((blk + shift) * tp + tc)
        ux = u[j]
        uy = u[j + 1]
        f[k] += a * ux + b * uy
        f[k + 1] += cc * ux + d * uy


@njit
def apply_stencils(index, coef, lo, hi, u, f):
    """Add the stencil entries ``lo:hi`` applied to ``u`` into ``f`` (``f`` zeroed by the caller).

    Parameters
    ----------
    index, coef : numpy.ndarray
        :class:`PlateStencils` arrays.
    lo, hi : int
        Entry range.
    u, f : numpy.ndarray
        [ndof] displacement and force.
    """
    for e in range(lo, hi):
        start = index[e, _START]
        p = index[e, _P]
        c = index[e, _CLASS]
        nb = index[e, _NB]
        tstart = index[e, _TSTART]
        tp = index[e, _TP]
        tc = index[e, _TCLASS]
        db = index[e, _DB]
        a = coef[e, 0]
        b = coef[e, 1]
        cc = coef[e, 2]
        d = coef[e, 3]
        first = max(0, -db)
        last = min(nb, nb - db)
        # literal strides for the common node-per-block counts (constant strides after inlining);
        # any other count takes the general loop
        if p == 1 and tp == 1:
            _passes(first, last, nb, start, 1, c, tstart, 1, tc, db, a, b, cc, d, u, f)
        elif p == 1 and tp == 3:
            _passes(first, last, nb, start, 1, c, tstart, 3, tc, db, a, b, cc, d, u, f)
        elif p == 3 and tp == 1:
            _passes(first, last, nb, start, 3, c, tstart, 1, tc, db, a, b, cc, d, u, f)
        elif p == 3 and tp == 3:
            _passes(first, last, nb, start, 3, c, tstart, 3, tc, db, a, b, cc, d, u, f)
        else:
            _passes(first, last, nb, start, p, c, tstart, tp, tc, db, a, b, cc, d, u, f)


@njit(inline="always")
def _passes(first, last, nb, start, p, c, tstart, tp, tc, db, a, b, cc, d, u, f):
    _pass(first, last, start, p, c, tstart, tp, tc, db, a, b, cc, d, u, f)  # no wrap
    _pass(0, first, start, p, c, tstart, tp, tc, db + nb, a, b, cc, d, u, f)  # wrapped on the left
    _pass(last, nb, start, p, c, tstart, tp, tc, db - nb, a, b, cc, d, u, f)  # wrapped on the right
