"""Lever kinematics: from the measured lever force drop to the friction drop of one interface.

The apparatus (paper, section "Measurements and lever kinematic"): slab ``j`` is pulled by a
spring of stiffness ``K`` attached to the lever at height ``j h``; the lever top (height ``H``)
moves at speed ``V``. A *driven set* ``D`` of springs is attached: ``D = {1, ..., n}`` in the
"stack" protocol, ``D = {a}`` in the "individual" protocol (slab ``a`` driven alone, the slabs
below it clamped). With ``f_j`` the force of spring ``j``:

- force balance on interface ``i``: ``mu_i = sum_{j in D, j >= i} f_j / N``;
- moment balance on the lever: ``F = sum_{j in D} f_j j h / H``;
- a slip ``dR_a`` of interface ``a`` (alone) moves every slab ``j >= a`` by ``dR_a`` and drops
  ``f_j`` by ``K dR_a`` for ``j >= a`` in ``D``.

Hence, with ``c_a = #{j in D: j >= a}`` and ``s_a = sum_{j in D, j >= a} j``::

    dmu_a = K c_a dR_a / N,      dF = K dR_a h s_a / H,      dmu_a = (c_a / s_a) (H / h) dF / N.

Stack: ``c_a = n - a + 1``, ``s_a = (n + a)(n - a + 1) / 2``, so ``dmu_a = (H/h) 2/(n + a) dF/N``
(the paper's eq. (mu_a) without its spurious factor ``U``). Individual: ``c_a = 1``,
``s_a = a``, so ``dF = K dR_a a h / H`` and ``dmu_a = dF H / (N a h)``. While nothing slips,
``f_j`` grows at ``K j h V / H``, so ``mu_a`` grows at ``K h (V / H) s_a / N``. The derivation is
in docs/experimental-analysis.md.

Units: forces [N], lengths [mm], stiffness [N/mm], speed [mm/s], time [s]. Every function
broadcasts over array arguments.
"""

import numpy as np

__all__ = ["PROTOCOLS", "driven_sums", "dmu_from_dF", "dR_from_dF", "dmu_from_dR", "mu_loading_rate"]

#: Driving protocols: all springs 1..n attached ("stack"), or spring a alone ("individual").
PROTOCOLS = ("stack", "individual")


def driven_sums(a, n, protocol):
    """Return the count and the height sum of the driven springs at or above interface ``a``.

    Parameters
    ----------
    a : int or array_like of int
        Slipping interface (1 = lowest).
    n : int or array_like of int
        Number of driven slabs (stack protocol; ignored for "individual").
    protocol : {"stack", "individual"}

    Returns
    -------
    count : numpy.ndarray of float
        ``c_a = #{j in D: j >= a}``: ``n - a + 1`` (stack, 0 if ``a > n``) or 1 (individual).
    moment : numpy.ndarray of float
        ``s_a = sum_{j in D, j >= a} j``: ``(n + a)(n - a + 1) / 2`` (stack) or ``a`` (individual).

    Raises
    ------
    ValueError
        For an unknown protocol or ``a < 1``.
    """
    a = np.asarray(a, dtype=float)
    if np.any(a < 1):
        raise ValueError(f"interface index a must be >= 1, got {a}")
    if protocol == "stack":
        count = np.maximum(np.asarray(n, dtype=float) - a + 1.0, 0.0)
        return count, (2.0 * a + count - 1.0) * count / 2.0
    if protocol == "individual":
        return np.ones_like(a), a.copy()
    raise ValueError(f"protocol must be one of {', '.join(PROTOCOLS)}, got {protocol!r}")


def dmu_from_dF(dF, a, n, protocol, *, normal_force, h, H):
    """Friction drop ``dmu_a`` of a single slip of interface ``a`` from the lever force drop.

    Parameters
    ----------
    dF : float or array_like
        Lever force drop [N] (positive for a drop).
    a, n, protocol
        See :func:`driven_sums`.
    normal_force : float
        Normal force N [N].
    h, H : float
        Slab thickness and lever height [mm].

    Returns
    -------
    numpy.ndarray
        ``dmu_a = (c_a / s_a) (H / h) dF / N`` [-]; stack: ``(H/h) 2/(n+a) dF/N``.
    """
    count, moment = driven_sums(a, n, protocol)
    return count / moment * (H / h) * np.asarray(dF, dtype=float) / normal_force


def dR_from_dF(dF, a, n, protocol, *, k_spring, h, H):
    """Slip ``dR_a`` of interface ``a`` predicted from the lever force drop.

    Parameters
    ----------
    dF : float or array_like
        Lever force drop [N].
    a, n, protocol
        See :func:`driven_sums`.
    k_spring : float
        Spring stiffness K [N/mm].
    h, H : float
        Slab thickness and lever height [mm].

    Returns
    -------
    numpy.ndarray
        ``dR_a = dF H / (K h s_a)`` [mm]; stack: ``s_a = (n + a)(n - a + 1)/2``; individual: ``a``.
    """
    _, moment = driven_sums(a, n, protocol)
    return np.asarray(dF, dtype=float) * H / (k_spring * h * moment)


def dmu_from_dR(dR, a, n, protocol, *, k_spring, normal_force):
    """Friction drop ``dmu_a`` of a single slip of interface ``a`` from its measured slip.

    Parameters
    ----------
    dR : float or array_like
        Slip of interface ``a`` [mm].
    a, n, protocol
        See :func:`driven_sums`.
    k_spring : float
        Spring stiffness K [N/mm].
    normal_force : float
        Normal force N [N].

    Returns
    -------
    numpy.ndarray
        ``dmu_a = K c_a dR / N`` [-]; stack: ``K (n - a + 1) dR / N``; individual: ``K dR / N``.
    """
    count, _ = driven_sums(a, n, protocol)
    return k_spring * count * np.asarray(dR, dtype=float) / normal_force


def mu_loading_rate(a, n, protocol, *, k_spring, h, H, V, normal_force):
    """Rate at which ``mu_a`` grows while no interface slips.

    Parameters
    ----------
    a, n, protocol
        See :func:`driven_sums`.
    k_spring : float
        Spring stiffness K [N/mm].
    h, H : float
        Slab thickness and lever height [mm].
    V : float
        Lever-top speed [mm/s] as driven in this run (individual protocol: already divided by
        ``a`` if the run follows the paper's ``gamma_dot / a`` rule).
    normal_force : float
        Normal force N [N].

    Returns
    -------
    numpy.ndarray
        ``d mu_a / dt = K h (V / H) s_a / N`` [1/s]. Stack: ``K h gamma_dot (n+a)(n-a+1) / (2N)``
        (paper, section "Interpretation"); individual: ``K a h (V/H) / N``, so that the disorder
        law of the paper reads ``dmu_a = mu_loading_rate * T_a``.
    """
    _, moment = driven_sums(a, n, protocol)
    return k_spring * h * (V / H) * moment / normal_force
