"""Yield-strain sequences of the interface blocks, generated as the paper's code does.

Each interface element ``e`` owns one pcg32 generator seeded with
``initstate = base + e``, ``initseq = 0`` (elements numbered interface by
interface, blocks left to right), ``base = seed * N * (max_plates - 1)`` with
``max_plates = 100``: the same seed gives the same disorder on the first
interfaces whatever the number of plates. Its wells have widths
``2 eps0 w + eps_offset`` with ``w ~ Weibull(k, 1)``; the yield strains are their
cumulative sum ``eps_y[j]``, and the sequence is prepended with ``-eps_y[0]`` so
that the initial well ``[-eps_y[0], eps_y[0]]`` is centred on zero strain.
Reference: shared/reference-model.md, section 4.
"""

import numpy as np

from .random import weibull_rows

__all__ = ["MAX_PLATES", "seed_base", "interface_initstate", "yield_strains"]

#: Plates reserved per realisation when spacing the seeds (the paper's ``--max-plates``).
MAX_PLATES = 100


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


def yield_strains(initstate, nchunk, eps0, eps_offset, k):
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

    Returns
    -------
    numpy.ndarray
        float64 [nelem, nchunk + 1]: ``[-eps_y0, eps_y0, eps_y1, ...]``, increasing.
    """
    widths = 2.0 * eps0 * weibull_rows(initstate, 0, nchunk, k) + eps_offset
    epsy = np.cumsum(widths, axis=1)
    return np.concatenate([-epsy[:, :1], epsy], axis=1)
