"""Event-by-event integration of the virtual lever experiment: which interface slips when, and by how much.

Between events every friction coefficient is linear in time (the drive loads, creeping
interfaces unload, see :mod:`.apparatus`), so the next event is the earliest of

- a slip onset: ``mu_i`` reaches the strength ``mu_s,i(T_i)`` (:class:`.friction.FrictionLaw`);
- a creep onset: ``mu_i`` reaches the creep level of an interface that can creep;
- the end of the run,

each found in closed form by :func:`.friction.first_crossing`. A slip of interface ``a``
starts at ``t_start`` and, together with every other interface within ``trigger_margin`` of
its strength (a simultaneous, triggered slip), drops the friction coefficients of the slipping
interfaces to their dynamic levels: the slips ``dR`` [mm] solve ``C_SS dR = mu_S - mu_d,S``
(``C`` the coupling matrix; a triggered interface whose solution is not positive is dropped
from the group, as the others unload it below its dynamic level). Every slab above a slipping
interface moves with it (rigid slabs). The slip lasts ``slip_duration``; no other event starts
during it (the drive keeps loading); it stops every creeping interface. Then the slipped
interfaces draw new threshold excesses and their aging clocks restart from ``t_start``.

At t = 0 every slippable interface has just slipped: ``mu_i = mu_d,i``, ``T_i = 0``.
"""

import dataclasses
import math

import numpy as np
import pandas as pd

from ...fixed_order import dot, solve
from ...progress import bar
from .friction import first_crossing

__all__ = ["SlipHistory", "integrate"]

#: Columns of :attr:`SlipHistory.slips`, see :func:`integrate`.
SLIP_COLUMNS = ("event", "t_start", "t_end", "a", "dR", "dF", "dmu", "mu_before", "mu_after", "T", "age",
                "excess", "multi", "triggered", "creep_before")


@dataclasses.dataclass(frozen=True)
class SlipHistory:
    """What the virtual experiment did: initial slips, every fast slip and every creep segment.

    Attributes
    ----------
    R0 : numpy.ndarray
        float64 [n_slabs]: slip of every interface at t = 0 [mm].
    slips : pandas.DataFrame
        One row per interface per slip, columns :data:`SLIP_COLUMNS` (see :func:`integrate`).
    creep : pandas.DataFrame
        One row per creep segment: ``a`` (interface), ``t_on``, ``t_off`` [s], ``velocity`` [mm/s].
    slip_duration : float
        Duration of every slip [s].
    duration : float
        Duration of the run [s].
    """

    R0: np.ndarray
    slips: pd.DataFrame
    creep: pd.DataFrame
    slip_duration: float
    duration: float


def _slip_group(C, mu, target_mu, group):
    """Slips of a group of interfaces that bring each to its target friction coefficient.

    Parameters
    ----------
    C : numpy.ndarray
        Coupling matrix [n_slabs, n_slabs] [1/mm].
    mu, target_mu : numpy.ndarray
        Current and target friction coefficients [n_slabs].
    group : list[int]
        0-based interfaces; the first is the one that reached its strength.

    Returns
    -------
    group : list[int]
        The interfaces that slip: a triggered interface whose solved slip is not positive is
        unloaded below its dynamic level by the others and drops out; if the first one's is
        not positive, it slips alone.
    dR : numpy.ndarray
        Their slips [mm].
    """
    group = list(group)
    while True:
        dR = solve(C[np.ix_(group, group)], mu[group] - target_mu[group])
        if np.all(dR > 0.0) or len(group) == 1:
            return group, dR
        if dR[0] <= 0.0:
            group = group[:1]
        else:
            group = [i for i, d in zip(group, dR) if d > 0.0]


def integrate(apparatus, law, duration, slip_duration, rng):
    """Run the virtual experiment event by event.

    Parameters
    ----------
    apparatus : Apparatus
    law : FrictionLaw
    duration : float
        Length of the run [s].
    slip_duration : float
        Duration of every slip [s] (> 0).
    rng : numpy.random.Generator
        Source of the threshold excesses (one draw per slippable interface at t = 0, then
        one per slipped interface per slip, in increasing interface order).

    Returns
    -------
    SlipHistory
        ``slips`` columns: ``event`` (slip event id; the rows of a simultaneous slip share it),
        ``t_start``, ``t_end`` [s], ``a`` (interface, 1 = lowest), ``dR`` [mm] (its slip),
        ``dF`` [N] (drop of the lever force caused by ``dR``: ``K dR (h/H) sum_{j driven >= a} j``;
        the rows of one event add up to the event's drop), ``dmu`` (drop of ``mu_a`` caused by the
        event's slips, ``mu_before - mu_after``), ``mu_before`` (``mu_a`` at ``t_start``),
        ``mu_after`` (``mu_a`` after the slips, without the drive during the slip: ``mu_d,a``),
        ``T`` [s] (time since the previous slip onset of ``a``; NaN for its first slip), ``age``
        [s] (argument of the aging law: ``T``, or the time since t = 0 for the first slip),
        ``excess`` (threshold excess eps of that stick), ``multi`` (more than one interface
        slipped in the event), ``triggered`` (slipped because within ``trigger_margin`` of its
        strength, not by reaching it), ``creep_before`` [mm] (creep of ``a`` since its previous slip).
    """
    n_slabs = apparatus.n_slabs
    slippable = [i - 1 for i in apparatus.slippable]
    C = apparatus.coupling()
    drive_rates = apparatus.loading_rates()
    unloaded = apparatus.mu(0.0, np.zeros(n_slabs))     # mu at t = 0 with every R = 0
    force_per_slip = apparatus.k_spring * np.cumsum(apparatus.heights[::-1])[::-1] / apparatus.H
    can_creep = (law.creep_velocity > 0.0).tolist()
    mu_d, B = law.mu_d.tolist(), law.B.tolist()

    R0 = apparatus.relaxed_slips(law.mu_d)
    R = R0.copy()
    t = 0.0
    onset = np.zeros(n_slabs)               # onset time of the previous slip (aging clock origin)
    has_slipped = np.zeros(n_slabs, bool)
    excess = np.zeros(n_slabs)
    excess[slippable] = law.draw_excess(rng, len(slippable))
    creeping = np.zeros(n_slabs, bool)
    creep_start = np.zeros(n_slabs)
    creep_since_slip = np.zeros(n_slabs)
    rows, creep_rows = [], []
    event = 0

    report = bar(math.ceil(duration), desc="virtual experiment", unit="s simulated")  # whole seconds

    def stop_creep(at):
        for i in np.flatnonzero(creeping):
            creep_rows.append((i + 1, creep_start[i], at, law.creep_velocity[i]))
        creeping[:] = False

    while t < duration:
        velocity = np.where(creeping, law.creep_velocity, 0.0)
        rates = (drive_rates - dot(C, velocity)).tolist()
        mu = (unloaded + drive_rates * t - dot(C, R)).tolist()
        tau, kind, which = duration - t, "end", -1
        for i in slippable:
            T = t - float(onset[i])
            level, slope = mu_d[i] + float(excess[i]), B[i]
            candidates = [("slip", level, slope)]
            if can_creep[i] and not creeping[i]:
                candidates.append(("creep", mu_d[i] + law.creep_onset * float(excess[i]), law.creep_onset * slope))
            for name, level, slope in candidates:
                reach = first_crossing(mu[i], rates[i], level, slope, T, law.T0)
                if reach < tau:
                    tau, kind, which = reach, name, i
        R += velocity * tau
        creep_since_slip += velocity * tau
        t += tau
        report.update(math.floor(min(t, duration)) - report.n)
        if kind == "end":
            break
        if kind == "creep":
            creeping[which] = True
            creep_start[which] = t
            continue
        stop_creep(t)
        mu = unloaded + drive_rates * t - dot(C, R)
        gap = law.strength(t - onset, excess) - mu
        group = [which] + [i for i in slippable if i != which and gap[i] < law.trigger_margin]
        group, dR = _slip_group(C, mu, law.mu_d, group)
        mu_after = mu - dot(C[:, group], dR)
        for i, d in sorted(zip(group, dR)):
            rows.append((event, t, t + slip_duration, i + 1, d, d * force_per_slip[i], mu[i] - mu_after[i],
                         mu[i], mu_after[i], t - onset[i] if has_slipped[i] else math.nan, t - onset[i],
                         excess[i], len(group) > 1, i != which, creep_since_slip[i]))
        for i in sorted(group):
            R[i] += dR[group.index(i)]
            onset[i] = t
            has_slipped[i] = True
            creep_since_slip[i] = 0.0
            excess[i] = law.draw_excess(rng, 1)[0]
        event += 1
        t += slip_duration
    stop_creep(min(t, duration))
    report.update(report.total - report.n)
    report.close()
    slips = pd.DataFrame(rows, columns=list(SLIP_COLUMNS))
    creep = pd.DataFrame(creep_rows, columns=["a", "t_on", "t_off", "velocity"])
    return SlipHistory(R0=R0, slips=slips, creep=creep, slip_duration=slip_duration, duration=duration)
