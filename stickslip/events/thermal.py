"""The ``thermal-events`` analysis plugin: slips with their waiting times, slow slip and hold trials of a fem run.

What the experimental analysis measures (docs/experimental-analysis.md, sections 4 and 5), measured
on a ``fem`` run with a clock (a thermal run, ``temperature > 0``), plus the slide-hold-slide
experiment done on its stored states:

- **slips**: every steady-state slip of an interface (:func:`.extraction.slip_interfaces`) with
  ``t`` (the run's clock), ``T_fe`` (time since the previous slip of the same interface, any
  slip of it counted, also before the steady state), ``hold`` (time of ``T_fe`` during which the drive
  was held), ``mu_before_sig0`` (the interface's stress before the slip, its peak [sig0]) and the aging
  rate of the slip ``B_a_sig0 = dmu_sig0 / ln(T_fe / T0)`` [sig0] with the microscopic time
  ``T0 = 1 / attempt_rate`` (the model's counterparts of the lab's ``time``, ``T``, ``mu_before``, ``B_a``:
  :mod:`stickslip.vocabulary`);
  for an athermal run, whose ``t`` counts minimisation time steps, not time, these are NaN;
- **slow slip** per interface over the steady state: the interface's plastic slip ``R_a`` counted in
  well hops (the signed hops ``S_a`` of its blocks, Gauss point 0, summed over the increments; the
  model's counterpart of the slabs' relative position: the relative displacement of the plates would
  include their elastic shear, which returns every cycle and is no slip), ``R_tot`` its growth,
  ``dR_sum`` the part made in the interface's slip events (the paper's numerical slip criterion,
  ``A_a == N``), ``R_slow = 1 - dR_sum / R_tot`` (:func:`stickslip.experiment.aging.slow_slip_fraction`):
  the slip made by microscopic events, thermally activated or not;
- **hold trials** (thermal runs with ``hold_interfaces`` interfaces, any if 0): ``states`` steady-state
  slip increments, evenly spaced, each held
  for every one of ``hold_times`` at a load ``below`` under its athermal threshold and reloaded
  (:mod:`stickslip.fem.thermal.holds`, through the solver's replay), paired: every hold time of a
  state draws from the same random stream;
- **aging trials** (extension parameters, off by default; :mod:`.aging_trials`): the hold trials at
  further loads ``hold_loads`` (then ``holds`` has a column ``below``), every slip after them until
  each interface has slipped ``each`` times (table ``trial_slips``), and aftershock holds after
  ``aftershock_states`` slips of every interface with their controls (``aftershock_trials``,
  ``aftershocks``).

Output (format ``event-table``): ``slip_events`` (the normalised table; further columns ``T_fe``,
``hold``, ``B_a_sig0``, ``mu_before_sig0``, ``dgamma``), ``interfaces`` (``interface``, ``R_tot``, ``dR_sum`` [well hops],
``R_slow``, ``n_slips``), ``holds`` (one row per trial: ``trial``, ``state`` (increment), ``replica``,
``hold_time``, ``held_below`` [eps0] (the hold's load under the threshold: ``below``, or less where unloading
to it would move a block out of its well), ``peak``, ``interface``, ``mu_start`` [sig0], ``failed_in_hold``, ``t_slip``,
``hold_hops``, ``events``), ``creep`` (``trial``, ``t`` since the hold's start, ``R_<a>`` the slip of
interface a since then [well hops], after each hop within a hold), ``barriers`` (``trial``, ``block``,
``start``, ``end``: every block's forward barrier at the start and end of the hold, in units of the
temperature). Times are the run's (FE time units); root attributes as ``numerical-events`` plus
``T0`` and ``thermal``.
"""

import dataclasses

import numpy as np
import pandas as pd

from .. import progress
from ..experiment.aging import aging_rate, slow_slip_fraction
from ..formats.analysis_file import write_analysis_file
from ..formats.event_table import slip_events_table
from ..formats.fem_run import read_increments, read_run_attrs
from ..h5io import FileFormatError
from ..plugin_params import param
from ..registry import register
from . import extraction
from .aging_trials import aftershock_tables, trial_slip_table
from .fronts import solver_replay
from .plugin import event_attrs

__all__ = ["ThermalEventParams", "NAME", "VERSION", "slip_table", "interface_table", "hold_tables", "run"]

NAME = "thermal-events"
VERSION = "3"  # 2: the package's vocabulary (dmu_sig0, t, T_fe, B_a_sig0, mu_before_sig0, interface; event-table 2);
#             3: holds unload to ``below`` where a state is nearer its threshold (column held_below)


@dataclasses.dataclass(frozen=True)
class ThermalEventParams:
    """Parameters of the hold trials (the slip and slow-slip tables have none)."""

    states: int = param(10, "hold trials: number of steady-state slip increments held (0: no trials)", minimum=0)
    hold_times: tuple[float, ...] = param((0.0, 1e6, 1e8, 1e10, 1e12), "hold trials: hold durations",
                                          unit="1/attempt_rate", minimum=0.0)
    below: float = param(0.02, "hold trials: imposed shear between the held load and the athermal threshold",
                         unit="eps0", minimum=0.0)
    hold_interfaces: int = param(1, "hold trials only in runs with this many interfaces (0: every run)", minimum=0)
    hold_loads: tuple[float, ...] = param((), "aging trials: further loads of the hold trials below the athermal "
                                              "threshold (every state held at `below` and at each of these)",
                                          unit="eps0", minimum=0.0, extension=True)
    each: int = param(0, "aging trials: after a hold, drive on until every interface has slipped this many times "
                         "and record every slip (table trial_slips); 0: the trial ends at the first slip",
                      minimum=0, extension=True)
    aftershock_states: int = param(0, "aging trials: steady-state slips of every interface held at their post-slip "
                                      "load, each with a control hold mid-stick at the same stress (tables "
                                      "aftershock_trials, aftershocks); 0: none", minimum=0, extension=True)
    aftershock_time: float = param(1e12, "aging trials: duration of every aftershock and control hold",
                                   unit="1/attempt_rate", exclusive_minimum=0.0, extension="aftershock_states")


def _slip_rows(classified, N, a):
    """Rows of every kick increment in which interface ``a`` slipped (steady state or not)."""
    return np.flatnonzero(classified["kick"].to_numpy(dtype=bool) & (classified[f"A_a{a}"].to_numpy() == N))


def slip_table(increments, classified, N, *, T0=None):
    """The normalised slip table of a run, with waiting times (module docstring).

    Parameters
    ----------
    increments : pandas.DataFrame
        The run's increment table (:func:`stickslip.formats.fem_run.read_increments`): ``t`` and, for a
        thermal run, ``held``.
    classified : pandas.DataFrame
        Its :func:`.extraction.classify_increments`.
    N : int
    T0 : float, optional
        ``1 / attempt_rate`` of a thermal run; None: the run has no clock (times are NaN).

    Returns
    -------
    pandas.DataFrame
        :func:`stickslip.formats.event_table.slip_events_table` with ``t``, ``T_fe``, ``hold``, ``B_a_sig0``,
        ``mu_before_sig0``, ``dgamma``.
    """
    per_interface = extraction.slip_interfaces(classified, N)
    increment = classified["increment"].to_numpy()
    t = increments["t"].to_numpy(dtype=float)
    held = np.cumsum(increments["held"].to_numpy(dtype=float)) if "held" in increments else np.zeros(t.size)
    position = {inc: i for i, inc in enumerate(increment)}
    rows = np.array([position[inc] for inc in per_interface["increment"]], dtype=np.int64)
    waits, holds, before = np.full(rows.size, np.nan), np.full(rows.size, np.nan), np.empty(rows.size)
    for a in np.unique(per_interface["interface"]):
        mine = np.flatnonzero(per_interface["interface"].to_numpy() == a)
        slips = _slip_rows(classified, N, a)
        previous = slips[np.searchsorted(slips, rows[mine]) - 1]
        first = np.searchsorted(slips, rows[mine]) == 0
        if T0 is not None:
            waits[mine] = np.where(first, np.nan, t[rows[mine]] - t[previous])
            holds[mine] = np.where(first, np.nan, held[rows[mine]] - held[previous])
        before[mine] = classified[f"mu_a{a}"].to_numpy(dtype=float)[rows[mine] - 1]
    time = t[rows] if T0 is not None else np.full(rows.size, np.nan)
    return slip_events_table(pd.DataFrame({
        "event": np.unique(per_interface["increment"].to_numpy(), return_inverse=True)[1].reshape(-1),
        "interface": per_interface["interface"], "multi": per_interface["multi"],
        "dmu_sig0": per_interface["dmu_sig0"], "t": time, "increment": per_interface["increment"],
        "T_fe": waits, "hold": holds, "B_a_sig0": aging_rate(per_interface["dmu_sig0"], waits, t0=T0 or 1.0),
        "mu_before_sig0": before, "dgamma": per_interface["dgamma"]}))


def interface_table(classified, N):
    """Slow slip of every interface over the steady state (module docstring), from :func:`.extraction.classify_increments`.

    Returns
    -------
    pandas.DataFrame
        ``interface``, ``R_tot``, ``dR_sum`` [well hops], ``R_slow``, ``n_slips``; no rows without a steady state.
    """
    steady = np.flatnonzero(classified["steady"].to_numpy(dtype=bool))
    rows = []
    for a in extraction.interfaces_in(classified):
        if steady.size == 0:
            continue
        hops = classified[f"S_a{a}"].to_numpy(dtype=float)
        slips = _slip_rows(classified, N, a)
        slips = slips[slips > steady[0]]
        R_tot = float(np.sum(hops[steady[0] + 1:]))
        dR_sum = float(np.sum(hops[slips]))
        rows.append({"interface": a, "R_tot": R_tot, "dR_sum": dR_sum,
                     "R_slow": float(slow_slip_fraction(R_tot, dR_sum)),
                     "n_slips": slips.size})
    return pd.DataFrame(rows, columns=["interface", "R_tot", "dR_sum", "R_slow", "n_slips"])


def hold_tables(hold, states, params, T0, n_interfaces, results=None):
    """The hold trials of a thermal run (module docstring).

    Parameters
    ----------
    hold : callable
        ``hold(increment, hold_time, below, replica, each)``: :meth:`stickslip.fem.replay.EventReplay.hold`.
    states : Sequence[int]
        Stored increments to hold (one replica each).
    params : ThermalEventParams
    T0 : float
        ``1 / attempt_rate`` (the unit of ``params.hold_times``).
    n_interfaces : int
    results : list, optional
        Filled with every trial's result (:func:`stickslip.fem.thermal.holds.hold_trial`), in trial order.

    Returns
    -------
    tuple[pandas.DataFrame, pandas.DataFrame, pandas.DataFrame]
        ``holds`` (with ``below`` if ``params.hold_loads``), ``creep``, ``barriers``.
    """
    holds, creep, barriers = [], [], []
    names = [f"R_{a}" for a in range(1, n_interfaces + 1)]
    loads = (params.below, *params.hold_loads)
    bar = progress.bar(len(states) * len(params.hold_times) * len(loads), desc="hold trials", unit="trial")
    for replica, state in enumerate(states):
        for below, hold_time in ((below, hold_time) for below in loads for hold_time in params.hold_times):
            trial = len(holds)
            result = hold(int(state), hold_time * T0, below, replica, params.each)
            if results is not None:
                results.append(result)
            holds.append({"trial": trial, "state": int(state), "replica": replica, "hold_time": hold_time * T0,
                          **({"below": below} if params.hold_loads else {}),
                          **{k: result[k] for k in ("held_below", "peak", "interface", "mu_start", "failed_in_hold", "t_slip",
                                                    "hold_hops", "events")}})
            rows = result["creep"]
            creep.append(pd.DataFrame({"trial": np.full(len(rows), trial), "t": rows[:, 0],
                                       **{name: rows[:, k + 1] for k, name in enumerate(names)}}))
            blocks = result["barriers_start"].size
            barriers.append(pd.DataFrame({"trial": np.full(blocks, trial), "block": np.arange(blocks),
                                          "start": result["barriers_start"], "end": result["barriers_end"]}))
            bar.update(1)
    bar.close()
    columns = ["trial", "state", "replica", "hold_time", *(["below"] if params.hold_loads else []), "held_below", "peak",
               "interface", "mu_start", "failed_in_hold", "t_slip", "hold_hops", "events"]
    holds = pd.DataFrame(holds, columns=columns).astype({"trial": np.int64, "state": np.int64,
                                                         "replica": np.int64, "interface": np.int64,
                                                         "failed_in_hold": bool, "hold_hops": np.int64,
                                                         "events": np.int64})
    empty_creep = pd.DataFrame({"trial": np.zeros(0, np.int64), "t": np.zeros(0),
                                **{name: np.zeros(0) for name in names}})
    empty_barriers = pd.DataFrame({"trial": np.zeros(0, np.int64), "block": np.zeros(0, np.int64),
                                   "start": np.zeros(0), "end": np.zeros(0)})
    return (holds, pd.concat([empty_creep, *creep], ignore_index=True),
            pd.concat([empty_barriers, *barriers], ignore_index=True))


@register("analysis", NAME, VERSION, ThermalEventParams, consumes=("fem-run",), produces="event-table")
def run(params, input, output):
    """Slips with waiting times and aging rates, slow slip, and hold trials (thermal runs) of a fem run."""
    run_attrs = read_run_attrs(input)
    if "N" not in run_attrs:
        raise FileFormatError(f"{input}: run attributes lack N")
    N, n = int(run_attrs["N"]), int(run_attrs["n_interfaces"])
    increments = read_increments(input)
    classified = extraction.classify_increments(increments, N, source=str(input))
    temperature = float(run_attrs.get("temperature", 0.0))
    thermal = temperature > 0.0
    T0 = 1.0 / float(run_attrs["attempt_rate"]) if thermal else None
    slips = slip_table(increments, classified, N, T0=T0)
    steady_slips = np.unique(slips["increment"].to_numpy())
    states, trials = [], []
    holding = bool(thermal and params.states and steady_slips.size and params.hold_interfaces in (0, n))
    replay = solver_replay(input, NAME) if holding or (thermal and params.aftershock_states) else None
    if holding:
        pick = np.unique(np.linspace(0, steady_slips.size - 1, min(params.states, steady_slips.size)).round())
        states = steady_slips[pick.astype(np.int64)]
        holds, creep, barriers = hold_tables(replay.hold, states, params, T0, n, trials)
    else:
        holds, creep, barriers = hold_tables(None, [], params, 1.0, n)
    tables = {"slip_events": slips, "interfaces": interface_table(classified, N), "holds": holds, "creep": creep,
              "barriers": barriers}
    if params.each:
        tables["trial_slips"] = trial_slip_table(trials)
    if params.aftershock_states:
        tables["aftershock_trials"], tables["aftershocks"] = aftershock_tables(
            replay.aftershocks if replay is not None else None, increments["t"].to_numpy(dtype=float), classified,
            slips, n, params.aftershock_states, params.aftershock_time * (T0 or 1.0))
    attrs = {**event_attrs(run_attrs, classified, source=str(input)), "thermal": thermal,
             "T0": T0 if thermal else np.nan}
    write_analysis_file(output, "event-table", analysis=NAME, version=VERSION, params=params, input=input,
                        attrs=attrs, tables=tables)
