"""The well a strain lies in: the yield strains of a block bound its wells, whatever the law.

A block's wells are the intervals ``epsy[i] < eps_eq <= epsy[i + 1]`` of its increasing yield
strains ``epsy`` (:mod:`stickslip.fem.yield_strains`); every law is a potential in the current
well (:mod:`.generic`). Reference: shared/reference-model.md, section 4.
"""

from ...numba_options import njit

__all__ = ["well_index"]


@njit
def well_index(epsy, x, current):
    """Index ``i`` of the well containing ``x``: ``epsy[i] < x <= epsy[i + 1]``.

    Parameters
    ----------
    epsy : numpy.ndarray
        float64 [ny], increasing yield strains of one block.
    x : float
        Equivalent deviatoric strain (>= 0).
    current : int
        Current index (checked first; the result does not depend on it).

    Returns
    -------
    int
        In ``[0, ny - 2]`` (clamped at the last well; runs stop well before it).
    """
    ny = epsy.size
    if epsy[current] < x and x <= epsy[current + 1]:
        return current
    lo = 0
    hi = ny  # lower_bound: first j with epsy[j] >= x
    while lo < hi:
        mid = (lo + hi) // 2
        if epsy[mid] < x:
            lo = mid + 1
        else:
            hi = mid
    i = lo - 1
    if i < 0:
        return 0
    if i > ny - 2:
        return ny - 2
    return i
