"""A straight line through points with errors on both axes, with one intercept per group of points if asked.

``y = c_g + B x`` with weights ``1 / (sy^2 + B^2 sx^2)``: the effective variance of a point about a line of slope
``B`` when both coordinates scatter (Orear 1982; the weights depend on ``B``, so the weighted least-squares slope is
updated until it settles). The slope's error is the weighted fit's, scaled by the reduced chi-square where there
are more points than parameters and it exceeds 1 (the scatter about the line then sets it, not the points'
errors).
"""

import math

import numpy as np

__all__ = ["fit_line"]


def fit_line(x, sx, y, sy, groups=None, *, iterations=20, tolerance=1e-12):
    """The line (module docstring).

    Parameters
    ----------
    x, sx, y, sy : array_like, shape (m,)
        Points and their standard errors (> 0 on at least one axis per point).
    groups : array_like, shape (m,), optional
        A label per point: one intercept per label (None: one intercept).
    iterations : int
        Largest number of updates of the weights.
    tolerance : float
        The slope has settled when it changes by less than this times its magnitude (or absolutely, near 0).

    Returns
    -------
    dict
        ``B`` (slope), ``B_error``, ``intercepts`` (dict label -> intercept; label None without groups), ``chi2``,
        ``dof`` (points - intercepts - 1), ``scale`` (the factor applied to the error, >= 1).
    """
    x, sx, y, sy = (np.asarray(v, dtype=float) for v in (x, sx, y, sy))
    labels = np.zeros(x.size, dtype=int) if groups is None else np.asarray(groups)
    B = 0.0
    for _ in range(iterations):
        w = 1.0 / np.maximum(sy**2 + B**2 * sx**2, np.finfo(float).tiny)
        xc, yc = _centred(x, w, labels), _centred(y, w, labels)
        new = float(np.sum(w * xc * yc) / np.sum(w * xc**2))
        settled = abs(new - B) <= tolerance * max(abs(new), 1e-300)
        B = new
        if settled:
            break
    w = 1.0 / np.maximum(sy**2 + B**2 * sx**2, np.finfo(float).tiny)
    xc, yc = _centred(x, w, labels), _centred(y, w, labels)
    unique = np.unique(labels)
    dof = x.size - unique.size - 1
    chi2 = float(np.sum(w * (yc - B * xc) ** 2))
    scale = max(1.0, chi2 / dof) if dof > 0 else 1.0
    intercepts = {(None if groups is None else label): float(np.average(y[labels == label] - B * x[labels == label],
                                                                        weights=w[labels == label]))
                  for label in unique}
    return {"B": B, "B_error": math.sqrt(scale / np.sum(w * xc**2)), "intercepts": intercepts, "chi2": chi2,
            "dof": int(dof), "scale": scale}


def _centred(values, weights, labels):
    """``values`` minus the weighted mean of their label's values."""
    out = np.empty_like(values)
    for label in np.unique(labels):
        mine = labels == label
        out[mine] = values[mine] - np.average(values[mine], weights=weights[mine])
    return out
