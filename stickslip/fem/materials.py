"""Constitutive laws: linear elasticity (plates) and the cusp potential (interface blocks).

Small-strain 2-D tensors are stored as ``(xx, yy, xy)`` (tensorial shear ``xy``).
With ``eps_m = tr(eps) / 2``, ``eps_d = eps - eps_m I`` and the equivalent
deviatoric strain ``eps_eq = sqrt(eps_d : eps_d / 2) = sqrt(((xx - yy) / 2)^2 + xy^2)``:

- elastic energy density ``U = K eps_m^2 + G eps_eq^2``, stress
  ``sigma = K eps_m I + G eps_d`` (so ``G = 2 mu`` and ``sigma_xy = G eps_xy``);
- cusp energy density ``U = K eps_m^2 + G [(eps_eq - eps_min)^2 - Delta^2]`` in the
  current well ``eps_y[i] < eps_eq <= eps_y[i + 1]``, ``eps_min`` its centre and
  ``Delta`` its half-width; stress ``sigma = K eps_m I + G (1 - eps_min / eps_eq) eps_d``.

The equivalent deviatoric stress is ``sig_eq = sqrt(2 sigma_d : sigma_d)``.
Reference: shared/reference-model.md, sections 2 and 4.
"""

import math

from ..numba_options import njit

__all__ = ["equivalent_strain", "equivalent_stress", "well_index", "elastic_stress", "cusp_stress"]


@njit
def equivalent_strain(xx, yy, xy):
    """Equivalent deviatoric strain ``sqrt(((xx - yy) / 2)^2 + xy^2)`` [strain]."""
    e = 0.5 * (xx - yy)
    return math.sqrt(e * e + xy * xy)


@njit
def equivalent_stress(xx, yy, xy):
    """Equivalent deviatoric stress ``sqrt(2 sigma_d : sigma_d) = 2 sqrt(((xx - yy) / 2)^2 + xy^2)`` [stress]."""
    e = 0.5 * (xx - yy)
    return 2.0 * math.sqrt(e * e + xy * xy)


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


@njit
def elastic_stress(xx, yy, xy, K, G):
    """Stress ``K eps_m I + G eps_d`` of strain ``(xx, yy, xy)``; returns ``(sxx, syy, sxy)``."""
    m = 0.5 * (xx + yy)
    return K * m + G * (xx - m), K * m + G * (yy - m), G * xy


@njit
def cusp_stress(xx, yy, xy, K, G, eps_min):
    """Cusp stress ``K eps_m I + G (1 - eps_min / eps_eq) eps_d``; returns ``(sxx, syy, sxy)``.

    At ``eps_eq = 0`` (possible only in the first, centred well) the deviatoric part is zero.
    """
    m = 0.5 * (xx + yy)
    eq = equivalent_strain(xx, yy, xy)
    factor = 0.0 if eq <= 0.0 else G * (1.0 - eps_min / eq)
    return K * m + factor * (xx - m), K * m + factor * (yy - m), factor * xy
