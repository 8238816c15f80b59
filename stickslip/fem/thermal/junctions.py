"""Junction aging: the contact of every block strengthens at rest, and a change of well renews it.

A trap model of the contact junctions (Bouchaud 1992; Fielding, Sollich and Cates 2000; the
contact-creep picture of Dieterich and Kilgore 1994 and Baumberger and Caroli 2006) on top of the
interface law. The current contact of a block (an interface element whose four Gauss points lie in
one well ``j``) is a junction of depth ``E`` [G eps0^2 h^2], drawn from
``rho(E) = exp(-E / T_g) / T_g`` when the block enters the well, and redrawn from the same density
at rest at the thermally activated rate ``nu_j exp(-E / T)`` (:mod:`.redraws`). For ``T < T_g`` the
depth of the current junction grows as ``T ln(nu_j t)``; above ``T_g`` it saturates.

The junction **widens the well about its centre**: the well's yield strains become
``y_j - w`` and ``y_(j+1) + w`` with ``w = lambda E eps0`` (``lambda``: ``junction_strengthening``),
and its two neighbours shrink by ``w`` (they share those yield strains); ``w`` is capped at
:data:`CAP` of the width of either neighbour, so that the sequence stays increasing. For a law
whose stress depends only on the well's centre (the cusp, ``junction_aging``) the stress of every
Gauss point in the well is unchanged (to round-off): a junction raises the block's threshold
(by ``w``, i.e. ``2 G w`` in stress) and its barriers, and nothing needs to be solved. A block whose
Gauss points lie in different wells has no junction: a junction holds a whole block, and when part
of a block slips its junction is gone.

The junctions are part of the yield strains the backend holds: the aging protocol registers them with the
stack as its yield-strain modifier (:meth:`..stack.Stack.modify_yield_strains`), which widens the window of the
blocks' sequences (:class:`..yield_strains.HeldYieldStrains`) by :meth:`Junctions.modify` whenever it gives the
backend its yield strains. The state (the well of every junction, as a global
index, and its depth) is stored with every increment (``junction_well``, ``junction_depth``).
"""

import numpy as np

from ...numba_options import njit
from .sampler import exponential

__all__ = ["Junctions", "CAP", "STATE_FIELDS", "widening", "widen", "renew"]

#: Largest widening, as a fraction of the width of the neighbouring well it eats into.
CAP = 0.5

#: The per-increment state datasets of a run with junctions: name -> dtype (one value per block).
STATE_FIELDS = {"junction_depth": np.float64, "junction_well": np.int64}


@njit
def widening(row, j, depth, scale):
    """Widening ``w`` [strain] of well ``j`` (held index) of one block's held yield strains ``row`` [ny] by a junction.

    ``min(scale depth, CAP (width of each neighbouring well that is held))``.
    """
    w = scale * depth
    if j + 2 < row.size:
        w = min(w, CAP * (row[j + 2] - row[j + 1]))
    if j >= 1:
        w = min(w, CAP * (row[j] - row[j - 1]))
    return w


@njit
def widen(base, offset, well, depth, scale, out):
    """``out`` [ni, ny] = the held yield strains ``base`` with every junction's well widened about its centre.

    Parameters
    ----------
    base : numpy.ndarray
        [ni, ny] held yield strains.
    offset : numpy.ndarray
        int64 [ni] global index of ``base[:, 0]``.
    well : numpy.ndarray
        int64 [ni] global well of every junction (-1: none).
    depth : numpy.ndarray
        [ni] depths [G eps0^2 h^2].
    scale : float
        ``lambda eps0``: widening per unit depth [strain].
    out : numpy.ndarray
        [ni, ny], written.
    """
    out[...] = base
    for e in range(base.shape[0]):
        j = well[e] - offset[e]
        if well[e] < 0 or j < 0 or j + 1 >= base.shape[1]:
            continue
        w = widening(base[e], j, depth[e], scale)
        out[e, j] -= w
        out[e, j + 1] += w


@njit
def renew(well, depth, idx, glass_temperature, state, inc):
    """After an event: a block whose four Gauss points share a well other than its junction's gets a new junction.

    Parameters
    ----------
    well, depth : numpy.ndarray
        int64 [ni], float64 [ni]: the junctions (changed in place).
    idx : numpy.ndarray
        int64 [ni, 4] global well of every Gauss point.
    glass_temperature : float
        ``T_g`` [G eps0^2 h^2]: a new depth is ``T_g`` times an exponential variate of mean 1.
    state, inc : numpy.ndarray
        uint64 [1]: the pcg32 generator (advanced once per new junction, in block order).

    Returns
    -------
    int
        Junctions changed: drawn anew, or removed from a block whose Gauss points lie in different wells.
    """
    changed = 0
    for e in range(idx.shape[0]):
        j = idx[e, 0]
        whole = idx[e, 1] == j and idx[e, 2] == j and idx[e, 3] == j
        if whole and well[e] != j:
            well[e] = j
            depth[e] = glass_temperature * exponential(state, inc)
            changed += 1
        elif not whole and well[e] >= 0:
            well[e] = -1
            depth[e] = 0.0
            changed += 1
    return changed


class Junctions:
    """The contact junction of every block (module docstring).

    Parameters
    ----------
    ni : int
        Interface blocks.
    strengthening : float
        ``lambda`` [eps0 per G eps0^2 h^2].
    glass_temperature : float
        ``T_g`` [G eps0^2 h^2].
    attempt_rate : float
        ``nu_j`` [1/time].
    eps0 : float
        Strain unit.

    Attributes
    ----------
    well : numpy.ndarray
        int64 [ni] global well index of every block's junction (-1: none).
    depth : numpy.ndarray
        float64 [ni] its depth [G eps0^2 h^2] (0 without a junction).
    scale : float
        Widening per unit depth ``lambda eps0`` [strain].
    glass_temperature, attempt_rate, eps0 : float
    """

    def __init__(self, ni, strengthening, glass_temperature, attempt_rate, eps0):
        self.well = np.full(ni, -1, dtype=np.int64)
        self.depth = np.zeros(ni)
        self.scale = float(strengthening) * float(eps0)
        self.glass_temperature = float(glass_temperature)
        self.attempt_rate = float(attempt_rate)
        self.eps0 = float(eps0)

    def modify(self, wells):
        """The held yield strains widened by the junctions: a new float64 [ni, ny] array (the junctions as the stack's
        yield-strain modifier, :meth:`...stack.Stack.modify_yield_strains`).

        Parameters
        ----------
        wells : stickslip.fem.yield_strains.HeldYieldStrains
        """
        out = np.empty_like(wells.epsy)
        widen(wells.epsy, wells.offset, self.well, self.depth, self.scale, out)
        return out

    def widenings(self, wells):
        """Widening of every block's well [strain] (0 without a junction) and whether the cap bound it: ([ni], bool [ni])."""
        w, capped = np.zeros(self.well.size), np.zeros(self.well.size, dtype=bool)
        for e in np.flatnonzero(self.well >= 0):
            w[e] = widening(wells.epsy[e], self.well[e] - wells.offset[e], self.depth[e], self.scale)
            capped[e] = w[e] < self.scale * self.depth[e]
        return w, capped

    def renew(self, well_index, state, inc):
        """New junctions for the blocks that changed well (:func:`renew`); the number changed."""
        return renew(self.well, self.depth, well_index, self.glass_temperature, state, inc)

    def stored(self):
        """Copies of the state, by the names of :data:`STATE_FIELDS`."""
        return {"junction_depth": self.depth.copy(), "junction_well": self.well.copy()}

    def restore(self, stored):
        """Set the state from :meth:`stored` (or the run file's datasets of the same names)."""
        self.depth[:] = stored["junction_depth"]
        self.well[:] = stored["junction_well"]
