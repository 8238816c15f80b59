"""Slip detection on slab positions and the amplitudes of the detected slips.

Detection follows the paper's appendix "Slow slip" exactly:

1. velocity of each interface from frame differences, ``v_k = (R_{k+1} - R_k) / (t_{k+1} - t_k)``;
2. a centred running average over five frames;
3. a slip is every cluster of at least three consecutive frames with smoothed velocity above
   ``0.02 mm/s``.

A cluster ``[k0, k1]`` of smoothed velocities involves the raw velocities ``k0 - w .. k1 + w``
(``w = 2``, half the averaging width), that is the frames ``k0 - w .. k1 + w + 1``: the slip lies
between those two frames, which bracket it (``t_start``, ``t_end``). The position of the
interface before and after the slip is the mean over up to ``position_frames`` frames of stick
that end at ``t_start`` and start at ``t_end`` (never reaching into the neighbouring slips of
the same interface): averaging beats the camera's position resolution, and ``dR`` is their
difference. Clusters of different interfaces whose brackets overlap form
one *event* with several slipping interfaces: it is flagged ``multi`` and never assigned to one
interface.

The lever force drop of an event is measured on the force signal outside the bracket, see
:func:`force_drop`.
"""

import numpy as np
import pandas as pd

__all__ = ["VELOCITY_THRESHOLD", "AVERAGE_FRAMES", "MIN_FRAMES", "POSITION_FRAMES", "frame_velocity",
           "running_average", "clusters", "detect_slips", "force_drop"]

#: Velocity above which a frame belongs to a slip [mm/s] (paper, appendix "Slow slip").
VELOCITY_THRESHOLD = 0.02
#: Width of the running average of the velocity [frames].
AVERAGE_FRAMES = 5
#: Minimum length of a cluster of fast frames [frames].
MIN_FRAMES = 3
#: Frames averaged for the position of an interface before and after a slip [frames].
POSITION_FRAMES = 5


def frame_velocity(t_x, R):
    """Velocity of every interface from frame differences.

    Parameters
    ----------
    t_x : numpy.ndarray, shape (n_frames,)
        Frame times [s], strictly increasing.
    R : numpy.ndarray, shape (n_frames, n_slabs)
        Relative positions ``R_i = x_i - x_{i-1}`` [mm].

    Returns
    -------
    numpy.ndarray, shape (n_frames - 1, n_slabs)
        ``(R[k+1] - R[k]) / (t_x[k+1] - t_x[k])`` [mm/s].
    """
    return np.diff(R, axis=0) / np.diff(t_x)[:, None]


def running_average(values, width=AVERAGE_FRAMES):
    """Centred running average along the first axis; NaN where the window is incomplete.

    Parameters
    ----------
    values : numpy.ndarray, shape (m, ...)
    width : int
        Odd window length [samples].

    Returns
    -------
    numpy.ndarray, shape (m, ...)
        ``out[k] = mean(values[k - width//2 : k + width//2 + 1])``; the first and last
        ``width // 2`` entries are NaN.
    """
    if width < 1 or width % 2 == 0:
        raise ValueError(f"running-average width must be a positive odd number, got {width}")
    values = np.asarray(values, dtype=float)
    half = width // 2
    out = np.full(values.shape, np.nan)
    if values.shape[0] < width:
        return out
    cumulative = np.concatenate([np.zeros((1,) + values.shape[1:]), np.cumsum(values, axis=0)])
    out[half:values.shape[0] - half] = (cumulative[width:] - cumulative[:-width]) / width
    return out


def clusters(mask, min_length=MIN_FRAMES):
    """First and last index of every run of consecutive True values of at least ``min_length``.

    Parameters
    ----------
    mask : numpy.ndarray of bool, shape (m,)
    min_length : int

    Returns
    -------
    numpy.ndarray of int, shape (n_clusters, 2)
        Inclusive ``[first, last]`` per run, in increasing order.
    """
    padded = np.concatenate([[0], np.asarray(mask, dtype=np.int8), [0]])
    change = np.diff(padded)
    first = np.flatnonzero(change == 1)
    last = np.flatnonzero(change == -1) - 1
    keep = last - first + 1 >= min_length
    return np.column_stack([first[keep], last[keep]])


def _window_means(values, first, last):
    """Mean of ``values[first[k] : last[k] + 1]`` for every k (inclusive bounds)."""
    cumulative = np.concatenate([[0.0], np.cumsum(values)])
    return (cumulative[last + 1] - cumulative[first]) / (last - first + 1)


def detect_slips(t_x, R, *, threshold=VELOCITY_THRESHOLD, width=AVERAGE_FRAMES, min_frames=MIN_FRAMES,
                 position_frames=POSITION_FRAMES):
    """Detect slips on every interface and group simultaneous ones into events.

    Parameters
    ----------
    t_x : numpy.ndarray, shape (n_frames,)
        Frame times [s].
    R : numpy.ndarray, shape (n_frames, n_slabs)
        Relative positions [mm]; column ``i - 1`` is interface ``i``.
    threshold : float
        Smoothed velocity above which a frame is fast [mm/s].
    width : int
        Running-average width [frames] (odd).
    min_frames : int
        Minimum number of consecutive fast frames of a slip.
    position_frames : int
        Frames averaged for the position before and after a slip.

    Returns
    -------
    pandas.DataFrame
        One row per slip, sorted by ``t_start`` then ``a``, columns:

        - ``event`` (int): event number; the slips of one event have brackets that overlap;
        - ``a`` (int): slipping interface (1 = lowest);
        - ``multi`` (bool): the event has more than one slipping interface;
        - ``i_start``, ``i_end`` (int): frames that bracket the slip;
        - ``t_start``, ``t_end`` [s]: their times;
        - ``t`` [s]: middle of the frame interval with the largest displacement of ``R_a``;
        - ``R_before``, ``R_after`` [mm]: mean ``R_a`` over the stick frames just before
          ``i_start`` (inclusive) and just after ``i_end`` (inclusive);
        - ``dR`` [mm]: ``R_after - R_before``.
    """
    t_x = np.asarray(t_x, dtype=float)
    R = np.asarray(R, dtype=float)
    smooth = running_average(frame_velocity(t_x, R), width)
    half = width // 2
    columns = ["a", "i_start", "i_end", "t_start", "t_end", "t", "R_before", "R_after"]
    parts = []
    for column in range(R.shape[1]):
        fast = np.nan_to_num(smooth[:, column], nan=-np.inf) > threshold
        found = clusters(fast, min_frames)
        if not len(found):
            continue
        i_start, i_end = found[:, 0] - half, found[:, 1] + half + 1
        position = R[:, column]
        previous_end = np.concatenate([[0], i_end[:-1]])
        next_start = np.concatenate([i_start[1:], [R.shape[0] - 1]])
        step = np.array([i + int(np.argmax(np.diff(position[i:j + 1]))) for i, j in zip(i_start, i_end)])
        parts.append(pd.DataFrame({
            "a": column + 1, "i_start": i_start, "i_end": i_end, "t_start": t_x[i_start], "t_end": t_x[i_end],
            "t": 0.5 * (t_x[step] + t_x[step + 1]),
            "R_before": _window_means(position, np.maximum(i_start - position_frames + 1, previous_end), i_start),
            "R_after": _window_means(position, i_end, np.minimum(i_end + position_frames - 1, next_start))}))
    slips = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=columns)
    slips["dR"] = (slips["R_after"] - slips["R_before"]).astype(float)
    slips = slips.sort_values(["i_start", "a"], kind="stable").reset_index(drop=True)
    # Overlapping brackets (on different interfaces) make one event.
    reach = np.maximum.accumulate(slips["i_end"].to_numpy(dtype=int)) if len(slips) else np.zeros(0, int)
    new_event = np.ones(len(slips), dtype=bool)
    new_event[1:] = slips["i_start"].to_numpy(dtype=int)[1:] > reach[:-1]
    slips.insert(0, "event", np.cumsum(new_event) - 1)
    size = slips.groupby("event")["a"].transform("size").to_numpy()
    slips.insert(2, "multi", size > 1)
    return slips.astype({"event": int, "a": int, "i_start": int, "i_end": int})


def _line_at(t, F, at):
    """Value at ``at`` of the least-squares line through ``(t, F)``."""
    t_mean = t.mean()
    slope = np.sum((t - t_mean) * (F - F.mean())) / np.sum((t - t_mean) ** 2)
    return F.mean() + slope * (at - t_mean)


def _drop_interval(F, first, last, floor):
    """Samples ``[i0, i1]`` that bound the force drop in ``F[first : last + 1]``.

    The drop is the run of consecutive decrements around the steepest one that exceed both a tenth
    of it and ``floor``; ``i0`` is the last sample before it, ``i1`` the first after it.
    """
    steps = np.diff(F[first:last + 1])
    steepest = int(np.argmin(steps))
    limit = -max(0.1 * -steps[steepest], floor)
    begin = end = steepest
    while begin > 0 and steps[begin - 1] < limit:
        begin -= 1
    while end < steps.size - 1 and steps[end + 1] < limit:
        end += 1
    return first + begin, first + end + 1


def force_drop(t_F, F, t_start, t_end, *, window, t_previous=None, t_next=None):
    """Lever force drop of slips, robust to sensor noise, to the loading ramp and to creep.

    For each slip:

    1. the drop is located on the force signal inside the bracket ``[t_start, t_end]`` (the camera
       brackets a slip within about a second; the force sensor is faster): the run of consecutive
       sample-to-sample decreases around the steepest one that exceed a tenth of it and three times
       the noise of the decrements (robust estimate, ``1.4826 MAD`` of ``diff(F)`` over the record);
    2. a straight line is fitted (least squares) to ``F`` on the ``window`` seconds that end where
       the drop starts (not before ``t_previous``), another one on the ``window`` seconds that start
       where it ends (not after ``t_next``);
    3. ``dF`` is their difference in the middle of the drop.

    The fits average out the noise; each line carries the drive's loading (and any creep) right up
    to the drop, so ``dF`` is the jump of the force, with an extrapolation over half the drop only.
    The difference of window means would be biased low by the loading during the gap between the
    windows; fits on windows outside the camera bracket would extrapolate over a second, across
    changes of the loading rate (an interface that starts creeping bends ``F(t)``).

    Parameters
    ----------
    t_F : numpy.ndarray, shape (n_F,)
        Force sample times [s], increasing.
    F : numpy.ndarray, shape (n_F,)
        Lever force [N].
    t_start, t_end : numpy.ndarray, shape (n_slips,)
        Brackets in which the drops lie [s].
    window : float
        Length of the fit windows [s].
    t_previous, t_next : numpy.ndarray, shape (n_slips,), optional
        End of the previous and start of the next bracket [s]: the windows stop there.

    Returns
    -------
    numpy.ndarray, shape (n_slips,)
        ``dF`` [N]; NaN where the bracket holds fewer than two samples or a window fewer than three.
    """
    t_F = np.asarray(t_F, dtype=float)
    F = np.asarray(F, dtype=float)
    t_start = np.atleast_1d(np.asarray(t_start, dtype=float))
    t_end = np.atleast_1d(np.asarray(t_end, dtype=float))
    t_previous = np.full(t_start.shape, -np.inf) if t_previous is None else np.asarray(t_previous, dtype=float)
    t_next = np.full(t_start.shape, np.inf) if t_next is None else np.asarray(t_next, dtype=float)
    steps = np.diff(F)
    floor = 3.0 * 1.4826 * np.median(np.abs(steps - np.median(steps))) if steps.size else 0.0
    first = np.searchsorted(t_F, t_start, side="left")
    last = np.searchsorted(t_F, t_end, side="right") - 1
    drop = np.full(t_start.shape, np.nan)
    for index in range(t_start.size):
        if last[index] - first[index] < 1:
            continue
        i0, i1 = _drop_interval(F, first[index], last[index], floor)
        b0 = np.searchsorted(t_F, max(t_F[i0] - window, t_previous[index]), side="left")
        a1 = np.searchsorted(t_F, min(t_F[i1] + window, t_next[index]), side="right")
        if i0 + 1 - b0 < 3 or a1 - i1 < 3:
            continue
        middle = 0.5 * (t_F[i0] + t_F[i1])
        drop[index] = (_line_at(t_F[b0:i0 + 1], F[b0:i0 + 1], middle)
                       - _line_at(t_F[i1:a1], F[i1:a1], middle))
    return drop
