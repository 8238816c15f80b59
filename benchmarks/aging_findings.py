"""What junction aging does in the fem model: the numbers of docs/numerical-analysis.md, "Junction aging".

    python benchmarks/aging_findings.py results/aging

Reads the aging study's ``thermal-events`` outputs (``STUDY/events/thermal-events/fem/*.h5``) and its runs
(``STUDY/sim/fem/*.h5``) with :mod:`stickslip.summaries.aging_summary` and prints, each with the states, slips or
holds behind it (standard errors over the states of paired hold trials, pooled over the seeds):

1. per run: events (hops, athermal kicks, redraw events), junction redraws, steady-state slips, peak and drop;
2. the paired holds at n = 1: the slope of the peak in ln T_w (T_w >= 1e6) per setting (lambda, T, aging off),
   its curvature, the ratios lambda x 2 and T x 2 against the base, one block's strengthening (the widening of
   the junctions at the peak) and the collective factor, the second slip after the hold (memory), the
   steady-state peak against the drive rate;
3. the paper's estimator on the stacks n = 1, 2, 3 with aging and without: the fits through the origin and
   with an intercept per n and per interface beside the true B of the paired holds; the spread of T_a, std(B_a)
   and R_slow per interface;
4. aftershocks: events per interface in the holds after slips and in the controls, Omori-Utsu fits; in the
   driven runs, the time and the drive from a slip to the next event per pair of interfaces at two drive rates;
5. aging against the hold load: the slope per ``below``, the held stress, the precursors before the peak (base);
   the slope per ``below`` of the other settings and its ratio to the base's at the same load.
"""

import argparse
import glob
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from stickslip.summaries.aging_summary import (aftershock_pairs, curvature, driven_aftershocks, estimator, load_aging_runs,
                                            mean_sem, paired_slopes, rate_slope, ratio, select_runs, trial_peaks)
from stickslip.experiment.aging import spread_of_aging_rate
from stickslip.formats.fem_run import read_increments

BASE = {"n": 1, "temperature": 1e-3, "drive_rate": 2e-8, "strengthening": 5.0}

#: The n = 1 settings of the paired holds: the base and the base with lambda or T doubled, or aging off.
SETTINGS = {"base (lambda 5, T 1e-3)": BASE, "lambda 10": {**BASE, "strengthening": 10.0},
            "T 2e-3": {**BASE, "temperature": 2e-3}, "aging off": {**BASE, "strengthening": 0.0}}


def fmt(value, error, digits=4):
    return f"{value:.{digits}f} ± {error:.{digits}f}"


def runs_summary(runs, study):
    print("## Runs")
    for _, run in runs.sort_values(["n", "strengthening", "temperature", "drive_rate", "seed"]).iterrows():
        table = read_increments(Path(study) / "sim" / "fem" / Path(run["file"]).name)
        events = table[table["kick"]].iloc[1:]
        hops = int((events["hop_block"] >= 0).sum())
        redrawn = int((events["redraw_block"] >= 0).sum()) if "redraw_block" in events else 0
        slips = run["data"].tables["slip_events"]
        print(f"- n = {run['n']}, lambda = {run['strengthening']:g}, T = {run['temperature']:g}, rate "
              f"{run['drive_rate']:g}, seed {run['seed']}: {len(events)} events ({hops} hops, {redrawn} redraw events, "
              f"{len(events) - hops - redrawn} athermal kicks), "
              f"{int(table['redraws'].sum()) if 'redraws' in table else 0} junction redraws, {len(slips)} steady-state "
              f"slips, peak {fmt(*mean_sem(slips['mu_before_sig0'])[:2], 3)}, drop "
              f"{fmt(*mean_sem(slips['dmu_sig0'])[:2], 3)} sig0")


def holds_summary(runs):
    print("\n## Paired holds, n = 1 (slope of the first-slip peak in ln T_w, T_w >= 1e6, below = 0.02)")
    slopes = {}
    for name, where in SETTINGS.items():
        peaks = trial_peaks(select_runs(runs, **where))
        if peaks.empty:
            continue
        peaks = peaks[np.isclose(peaks["below"], 0.02)]
        slope, error, states = paired_slopes(peaks)
        widening = paired_slopes(peaks, "widening")
        bend, bend_error = curvature(peaks)
        second = paired_slopes(trial_peaks(select_runs(runs, **where), slip=2).query("below == 0.02"))
        failed = peaks.drop_duplicates(["run", "state", "hold_time"])["failed_in_hold"].mean()
        slopes[name] = (slope, error, widening)
        lam, T = where["strengthening"], where["temperature"]
        print(f"- {name}: slope {fmt(slope, error)} sig0 per e-fold ({states} states, {slope / error:.1f} standard "
              f"errors); curvature {fmt(bend, bend_error, 5)}; failed in the hold {failed:.2f}; one block's "
              f"strengthening (widening at the peak) {fmt(widening[0], widening[1])} eps0 per e-fold (lambda T = "
              f"{lam * T:.4f}); collective factor slope / widening slope "
              + (f"{fmt(*ratio(slope, error, widening[0], widening[1]), 2)}" if lam else "-")
              + f"; second slip after the hold: slope {fmt(*second[:2])} ({second[2]} states)")
    base = slopes.get("base (lambda 5, T 1e-3)")
    for name in ("lambda 10", "T 2e-3"):
        if base and name in slopes:
            print(f"- {name} / base: {fmt(*ratio(slopes[name][0], slopes[name][1], base[0], base[1]), 2)} "
                  f"(the mechanism: 2)")
    table, slope, error = rate_slope(select_runs(runs, n=1, temperature=1e-3, strengthening=5.0))
    print("- steady-state peak against the drive rate (aging on): "
          + ", ".join(f"{row.drive_rate:g}: {fmt(row.peak, row.sem, 3)} ({row.slips})" for row in table.itertuples())
          + f"; slope {fmt(slope, error)} sig0 per e-fold of rate (negative: velocity weakening, a - b < 0)")
    off = select_runs(runs, n=1, temperature=1e-3, strengthening=0.0, drive_rate=2e-8)
    if len(off):
        peaks = np.concatenate([item.tables["slip_events"]["mu_before_sig0"].to_numpy() for item in off["data"]])
        print(f"- aging off at 2e-8: steady-state peak {fmt(*mean_sem(peaks)[:2], 3)} ({len(peaks)} slips)")


def loads_summary(runs):
    print("\n## Aging against the hold load (base runs; then the other settings, their ratio to the base at each load)")
    peaks = trial_peaks(select_runs(runs, **BASE))
    if peaks.empty:
        return
    base = {}
    for below, part in peaks.groupby("below"):
        slope, error, states = base[below] = paired_slopes(part)
        stress = mean_sem(part.drop_duplicates(["run", "state"])["mu_start"])
        held = part["hold_time"] >= 1e6
        print(f"- below {below:g} eps0: held stress {fmt(*stress[:2], 3)} sig0; slope {fmt(slope, error)} ({states} "
              f"states); precursors before the first peak {fmt(*mean_sem(part['precursors'])[:2], 3)} of the blocks "
              f"(holds >= 1e6: {fmt(*mean_sem(part.loc[held, 'precursors'])[:2], 3)}); failed in the hold "
              f"{part.drop_duplicates(['run', 'state', 'hold_time'])['failed_in_hold'].mean():.2f}")
    for name, where in list(SETTINGS.items())[1:]:
        others = trial_peaks(select_runs(runs, **where))
        for below, part in (others.groupby("below") if not others.empty else []):
            slope, error, states = paired_slopes(part)
            against = (f"{fmt(*ratio(slope, error, *base[below][:2]), 2)}" if below in base and where["strengthening"]
                       else "-")
            print(f"  {name}, below {below:g} eps0: slope {fmt(slope, error)} ({states} states); failed in the hold "
                  f"{part.drop_duplicates(['run', 'state', 'hold_time'])['failed_in_hold'].mean():.2f}; / base at "
                  f"this load {against}")


def estimator_summary(runs, every):
    print("\n## The paper's estimator (Delta mu_a against ln(T_a / T0), T0 = 1 / nu), drive rate 2e-8, T = 1e-3")
    for strengthening in (5.0, 0.0):
        pooled = []
        for n in (1, 2, 3):
            chosen = select_runs(runs, n=n, temperature=1e-3, drive_rate=2e-8, strengthening=strengthening)
            if chosen.empty:
                continue
            slips = pd.concat([item.tables["slip_events"].assign(seed=seed) for item, seed in
                               zip(chosen["data"], chosen["seed"])], ignore_index=True)
            pooled.append(slips.rename(columns={"B_a_sig0": "B_a"}).assign(n=n, protocol="stack"))
            T0 = float(chosen["T0"].iloc[0])
            peaks = trial_peaks(select_runs(every[every["trials"] == n], n=n, temperature=1e-3, drive_rate=2e-8,
                                    strengthening=strengthening))
            peaks = peaks[np.isclose(peaks["below"], 0.02)] if not peaks.empty else peaks
            for a in range(1, n + 1):
                mine = slips[slips["interface"] == a]
                origin, intercept = estimator(mine, T0, "origin"), estimator(mine, T0, "intercept")
                true = paired_slopes(peaks[peaks["interface"] == a]) if not peaks.empty else (np.nan, np.nan, 0)
                T = mine["T_fe"].to_numpy(dtype=float)
                T = T[np.isfinite(T)]
                spread = np.percentile(T / T.mean(), [5, 95]) if T.size else [np.nan, np.nan]
                interfaces = pd.concat([item.tables["interfaces"] for item in chosen["data"]])
                R_slow = mean_sem(interfaces.loc[interfaces["interface"] == a, "R_slow"])
                print(f"- lambda {strengthening:g}, n = {n}, a = {a}: origin B = {fmt(origin['B'], origin['B_error'])} "
                      f"({origin['slips']} slips, {origin['bins']} bins); intercept B = "
                      f"{fmt(intercept['B'], intercept['B_error'])}, c = {fmt(intercept['c'], intercept['c_error'], 3)}; "
                      f"true B (paired holds) {fmt(*true[:2])} ({true[2]} states); T_a / <T_a> 5-95 %: "
                      f"{spread[0]:.2f}-{spread[1]:.2f}; R_slow {fmt(*R_slow[:2], 2)}")
        if pooled:
            spread = spread_of_aging_rate(pd.concat(pooled, ignore_index=True))
            print(f"- lambda {strengthening:g}: std(B_a) / std at n = 1, per (a, n): "
                  + ", ".join(f"({row.interface}, {row.n}) {row.std_normalised:.2f}" for row in spread.itertuples()))


def aftershock_summary(runs, study):
    print("\n## Aftershocks (holds of 1e12 after slips of a, events that move blocks of b; controls mid-stick at the "
          "same stress of a)")
    for (n, strengthening, rate), chosen in runs[runs["n"] > 1].groupby(["n", "strengthening", "drive_rate"]):
        table = aftershock_pairs(list(chosen["data"]), n, samples=100)
        for row in table.itertuples():
            fit = f"p = {fmt(row.p, row.p_error, 2)}, c = {row.c:.3g}" if np.isfinite(row.p) else "no fit"
            print(f"- n = {n}, lambda {strengthening:g}, rate {rate:g}: a = {row.a} -> b = {row.b}, {row.kind}: "
                  f"{row.events:.2f} ± {row.events_sem:.2f} events per hold ({row.holds} holds, complete "
                  f"{row.complete:.2f}); {fit} ({row.n_events} events)")
        for _, run in chosen.iterrows():
            table = read_increments(Path(study) / "sim" / "fem" / Path(run["file"]).name)
            driven = driven_aftershocks(table, 162, rate)
            for (a, b), part in driven.groupby(["a", "b"]):
                found = part["t"].dropna()
                print(f"  driven, a = {a} -> b = {b}: next event on b after {len(found)} of {len(part)} slips, median "
                      f"time {found.median():.3g}, median drive {part['drive'].dropna().median():.3g} eps0")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", help="results directory of the aging study (e.g. results/aging)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", RuntimeWarning)
    every = load_aging_runs(sorted(glob.glob(str(Path(args.study) / "events" / "thermal-events*" / "fem" / "*.h5"))))
    runs = every[every["trials"] == 1]  # the main parameterisation: hold trials in the n = 1 runs
    runs_summary(runs, args.study)
    holds_summary(runs)
    loads_summary(runs)
    estimator_summary(runs, every)
    aftershock_summary(runs, args.study)


if __name__ == "__main__":
    main()
