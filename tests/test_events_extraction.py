"""Event extraction on synthetic increment tables with known answers.

:func:`history` builds the table a quasistatic ``fem`` run would give for a scripted
sequence of events, :func:`run_attrs` the header of its file; other test modules import them.
"""

import numpy as np
import pandas as pd
import pytest

from stickslip.events import extraction as ex
from stickslip.fem.stiffness import driving_regime, stiffness_ratio
from stickslip.h5io import FileFormatError


def history(N, events, *, load_gamma=1.0, elastic_modulus=1.0):
    """Increment table of a scripted event sequence.

    Increment 0 is the unloaded state; then every event is one elastic load step (gamma,
    epsd, every interface stress mu_a and Sigma grow by ``load_gamma``,
    ``elastic_modulus * load_gamma``) followed by one kick increment in which interface a has
    ``A[a - 1]`` blocks in another well and its stress drops by ``drop[a - 1]``; Sigma drops by
    the mean drop.

    Parameters
    ----------
    N : int
    events : list[tuple[tuple[int, ...], tuple[float, ...]]]
        (A per interface, stress drop per interface) of each kick.

    Returns
    -------
    pandas.DataFrame
    """
    n = len(events[0][0])
    gamma = epsd = sigd = 0.0
    mu = np.zeros(n)
    rows = [dict(increment=0, kick=True, gamma=0.0, epsd=0.0, sigd=0.0, A=(0,) * n, mu=mu.copy())]
    for A, drop in events:
        gamma += load_gamma
        epsd += load_gamma
        sigd += elastic_modulus * load_gamma
        mu += elastic_modulus * load_gamma
        rows.append(dict(increment=len(rows), kick=False, gamma=gamma, epsd=epsd, sigd=sigd, A=(0,) * n, mu=mu.copy()))
        mu -= np.asarray(drop, dtype=float)
        sigd -= float(np.mean(drop))
        rows.append(dict(increment=len(rows), kick=True, gamma=gamma, epsd=epsd, sigd=sigd, A=tuple(A), mu=mu.copy()))
    table = pd.DataFrame({k: [r[k] for r in rows] for k in ("increment", "kick", "gamma", "epsd", "sigd")})
    table["yield_element"] = False
    table["t"] = np.arange(len(rows), dtype=float)
    for a in range(1, n + 1):
        table[f"S_a{a}"] = [r["A"][a - 1] for r in rows]
        table[f"A_a{a}"] = [r["A"][a - 1] for r in rows]
    for layer in range(2 * n + 1):
        values = [r["mu"][(layer - 1) // 2] if layer % 2 else r["sigd"] for r in rows]
        table[f"sigd_{layer}"] = values
        table[f"epsd_{layer}"] = table["epsd"]
    return table


def run_attrs(N, plates, k_drive, **further):
    """Root attributes of a synthetic ``fem`` run file: its typed header with ``phi`` and ``regime``
    as the solver states them (:mod:`stickslip.fem.stiffness`), then ``further``."""
    phi = stiffness_ratio(k_drive, N)
    return {"N": N, "plates": plates, "n_interfaces": plates - 1, "k_drive": k_drive, "phi": phi,
            "regime": driving_regime(phi), **further}


N = 9
MICRO = ((3, 0), (0.0, 0.0))
SLIP1 = ((N, 2), (1.5, 0.0))
SLIP2 = ((1, N), (0.0, 2.5))
MULTI = ((N, N), (1.0, 2.0))
#: Two interfaces: a transient (micro, slip of 1, micro, slip of 2), then the steady state.
EVENTS = [MICRO, SLIP1, MICRO, SLIP2, MICRO, SLIP1, MULTI, MULTI, SLIP2, MICRO, SLIP1, MULTI]


def test_kinds_of_every_increment():
    table = ex.classify_increments(history(N, EVENTS), N)
    kicks = table[table["kick"]]["kind"].tolist()
    assert kicks[0] == "initial"  # increment 0: the unloaded state
    assert kicks[1:] == ["micro", "single", "micro", "single", "micro", "single", "multi", "multi",
                         "single", "micro", "single", "multi"]
    assert (table[~table["kick"]]["kind"] == "load").all()
    assert table["s"].tolist()[14] == 2 and table["s"].tolist()[12] == 1
    np.testing.assert_allclose(table["mu_a2"], history(N, EVENTS)["sigd_3"])


def test_steady_state_waits_for_every_interface_to_slip():
    table = history(N, EVENTS)
    # interface 2 first slips at the 4th event: kick increment 8; the curve has softened by then
    assert ex.steady_state(table, N) == 8
    classified = ex.classify_increments(table, N)
    assert classified["steady"].tolist() == [i >= 8 for i in range(len(table))]


def test_steady_state_waits_for_the_stress_strain_curve_to_soften():
    # both interfaces slip from the first kick, but with tiny drops: the secant slope
    # (sigd - sigd0)/(epsd - epsd0) = 1 - 0.01 k / k stays above 0.95 until the large drop
    # of the 4th kick (increment 8): (4 - 0.03 - 0.3) / 4 = 0.9175
    events = [((N, N), (0.01, 0.01))] * 3 + [((N, N), (0.3, 0.3))] * 3
    table = history(N, events)
    assert ex.steady_state(table, N) == 8
    # three times stiffer: the same drops soften the curve only at the 6th kick, 17.07 / 18 = 0.948
    assert ex.steady_state(history(N, events, elastic_modulus=3.0), N) == 12



def test_no_steady_state_without_softening_or_without_a_slip_everywhere():
    assert ex.steady_state(history(N, [SLIP1] * 6), N) is None  # interface 2 never slips
    assert ex.steady_state(history(N, [MICRO] * 6), N) is None
    classified = ex.classify_increments(history(N, [SLIP1] * 6), N)
    assert not classified["steady"].any()
    assert ex.steady_slips(classified, N).empty


def test_slip_events_and_their_interfaces():
    classified = ex.classify_increments(history(N, EVENTS), N)
    slips = ex.steady_slips(classified, N)
    # steady state from increment 8: SLIP2, SLIP1, MULTI, MULTI, SLIP2, SLIP1, MULTI
    assert slips["increment"].tolist() == [8, 12, 14, 16, 18, 22, 24]
    assert slips["interfaces"].tolist() == ["2", "1", "1,2", "1,2", "2", "1", "1,2"]
    assert slips["s"].tolist() == [1, 1, 2, 2, 1, 1, 2]
    assert slips["multi"].tolist() == [False, False, True, True, False, False, True]
    np.testing.assert_allclose(slips["gamma"], [4, 6, 7, 8, 9, 11, 12])
    np.testing.assert_allclose(slips["dsigma"], [1.25, 0.75, 1.5, 1.5, 1.25, 0.75, 1.5])
    np.testing.assert_allclose(slips["sigma_before"] - slips["sigma_after"], slips["dsigma"])


def test_stress_drop_and_shear_since_the_previous_slip_of_the_same_interface():
    classified = ex.classify_increments(history(N, EVENTS), N)
    per = ex.slip_interfaces(classified, N)
    one = per[per["interface"] == 1]
    two = per[per["interface"] == 2]
    assert one["increment"].tolist() == [12, 14, 16, 22, 24]
    np.testing.assert_allclose(one["dmu_sig0"], [1.5, 1.0, 1.0, 1.5, 1.0])
    # gamma of interface-1 slips: 6, 7, 8, 11, 12 (multi-slips count, the transient slip at 2 does not)
    np.testing.assert_allclose(one["dgamma"], [np.nan, 1, 1, 3, 1])
    assert one["multi"].tolist() == [False, True, True, False, True]
    assert two["increment"].tolist() == [8, 14, 16, 18, 24]
    np.testing.assert_allclose(two["dmu_sig0"], [2.5, 2.0, 2.0, 2.5, 2.0])
    np.testing.assert_allclose(two["dgamma"], [np.nan, 3, 1, 1, 3])
    assert per["increment"].is_monotonic_increasing


def test_rho_of_s():
    classified = ex.classify_increments(history(N, EVENTS), N)
    slips = ex.steady_slips(classified, N)
    np.testing.assert_allclose(ex.slip_fractions(slips, 2), [4 / 7, 3 / 7])
    np.testing.assert_allclose(ex.slip_fractions(slips, 3), [4 / 7, 3 / 7, 0])
    assert np.isnan(ex.slip_fractions(slips.iloc[:0], 2)).all()


def test_sequences_of_single_and_multi_slips():
    classified = ex.classify_increments(history(N, EVENTS), N)
    sequences = ex.slip_sequences(ex.steady_slips(classified, N))
    # single, single | multi, multi | single, single | multi
    assert sequences["kind"].tolist() == ["single", "multi", "single", "multi"]
    assert sequences["length"].tolist() == [2, 2, 2, 1]
    assert sequences["first_increment"].tolist() == [8, 14, 18, 24]
    assert sequences["last_increment"].tolist() == [12, 16, 22, 24]
    fractions = ex.sequence_fractions(sequences)
    assert fractions == pytest.approx({"single": 4 / 7, "multi": 2 / 7, "any": 6 / 7})
    # pooling runs: concatenated tables give the pooled fractions
    pooled = ex.sequence_fractions(pd.concat([sequences, sequences.iloc[3:]]))
    assert pooled == pytest.approx({"single": 4 / 8, "multi": 2 / 8, "any": 6 / 8})


def test_alternating_slips_form_no_sequence():
    events = [SLIP1, MULTI] * 4  # steady from the first multi-slip
    sequences = ex.slip_sequences(ex.steady_slips(ex.classify_increments(history(N, events), N), N))
    assert (sequences["length"] == 1).all()
    assert ex.sequence_fractions(sequences) == {"single": 0, "multi": 0, "any": 0}


def test_bad_tables_are_refused_with_the_column_named():
    table = history(N, EVENTS)
    with pytest.raises(FileFormatError, match="sigd_3"):
        ex.classify_increments(table.drop(columns="sigd_3"), N, source="run.h5")
    with pytest.raises(FileFormatError, match="consecutive"):
        ex.classify_increments(table.drop(index=5), N)
    with pytest.raises(FileFormatError, match="S_a"):
        ex.interfaces_in(table[["increment", "gamma"]])
