"""Linear elasticity of the plates and the invariants of 2-D strain and stress.

Small-strain 2-D tensors are stored as ``(xx, yy, xy)`` (tensorial shear ``xy``).
With ``eps_m = tr(eps) / 2``, ``eps_d = eps - eps_m I`` and the equivalent
deviatoric strain ``eps_eq = sqrt(eps_d : eps_d / 2) = sqrt(((xx - yy) / 2)^2 + xy^2)``:
elastic energy density ``U = K eps_m^2 + G eps_eq^2``, stress
``sigma = K eps_m I + G eps_d`` (so ``G = 2 mu`` and ``sigma_xy = G eps_xy``).
The equivalent deviatoric stress is ``sig_eq = sqrt(2 sigma_d : sigma_d)``.
The interface blocks' laws, potentials in wells of the same invariants, are in :mod:`.laws`.
Reference: shared/reference-model.md, sections 2 and 4.
"""

import math

import numpy as np

from ..numba_options import njit

__all__ = ["equivalent_strain", "equivalent_strains", "equivalent_stress", "elastic_stress"]


@njit
def equivalent_strain(xx, yy, xy):
    """Equivalent deviatoric strain ``sqrt(((xx - yy) / 2)^2 + xy^2)`` [strain]."""
    e = 0.5 * (xx - yy)
    return math.sqrt(e * e + xy * xy)


@njit
def equivalent_strains(eps):
    """:func:`equivalent_strain` of every strain of an array.

    Parameters
    ----------
    eps : numpy.ndarray
        float64 [n, 4, 3], C-contiguous: strains ``(xx, yy, xy)`` (e.g. of the interface Gauss points).

    Returns
    -------
    numpy.ndarray
        float64 [n, 4] [strain].
    """
    out = np.empty(eps.shape[:2])
    for e in range(eps.shape[0]):
        for q in range(eps.shape[1]):
            out[e, q] = equivalent_strain(eps[e, q, 0], eps[e, q, 1], eps[e, q, 2])
    return out


@njit
def equivalent_stress(xx, yy, xy):
    """Equivalent deviatoric stress ``sqrt(2 sigma_d : sigma_d) = 2 sqrt(((xx - yy) / 2)^2 + xy^2)`` [stress]."""
    e = 0.5 * (xx - yy)
    return 2.0 * math.sqrt(e * e + xy * xy)


@njit
def elastic_stress(xx, yy, xy, K, G):
    """Stress ``K eps_m I + G eps_d`` of strain ``(xx, yy, xy)``; returns ``(sxx, syy, sxy)``."""
    m = 0.5 * (xx + yy)
    return K * m + G * (xx - m), K * m + G * (yy - m), G * xy
