"""The paper's test of aging replayed in the model: the numbers of docs/numerical-analysis.md, "Slip dissonance".

    python benchmarks/dissonance_findings.py results/dissonance

Reads the study of workflow/config/dissonance.yaml (its ``waiting-times``, ``thermal-events`` and ``experiment-events``
outputs and its run files) and prints, each number with the slips, states or runs behind it:

1. the drive's loading rate of every interface while nothing yields (the runs' linear responses), against the lab's
   ``(n + a)(n - a + 1) / 2`` (relative to n = 1);
2. the go/no-go scan: std(ln T_a) per interface for every drive setting and n (athermal runs: the drive since the
   previous slip), pooled over n, and what makes it (the thresholds' spread, the share of the loading lost to
   interruptions by other slips);
3. the rate-and-state twin (the lab's drive on rate-and-state interfaces, B = b known by construction): the same
   spread, and the paper's estimator per interface and pooled against the b put in, at two b for one b - a (the
   twin cannot switch aging off: stick-slip needs b > a);
4. the true B: paired holds at a load where no hold fails, the first peak after the hold against the contacts' age
   at the peak (reload included) and against the hold time, per lambda and per interface in the stacks, and its
   ratio to lambda = 5 (does B scale with the junctions' strengthening?);
5. the thermal runs' waiting times (the re-slips soon after a slip and the slips after a reload), and the paper's
   estimator on them (aging on, and the aging-off control) per interface, per n and pooled, with the true B of item 4
   beside it;
6. what a measurement needs for 25 %: the estimator's bias (the aging-off control) and the slips for a standard error
   of 25 % of the true B, from the measured errors;
7. the cost: CPU and wall time of every simulation (Snakemake's benchmark files) and of the analyses (their logs'
   progress lines aside, the events jobs have no benchmark file: their sum is the study's wall time minus the runs').
"""

import argparse
import glob
import json
import math
import warnings
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from stickslip.summaries.aging_summary import curvature, load_aging_runs, mean_sem, paired_slopes, ratio
from stickslip.events.waiting_times import spread
from stickslip.summaries.dissonance_summary import (estimator_runs, hold_peaks, load_runs, loading_rates, scan_table,
                                                 setting_of)
from stickslip.statistics.estimator import biases, estimator_table
from stickslip.figures.experimental_data import load_slips
from stickslip.experiment.timeseries import read_truth

#: The target of the scan: std(ln T_a) per interface (the paper's ~1.3, two decades of T_a).
TARGET = 0.7


def fmt(value, error, digits=3):
    return f"{value:.{digits}f} ± {error:.{digits}f}"


def lab_rates(n):
    """The lab's loading rate of interfaces a = 1..n, relative to a single interface: (n + a)(n - a + 1) / 2."""
    return np.array([(n + a) * (n - a + 1) / 2 for a in range(1, n + 1)])


def rates_summary(study, runs):
    print("## 1. Loading rates while nothing yields [sig0 per eps0 of drive] (linear response), relative to n = 1")
    for setting, group in runs[~runs["thermal"]].groupby(runs.apply(setting_of, axis=1)):
        reference = None
        for _, run in group.sort_values("n").iterrows():
            rates = loading_rates(Path(study) / "sim" / "fem" / Path(run["file"]).name)
            if run["n"] == 1:
                reference = rates[0]
            relative = rates / reference if reference else rates * np.nan
            print(f"- {setting}, n = {run['n']}: " + ", ".join(f"{r:.4f}" for r in rates)
                  + f"; relative {', '.join(f'{r:.2f}' for r in relative)} (lab {', '.join(f'{r:g}' for r in lab_rates(run['n']))})")


def scan_summary(runs):
    print(f"\n## 2. The scan: std(ln T_a) per interface (target >= {TARGET}); athermal: T_a = drive since the "
          "previous slip")
    athermal = runs[~runs["thermal"]]
    per_n, pooled = scan_table(athermal)
    for row in per_n.itertuples():
        print(f"- {row.setting}, n = {row.n}, a = {row.interface}: {fmt(row.std_lnT, row.std_lnT_error)} "
              f"({row.n_slips} slips; 5-95 % over {row.decades:.2f} decades; median {row.median_T:.3f} eps0); "
              f"thresholds alone std(ln recovered) {row.std_ln_recovered:.3f}; interrupted share "
              f"{row.interrupted_share:.2f}; median drop {row.median_dmu_sig0:.3f}, std of the peaks "
              f"{row.std_peak_sig0:.3f} sig0")
    print("- pooled over n (one clock, the drive):")
    for row in pooled.itertuples():
        verdict = "reaches" if row.std_lnT - 2 * row.std_lnT_error >= TARGET else (
            "below" if row.std_lnT + 2 * row.std_lnT_error < TARGET else "undecided")
        print(f"  {row.setting}, a = {row.interface}: {fmt(row.std_lnT, row.std_lnT_error)} ({row.n_slips} slips, "
              f"{row.decades:.2f} decades) {verdict}")
    return per_n, pooled


def twin_summary(study):
    paths = sorted(glob.glob(str(Path(study) / "events" / "experiment-events" / "rate-state-lever" / "*.h5")))
    if not paths:
        return None
    print("\n## 3. The rate-and-state twin (rate-state-lever, stack, slips after 300 s)")
    slips = load_slips(paths)
    slips = slips[slips["protocol"] == "stack"].copy()
    b_of = {}
    for path in paths:
        truth = read_truth(Path(study) / "sim" / "rate-state-lever" / Path(path).name, "interfaces")
        b_of[path] = dict(zip(truth["a"], truth["b"]))
    slips["b"] = [b_of[f].get(a, np.nan) for f, a in zip(slips["file"], slips["interface"])]
    slips["pair"] = [_pair(f) for f in slips["file"]]
    for pair, group in slips.groupby("pair"):
        print(f"- rs_a, rs_b = {pair}: {group['file'].nunique()} runs, {len(group)} slips")
        for by in (("interface", "n"), ("interface",)):  # per n, then pooled over n (printed as n = 0)
            for key, part in group.groupby(list(by)):
                std, error, count = spread(part["T"])
                a, n = (key if len(by) == 2 else (key[0] if isinstance(key, tuple) else key, 0))
                print(f"  spread a = {a}, n = {n}: {fmt(std, error)} ({count} slips)")
        fits = estimator_table(group, t0=1.0, by=("interface",), T="T", dmu="dmu")
        for row in fits.itertuples():
            b = group.loc[group["interface"] == row.interface, "b"].mean()
            print(f"  estimator a = {row.interface} ({row.fit}): B = {fmt(row.B, row.B_error, 4)} [{row.B_low:.4f}, "
                  f"{row.B_high:.4f}], c = {fmt(row.c, row.c_error, 3)}; true B = b = {b:.4f}; B / b = "
                  f"{row.B / b:.2f}; {row.slips} slips in {row.bins} bins, std(ln T) {row.std_lnT:.2f}")
        for row in estimator_table(group, t0=1.0, T="T", dmu="dmu").itertuples():
            print(f"  estimator pooled ({row.fit}): B = {fmt(row.B, row.B_error, 4)} [{row.B_low:.4f}, "
                  f"{row.B_high:.4f}], c = {fmt(row.c, row.c_error, 3)}; mean b {group['b'].mean():.4f}; "
                  f"{row.slips} slips, {row.bins} bins, std(ln T) {row.std_lnT:.2f}")
    return slips


def _pair(path):
    """The (rs_a, rs_b) of the run an experiment-events file analysed (its header's parameters)."""
    with h5py.File(path, "r") as file:
        params = json.loads(file.attrs["params"])
    return (tuple(params.get("rs_a", ())), tuple(params.get("rs_b", ())))


def true_summary(study):
    """Item 4: the true B of the paired holds, per setting; returns {(n, lambda, T, interface): (B, error, states)}."""
    print("\n## 4. The true B: paired holds, first peak after the hold against ln(age at the peak) (hold + reload) "
          "and against ln T_w (T_w >= 1e6)")
    truth = {}
    for analysis in ("thermal-events", "thermal-events@stack"):
        every = load_aging_runs(sorted(glob.glob(str(Path(study) / "events" / analysis / "fem" / "*.h5"))))
        every = every[every["trials"] == every["n"]]
        for (n, lam, T, rate), runs in every.groupby(["n", "strengthening", "temperature", "drive_rate"]):
            peaks = hold_peaks(runs["data"])
            if peaks.empty:
                continue
            for below, part in peaks.groupby("below") if "below" in peaks else [(0.02, peaks)]:
                held = part.drop_duplicates(["run", "state", "hold_time"])
                for a, mine in part.groupby("interface"):
                    age = paired_slopes(mine, t_min=0.0, time="age")
                    hold = paired_slopes(mine)
                    bend = curvature(mine.assign(hold_time=mine["age"]), t_min=0.0) if len(mine) > 5 else (
                        math.nan, math.nan)
                    reload = mean_sem(mine.loc[mine["hold_time"] == 0, "age"])
                    print(f"- n = {n}, lambda {lam:g}, T {T:g}, rate {rate:g}, below {below:g}, a = {a}: B(age) = "
                          f"{fmt(*age[:2], 4)} ({age[2]} states), B(T_w) = {fmt(*hold[:2], 4)} ({hold[2]}); "
                          f"curvature in ln age {fmt(*bend, 5)}; age at the peak without a hold "
                          f"{reload[0]:.3g} ± {reload[1]:.2g}; failed in the hold "
                          f"{held['failed_in_hold'].mean():.2f} of {len(held)} holds; held stress "
                          f"{held['mu_start'].mean():.3f} sig0, {held['held_below'].mean():.2f} eps0 under the "
                          f"threshold (least {held['held_below'].min():.2f}; "
                          f"{(held['held_below'] < below * (1 - 1e-9)).mean():.2f} of the holds short of {below:g})")
                    truth[(n, lam, T, below, a)] = age
    return truth


def scaling_summary(truth):
    print("\n## 4b. Does B scale with lambda and T? (n = 1, age fits, relative to lambda 5 at T 1e-3 and the same load)")
    for (n, lam, T, below, a), value in sorted(truth.items()):
        base = truth.get((1, 5.0, 1e-3, below, 1))
        if n != 1 or base is None or (lam, T) == (5.0, 1e-3):
            continue
        print(f"- below {below:g}: lambda {lam:g}, T {T:g} / lambda 5, T 1e-3: "
              f"{fmt(*ratio(value[0], value[1], *base[:2]), 2)} (the mechanism, lambda T: {lam * T / 5e-3:.2f})")


def truth_at(truth, lam, T):
    """The true B of interface 1 at n = 1, (B, error, states), at the load farthest below the threshold; or None."""
    keys = [key for key in truth if key[0] == 1 and key[1] == lam and key[2] == T and key[4] == 1]
    return truth[max(keys, key=lambda key: key[3])] if keys else None


def pooled_estimates(runs):
    """Both fits on every single slip of each thermal setting, pooled over interfaces and n: {(T, lambda): table}."""
    slips = estimator_runs(runs)
    out = {}
    for (T, lam), group in slips.groupby(["temperature", "strengthening"]):
        out[(T, lam)] = estimator_table(group, t0=float(group["T0"].iloc[0]), T="T_fe", dmu="dmu_sig0").set_index(
            "fit")
    return out


def thermal_waits_summary(runs):
    print("\n## 5a. The thermal runs' waiting times: T_fe / T0 of every slip, the re-slips soon after a slip "
          "(T < 1e6 T0) and the slips after a reload (T >= 1e7 T0)")
    slips = estimator_runs(runs)
    for setting, group in slips.groupby("setting"):
        T = group["T_fe"].to_numpy(dtype=float) / group["T0"].to_numpy(dtype=float)
        ok = np.isfinite(T) & (T > 0)
        std, error, count = spread(T)
        short, long = ok & (T < 1e6), ok & (T >= 1e7)
        drops = group["dmu_sig0"].to_numpy(dtype=float)
        print(f"- {setting}: {count} slips, std(ln T) {fmt(std, error, 2)}, median T {np.median(T[ok]):.2g} T0; "
              f"T < 1e6 T0: {short.sum() / ok.sum():.2f} of them, median drop {np.median(drops[short]):.3f} sig0; "
              f"T >= 1e7 T0: median drop {np.median(drops[long]):.3f} sig0")


def estimator_summary(runs, truth, pooled):
    print("\n## 5. The paper's estimator on the model's thermal runs (T_fe, T0 = 1 / nu): per interface and n, "
          "per interface pooled over n, all pooled")
    slips = estimator_runs(runs)
    if slips.empty:
        return
    for setting, group in slips.groupby("setting"):
        T0 = float(group["T0"].iloc[0])
        tables = [estimator_table(group, t0=T0, by=("n", "interface"), T="T_fe", dmu="dmu_sig0"),
                  estimator_table(group, t0=T0, by=("interface",), T="T_fe", dmu="dmu_sig0").assign(n=0),
                  estimator_table(group, t0=T0, T="T_fe", dmu="dmu_sig0").assign(n=0, interface=0)]
        for row in pd.concat(tables, ignore_index=True).itertuples():
            where = ("pooled" if row.interface == 0 else f"a = {row.interface}") + (
                f", n = {row.n}" if row.n else (", n pooled" if row.interface else ""))
            print(f"- {setting}, {where} ({row.fit}): B = {fmt(row.B, row.B_error, 4)} [{row.B_low:.4f}, "
                  f"{row.B_high:.4f}], c = {fmt(row.c, row.c_error, 3)}; {row.slips} slips, {row.bins} bins, "
                  f"std(ln T) {row.std_lnT:.2f}, {row.decades:.2f} decades" + (f" ({row.reason})" if row.reason else ""))
    print("\n## 5b. The estimate (pooled) against the true B (section 4, n = 1), and after subtracting the aging-off "
          "control (lambda 0, same T)")
    for (T, lam), table in sorted(pooled.items()):
        true = truth_at(truth, lam, T)
        control = pooled.get((T, 0.0))
        for fit, row in table.iterrows():
            line = f"- T {T:g}, lambda {lam:g} ({fit}): B = {fmt(row.B, row.B_error, 4)}"
            if control is not None and lam != 0.0:
                off = control.loc[fit]
                line += f"; minus the control: {fmt(row.B - off.B, math.hypot(row.B_error, off.B_error), 4)}"
            if true is not None:
                line += f"; true B {fmt(true[0], true[1], 4)} ({true[2]} states)"
                if lam != 0.0 and true[0] > 0:
                    line += f": estimate / true {fmt(*ratio(row.B, row.B_error, true[0], true[1]), 2)}"
            print(line)


def requirements_summary(truth, pooled):
    print("\n## 6. What the estimator would need to be right within 25 % (pooled fits, section 5b)")
    for (T, lam), table in sorted(pooled.items()):
        true = truth_at(truth, lam, T)
        control = pooled.get((T, 0.0))
        if lam == 0.0 or true is None or not true[0] > 0 or control is None:
            continue
        for fit, row in table.iterrows():
            bias = control.loc[fit]
            needed = row.slips * (row.B_error / (0.25 * true[0])) ** 2
            print(f"- T {T:g}, lambda {lam:g} ({fit}): the aging-off control reads {fmt(bias.B, bias.B_error, 4)} = "
                  f"{bias.B / true[0]:.2f} of the true B {true[0]:.4f} (bias; within 25 % if below 0.25); standard error "
                  f"{row.B_error / true[0]:.2f} of it from {row.slips} slips over std(ln T) {row.std_lnT:.2f} "
                  f"({row.decades:.1f} decades): {needed:.0f} slips for 25 %")
    print("- the synthetic construction (stickslip.statistics.estimator.biases) at the lab's numbers (the paper's B = "
          "0.053, drops ~0.2, thresholds' CV ~0.1, std(ln T) ~1.3, <ln T / T0> ~4.6): disorder-law bias of the free "
          f"intercept {biases(gap=0, drop=0.2, disorder=0.1, std_lnT=1.3, mean_ln=4.6)['intercept']:.4f} "
          f"({biases(gap=0, drop=0.2, disorder=0.1, std_lnT=1.3, mean_ln=4.6)['intercept'] / 0.053:.2f} B); "
          "the origin fit's bias gap <x> / <x^2> at a strength offset c = 0.04 (the twin's): "
          f"{biases(gap=0.04, drop=0.2, disorder=0.1, std_lnT=1.3, mean_ln=4.6)['origin']:.4f} "
          f"({biases(gap=0.04, drop=0.2, disorder=0.1, std_lnT=1.3, mean_ln=4.6)['origin'] / 0.053:.2f} B)")


def cost_summary(study, runs):
    print("\n## 7. The cost: CPU seconds of every simulation (logs/benchmarks, cpu_time; wall s in brackets)")
    settings = {Path(row["file"]).stem: (setting_of(row), row["n"]) for _, row in runs.iterrows()}
    total = 0.0
    rows = []
    for path in sorted(Path(study, "logs", "benchmarks", "sim", "fem").glob("*.tsv")):
        table = pd.read_csv(path, sep="\t")
        cpu, wall = float(table["cpu_time"].iloc[-1]), float(table["s"].iloc[-1])
        total += cpu
        setting, n = settings.get(path.stem, ("?", 0))
        rows.append((setting, n, path.stem, cpu, wall))
    for setting, n, run, cpu, wall in sorted(rows):
        print(f"- {setting}, n = {n} ({run}): {cpu:.0f} CPU-s ({wall:.0f} s)")
    others = sorted(Path(study, "logs", "benchmarks", "sim").glob("[!f]*/*.tsv"))
    other = sum(float(pd.read_csv(path, sep="\t")["cpu_time"].iloc[-1]) for path in others)
    print(f"- fem runs: {total / 60:.0f} CPU-min in {len(rows)} runs; other solvers: {other / 60:.1f} CPU-min in "
          f"{len(others)} runs (a resumed run counts only the part after its resume)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", help="results directory of the dissonance study (e.g. results/dissonance)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", RuntimeWarning)
    runs = load_runs(glob.glob(str(Path(args.study) / "events" / "waiting-times" / "fem" / "*.h5")))
    rates_summary(args.study, runs)
    scan_summary(runs)
    twin_summary(args.study)
    truth = true_summary(args.study)
    scaling_summary(truth)
    pooled = pooled_estimates(runs)
    thermal_waits_summary(runs)
    estimator_summary(runs, truth, pooled)
    requirements_summary(truth, pooled)
    cost_summary(args.study, runs)


if __name__ == "__main__":
    main()
