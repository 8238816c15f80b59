"""Yield-strain sequences of the interface blocks, generated as the paper's code does, and held in windows.

Each interface element ``e`` owns one pcg32 generator seeded with
``initstate = base + e``, ``initseq = 0`` (elements numbered interface by
interface, blocks left to right), ``base = seed * N * (max_plates - 1)`` with
``max_plates = 100``: the same seed gives the same disorder on the first
interfaces whatever the number of plates. Its wells have widths
``2 eps0 w + eps_offset`` with ``w ~ Weibull(k, 1)``, times the strength scale of its
interface (1 unless ``interface_strength`` says otherwise: :func:`element_scale`); the
yield strains are their cumulative sum ``eps_y[j]``, and the sequence is prepended with
``-eps_y[0]`` so that the initial well ``[-eps_y[0], eps_y[0]]`` is centred on zero strain.
Reference: shared/reference-model.md, section 4.

The sequence of a block is unbounded: :class:`HeldYieldStrains` holds ``ny``
consecutive values of every block's sequence (a window starting at the block's
``offset``) and slides or widens the windows by drawing further from each
block's own generator and continuing its running sum, so that every held value
is bit for bit the value a longer sequence generated up front has at that place.
"""

import math

import numpy as np

from ..numba_options import njit
from .random import pcg32_next, pcg32_seed

__all__ = ["MAX_PLATES", "seed_base", "interface_initstate", "element_scale", "yield_strains", "narrowest_well",
           "HeldYieldStrains"]

#: Plates reserved per realisation when spacing the seeds (the paper's ``--max-plates``).
MAX_PLATES = 100

_TWO_POW_32 = 2.0**32


def seed_base(seed, N):
    """Base seed of realisation ``seed``: ``seed * N * (MAX_PLATES - 1)``.

    Parameters
    ----------
    seed : int
        Realisation id (>= 0).
    N : int
        Blocks per interface.

    Returns
    -------
    int
    """
    return int(seed) * int(N) * (MAX_PLATES - 1)


def interface_initstate(seed, N, n_interfaces):
    """pcg32 ``initstate`` of every interface element.

    Parameters
    ----------
    seed : int
        Realisation id.
    N : int
        Blocks per interface.
    n_interfaces : int
        Number of interfaces.

    Returns
    -------
    numpy.ndarray
        int64 [n_interfaces * N]: ``base + arange``; element ``(a - 1) * N + b`` is
        block ``b`` of interface ``a``.
    """
    return seed_base(seed, N) + np.arange(N * n_interfaces, dtype=np.int64)


def element_scale(strengths, N, n_interfaces):
    """The strength scale of every interface element's wells (``interface_strength`` per element).

    Parameters
    ----------
    strengths : Sequence[float]
        One scale for every interface, or one per interface (bottom to top); empty: 1.
    N : int
        Blocks per interface.
    n_interfaces : int

    Returns
    -------
    numpy.ndarray
        float64 [n_interfaces * N]: element ``(a - 1) * N + b`` has interface ``a``'s scale.
    """
    values = np.ones(n_interfaces) if len(strengths) == 0 else np.broadcast_to(
        np.asarray(strengths, dtype=np.float64), (n_interfaces,))
    return np.repeat(values, N)


@njit
def _next_yield_strain(state, inc, row, last, two_eps0, eps_offset, inv_k, scale):
    """The yield strain after ``last`` of block ``row``: ``last + scale[row] (2 eps0 w + eps_offset)``, one draw
    (a scale of 1 leaves every bit as without it)."""
    r = float(pcg32_next(state, inc, row)) / _TWO_POW_32
    return last + scale[row] * (two_eps0 * (-math.log(1.0 - r)) ** inv_k + eps_offset)


@njit
def _fill(epsy, start, state, inc, last, two_eps0, eps_offset, inv_k, scale):
    """Fill ``epsy[e, start[e]:]`` with the next yield strains of every block ``e``; updates ``last``."""
    for e in range(epsy.shape[0]):
        for j in range(start[e], epsy.shape[1]):
            last[e] = _next_yield_strain(state, inc, e, last[e], two_eps0, eps_offset, inv_k, scale)
            epsy[e, j] = last[e]


@njit
def _slide(epsy, offset, shift, state, inc, last, two_eps0, eps_offset, inv_k, scale):
    """Move the window of every block ``e`` forward by ``shift[e]`` values (drawing as many new ones)."""
    ny = epsy.shape[1]
    start = np.full(epsy.shape[0], ny, dtype=np.int64)
    for e in range(epsy.shape[0]):
        s = shift[e]
        if s <= 0:
            continue
        for j in range(ny - s):
            epsy[e, j] = epsy[e, j + s]
        offset[e] += s
        start[e] = ny - s
    _fill(epsy, start, state, inc, last, two_eps0, eps_offset, inv_k, scale)


@njit
def _narrowest(state, inc, nwell, two_eps0, eps_offset, inv_k, scale):
    """Narrowest of the first ``nwell`` wells of every block (differences of the held values)."""
    width = np.inf
    for e in range(state.size):
        first = _next_yield_strain(state, inc, e, 0.0, two_eps0, eps_offset, inv_k, scale)
        width = min(width, first - (-first))
        previous = first
        for _ in range(nwell - 1):
            value = _next_yield_strain(state, inc, e, previous, two_eps0, eps_offset, inv_k, scale)
            width = min(width, value - previous)
            previous = value
    return width


def _generators(initstate):
    initstate = np.asarray(initstate, dtype=np.int64).astype(np.uint64)
    return pcg32_seed(initstate, np.zeros_like(initstate))


def yield_strains(initstate, nchunk, eps0, eps_offset, k, scale=None):
    """Yield-strain sequence of each element, including the symmetric first well.

    Parameters
    ----------
    initstate : numpy.ndarray
        int64 [nelem]: generator seeds (``initseq = 0``).
    nchunk : int
        Number of random well widths per element.
    eps0 : float
        Typical yield strain [strain]; well widths are ``2 eps0 w + eps_offset``.
    eps_offset : float
        Minimal well width [strain].
    k : float
        Weibull shape parameter.
    scale : numpy.ndarray, optional
        float64 [nelem]: each element's strength scale (:func:`element_scale`); None: 1.

    Returns
    -------
    numpy.ndarray
        float64 [nelem, nchunk + 1]: ``[-eps_y0, eps_y0, eps_y1, ...]``, increasing.
    """
    return HeldYieldStrains(initstate, nchunk, eps0, eps_offset, k, scale).epsy


def narrowest_well(initstate, nchunk, eps0, eps_offset, k, scale=None):
    """Width of the narrowest well among the first ``nchunk + 1`` yield strains of every element [strain].

    Equals the smallest difference of consecutive values of :func:`yield_strains`
    (``nchunk`` wells, the first one ``[-eps_y0, eps_y0]``), without holding them.
    Parameters as :func:`yield_strains`.

    Returns
    -------
    float
    """
    state, inc = _generators(initstate)
    return float(_narrowest(state, inc, int(nchunk), 2.0 * eps0, eps_offset, 1.0 / k, _scale(scale, state.size)))


def _scale(scale, nelem):
    return np.ones(nelem) if scale is None else np.ascontiguousarray(scale, dtype=np.float64)


class HeldYieldStrains:
    """A window of ``ny`` consecutive yield strains of every element's unbounded sequence.

    Held value ``epsy[e, j]`` is value ``offset[e] + j`` of element ``e``'s sequence
    ``[-eps_y0, eps_y0, eps_y1, ...]`` (global well index = held index + offset).

    Parameters
    ----------
    initstate : numpy.ndarray
        int64 [nelem]: generator seeds (``initseq = 0``).
    nwell : int
        Wells held at the start per element (``ny = nwell + 1`` values).
    eps0, eps_offset, k : float
        See :func:`yield_strains`.
    scale : numpy.ndarray, optional
        float64 [nelem]: each element's strength scale (:func:`element_scale`); None: 1.

    Attributes
    ----------
    epsy : numpy.ndarray
        float64 [nelem, ny]: the held values, never changed in place (every move gives a new array), so that what
        was given out of it (to a backend, to a :meth:`snapshot`) keeps its values.
    offset : numpy.ndarray
        int64 [nelem]: global index of ``epsy[:, 0]``.
    """

    def __init__(self, initstate, nwell, eps0, eps_offset, k, scale=None):
        self.initstate = np.asarray(initstate, dtype=np.int64)
        self._constants = (2.0 * eps0, float(eps_offset), 1.0 / k, _scale(scale, self.initstate.size))
        self.start(int(nwell))

    def start(self, nwell):
        """Hold the first ``nwell`` wells of every element (the window at the origin)."""
        self.state, self.inc = _generators(self.initstate)
        nelem = self.initstate.size
        self.last = np.zeros(nelem)
        self.offset = np.zeros(nelem, dtype=np.int64)
        self.epsy = np.empty((nelem, nwell + 1))
        _fill(self.epsy, np.ones(nelem, dtype=np.int64), self.state, self.inc, self.last, *self._constants)
        self.epsy[:, 0] = -self.epsy[:, 1]

    def slide(self, shift):
        """Move windows forward (the held well indices of a block fall by its shift: the caller renumbers them).

        Parameters
        ----------
        shift : numpy.ndarray
            int64 [nelem] values to drop at the front of each window (0: unchanged).
        """
        epsy = self.epsy.copy()
        _slide(epsy, self.offset, np.asarray(shift, dtype=np.int64), self.state, self.inc, self.last, *self._constants)
        self.epsy = epsy

    def widen(self, extra):
        """Hold ``extra`` more values per element (appended; ``epsy`` becomes a new array)."""
        nelem, ny = self.epsy.shape
        wider = np.empty((nelem, ny + int(extra)))
        wider[:, :ny] = self.epsy
        _fill(wider, np.full(nelem, ny, dtype=np.int64), self.state, self.inc, self.last, *self._constants)
        self.epsy = wider

    def snapshot(self):
        """What :meth:`resume` returns to: the windows and their generators now (a tuple; the held values shared)."""
        return self.epsy, self.offset.copy(), self.state.copy(), self.inc.copy(), self.last.copy()

    def resume(self, snapshot):
        """Return to a :meth:`snapshot`: the same windows, the same values to be drawn next."""
        self.epsy = snapshot[0]
        self.offset, self.state, self.inc, self.last = (array.copy() for array in snapshot[1:])
