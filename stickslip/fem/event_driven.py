"""Event-driven quasistatic loading: linear response, elastic step to the brink, kick.

The linear (purely elastic) response ``du`` to a unit change of the drive is
computed once. Along it, the interface strain changes linearly,
``eps(s) = eps + s deps``, so the step ``s`` at which a Gauss point reaches a
target equivalent strain solves a quadratic. As in FrictionQPotFEM
(``eventDrivenStep(..., iterative=True)``): the candidate steps of all Gauss points
are sorted and tried in turn until a well index changes (with ``yield_element``:
until all four points of some element changed), then bisected until
``(right - left) / left < 1e-5``. An elastic load step applies ``left``
(largest step without any index change, targets ``eps_y,right - deps / 2``); a
kick applies ``right`` (smallest step that changes an index, targets
``eps_y,right + deps / 2``).
Reference: shared/reference-model.md, section 8a-8b.
"""

import numpy as np

from ..numba_options import njit
from .laws import well_index
from .materials import equivalent_strain
from .quad4 import element_strain

__all__ = ["step_size", "unload_size", "autoscale", "BISECTION_RTOL", "MAX_BISECTIONS"]

#: Relative width at which the bisection stops.
BISECTION_RTOL = 1e-5
#: Maximum number of bisection iterations.
MAX_BISECTIONS = 1000


@njit
def _yields(epsy, dofs, dNdx, u, du, idx, s, yield_element):
    """Whether the trial displacement ``u + s du`` changes an index (or all 4 of an element).

    The trial strain is computed from the trial displacement exactly as the force
    evaluation will compute it once the step is applied (same operations, same bits).
    """
    ue = np.empty(8)
    eps = np.empty((4, 3))
    for e in range(idx.shape[0]):
        for a in range(8):
            ue[a] = u[dofs[e, a]] + s * du[dofs[e, a]]
        element_strain(dNdx[e], ue, eps)
        changed = 0
        for q in range(4):
            if well_index(epsy[e], equivalent_strain(eps[q, 0], eps[q, 1], eps[q, 2]), idx[e, q]) != idx[e, q]:
                changed += 1
        if yield_element:
            if changed == 4:
                return True
        elif changed > 0:
            return True
    return False


@njit
def step_size(epsy, dofs, dNdx, u, du, eps, deps, idx, deps_kick, kick, yield_element, bisect=True):
    """Step along the linear response to the brink of yielding (load) or just past it (kick).

    Parameters
    ----------
    epsy : numpy.ndarray
        [ni, ny] yield strains.
    dofs : numpy.ndarray
        int64 [ni, 8] DOFs of the interface elements.
    dNdx : numpy.ndarray
        [ni, 4, 4, 2] their shape-function gradients.
    u, du : numpy.ndarray
        [ndof] current displacement and linear response.
    eps : numpy.ndarray
        [ni, 4, 3] current interface strain (xx, yy, xy).
    deps : numpy.ndarray
        [ni, 4, 3] interface strain of the linear response.
    idx : numpy.ndarray
        int64 [ni, 4] current well indices.
    deps_kick : float
        Kick size in equivalent strain.
    kick : bool
        Kick (True) or elastic load step (False).
    yield_element : bool
        Kick: require all 4 Gauss points of one element to change well.
    bisect : bool, optional
        False (kicks only): the first candidate step that yields, unrefined, which carries its Gauss point
        ``deps_kick / 2`` past its yield strain rather than just past it.

    Returns
    -------
    float
        The step ``s`` (>= 0); 0 for a load step when a point is already within
        ``deps_kick / 2`` of yielding; -1 if no candidate step yields (error).
    """
    ni = idx.shape[0]
    sign = 1.0 if kick else -1.0
    candidates = np.empty(ni * 4)
    for e in range(ni):
        for q in range(4):
            target = epsy[e, idx[e, q] + 1] + sign * 0.5 * deps_kick
            et = 0.5 * (eps[e, q, 0] - eps[e, q, 1])
            gt = eps[e, q, 2]
            if not kick and target < equivalent_strain(eps[e, q, 0], eps[e, q, 1], eps[e, q, 2]):
                return 0.0
            ed = 0.5 * (deps[e, q, 0] - deps[e, q, 1])
            gd = deps[e, q, 2]
            a = ed * ed + gd * gd
            b = 2.0 * (et * ed + gt * gd)
            c = et * et + gt * gt - target * target
            candidates[e * 4 + q] = abs((-b + np.sqrt(b * b - 4.0 * a * c)) / (2.0 * a))
    candidates.sort()
    i = 0
    while i < candidates.size and not _yields(epsy, dofs, dNdx, u, du, idx, candidates[i], yield_element and kick):
        i += 1
    if i == candidates.size:
        return -1.0
    right = candidates[i]
    if kick and not bisect:
        return right
    left = candidates[i - 1] if i > 0 else 0.0
    for _ in range(MAX_BISECTIONS):
        mid = 0.5 * (right + left)
        if _yields(epsy, dofs, dNdx, u, du, idx, mid, yield_element and kick):
            right = mid
        else:
            left = mid
        if (right - left) / left < BISECTION_RTOL:
            break
    return right if kick else left


@njit
def unload_size(epsy, dofs, dNdx, u, du, idx, step):
    """Largest step back along the linear response, at most ``step``, that changes no well index.

    An elastic unload: ``u - s du`` for ``s`` up to ``step`` while every Gauss point stays in its
    well (the backward twin of an elastic load step, without its ``deps_kick / 2`` margin); bisected
    to ``(right - left) < BISECTION_RTOL * right`` where a point would leave its well before ``step``.

    Parameters
    ----------
    epsy, dofs, dNdx, u, du, idx
        As :func:`step_size`.
    step : float
        The unload wanted (>= 0) [in units of the linear response].

    Returns
    -------
    float
        The unload ``s`` (0 <= s <= step); ``u - s du`` has the well indices ``idx``.
    """
    back = -du
    if not _yields(epsy, dofs, dNdx, u, back, idx, step, False):
        return step
    left, right = 0.0, step
    for _ in range(MAX_BISECTIONS):
        mid = 0.5 * (right + left)
        if _yields(epsy, dofs, dNdx, u, back, idx, mid, False):
            right = mid
        else:
            left = mid
        if right - left < BISECTION_RTOL * right:
            break
    return left


@njit
def autoscale(width, deps):
    """Scale factor of the linear response: ``0.1 * width / max eps_eq(deps)``.

    Parameters
    ----------
    width : float
        Width of the narrowest well [strain] (:func:`.yield_strains.narrowest_well`).
    deps : numpy.ndarray
        [ni, 4, 3] interface strain of the unscaled response.

    Returns
    -------
    float
    """
    largest = 0.0
    for e in range(deps.shape[0]):
        for q in range(4):
            largest = max(largest, equivalent_strain(deps[e, q, 0], deps[e, q, 1], deps[e, q, 2]))
    return 0.1 * width / largest
