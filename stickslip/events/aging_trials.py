"""The aging trials of a thermal fem run: paired holds at several loads with every slip after them, and aftershocks.

Tables of the ``thermal-events`` analysis (:mod:`.thermal`) when its aging parameters ask for them:

- ``trial_slips`` (holds with ``each > 0``): every slip of an interface after a hold trial
  (:func:`stickslip.fem.thermal.holds.hold_trial`), one row per (trial, slip): ``trial``, ``slip``
  (its rank among the interface's slips after the hold, from 1), ``interface``, ``peak`` [sig0],
  ``t`` (time since the hold's start), ``precursors`` (the share of the interface's blocks that
  changed well between the end of the hold and the peak), and the interface's junctions at the
  peak: ``depth`` (mean depth [G eps0^2 h^2]), ``widening`` (mean widening of the wells [eps0]),
  ``capped`` (the share bound by the cap), NaN without aging;
- ``aftershock_trials`` and ``aftershocks`` (``aftershock_states > 0``): for every interface ``a``,
  ``aftershock_states`` of its steady-state slips (mainshocks), each held at its post-slip load for
  ``aftershock_time`` (kind ``post-slip``), and a control hold from the load increment halfway (in
  time) to the interface's next slip, unloaded until ``a``'s stress is the post-slip one (kind
  ``control``) (:func:`stickslip.fem.thermal.aftershocks.aftershock_trial`); ``aftershock_trials``: one row
  per hold (``trial``, ``kind`` 0 post-slip / 1 control, ``mainshock`` (increment), ``a``,
  ``state`` (increment held), ``complete``, ``events``, ``stress_<b>`` [sig0] at the hold's start);
  ``aftershocks``: one row per event of a hold (``trial``, ``t`` since the hold's start, ``A_<b>``
  the blocks of interface ``b`` that changed well).
"""

import numpy as np
import pandas as pd

from .. import progress

__all__ = ["trial_slip_table", "aftershock_tables", "KINDS"]

#: Kinds of aftershock holds, by their code in ``aftershock_trials``.
KINDS = ("post-slip", "control")

_SLIP_COLUMNS = ["trial", "slip", "interface", "peak", "t", "precursors", "depth", "widening", "capped"]


def trial_slip_table(trials):
    """``trial_slips`` from the hold trials' results.

    Parameters
    ----------
    trials : Sequence[dict]
        Results of :func:`stickslip.fem.thermal.holds.hold_trial`, in trial order.

    Returns
    -------
    pandas.DataFrame
        Columns of the module docstring.
    """
    rows = []
    for trial, result in enumerate(trials):
        ranks = {}
        for interface, peak, t, precursors, depth, widening, capped in result["slips"]:
            ranks[interface] = ranks.get(interface, 0) + 1
            rows.append([trial, ranks[interface], int(interface), peak, t, precursors, depth, widening, capped])
    table = pd.DataFrame(rows, columns=_SLIP_COLUMNS)
    return table.astype({"trial": np.int64, "slip": np.int64, "interface": np.int64, "peak": float, "t": float,
                         "precursors": float, "depth": float, "widening": float, "capped": float})


def _mainshocks(t, classified, slips, count):
    """``(a, mainshock, control state, post-slip stress)`` for ``count`` steady-state slips of every interface.

    The control state is the load increment nearest to halfway (in time) between the mainshock and
    the interface's next slip; mainshocks without a next slip are left out.
    """
    kick = classified["kick"].to_numpy(dtype=bool)
    out = []
    for a in np.unique(slips["interface"]):
        mine = np.sort(slips.loc[slips["interface"] == a, "increment"].to_numpy(dtype=np.int64))
        if mine.size < 2:
            continue
        pick = np.unique(np.linspace(0, mine.size - 2, min(count, mine.size - 1)).round().astype(np.int64))
        for i in pick:
            shock, following = mine[i], mine[i + 1]
            loads = np.flatnonzero(~kick[shock:following]) + shock
            if loads.size == 0:
                continue
            middle = loads[np.argmin(np.abs(t[loads] - 0.5 * (t[shock] + t[following])))]
            out.append((int(a), int(shock), int(middle), float(classified[f"mu_a{a}"].to_numpy()[shock])))
    return out


def aftershock_tables(aftershocks, t, classified, slips, n_interfaces, count, hold_time):
    """``aftershock_trials`` and ``aftershocks`` of a run (module docstring).

    Parameters
    ----------
    aftershocks : callable or None
        ``aftershocks(increment, hold_time, replica, control)``:
        :meth:`stickslip.fem.replay.EventReplay.aftershocks`; None: no trials (empty tables).
    t : numpy.ndarray
        The run's clock per increment [time].
    classified : pandas.DataFrame
        :func:`.extraction.classify_increments` of the run.
    slips : pandas.DataFrame
        Its steady-state slips (``interface``, ``increment``).
    n_interfaces : int
    count : int
        Mainshocks per interface.
    hold_time : float
        Duration of every hold [time].

    Returns
    -------
    tuple[pandas.DataFrame, pandas.DataFrame]
    """
    names = [f"A_{b}" for b in range(1, n_interfaces + 1)]
    trials, events = [], []
    shocks = _mainshocks(t, classified, slips, count) if aftershocks is not None and count else []
    bar = progress.bar(2 * len(shocks), desc="aftershock holds", unit="hold")
    for replica, (a, shock, middle, stress) in enumerate(shocks):
        for kind, (state, control) in enumerate(((shock, None), (middle, (a, stress)))):
            trial = len(trials)
            result = aftershocks(state, hold_time, replica, control)
            rows = result["events"]
            trials.append({"trial": trial, "kind": kind, "mainshock": shock, "a": a, "state": state,
                           "complete": bool(result["complete"]), "events": len(rows),
                           **{f"stress_{b + 1}": value for b, value in enumerate(result["stress"])}})
            events.append(pd.DataFrame({"trial": np.full(len(rows), trial, dtype=np.int64), "t": rows[:, 0],
                                        **{name: rows[:, k + 1].astype(np.int64) for k, name in enumerate(names)}}))
            bar.update(1)
    bar.close()
    columns = ["trial", "kind", "mainshock", "a", "state", "complete", "events"] + \
        [f"stress_{b}" for b in range(1, n_interfaces + 1)]
    trials = pd.DataFrame(trials, columns=columns).astype(
        {"trial": np.int64, "kind": np.int64, "mainshock": np.int64, "a": np.int64, "state": np.int64,
         "complete": bool, "events": np.int64, **{f"stress_{b}": float for b in range(1, n_interfaces + 1)}})
    empty = pd.DataFrame({"trial": np.zeros(0, np.int64), "t": np.zeros(0),
                          **{name: np.zeros(0, np.int64) for name in names}})
    return trials, pd.concat([empty, *events], ignore_index=True)
