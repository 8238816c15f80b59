"""Front velocity and inter-interface delay on synthetic failure tables with known answers."""

import numpy as np
import pandas as pd
import pytest

from stickslip.events import extraction, fronts
from stickslip.plugin_params import ParameterError, parse_params
from test_events_extraction import EVENTS, history

H_BLOCK = np.pi  # block size l0 [FE length]
C_S = np.sqrt(0.5)  # shear-wave speed [FE length / FE time]
SPACING = 40.0 * H_BLOCK  # distance between interface mid-lines [FE length]


def rupture(N, a, *, c_f, nucleation, start, rng, jitter=0.0, nucleation_extent=0.15, nucleation_time=30.0,
            covered=1.0):
    """Failures of one interface: a slow, random nucleation patch, then a ballistic front.

    Blocks within ``nucleation_extent * N/2`` of the nucleation block fail at random times
    in the ``nucleation_time`` after ``start``; beyond, block at periodic distance d first
    fails at ``start + nucleation_time + (d - d_patch) h / (c_f c_s)`` (+ uniform jitter).
    Every block then fails a second time (backwards or forwards) later on. Only the
    fraction ``covered`` of the interface (nearest blocks) is reached.
    """
    blocks = np.arange(N)
    offset = np.abs(blocks - nucleation)
    distance = np.minimum(offset, N - offset)
    patch = nucleation_extent * N / 2
    speed = c_f * C_S / H_BLOCK  # blocks per FE time
    first = np.where(distance <= patch, start + rng.uniform(0, nucleation_time, N),
                     start + nucleation_time + (distance - patch) / speed + rng.uniform(-jitter, jitter, N))
    first[nucleation] = start
    reached = distance <= covered * N / 2
    blocks, first = blocks[reached], first[reached]
    again = first + rng.uniform(1.0, 50.0, blocks.size)
    return pd.DataFrame({
        "a": a,
        "block": np.r_[blocks, blocks],
        "t": np.r_[first, again],
        "direction": np.r_[np.ones(blocks.size, int), rng.choice([-1, 1], blocks.size)],
    })


C_D = fronts.p_wave_speed(4.5, 1.0, 1.0)  # the paper's K = 4.5 G: 2.35 c_s


def test_p_wave_speed_of_the_plane_model():
    assert C_D / C_S == pytest.approx(np.sqrt(5.5))


def test_front_speed_of_a_clean_front_is_exact():
    N = 162
    failures = rupture(N, 1, c_f=2.0, nucleation=3, start=0.0, rng=np.random.default_rng(0))
    fit = fronts.front_fit(failures, 1, N)
    assert fit["nucleation"] == 3 and fit["meeting"] in (83, 84)  # the antipode: 81 blocks either way
    for side in fronts.BRANCHES:
        branch = fit[side]
        assert branch["speed"] * H_BLOCK / C_S == pytest.approx(2.0, rel=1e-10)
        assert branch["quality"] == "ok" and branch["r2"] == pytest.approx(1.0)
        # the fitted front leaves the nucleation block when the patch would have been crossed at c_f
        patch = 0.15 * N / 2
        assert branch["t0"] == pytest.approx(30.0 - patch * H_BLOCK / (2.0 * C_S), rel=1e-10)
    assert fit["right"]["points"] + fit["left"]["points"] == pytest.approx(2 * 0.6 * N / 2, abs=2)


@pytest.mark.parametrize("c_f", [1.0, 2.0, 1.6])
def test_front_speed_with_noisy_arrivals(c_f):
    N = 486
    failures = rupture(N, 2, c_f=c_f, nucleation=400, start=5.0, rng=np.random.default_rng(1), jitter=2.0)
    row = fronts.analyse_event(failures, N, h=H_BLOCK, c_s=C_S, spacing=SPACING, c_d=C_D)
    assert row["fit"] == "ok" and row["c_f"] == pytest.approx(c_f, rel=0.02)
    assert row["c_f_left"] == pytest.approx(c_f, rel=0.02) and row["c_f_right"] == pytest.approx(c_f, rel=0.02)


def test_two_branches_of_different_speed_and_origin_meet_where_they_arrive_together():
    """Right branch at 1.8 c_s from block 100, left at 1.2 c_s from block 90, 20 time units later."""
    N = 486
    rng = np.random.default_rng(4)
    blocks = np.arange(N)
    right, left = np.mod(blocks - 100, N), np.mod(90 - blocks, N)
    t_right = 10.0 + right * H_BLOCK / (1.8 * C_S)
    t_left = 30.0 + left * H_BLOCK / (1.2 * C_S)
    first = np.minimum(t_right, t_left)
    first[91:100] = rng.uniform(0.0, 8.0, 9)  # the nucleation patch between the two origins
    first[95] = 0.0
    first[300] += 500.0  # a block the front passed that failed only much later: not the meeting point
    first[350] -= 150.0  # a block that failed early by itself, ahead of the front
    failures = pd.DataFrame({"a": 1, "block": blocks, "t": first, "direction": 1})
    fit = fronts.front_fit(failures, 1, N, c_max=C_D / H_BLOCK)
    meeting = int(np.argmax(np.where(np.arange(N) == 300, 0.0, first)))
    assert fit["nucleation"] == 95 and abs(fit["meeting"] - meeting) <= 1
    assert fit["right"]["speed"] * H_BLOCK / C_S == pytest.approx(1.8, rel=1e-3)
    assert fit["left"]["speed"] * H_BLOCK / C_S == pytest.approx(1.2, rel=1e-3)
    assert fit["right"]["quality"] == fit["left"]["quality"] == "ok"


def test_meaningless_fits_are_flagged_and_not_averaged():
    N = 162
    # every block fails within one time unit: a "front" of tens of c_s, faster than any wave
    at_once = pd.DataFrame({"a": 1, "block": np.arange(N), "direction": 1,
                            "t": np.r_[0.0, np.random.default_rng(5).uniform(0.5, 1.5, N - 1)]})
    row = fronts.analyse_event(at_once, N, h=H_BLOCK, c_s=C_S, spacing=SPACING, c_d=C_D)
    assert np.isnan(row["c_f"]) and row["fit"] != "ok"
    assert {row["quality_left"], row["quality_right"]} <= {"faster than P waves", "not ballistic", "no front"}
    # a short interface: too few blocks in the fitted window
    short = rupture(12, 1, c_f=2.0, nucleation=0, start=0.0, rng=np.random.default_rng(6))
    row = fronts.analyse_event(short, 12, h=H_BLOCK, c_s=C_S, spacing=SPACING, c_d=C_D)
    assert row["quality_left"] == row["quality_right"] == "few points" and np.isnan(row["c_f"])
    assert row["fit"] == "right: few points; left: few points"
    # one good branch at 1.5 c_s, the other no line at all (blocks failing at random): c_f is the good one alone
    blocks = np.arange(N)
    right = np.mod(blocks - 40, N)
    first = np.where(right <= N // 2, right * H_BLOCK / (1.5 * C_S), np.random.default_rng(8).uniform(0, 150, N))
    failures = pd.DataFrame({"a": 1, "block": blocks, "t": first, "direction": 1})
    row = fronts.analyse_event(failures, N, h=H_BLOCK, c_s=C_S, spacing=SPACING, c_d=C_D)
    assert row["quality_right"] == "ok" and row["quality_left"] != "ok" and row["fit"] == "ok"
    assert row["c_f"] == row["c_f_right"] == pytest.approx(1.5, rel=1e-6)


def test_delay_between_first_and_second_slipping_interface():
    N, tau = 162, 37.5  # FE time
    rng = np.random.default_rng(2)
    failures = pd.concat([
        rupture(N, 2, c_f=2.0, nucleation=10, start=3.0, rng=rng),  # first to slip: the upper interface
        rupture(N, 1, c_f=2.0, nucleation=90, start=3.0 + tau, rng=rng),
        rupture(N, 3, c_f=2.0, nucleation=50, start=1.0, rng=rng, covered=0.5),  # active first, never slips
    ], ignore_index=True)
    assert fronts.slipping_interfaces(failures, N) == [(2, 3.0), (1, 3.0 + tau)]
    row = fronts.analyse_event(failures, N, h=H_BLOCK, c_s=C_S, spacing=SPACING)
    assert (row["s"], row["a_first"], row["a_second"], row["nucleation"]) == (2, 2, 1, 10)
    assert row["fit"] == "ok"
    assert row["tau"] == pytest.approx(tau * C_S / SPACING, rel=1e-12)
    assert row["c_f"] == pytest.approx(2.0, rel=1e-10)
    assert row["t_first"] == 1.0


def test_single_slipping_interface_has_no_delay():
    N = 54
    failures = rupture(N, 1, c_f=2.0, nucleation=0, start=0.0, rng=np.random.default_rng(3))
    row = fronts.analyse_event(failures, N, h=H_BLOCK, c_s=C_S, spacing=SPACING)
    assert row["s"] == 1 and row["a_second"] == 0 and np.isnan(row["tau"])


def test_front_tables_rerun_the_steady_multi_slips(tmp_path):
    N = 9
    classified = extraction.classify_increments(history(N, EVENTS), N)
    asked = []

    def rerun(increment):
        asked.append(increment)
        rng = np.random.default_rng(increment)
        return pd.concat([rupture(N, 1, c_f=2.0, nucleation=4, start=0.0, rng=rng, nucleation_extent=0.0),
                          rupture(N, 2, c_f=2.0, nucleation=1, start=float(increment), rng=rng)])

    params = parse_params(fronts.FrontParams, {"max_events": 2})
    failures, table = fronts.front_tables(classified, rerun, N=N, h=H_BLOCK, c_s=C_S, spacing=SPACING, params=params)
    assert asked == [14, 16]  # steady-state multi-slips: 14, 16, 24; the first two
    assert table["increment"].tolist() == [14, 16]
    np.testing.assert_allclose(table["tau"], np.array([14.0, 16.0]) * C_S / SPACING)
    assert (table["a_first"] == 1).all() and (table["s"] == 2).all()
    assert list(failures.columns) == ["increment", "a", "block", "t", "direction"]
    assert len(failures) == 2 * 2 * 2 * N
    assert failures.groupby("increment")["t"].apply(lambda t: t.is_monotonic_increasing).all()
    # every slip event, single slips too
    asked.clear()
    fronts.front_tables(classified, rerun, N=N, h=H_BLOCK, c_s=C_S, spacing=SPACING,
                        params=parse_params(fronts.FrontParams, {"events": "slip", "max_events": 3}))
    assert asked == [8, 12, 14]
    # runs with another number of interfaces are not re-run
    asked.clear()
    params = parse_params(fronts.FrontParams, {"interfaces": 3})
    failures, table = fronts.front_tables(classified, rerun, N=N, h=H_BLOCK, c_s=C_S, spacing=SPACING, params=params)
    assert asked == [] and failures.empty and table.empty
    assert failures.dtypes["t"] == np.float64 and table.dtypes["tau"] == np.float64


def test_fit_window_must_not_be_empty():
    with pytest.raises(ParameterError, match="fit_from"):
        parse_params(fronts.FrontParams, {"fit_from": 0.8, "fit_to": 0.5})


def test_interface_spacing_from_layer_heights():
    assert fronts.interface_spacing([3.0, 11.0]) == 8.0
    assert np.isnan(fronts.interface_spacing([3.0]))
