"""The trap model of the junctions in orders of magnitude: how often a junction at rest is redrawn.

What the parameters of junction aging are checked against (:mod:`.parameters`) and what bounds the exact sampling
of the redraws (:mod:`.thermal.redraws`); the junctions themselves are :mod:`.thermal.junctions`. Apart from
the thermal package so that the parameters import nothing of it.
"""

import math

__all__ = ["expected_redraws"]


def expected_redraws(attempt_rate, temperature, glass_temperature, duration):
    """How often a junction at rest is redrawn in ``duration`` from a fresh one: the trap model's order of magnitude.

    Below the glass temperature the waiting times of the redraws have a power-law tail of index
    ``x = T / T_g < 1`` (the deeper the junction, the longer it lasts), so the redraws grow as ``(nu_j t)^x``;
    at and above it as ``nu_j t``. Used to refuse parameters whose runs would not end
    (:mod:`stickslip.fem.parameters`) and to bound the sampling (:func:`.thermal.redraws.sample_with_redraws`).

    Parameters
    ----------
    attempt_rate : float
        ``nu_j`` [1/time].
    temperature, glass_temperature : float
        ``T``, ``T_g`` [G eps0^2 h^2].
    duration : float
        [time] (``inf``: none).

    Returns
    -------
    float
        ``max(1, (nu_j duration)^min(1, T / T_g))`` (``inf`` for an infinite duration).
    """
    attempts = attempt_rate * duration
    if not attempts > 1.0:
        return 1.0
    return math.inf if math.isinf(attempts) else attempts ** min(1.0, temperature / glass_temperature)
