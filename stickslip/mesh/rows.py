"""Element rows of a layered Quad4 mesh and GooseFEM's FineLayer coarsening rule.

A layered mesh is a vertical sequence of element *rows*, each spanning the
whole periodic length ``N`` (in units of the finest element edge ``h``):

- a *regular* row of square-or-rectangular ``width x height`` elements;
- a *transition* row that connects a node line of spacing ``width / 3`` on one
  side to a node line of spacing ``width`` on the other: each coarse block of
  width ``width`` holds 4 quadrilaterals and two extra nodes at half height.

All sizes are integers in units of ``h``, so node positions are exact
multiples of ``h`` (GooseFEM computes the same positions in floating point).

The coarsening rule is that of ``GooseFEM::Mesh::Quad4::FineLayer(nelx=N,
nely=M, h, nfine=1)`` (GooseFEM ``MeshQuad4.hpp``, ``FineLayer::init``):
working outward from the middle (fine) row, a row becomes a transition row when
(a) three times the current unit height fits in the height accumulated so far,
(b) ``N`` is divisible by three times the current element width and (c) the
accumulated height plus the current unit stays below the target half height
``ceil(M / 2)``; the transition row is two units high and every later row is
three times higher and wider. Growth stops as soon as the accumulated height
(middle row included) reaches ``ceil(M / 2)``.
"""

import dataclasses
import math

__all__ = ["Row", "REGULAR", "FINE_BELOW", "FINE_ABOVE", "plate_target_height", "fine_layer_half",
           "bottom_plate_rows", "middle_plate_rows", "top_plate_rows", "interface_rows"]

#: Row kinds: regular elements; transition with the fine side below; transition with the fine side above.
REGULAR, FINE_BELOW, FINE_ABOVE = "regular", "fine_below", "fine_above"


@dataclasses.dataclass(frozen=True)
class Row:
    """One row of elements spanning the periodic length.

    Attributes
    ----------
    width : int
        Element width in units of h; for a transition row the width of the coarse
        side (the fine side has ``width // 3``).
    height : int
        Row height in units of h (even for a transition row: its middle nodes sit
        at half height).
    kind : str
        :data:`REGULAR`, :data:`FINE_BELOW` (fine node line at the bottom, coarse at
        the top) or :data:`FINE_ABOVE` (coarse at the bottom, fine at the top).
    """

    width: int
    height: int
    kind: str = REGULAR

    @property
    def is_transition(self):
        """True for a transition (refinement) row."""
        return self.kind != REGULAR

    def flipped(self):
        """The same row mirrored in y (a transition row swaps its fine side)."""
        kind = {REGULAR: REGULAR, FINE_BELOW: FINE_ABOVE, FINE_ABOVE: FINE_BELOW}[self.kind]
        return Row(self.width, self.height, kind)


def plate_target_height(N):
    """Target plate height parameter ``M = max(3, int(N / 4))`` of the paper's runs.

    Parameters
    ----------
    N : int
        Blocks (finest elements) per interface.

    Returns
    -------
    int
        ``M``, in units of h (the FineLayer ``nely`` argument).
    """
    return max(3, N // 4)


def fine_layer_half(N, M):
    """Rows of one half of GooseFEM's FineLayer(N, M), from the middle row outward.

    The middle (fine) row itself is excluded: it is the interface of the stack.

    Parameters
    ----------
    N : int
        Elements of the middle row (x-length ``N h``).
    M : int
        FineLayer target height ``nely`` in units of h.

    Returns
    -------
    list[Row]
        Outward order; transition rows have kind :data:`FINE_BELOW` (the fine side
        faces the middle when the half lies above it).
    """
    target = (M + 1) // 2  # GooseFEM "nmin": half the height, the middle row included
    accumulated = 1  # the middle row
    unit_height, unit_width = 1, 1
    rows = []
    while accumulated < target:
        if (3 * unit_height <= accumulated and N % (3 * unit_width) == 0
                and accumulated + unit_height < target):
            row = Row(3 * unit_width, 2 * unit_height, FINE_BELOW)
            unit_height, unit_width = 3 * unit_height, 3 * unit_width
        else:
            row = Row(unit_width, unit_height)
        rows.append(row)
        accumulated += row.height
    return rows


def _coarse_rows(M, half):
    """Regular rows of the coarsest size that bring a half up to the target height M.

    Their number is ``ceil((M - half height) / coarse width)``, as in the paper's
    ``BottomLayerElastic`` / ``TopLayerElastic``; it is at least 1 because the half
    height never exceeds ``M - 1``.
    """
    coarse = half[-1].width
    half_height = sum(row.height for row in half)
    return [Row(coarse, coarse)] * math.ceil((M - half_height) / coarse)


def bottom_plate_rows(N, M):
    """Rows of the bottom plate, bottom to top: coarse rows, then a FineLayer lower half.

    Parameters
    ----------
    N, M : int
        See :func:`fine_layer_half`.

    Returns
    -------
    list[Row]
        Bottom-to-top order; fine (width 1) at the top face.
    """
    half = fine_layer_half(N, M)
    return _coarse_rows(M, half) + [row.flipped() for row in reversed(half)]


def middle_plate_rows(N, M):
    """Rows of a middle plate, bottom to top: FineLayer upper half, then lower half.

    The plate is fine at both faces and coarse in its middle (the FineLayer
    without its middle row, upper half placed below the lower half).

    Returns
    -------
    list[Row]
        Bottom-to-top order.
    """
    half = fine_layer_half(N, M)
    return half + [row.flipped() for row in reversed(half)]


def top_plate_rows(N, M):
    """Rows of the top plate, bottom to top: FineLayer upper half, then coarse rows.

    The mirror image of :func:`bottom_plate_rows`.

    Returns
    -------
    list[Row]
        Bottom-to-top order; fine (width 1) at the bottom face.
    """
    return [row.flipped() for row in reversed(bottom_plate_rows(N, M))]


def interface_rows():
    """The interface: one regular row of 1 x 1 elements (the blocks)."""
    return [Row(1, 1)]
