"""Event extraction for quasistatic ``fem`` runs: one row per stored increment in, events out.

Definitions follow the paper's section "Numerical results" and the reference code
(shared/reference-model.md, section 10):

- A *kick* increment (a minimal kick followed by energy minimisation) is an event; an
  elastic load step is not. Every kick makes at least one block yield.
- Interface ``a`` *slips* in an event when every one of its ``N`` blocks is in another
  well after the event than before it: ``A_a == N``, with ``A_a`` counted between the two
  stored increments that bracket the kick. (The paper says "every block yields at least
  once"; a block that yields and comes back to its well is not counted by ``A_a``. This
  is the reference code's criterion; :mod:`stickslip.events.fronts` uses the paper's
  from the time-resolved re-run.)
- A *slip event* has ``s >= 1`` slipping interfaces: *single-slip* if ``s == 1``,
  *multi-slip* if ``s > 1``; any other kick is a *microscopic event*.
- Statistics use the steady state only (:func:`steady_state`).

Units: ``gamma`` in gamma0 (the lever rotation that yields a typical block of the first
interface), stresses in sig0 (the typical yield stress), as in the solver's table.
"""

import re

import numpy as np
import pandas as pd

from ..h5io import FileFormatError
from ..mesh.layered import interface_layer

__all__ = [
    "interfaces_in",
    "steady_state",
    "classify_increments",
    "steady_slips",
    "slip_interfaces",
    "slip_fractions",
    "slip_sequences",
    "sequence_fractions",
]

#: Steady state: the secant modulus of the stress-strain curve has dropped below this
#: fraction of the elastic one (reference code).
TANGENT_FRACTION = 0.95

_S_COLUMN = re.compile(r"^S_a(\d+)$")


def interfaces_in(increments, source="increment table"):
    """Return the interface numbers ``a = 1 ... n`` present in an increment table.

    Parameters
    ----------
    increments : pandas.DataFrame
        Table with columns ``S_a<a>`` (one per interface).
    source : str, optional
        Name of the table's origin, for error messages.

    Returns
    -------
    list[int]
        Sorted interface numbers.
    """
    found = sorted(int(m.group(1)) for c in increments.columns if (m := _S_COLUMN.match(str(c))))
    if not found:
        raise FileFormatError(f"{source}: increment table has no interface columns 'S_a<a>'")
    return found


def _check_table(increments, interfaces, source):
    required = ["increment", "kick", "gamma", "epsd", "sigd"]
    for a in interfaces:
        required += [f"S_a{a}", f"A_a{a}", f"sigd_{interface_layer(a)}"]
    missing = [c for c in required if c not in increments.columns]
    if missing:
        raise FileFormatError(f"{source}: increment table lacks column(s) {', '.join(missing)}")
    inc = increments["increment"].to_numpy()
    if inc.size == 0 or not np.array_equal(inc, np.arange(inc[0], inc[0] + inc.size)):
        raise FileFormatError(f"{source}: column 'increment' must hold consecutive increments, got {inc[:5]}...")


def _slipping(increments, interfaces, N):
    """Return a boolean [ninc, n] array: interface slipped (``A_a == N``) in a kick increment."""
    A = increments[[f"A_a{a}" for a in interfaces]].to_numpy()
    return (A == N) & increments["kick"].to_numpy(dtype=bool)[:, None]


def steady_state(increments, N):
    """Return the first increment of the steady state, or None if it is not reached.

    The steady state starts at the latest of: increment 2; the first increment at which
    the secant slope ``(sigd - sigd[0]) / (epsd - epsd[0])`` is at most 0.95 times that of
    increment 1 (the elastic slope); the first increment by which every interface has slipped
    at least once.

    The reference code uses "every block is in another well than at increment 0" as the last
    condition; a per-increment table cannot tell which blocks moved, so a slip of every
    interface (which implies it) stands in for it. It may start the steady state a little later,
    never earlier.

    Parameters
    ----------
    increments : pandas.DataFrame
        Increment table (columns ``increment``, ``kick``, ``epsd``, ``sigd`` [eps0, sig0],
        ``A_a<a>``), consecutive increments from 0.
    N : int
        Blocks per interface.

    Returns
    -------
    int or None
    """
    interfaces = interfaces_in(increments)
    _check_table(increments, interfaces, "increment table")
    epsd = increments["epsd"].to_numpy(dtype=float)
    sigd = increments["sigd"].to_numpy(dtype=float)
    if epsd.size < 3:
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        secant = (sigd[1:] - sigd[0]) / (epsd[1:] - epsd[0])
    softened = np.flatnonzero(secant <= TANGENT_FRACTION * secant[0])
    everyone_slipped = np.logical_or.accumulate(_slipping(increments, interfaces, N), axis=0).all(axis=1)
    if softened.size == 0 or not everyone_slipped.any():
        return None
    rows = max(2, int(softened[0]) + 1, int(np.argmax(everyone_slipped)))
    return int(increments["increment"].iloc[rows])


def classify_increments(increments, N, *, source="increment table"):
    """Classify every increment and add the per-interface stresses.

    Parameters
    ----------
    increments : pandas.DataFrame
        The solver's increment table (see :func:`stickslip.formats.fem_run.read_increments`):
        ``increment``, ``kick``, ``gamma`` [gamma0], ``epsd`` [eps0], ``sigd`` [sig0], per
        interface ``S_a<a>``, ``A_a<a>`` and per layer ``sigd_<l>`` [sig0], consecutive
        increments from 0.
    N : int
        Blocks per interface.
    source : str, optional
        Name of the table's origin, for error messages.

    Returns
    -------
    pandas.DataFrame
        One row per increment: ``increment``, ``kick``, ``gamma``, ``epsd``, ``sigd``,
        per interface ``S_a<a>``, ``A_a<a>``, ``mu_a<a>`` (volume-averaged equivalent stress
        of interface a [sig0]), then ``s`` (number of slipping interfaces), ``kind``
        ("initial" for increment 0, "load", "micro", "single" or "multi") and ``steady`` (bool: at or after the steady
        state).
    """
    interfaces = interfaces_in(increments, source)
    _check_table(increments, interfaces, source)
    out = pd.DataFrame({c: increments[c].to_numpy() for c in ("increment", "kick", "gamma", "epsd", "sigd")})
    out["kick"] = out["kick"].astype(bool)
    for a in interfaces:
        out[f"S_a{a}"] = increments[f"S_a{a}"].to_numpy(dtype=np.int64)
        out[f"A_a{a}"] = increments[f"A_a{a}"].to_numpy(dtype=np.int64)
    for a in interfaces:
        out[f"mu_a{a}"] = increments[f"sigd_{interface_layer(a)}"].to_numpy(dtype=float)
    s = _slipping(increments, interfaces, N).sum(axis=1)
    out["s"] = s.astype(np.int64)
    kind = np.where(s > 1, "multi", np.where(s == 1, "single", "micro"))
    kind = np.where(out["kick"].to_numpy(), kind, "load").astype(object)
    kind[out["increment"].to_numpy() == 0] = "initial"
    out["kind"] = kind
    start = steady_state(increments, N)
    out["steady"] = out["increment"].to_numpy() >= start if start is not None else False
    return out


def _slip_rows(classified):
    return classified["kind"].isin(("single", "multi")).to_numpy() & classified["steady"].to_numpy(dtype=bool)


def steady_slips(classified, N):
    """Return the slip events of the steady state, one row each.

    Parameters
    ----------
    classified : pandas.DataFrame
        Output of :func:`classify_increments`.
    N : int
        Blocks per interface.

    Returns
    -------
    pandas.DataFrame
        Columns ``increment``, ``gamma`` [gamma0], ``s`` (number of slipping interfaces),
        ``interfaces`` (e.g. "1,3"), ``multi`` (bool: s > 1), ``sigma_before``,
        ``sigma_after`` (macroscopic stress Sigma before the kick and after minimisation
        [sig0]) and ``dsigma`` (their difference [sig0]).
    """
    interfaces = interfaces_in(classified)
    rows = np.flatnonzero(_slip_rows(classified))
    slipping = classified[[f"A_a{a}" for a in interfaces]].to_numpy() == N
    names = [",".join(str(a) for a, slipped in zip(interfaces, slipping[r]) if slipped) for r in rows]
    sigd = classified["sigd"].to_numpy(dtype=float)
    before = sigd[rows - 1]
    return pd.DataFrame({
        "increment": classified["increment"].to_numpy()[rows],
        "gamma": classified["gamma"].to_numpy(dtype=float)[rows],
        "s": classified["s"].to_numpy()[rows],
        "interfaces": np.asarray(names, dtype=object),
        "multi": classified["s"].to_numpy()[rows] > 1,
        "sigma_before": before,
        "sigma_after": sigd[rows],
        "dsigma": before - sigd[rows],
    })


def slip_interfaces(classified, N):
    """Return one row per (steady-state slip event, slipping interface).

    Parameters
    ----------
    classified : pandas.DataFrame
        Output of :func:`classify_increments`.
    N : int
        Blocks per interface.

    Returns
    -------
    pandas.DataFrame
        Columns ``increment``, ``interface`` (a), ``dmu_sig0`` (stress drop of interface a: its
        volume-averaged equivalent stress before the kick minus after minimisation [sig0]),
        ``dgamma`` (lever rotation since the previous steady-state slip involving interface a
        [gamma0]; NaN for the first) and ``multi`` (bool: more than one interface slipped in the event).
        Sorted by increment, then interface.
    """
    interfaces = interfaces_in(classified)
    steady_slips = _slip_rows(classified)
    gamma = classified["gamma"].to_numpy(dtype=float)
    increment = classified["increment"].to_numpy()
    multi = classified["s"].to_numpy() > 1
    parts = []
    for a in interfaces:
        rows = np.flatnonzero(steady_slips & (classified[f"A_a{a}"].to_numpy() == N))
        mu = classified[f"mu_a{a}"].to_numpy(dtype=float)
        dgamma = np.full(rows.size, np.nan)
        dgamma[1:] = np.diff(gamma[rows])
        parts.append(pd.DataFrame({"increment": increment[rows], "interface": np.full(rows.size, a, dtype=np.int64),
                                   "dmu_sig0": mu[rows - 1] - mu[rows], "dgamma": dgamma, "multi": multi[rows]}))
    table = pd.concat(parts, ignore_index=True)
    return table.sort_values(["increment", "interface"], kind="stable").reset_index(drop=True)


def slip_fractions(slips, n):
    """Return rho(s): the fraction of slip events that involve s = 1 ... n interfaces.

    Parameters
    ----------
    slips : pandas.DataFrame
        Slip events (column ``s``), e.g. of :func:`steady_slips`; several runs may be
        concatenated.
    n : int
        Number of interfaces.

    Returns
    -------
    numpy.ndarray
        Shape [n]; entry s - 1 is rho(s). NaN everywhere if there is no slip event.
    """
    counts = np.bincount(slips["s"].to_numpy(dtype=np.int64), minlength=n + 1)[1:n + 1].astype(float)
    total = counts.sum()
    return counts / total if total > 0 else np.full(n, np.nan)


def slip_sequences(slips):
    """Split the slip events into maximal runs of consecutive single- or multi-slip events.

    Microscopic events between slips do not interrupt a run.

    Parameters
    ----------
    slips : pandas.DataFrame
        Slip events of one simulation in order (columns ``increment``, ``multi``).

    Returns
    -------
    pandas.DataFrame
        One row per run: ``first_increment``, ``last_increment``, ``kind`` ("single" or
        "multi") and ``length`` (number of slip events). A run of length >= 2 is a sequence.
    """
    single = ~slips["multi"].to_numpy(dtype=bool)
    increment = slips["increment"].to_numpy()
    starts = np.flatnonzero(np.r_[True, single[1:] != single[:-1]])[:single.size]
    ends = np.r_[starts[1:], single.size][:starts.size] - 1
    return pd.DataFrame({
        "first_increment": increment[starts],
        "last_increment": increment[ends],
        "kind": np.asarray(np.where(single[starts], "single", "multi"), dtype=object),
        "length": (ends - starts + 1).astype(np.int64),
    })


def sequence_fractions(sequences):
    """Return the fractions of slip events that are part of a sequence (>= 2 in a row).

    Parameters
    ----------
    sequences : pandas.DataFrame
        Output of :func:`slip_sequences`; tables of several runs may be concatenated.

    Returns
    -------
    dict[str, float]
        ``"single"``: fraction of all slip events that belong to a sequence of single
        slips; ``"multi"``: to a sequence of multi-slips; ``"any"``: their sum. NaN if
        there is no slip event.
    """
    length = sequences["length"].to_numpy(dtype=np.int64)
    total = length.sum()
    if total == 0:
        return {"single": np.nan, "multi": np.nan, "any": np.nan}
    in_sequence = length >= 2
    fractions = {kind: length[in_sequence & (sequences["kind"].to_numpy() == kind)].sum() / total
                 for kind in ("single", "multi")}
    fractions["any"] = fractions["single"] + fractions["multi"]
    return fractions
