"""Ground truth of a continuous slab trajectory: every slip of every interface, from its slip rate.

A slip of interface ``a`` is a maximal time interval in which its slip rate exceeds
``slip_velocity`` (linear interpolation between the integrator's steps gives its onset and end);
slips of different interfaces whose intervals overlap form one event (``multi`` if more than
one interface). The columns follow the ``lever`` solver's truth table
(:func:`stickslip.experiment.virtual.history.integrate`) where they have a meaning here.
"""

import numpy as np
import pandas as pd

__all__ = ["TRUTH_COLUMNS", "slip_intervals"]

#: Columns of the truth table, see :func:`slip_intervals`.
TRUTH_COLUMNS = ("event", "t_start", "t_end", "a", "dR", "dF", "dmu", "mu_before", "mu_after", "T", "age", "multi",
                 "creep_before", "V_max", "theta_before")


def _crossings(t, V, threshold):
    """Onsets and ends [s] of the intervals where ``V > threshold`` (interpolated), and the step
    index ranges ``[first, last)`` inside each."""
    fast = V > threshold
    change = np.flatnonzero(np.diff(fast.astype(np.int8)))
    up = change[fast[change + 1]]
    down = change[~fast[change + 1]]
    if fast[0]:
        up = np.concatenate([[-1], up])
    if fast[-1]:
        down = np.concatenate([down, [t.size - 1]])

    def cross(i):
        if i < 0 or i >= t.size - 1:
            return t[max(i, 0)]
        w = (threshold - V[i]) / (V[i + 1] - V[i])
        return t[i] + w * (t[i + 1] - t[i])

    onsets = np.array([cross(i) for i in up])
    ends = np.array([cross(i) for i in down])
    return onsets, ends, up + 1, down + 1


def slip_intervals(apparatus, t, R_at, V, theta, slip_velocity):
    """Every slip of a trajectory.

    Parameters
    ----------
    apparatus : Apparatus
    t : numpy.ndarray
        Times of the integrator's steps [s], [n_t].
    R_at : callable
        Slip of every interface at given times, ``R_at(times [k]) -> [k, n_slabs]`` [mm].
    V : numpy.ndarray
        Slip rates of every interface at ``t`` [mm/s], [n_t, n_slabs] (0 where it cannot slip).
    theta : numpy.ndarray
        Contact ages (rate-and-state states) at ``t`` [s], [n_t, n_slabs].
    slip_velocity : float
        Slip rate above which an interface slips [mm/s].

    Returns
    -------
    pandas.DataFrame
        One row per interface per slip, sorted by onset: ``event``, ``t_start``, ``t_end`` [s], ``a``,
        ``dR`` [mm] (``R_a(t_end) - R_a(t_start)``), ``dF`` [N] (lever-force drop caused by ``dR``,
        ``K dR (h/H) sum_{driven j >= a} j``), ``dmu`` (``mu_before - mu_after``), ``mu_before``,
        ``mu_after`` (the apparatus's ``mu_a`` at onset and end, drive included), ``T`` [s] (since the
        previous onset on ``a``; NaN for the first), ``age`` [s] (``T``, or since t = 0), ``multi``,
        ``creep_before`` [mm] (slip of ``a`` since the end of its previous slip), ``V_max`` [mm/s],
        ``theta_before`` [s] (state at onset).
    """
    force_per_slip = apparatus.k_spring * np.cumsum(apparatus.heights[::-1])[::-1] / apparatus.H
    rows = []
    for i in np.asarray(apparatus.slippable) - 1:
        onsets, ends, first, last = _crossings(t, V[:, i], slip_velocity)
        if onsets.size == 0:
            continue
        R_on, R_off = R_at(onsets), R_at(ends)
        mu_on = np.array([apparatus.mu(s, r)[i] for s, r in zip(onsets, R_on)])
        mu_off = np.array([apparatus.mu(s, r)[i] for s, r in zip(ends, R_off)])
        previous_end = np.concatenate([[0.0], ends[:-1]])
        creep = R_on[:, i] - R_at(previous_end)[:, i]
        T = np.concatenate([[np.nan], np.diff(onsets)])
        theta_on = np.interp(onsets, t, theta[:, i])
        for k in range(onsets.size):
            dR = R_off[k, i] - R_on[k, i]
            rows.append((onsets[k], ends[k], i + 1, dR, dR * force_per_slip[i], mu_on[k] - mu_off[k], mu_on[k],
                         mu_off[k], T[k], T[k] if k else onsets[k], creep[k],
                         float(V[first[k]:last[k] + 1, i].max()), float(theta_on[k])))
    columns = [c for c in TRUTH_COLUMNS if c not in ("event", "multi")]
    slips = pd.DataFrame(rows, columns=columns).sort_values(["t_start", "a"], kind="stable").reset_index(drop=True)
    # Events: chains of overlapping intervals.
    event, reach, events = -1, -np.inf, []
    for start, end in zip(slips["t_start"], slips["t_end"]):
        if start > reach:
            event += 1
        reach = max(reach, end) if start <= reach else end
        events.append(event)
    slips.insert(0, "event", np.asarray(events, dtype=np.int64))
    slips["multi"] = slips.groupby("event")["a"].transform("size").to_numpy() > 1
    return slips[list(TRUTH_COLUMNS)]
