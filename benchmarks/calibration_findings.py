"""The paper's aging estimator calibrated against the truth: the numbers of docs/numerical-analysis.md, "Slip
dissonance" (issue 56).

    python benchmarks/calibration_findings.py results/calibration results/calibration-b \\
        results/calibration-stacks results/pooling results/pooling-twin results/drive-precheck

Reads the studies of workflow/config/calibration.yaml, calibration-b.yaml (the thermal n = 1 runs at Phi = 5e-9, 4
lambda, seeds 1-5), calibration-stacks.yaml (n = 2, lambda 0 and 5, seeds 1-3), pooling.yaml (interfaces of
different strength, fem and rate-and-state twin) and drive-precheck.yaml (the athermal pre-check of the decisive
drive); a study that is missing leaves its sections empty. Prints, each number with the seeds, states or slips
behind it (errors over seeds: the standard error of the seeds' spread, ``sd / sqrt(k)``; within-seed errors beside
them: the root mean square of the seeds' own errors over ``sqrt(k)``):

1. per lambda and seed: the true B (paired holds against the contacts' age at the peak, and against T_w), the
   waiting times (re-slips after < 1e6 / nu, std ln T with its normal-theory and bootstrap errors, the robust
   spread IQR / 1.349), raw and as the lab resolves them; over seeds;
2. the lab's clock: the model time of one lab second per lambda (resolved slips at <ln(T / T0)> = 4.6);
3. the paper's estimator (both fits) on the n = 1 slips, on both clocks (T0 = 1 / nu, the lab's), raw and with the
   lab's resolution: per seed, over seeds, against the truth (ratio and whether it is within 25 %), and the
   calibration line over lambda and seeds; the same with the n = 2 stacks pooled in (lambda 0 and 5);
4. the post-slip stress against ln T of the slips after a reload (the paper assumes it constant); the aging-off
   control's bend;
5. the true B per interface in the n = 2 stacks;
6. pooling: the pooled and per-interface fits of interfaces of different strength (fem, twin with the aging and
   the slip law, synthetic slips with the paper's strengths and loading rates), beside the paper's 0.053 +- 0.005;
   6d. the twin's records with and without healing at rest compared (drops, ln T, KS, the estimators);
7. the estimator beside the paper's (:mod:`stickslip.statistics.loading_contrast`) against the truth, fem and twin,
   with the slips per path it would need at the reach measured; 7b. what (dmu_a, T_a) can tell at all: an aging
   interface's drops against its aging-free control's drop law at equal T (:mod:`stickslip.statistics.drop_law`), and
   the paper's estimator on the aging interface's waiting times with the control's drops;
8. the pre-check of the decisive drive: std ln T_a per interface, its robust spread, the share of the loading that
   other slips take, against the criteria, per N, Phi and n; the go/no-go;
9. the cost: CPU seconds of every simulation (and its wall seconds per increment once slipping, from its log) and
   the wall time of the events jobs, per study;
10. the cost of the configs not run here (:data:`PLANNED`) from the CPU seconds per increment and per hold state
    measured here.
"""

import argparse
import glob
import json
import math
import re
import warnings
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import yaml
from scipy import stats

from stickslip.experiment.timeseries import read_truth
from stickslip.experiment.virtual.rate_state import RateStateLaw
from stickslip.experiment.virtual.slide_hold_slide import hold_healing
from stickslip.figures.experimental_data import load_slips
from stickslip.statistics.calibration import (LAB_MEAN_LN, LAB_RESOLUTION, calibration_line, lab_clock, log_spread,
                                              merge_unresolved, over_seeds)
from stickslip.statistics.drop_law import at_equal_T, drop_law_contrast
from stickslip.statistics.estimator import estimate, lab_slips
from stickslip.statistics.loading_contrast import loading_contrast, slips_needed
from stickslip.summaries.aging_summary import curvature, first_peaks, ratio
from stickslip.summaries.calibration_summary import load_calibration_runs, post_slip_slope, run_slips, run_truth
from stickslip.summaries.dissonance_summary import loading_rates, peak_ages
from stickslip.study_plan import Study

#: The broad drive of the calibration (Phi = 5e-9) and the split of its waiting times: thermal re-slips below
#: RESLIP, slips after a reload above RELOAD [1 / nu].
PHI = 5e-9
RESLIP, RELOAD = 1e6, 1e7
#: The paper's estimate (its Fig. 5c).
PAPER_B, PAPER_B_ERROR = 0.053, 0.005
#: The pre-check's criteria: n = 1 narrow, n >= 3 broad by the lever.
NARROW, BROAD, INTERRUPTED = 0.4, 0.8, 0.3
FITS = ("origin", "intercept")
EYES = ("raw", "lab")


def fmt(value, error, digits=4):
    return f"{value:.{digits}f} ± {error:.{digits}f}"


def seeds_line(stats_, digits=4):
    """'mean ± between [low, high] (within w; k seeds)' (no within-seed error where the values have none)."""
    within = f"within {stats_['within']:.{digits}f}; " if math.isfinite(stats_["within"]) else ""
    return (f"{fmt(stats_['mean'], stats_['error'], digits)} [{stats_['low']:.{digits}f}, {stats_['high']:.{digits}f}]"
            f" ({within}{stats_['seeds']} seeds)")


def calibration_runs(runs):
    """The calibration's thermal runs at the broad drive with every interface of strength 1."""
    plain = runs["strength"].apply(lambda s: all(v == 1.0 for v in s))
    return runs[runs["thermal"] & np.isclose(runs["phi"], PHI, rtol=0.05, atol=0.0) & plain & (runs["N"] == 162)]


def truth_table(runs):
    """Per run with holds: its true B per interface, with ``seed``, ``n``, ``strengthening``, ``strength``."""
    parts = []
    for _, run in runs.iterrows():
        if run["holds"] is None:
            continue
        table = run_truth(run["holds"])
        parts.append(table.assign(run=run["run"], seed=run["seed"], n=run["n"], strengthening=run["strengthening"],
                                  strength=[run["strength"][a - 1] for a in table["interface"]]))
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(
        columns=["interface", "B", "B_error", "states", "B_hold", "B_hold_error", "failed", "run", "seed", "n",
                 "strengthening", "strength"])


def eye(slips, t0_lab, which):
    """The slips raw or as the lab resolves them (merged within LAB_RESOLUTION lab seconds)."""
    return slips if which == "raw" else merge_unresolved(slips, LAB_RESOLUTION * t0_lab)


# --- 1. the truth and the waiting times ------------------------------------------------------------------------------

def truth_summary(runs, truth):
    print("## 1. The calibration runs (n = 1, Phi = 5e-9, T = 1e-3, drive 2e-8, 1000 increments): the true B and "
          "the waiting times, per lambda and seed")
    slips = run_slips(runs[runs["n"] == 1])
    clocks = {}
    for lam, group in slips.groupby("strengthening"):
        t0_lab = lab_clock(group)
        resolved = eye(group, t0_lab, "lab")
        single = resolved[~resolved["multi"].to_numpy(dtype=bool)]
        clocks[lam] = (t0_lab, lab_clock(group, merge=False), float(np.nanmedian(single["T"])) / t0_lab,
                       len(resolved) / len(group))
        for seed, mine in group.groupby("seed"):
            row = truth[(truth["strengthening"] == lam) & (truth["seed"] == seed) & (truth["n"] == 1)]
            line = f"- lambda {lam:g}, seed {seed}: "
            if len(row):
                r = row.iloc[0]
                bend = _control_bend(runs, lam, seed)
                line += (f"true B(age) {fmt(r.B, r.B_error)} ({r.states} states), B(T_w) "
                         f"{fmt(r.B_hold, r.B_hold_error)}, holds failing {r.failed:.2f}, curvature in ln age "
                         f"{fmt(*bend, 5)}; ")
            T = mine["T"].to_numpy(dtype=float) / mine["T0"].to_numpy(dtype=float)
            ok = np.isfinite(T) & (T > 0)
            raw, lab = log_spread(T), log_spread(eye(mine, t0_lab, "lab")["T"])
            line += (f"{ok.sum()} slips, re-slips (T < 1e6 T0) {np.mean(T[ok] < RESLIP):.2f}, median T "
                     f"{np.median(T[ok]):.2g} T0; std ln T {fmt(raw['std'], raw['std_error'], 2)} (bootstrap "
                     f"{raw['std_error_bootstrap']:.2f}), robust {fmt(raw['robust'], raw['robust_error_bootstrap'], 2)}; "
                     f"as the lab resolves them: {lab['slips']} slips, std ln T "
                     f"{fmt(lab['std'], lab['std_error'], 2)} (bootstrap {lab['std_error_bootstrap']:.2f}), robust "
                     f"{fmt(lab['robust'], lab['robust_error_bootstrap'], 2)}")
            print(line)
    print("- over seeds (n = 1):")
    base = truth[(truth["n"] == 1) & (truth["strengthening"] == 5.0)]
    reference = over_seeds(base["B"]) if len(base) else None
    for lam, group in truth[truth["n"] == 1].sort_values("seed").groupby("strengthening"):
        age, hold = over_seeds(group["B"], group["B_error"]), over_seeds(group["B_hold"], group["B_hold_error"])
        bends = np.array([_control_bend(runs, lam, seed) for seed in group["seed"]])
        print(f"  lambda {lam:g}: true B(age) {seeds_line(age)}; B(T_w) {seeds_line(hold)}; B(T_w) / B(age) "
              f"{hold['mean'] / age['mean']:.2f}; seeds' sd {age['sd']:.4f}; curvature in ln age "
              f"{seeds_line(over_seeds(bends[:, 0], bends[:, 1]), 5)}; seeds' values "
              + ", ".join(f"{v:.4f}" for v in group["B"])
              + (f"; / lambda 5 {fmt(*ratio(age['mean'], age['error'], reference['mean'], reference['error']), 2)}"
                 if reference else ""))
    for lam, group in slips.groupby("strengthening"):
        per = []
        for _, mine in group.groupby("seed"):
            T = (mine["T"] / mine["T0"]).to_numpy(dtype=float)
            per.append((np.mean(T[np.isfinite(T)] < RESLIP), log_spread(T)["std"], log_spread(T)["robust"],
                        log_spread(eye(mine, clocks[lam][0], "lab")["T"])["std"],
                        log_spread(eye(mine, clocks[lam][0], "lab")["T"])["robust"]))
        per = np.array(per)
        names = ("re-slip share", "std ln T", "robust", "std ln T as resolved", "robust as resolved")
        print(f"  lambda {lam:g}: " + "; ".join(f"{name} {seeds_line(over_seeds(per[:, k]), 2)}"
                                                 for k, name in enumerate(names)))
    return slips, clocks


def _control_bend(runs, lam, seed):
    chosen = runs[(runs["strengthening"] == lam) & (runs["seed"] == seed) & (runs["n"] == 1)]
    if chosen.empty or chosen.iloc[0]["holds"] is None:
        return math.nan, math.nan
    item = chosen.iloc[0]["holds"]
    peaks = peak_ages(first_peaks(item), item.tables["slip_events"])
    return curvature(peaks.assign(hold_time=peaks["age"]), t_min=0.0)


def clock_summary(clocks):
    print(f"\n## 2. The lab's clock: one lab second (T0 = 1 s) in model time, from <ln(T / T0)> = {LAB_MEAN_LN} of the "
          f"single slips the lab resolves (slips of an interface within {LAB_RESOLUTION:g} s merged), per lambda "
          "(seeds pooled)")
    for lam, (resolved, raw, median, kept) in sorted(clocks.items()):
        print(f"- lambda {lam:g}: 1 s = {resolved:.3g} / nu (resolution {LAB_RESOLUTION * resolved:.3g} / nu; the lab "
              f"sees {kept:.2f} of the slips, median T {median:.0f} s; the lab's n = 1 cycle, a drop of 0.2 at K h "
              f"gamma_dot / N = 1.1e-3 / s: ~180 s); without merging {raw:.3g} / nu")


# --- 3. the estimator against the truth ------------------------------------------------------------------------------

def seed_estimates(slips, clocks, by_n=False):
    """Per (lambda, seed, clock, eye, fit): the paper's fit of the single slips."""
    rows = []
    for (lam, seed), mine in slips.groupby(["strengthening", "seed"]):
        t0_lab = clocks[lam][0]
        for which in EYES:
            seen = eye(mine, t0_lab, which)
            single = seen[~seen["multi"].to_numpy(dtype=bool)]
            for clock, t0 in (("model", float(mine["T0"].iloc[0])), ("lab", t0_lab)):
                for fit in FITS:
                    result = estimate(single["T"], single["dmu"], t0=t0, fit=fit)
                    rows.append({"strengthening": lam, "seed": seed, "clock": clock, "eye": which, "fit": fit,
                                 "mean_ln": _mean_log(single["T"] / t0), **result})
    return pd.DataFrame(rows)


def _mean_log(values):
    """The mean of ``ln values`` over the positive finite ones (a slip at T = 0 has no log)."""
    values = np.asarray(values, dtype=float)
    return float(np.mean(np.log(values[np.isfinite(values) & (values > 0)])))


def estimator_summary(estimates, truth, title):
    print(f"\n## 3. The paper's estimator against the true B: {title}")
    for row in estimates.itertuples():
        print(f"- lambda {row.strengthening:g}, seed {row.seed}, {row.clock} clock, {row.eye}, {row.fit}: B = "
              f"{fmt(row.B, row.B_error)}, c = {fmt(row.c, row.c_error, 3)}; {row.slips} slips, {row.bins} bins, "
              f"<ln T/T0> {row.mean_ln:.1f}, std ln T {row.std_lnT:.2f}" + (f" ({row.reason})" if row.reason else ""))
    true = truth[truth["n"] == 1].set_index(["strengthening", "seed"])
    print("- over seeds, against the true B (ratio of the seeds' means, error propagated from both; within 25 % if "
          "its 95 % interval lies in 0.75-1.25):")
    points = {}
    for (clock, which, fit), part in estimates.groupby(["clock", "eye", "fit"]):
        for lam, mine in part.groupby("strengthening"):
            result = over_seeds(mine["B"], mine["B_error"])
            keys = [(lam, s) for s in mine["seed"] if (lam, s) in true.index]
            truth_seeds = over_seeds(true.loc[keys, "B"]) if keys else None
            line = f"  {clock} clock, {which}, {fit}, lambda {lam:g}: B = {seeds_line(result)}"
            if truth_seeds and lam > 0:
                value, error = ratio(result["mean"], result["error"], truth_seeds["mean"], truth_seeds["error"])
                low, high = value - 1.96 * error, value + 1.96 * error
                verdict = "within 25 %" if 0.75 <= low and high <= 1.25 else (
                    "outside 25 %" if high < 0.75 or low > 1.25 else "undecided")
                line += f"; / true {fmt(value, error, 2)} [{low:.2f}, {high:.2f}] {verdict}"
            print(line)
            for seed_row in mine.itertuples():
                if (lam, seed_row.seed) in true.index:
                    t = true.loc[(lam, seed_row.seed)]
                    points.setdefault((clock, which, fit), []).append((t["B"], t["B_error"], seed_row.B,
                                                                        seed_row.B_error))
    print("- the calibration line, estimate = intercept + slope x true B, over (lambda, seed) [95 % intervals]:")
    for key, values in sorted(points.items()):
        x, sx, y, sy = np.array(values).T
        line = calibration_line(x, sx, y, sy)
        print(f"  {key[0]} clock, {key[1]}, {key[2]}: slope {fmt(line['slope'], line['slope_error'], 2)} "
              f"[{line['slope_low']:.2f}, {line['slope_high']:.2f}], intercept "
              f"{fmt(line['intercept'], line['intercept_error'])} [{line['intercept_low']:.4f}, "
              f"{line['intercept_high']:.4f}] ({line['points']} points)")


# --- 4. the post-slip stress, 5. the stacks' truth ---------------------------------------------------------------------

def post_slip_summary(slips):
    print(f"\n## 4. The post-slip stress (peak - drop) of the slips after a reload (T >= {RELOAD:.0e} T0) against "
          "ln T [sig0 per e-fold]")
    for lam, group in slips.groupby("strengthening"):
        per = [post_slip_slope(mine, RELOAD * float(mine["T0"].iloc[0])) for _, mine in group.groupby("seed")]
        per = np.array(per)
        print(f"- lambda {lam:g}: " + ", ".join(f"{fmt(s, e)} ({int(m)})" for s, e, m in per)
              + f"; over seeds {seeds_line(over_seeds(per[:, 0], per[:, 1]))}")


def stack_truth_summary(truth):
    stacks = truth[(truth["n"] == 2) & truth["strength"].eq(1.0)]
    if stacks.empty:
        return
    print("\n## 5. The true B per interface in the n = 2 stacks (paired holds 0 and 1e12 / nu until both slipped)")
    for (lam, a), group in stacks.groupby(["strengthening", "interface"]):
        print(f"- lambda {lam:g}, a = {a}: " + ", ".join(
            f"seed {r.seed} {fmt(r.B, r.B_error)} ({r.states})" for r in group.itertuples())
              + f"; over seeds {seeds_line(over_seeds(group['B'], group['B_error']))}")


# --- 6. pooling, 7. the estimator beside the paper's -------------------------------------------------------------------

def fits_line(slips, t0, label):
    out = []
    for fit in FITS:
        r = estimate(slips["T"][~slips["multi"]], slips["dmu"][~slips["multi"]], t0=t0, fit=fit)
        out.append(f"{label} {fit} {fmt(r['B'], r['B_error'])}")
    return out


def pooling_fem_summary(runs, truth, clocks):
    slips = run_slips(runs[runs["thermal"] & np.isclose(runs["phi"], PHI, rtol=0.05, atol=0.0) & (runs["N"] == 162)])
    slips = slips.assign(group=slips["strength"].astype(str) + "/" + slips["n"].astype(str))
    strong = slips["run"].isin(slips.loc[slips["strength"] == 2.0, "run"])
    partners = slips[strong | ((slips["n"] == 1) & slips["run"].isin(_weak_alone(runs)))]
    if partners.empty:
        return
    print("\n## 6a. Pooling in the fem model: interfaces of strength 1 and 2 (alone, n = 1, and stacked, weak under "
          "strong, n = 2), lambda 0 and 5, per seed; fits on T0 = 1 / nu, raw, and as the lab reads them ('lab': its eye "
          "and clock of the lambda, section 2)")
    table = []
    for (lam, seed), mine in partners.groupby(["strengthening", "seed"]):
        t0 = float(mine["T0"].iloc[0])
        single = mine[~mine["multi"].to_numpy(dtype=bool)]
        row = {"lambda": lam, "seed": seed}
        for fit in FITS:
            row[f"pooled {fit}"] = estimate(single["T"], single["dmu"], t0=t0, fit=fit)["B"]
            for s, part in single.groupby("strength"):
                row[f"strength {s:g} {fit}"] = estimate(part["T"], part["dmu"], t0=t0, fit=fit)["B"]
        if lam in clocks:
            t0_lab = clocks[lam][0]
            seen = eye(mine, t0_lab, "lab")
            seen = seen[~seen["multi"].to_numpy(dtype=bool)]
            for fit in FITS:
                row[f"lab pooled {fit}"] = estimate(seen["T"], seen["dmu"], t0=t0_lab, fit=fit)["B"]
                for s, part in seen.groupby("strength"):
                    row[f"lab strength {s:g} {fit}"] = estimate(part["T"], part["dmu"], t0=t0_lab, fit=fit)["B"]
        contrast = loading_contrast(mine, t0=t0, interface="strength")
        row["contrast"], row["contrast error"] = contrast["B"], contrast["B_error"]
        for s in (1.0, 2.0):
            t = truth[(truth["strengthening"] == lam) & (truth["seed"] == seed) & (truth["n"] == 1)
                      & (truth["strength"] == s)]
            row[f"true {s:g}"] = float(t["B"].iloc[0]) if len(t) else math.nan
        row["contrast reach"] = contrast["lnT_range"]
        row["slips per path for 25 %"] = slips_needed(float(single.groupby("group")["dmu"].std().mean()),
                                                      row["true 1"], contrast["lnT_range"])
        groups = single.groupby("group")
        print(f"- lambda {lam:g}, seed {seed}: " + "; ".join(f"{k} {v:.4f}" for k, v in row.items()
                                                              if k not in ("lambda", "seed"))
              + "; per group (strength/n) mean drop, <ln T/T0>: " + ", ".join(
                  f"{g} {p['dmu'].mean():.3f}, {_mean_log(p['T'] / t0):.1f} ({len(p)})" for g, p in groups))
        table.append(row)
    table = pd.DataFrame(table)
    print("- over seeds:")
    for lam, part in table.groupby("lambda"):
        print(f"  lambda {lam:g}: " + "; ".join(f"{k} {seeds_line(over_seeds(part[k]))}" for k in part
                                                 if k not in ("lambda", "seed", "contrast error")))


def _weak_alone(runs):
    """The n = 1 runs of strength 1 whose seed and lambda have a stack of strengths (1, 2)."""
    stacks = runs[runs["strength"].apply(lambda s: s == (1.0, 2.0))]
    keys = set(zip(stacks["seed"], stacks["strengthening"]))
    alone = runs[(runs["n"] == 1) & runs["strength"].apply(lambda s: s == (1.0,)) & runs["thermal"]
                 & np.isclose(runs["phi"], PHI, rtol=0.05, atol=0.0)]
    return [r.run for r in alone.itertuples() if (r.seed, r.strengthening) in keys]


def twin_slips(studies):
    paths = sorted({Path(p).name: p for s in studies for p in glob.glob(
        str(Path(s) / "events" / "experiment-events" / "rate-state-lever" / "*.h5"))}.values())
    if not paths:
        return pd.DataFrame()
    slips = load_slips(paths)
    slips = slips[slips["protocol"] == "stack"].copy()
    b_of, a_of, D_c_of, pair, law = {}, {}, {}, {}, {}
    for path in paths:
        study = Path(path).parents[3]
        truth = read_truth(study / "sim" / "rate-state-lever" / Path(path).name, "interfaces")
        b_of[path], a_of[path] = dict(zip(truth["a"], truth["b"])), dict(zip(truth["a"], truth["a_rs"]))
        D_c_of[path] = dict(zip(truth["a"], truth["D_c"]))
        with h5py.File(path, "r") as file:
            params = json.loads(file.attrs["params"])
        pair[path] = (tuple(params.get("rs_a", ())), tuple(params.get("rs_b", ())))
        law[path] = params.get("rs_state_law", "aging")
    for column, values in (("b", b_of), ("a_rs", a_of), ("D_c", D_c_of)):
        slips[column] = [values[f].get(a, np.nan) for f, a in zip(slips["file"], slips["interface"])]
    slips["pair"] = [pair[f] for f in slips["file"]]
    slips["law"] = [law[f] for f in slips["file"]]
    return slips


def twin_healing(single, law):
    """The hold healing per e-fold (slide-hold-slide at a stiff drive) of the slips' mean interface under ``law``."""
    values = {name: np.full(5, float(single[column].mean())) for name, column in (("a", "a_rs"), ("b", "b"),
                                                                                    ("D_c", "D_c"))}
    return hold_healing(RateStateLaw(**values, mu0=np.full(5, 0.35), V0=1e-3, state_law=law))["rate"]


def twin_summary(slips):
    if slips.empty:
        return
    print("\n## 6b. Pooling in the rate-and-state twin (aging law: B = b by construction; slip law: no healing at "
          "rest, the aging-off control; T0 = 1 s): per (rs_a, rs_b, state law) and seed, the pooled fits over "
          "interfaces and n, the per-interface fits (mean over interfaces), the loading contrast; the mean interface's "
          "healing per e-fold of a hold (slide-hold-slide, spring 100 K_c, 10-1000 s)")
    for (pair_, law), group in slips.groupby(["pair", "law"]):
        rows = []
        for seed, mine in group.groupby("seed"):
            single = mine[~mine["multi"].to_numpy(dtype=bool)]
            rows.append({"seed": seed, "b": float(single["b"].mean())} | _twin_readings(mine)
                        | {"b - a": float((single["b"] - single["a_rs"]).mean())})
        rows = pd.DataFrame(rows)
        drops = group[~group["multi"] & (group["n"] == group["interface"])].groupby("interface")["dmu"].mean()
        healing = twin_healing(group, law)
        print(f"- rs_a {list(pair_[0]) or 'default'}, rs_b {list(pair_[1]) or 'default'}, {law} law: "
              f"{group['file'].nunique()} runs, {len(group)} slips; hold healing {healing:.4f} per e-fold "
              f"({healing / group['b'].mean():.2f} b); mean drop of interface a in the stack n = a: "
              + ", ".join(f"{d:.3f}" for d in drops))
        for column in rows:
            if column != "seed":
                stats_ = over_seeds(rows[column])
                line = f"  {column}: {seeds_line(stats_)}"
                if column not in ("b", "b - a"):
                    line += f"; / b {stats_['mean'] / rows['b'].mean():.2f}"
                print(line)


def twin_match_summary(slips):
    """Section 6d: each slip-law setting against the aging-law setting of the same direct effects (rs_a)."""
    laws = dict(list(slips.groupby("law"))) if not slips.empty else {}
    if "slip" not in laws or "aging" not in laws:
        return
    print("\n## 6d. The twin's records with and without healing at rest: each slip-law setting against the aging-law "
          "setting of the same rs_a (seeds both have): per (interface, n) the ratio of the mean drops and the shift of "
          "the mean ln T (slip - aging), two-sample Kolmogorov-Smirnov p of the drops and of ln T (all single slips), "
          "the estimators (T0 = 1 s; means over the seeds' fits, as 6b) and the hold healing of both")
    for pair_, slip in laws["slip"].groupby("pair"):
        aging = laws["aging"][laws["aging"]["pair"].apply(lambda p: p[0] == pair_[0])]
        for aging_pair, reference in aging.groupby("pair"):
            seeds = sorted(set(slip["seed"]) & set(reference["seed"]))
            mine, theirs = (d[d["seed"].isin(seeds) & ~d["multi"].to_numpy(dtype=bool)] for d in (slip, reference))
            means = [d.assign(lnT=np.log(d["T"])).groupby(["interface", "n"])[["dmu", "lnT"]].mean()
                     for d in (mine, theirs)]
            joined = means[0].join(means[1], rsuffix="_aging", how="inner")
            ratio_, shift = joined["dmu"] / joined["dmu_aging"], joined["lnT"] - joined["lnT_aging"]
            logs = [np.log(d["T"].to_numpy(dtype=float)) for d in (mine, theirs)]
            logs = [x[np.isfinite(x)] for x in logs]
            readings = [pd.DataFrame([_twin_readings(d[d["seed"] == seed]) for seed in seeds]).mean()
                        for d in (slip, reference)]
            names = ("pooled origin", "pooled intercept", "per-interface intercept", "contrast")
            print(f"- slip law rs_b {list(pair_[1]) or 'default'} (b {mine['b'].mean():.4f}, hold healing "
                  f"{twin_healing(mine, 'slip'):.4f}) against the aging law rs_b {list(aging_pair[1])} (b "
                  f"{theirs['b'].mean():.4f}, hold healing {twin_healing(theirs, 'aging'):.4f}), rs_a "
                  f"{list(pair_[0])}, seeds {seeds}: drop ratio {ratio_.min():.2f}-{ratio_.max():.2f} (mean "
                  f"{ratio_.mean():.2f}), ln T shift {shift.min():.2f}-{shift.max():.2f} over {len(joined)} groups; "
                  f"{_ks_line('drops', mine['dmu'], theirs['dmu'])}, {_ks_line('ln T', *logs)} ({len(mine)}, "
                  f"{len(theirs)} slips); "
                  + "; ".join(f"{name} {readings[0][name]:.4f} / {readings[1][name]:.4f}" for name in names))


def _ks_line(name, first, second):
    """Two-sample Kolmogorov-Smirnov D and p, and the slips per record at which that D would be significant at 5 %
    (equal records: ``2 (1.358 / D)^2``)."""
    result = stats.ks_2samp(first, second)
    return (f"KS {name} D {result.statistic:.3f}, p {result.pvalue:.2g} (told apart at 5 % from "
            f"{2 * (1.358 / result.statistic) ** 2:.0f} slips per record)")


def _twin_readings(slips):
    """One seed's readings: the paper's fits pooled and per interface (mean over interfaces), the loading contrast."""
    single = slips[~slips["multi"].to_numpy(dtype=bool)]
    row = {}
    for fit in FITS:
        row[f"pooled {fit}"] = estimate(single["T"], single["dmu"], t0=1.0, fit=fit)["B"]
        row[f"per-interface {fit}"] = float(np.nanmean([estimate(p["T"], p["dmu"], t0=1.0, fit=fit)["B"]
                                                        for _, p in single.groupby("interface")]))
    return row | {"contrast": loading_contrast(slips, t0=1.0)["B"]}


def synthetic_pooling_summary():
    print("\n## 6c. Pooling on synthetic slips (stickslip.statistics.estimator.lab_slips): the paper's strengths "
          "0.15-0.3 (5 interfaces), its loading rates (n + a)(n - a + 1) / 2, n = 1 ... 5 (15 groups), thresholds' "
          "CV 0.1, path spread 0.5 in stacks, 300 slips per group, 10 seeds; the paper: "
          f"{PAPER_B} ± {PAPER_B_ERROR}")
    for B in (0.0, 0.02):
        for order, strengths in (("rising", np.linspace(0.15, 0.3, 5)), ("falling", np.linspace(0.3, 0.15, 5))):
            rows = []
            for seed in range(10):
                slips = lab_slips(np.random.default_rng(seed), 300, B=B, strengths=strengths, disorder=0.1,
                                  path_spread=0.5)
                single = slips[~slips["multi"]]
                row = {}
                for fit in FITS:
                    row[f"pooled {fit}"] = estimate(single["T"], single["dmu"], t0=1.0, fit=fit)["B"]
                    row[f"per-interface {fit}"] = float(np.nanmean(
                        [estimate(p["T"], p["dmu"], t0=1.0, fit=fit)["B"] for _, p in single.groupby("interface")]))
                row["contrast"] = loading_contrast(slips, t0=1.0)["B"]
                row["<ln T>"] = float(np.log(single["T"]).mean())
                rows.append(row)
            rows = pd.DataFrame(rows)
            print(f"- true B {B:g}, strength {order} with a: " + "; ".join(
                f"{k} {seeds_line(over_seeds(rows[k]))}" for k in rows))


def contrast_fem_summary(slips, truth):
    print("\n## 7. The estimator beside the paper's (loading contrast: per interface, the stacks' mean drops against "
          "their mean ln T) against the true B, fem: interface 1 alone (n = 1) and in the n = 2 stack, same seed")
    rows = []
    for (lam, seed), mine in slips.groupby(["strengthening", "seed"]):
        if mine["n"].nunique() < 2:
            continue
        t0 = float(mine["T0"].iloc[0])
        result = loading_contrast(mine[mine["interface"] == 1], t0=t0)
        t = truth[(truth["strengthening"] == lam) & (truth["seed"] == seed) & (truth["n"] == 1)]
        true = float(t["B"].iloc[0]) if len(t) else math.nan
        single = mine[(mine["interface"] == 1) & ~mine["multi"].to_numpy(dtype=bool)]
        needed = slips_needed(float(single.groupby("n")["dmu"].std().mean()), true, result["lnT_range"])
        print(f"- lambda {lam:g}, seed {seed}: B = {fmt(result['B'], result['B_error'])} (<ln T> apart by "
              f"{result['lnT_range']:.2f}); true {true:.4f}; slips per path for 25 % at this reach {needed:.3g} "
              f"(here {result['slips'] // 2})")
        rows.append({"lambda": lam, "B": result["B"], "error": result["B_error"], "true": true})
    for lam, part in pd.DataFrame(rows).groupby("lambda") if rows else []:
        est, tr = over_seeds(part["B"], part["error"]), over_seeds(part["true"])
        print(f"  over seeds, lambda {lam:g}: {seeds_line(est)}; true {seeds_line(tr)}")


def drop_law_summary(runs, truth, clocks):
    """Section 7b: at equal waiting time, do an interface's drops carry its aging (n = 1, same seed)?"""
    slips = run_slips(runs[runs["thermal"] & (runs["n"] == 1) & np.isclose(runs["phi"], PHI, rtol=0.05, atol=0.0)
                           & (runs["N"] == 162)])
    controls = slips[slips["strengthening"] == 0.0]
    if controls.empty or slips["strengthening"].nunique() < 2:
        return
    print("\n## 7b. What (dmu_a, T_a) can tell: an interface's drops against an aging-free interface's drop law at "
          "equal T (n = 1, same seed; single slips; stickslip.statistics.drop_law, bins of half an e-fold, bootstrap "
          "errors): the offset and slope at equal T beside the difference of the true B. The paper's estimator "
          "(origin fit) on the record and on its waiting times with the reference's drop law (at_equal_T): model "
          "clock raw, and as the lab reads it (its eye and clock)")
    true = truth[truth["n"] == 1].set_index(["strengthening", "seed", "strength"])["B"]
    rows = []
    for (lam, strength, seed), mine in slips.groupby(["strengthening", "strength", "seed"]):
        for reference_strength, reference in controls[controls["seed"] == seed].groupby("strength"):
            if (lam, strength) == (0.0, reference_strength) or lam not in clocks:
                continue
            row = {"lambda": lam, "strength": strength, "reference": reference_strength, "seed": seed,
                   "true - reference": true.get((lam, seed, strength), math.nan)
                   - true.get((0.0, seed, reference_strength), math.nan)}
            row |= _drop_law_row(mine, reference, clocks[lam][0], row)
            rows.append(row)
    print("- over seeds:")
    for (lam, strength, reference), part in pd.DataFrame(rows).groupby(["lambda", "strength", "reference"]):
        print(f"  lambda {lam:g}, strength {strength:g} against the aging-free strength {reference:g}: " + "; ".join(
            f"{k} {seeds_line(over_seeds(part[k], part.get(k + ' error')))}" for k in part
            if k not in ("lambda", "strength", "reference", "seed") and not k.endswith("error")))


def _drop_law_row(mine, reference, t0_lab, row):
    """The drop-law contrast and the estimates of one record against one reference, raw and as the lab sees them."""
    t0 = float(mine["T0"].iloc[0])
    out = {}
    for which in EYES:
        seen, ref = (eye(part, t0_lab, which) for part in (mine, reference))
        seen, ref = (part[~part["multi"].to_numpy(dtype=bool)] for part in (seen, ref))
        contrast = drop_law_contrast(seen["T"], seen["dmu"], ref["T"], ref["dmu"], t0=t0)
        swapped = at_equal_T(seen["T"], ref["T"], ref["dmu"], t0=t0, rng=np.random.default_rng(int(row["seed"])))
        clock = t0 if which == "raw" else t0_lab
        out |= {f"{which} slope": contrast["slope"], f"{which} slope error": contrast["slope_error"],
                f"{which} offset": contrast["offset"], f"{which} offset error": contrast["offset_error"],
                f"{which} share": contrast["share"],
                f"{which} estimate": estimate(seen["T"], seen["dmu"], t0=clock, fit="origin")["B"],
                f"{which} estimate at equal T": estimate(*swapped, t0=clock, fit="origin")["B"]}
        print(f"- lambda {row['lambda']:g}, strength {row['strength']:g} against the aging-free strength "
              f"{row['reference']:g}, seed {row['seed']}, {which}: slope at equal T "
              f"{fmt(contrast['slope'], contrast['slope_error'])}, offset "
              f"{fmt(contrast['offset'], contrast['offset_error'])} ({contrast['slips']} slips, "
              f"{contrast['share']:.2f} of them, ln T/T0 {contrast['lnT_low']:.1f}-{contrast['lnT_high']:.1f}); true B "
              f"- reference's {row['true - reference']:.4f}; estimate {out[f'{which} estimate']:.4f}, with the "
              f"reference's drops at its T {out[f'{which} estimate at equal T']:.4f}"
              + (f" ({contrast['reason']})" if contrast["reason"] else ""))
    return out


# --- 8. the pre-check ----------------------------------------------------------------------------------------------

def precheck_summary(runs, studies):
    athermal = runs[~runs["thermal"] & (runs["drive"] == "fixed-lever") & (runs["phi"] < 1e-8)]
    if athermal.empty:
        return
    print(f"\n## 8. The decisive drive's pre-check (athermal, T_a = drive since the previous slip): n = 1 narrow "
          f"(robust spread of ln T <= {NARROW}), n >= 3 broad by the lever (>= {BROAD} per interface, other slips "
          f"taking >= {INTERRUPTED} of its loading)")
    verdicts = {}
    for (N, phi, n), group in athermal.groupby(["N", "phi", "n"]):
        parts = []
        for _, run in group.iterrows():
            slips = run["data"].tables["slip_events"]
            parts.append(slips.assign(seed=run["seed"]))
        slips = pd.concat(parts, ignore_index=True)
        study = Path(group["file"].iloc[0]).parents[3]
        rates = loading_rates(study / "sim" / "fem" / f"{group['run'].iloc[0]}.h5")
        for a, mine in slips.groupby("interface"):
            spread_ = log_spread(mine["wait_drive"])
            share = (mine["interrupted_sig0"] / mine["rise_sig0"]).replace([np.inf, -np.inf], np.nan)
            cv = mine["dmu_sig0"].std() / mine["dmu_sig0"].mean()
            per_seed = [log_spread(p["wait_drive"])["robust"] for _, p in mine.groupby("seed")]
            ok = spread_["robust"] <= NARROW if n == 1 else (
                spread_["std"] >= BROAD and np.nanmean(share) >= INTERRUPTED)
            verdicts.setdefault((N, phi), []).append(bool(ok))
            print(f"- N {N}, Phi {phi:.0e}, n {n}, a = {a}: {spread_['slips']} slips ({group['seed'].nunique()} seeds, "
                  f"{len(mine) / group['seed'].nunique():.0f} per seed); std ln T {fmt(spread_['std'], spread_['std_error_bootstrap'], 2)}, "
                  f"robust {fmt(spread_['robust'], spread_['robust_error_bootstrap'], 2)} (per seed "
                  f"{', '.join(f'{v:.2f}' for v in per_seed)}); interrupted share {np.nanmean(share):.2f}; CV of the "
                  f"drop {cv:.2f}, median drop {mine['dmu_sig0'].median():.3f} sig0; loading rate {rates[a - 1]:.4g} "
                  f"sig0 per eps0; {'meets' if ok else 'fails'} its criterion")
    for (N, phi), oks in sorted(verdicts.items()):
        print(f"- go/no-go, N {N}, Phi {phi:.0e}: {'go' if all(oks) else 'no-go'} ({sum(oks)} of {len(oks)} "
              "interface criteria met)")


# --- 9. the cost -----------------------------------------------------------------------------------------------------

def cost_summary(studies, runs):
    print("\n## 9. The cost: CPU seconds of every simulation and analysis (Snakemake's benchmark files; wall s in "
          "brackets; where a study's analyses have none, their wall time from its Snakemake log)")
    label = {r.run: f"N {r.N}, n {r.n}, Phi {r.phi:.0e}" + (f", lambda {r.strengthening:g}" if r.thermal else "")
             + (f", strength {','.join(f'{s:g}' for s in r.strength)}" if any(s != 1 for s in r.strength) else "")
             + f", seed {r.seed}" for r in runs.itertuples()}
    for study in studies:
        rows = []
        for path in sorted(Path(study, "logs", "benchmarks", "sim").glob("*/*.tsv")):
            table = pd.read_csv(path, sep="\t")
            start = _resumed_at(study, path.parent.name, path.stem)
            rows.append((label.get(path.stem, path.parent.name) + (f", resumed at increment {start}: the CPU of "
                                                                   "its last part" if start else ""),
                         float(table["cpu_time"].iloc[-1]), float(table["s"].iloc[-1]),
                         slipping_pace(study, path.parent.name, path.stem)))
        if not rows:
            continue
        print(f"- {study}: {len(rows)} simulations, {sum(r[1] for r in rows) / 60:.0f} CPU-min")
        for name, cpu, wall, pace in sorted(rows):
            print(f"  {name}: {cpu:.0f} CPU-s ({wall:.0f} s)" + (
                f"; once slipping {pace[0]:.3g} s per increment (increments {pace[1]}-{pace[2]}, wall, its log)"
                if pace else ""))
        events = sorted(Path(study, "logs", "benchmarks", "events").glob("*/*/*.tsv"))
        for path in events:
            table = pd.read_csv(path, sep="\t")
            print(f"  events {path.parts[-3]} {label.get(path.stem, path.stem)}: {table['cpu_time'].iloc[-1]:.0f} CPU-s "
                  f"({table['s'].iloc[-1]:.0f} s)")
        if events:
            total = sum(float(pd.read_csv(path, sep="\t")["cpu_time"].iloc[-1]) for path in events)
            print(f"  events jobs: {total / 60:.0f} CPU-min in {len(events)} jobs")
        else:  # a study run before the analyses had benchmark files: their wall time from the Snakemake log
            for name, minutes in _events_minutes(study, label):
                print(f"  events {name}: {minutes:.1f} min of wall time")


def _events_minutes(study, label):
    """The wall time of every events job with hold trials, from the study's last Snakemake log in logs56/ or
    .snakemake/log (Snakemake's own timestamps)."""
    logs = sorted(Path(study).parent.parent.glob(f"logs56/{Path(study).name}.log"))
    if not logs:
        return []
    jobs, current, stamp = {}, None, None
    for line in logs[-1].read_text().splitlines():
        if line.startswith("[") and line.endswith("]"):
            stamp = pd.to_datetime(line[1:-1], format="%a %b %d %H:%M:%S %Y", errors="coerce")
        elif match := re.match(r"\s+jobid: (\d+)", line):
            current = match.group(1)
            jobs[current] = {"start": stamp}
        elif (match := re.match(r"\s+wildcards: analysis=(thermal-events[^,]*), solver=fem, run_id=(\w+)", line)) \
                and current:
            jobs[current]["name"] = f"{match.group(1)} {label.get(match.group(2), match.group(2))}"
        elif match := re.match(r"Finished jobid: (\d+)", line):
            if match.group(1) in jobs:
                jobs[match.group(1)]["end"] = stamp
    return sorted((job["name"], (job["end"] - job["start"]).total_seconds() / 60) for job in jobs.values()
                  if "name" in job and "end" in job)


# --- 10. the planned configs' cost -----------------------------------------------------------------------------------

#: The configs not run here whose cost section 10 projects.
PLANNED = ("workflow/config/calibration-stacks.yaml", "workflow/config/pooling.yaml", "workflow/config/pilot-probe.yaml",
           "workflow/config/dissonance-pilot.yaml", "workflow/config/dissonance-paper.yaml")


def _cpu(study, kind, run):
    """The CPU seconds of one job from Snakemake's benchmark file (NaN where it has none)."""
    paths = sorted(Path(study, "logs", "benchmarks", kind).glob(f"**/{run}.tsv"))
    return float(pd.read_csv(paths[0], sep="\t")["cpu_time"].iloc[-1]) if paths else math.nan


def _last_job_progress(study, solver, run):
    """A simulation's progress lines in its log since its last job started (its last resume, if any).

    Returns
    -------
    resumed : bool
        Whether the last job resumed a partial run.
    progress : list of tuple
        (increment, elapsed wall seconds of the job, slips so far) per progress line, in the log's order.
    """
    log = Path(study, "logs", "sim", solver, f"{run}.log")
    text = log.read_text() if log.exists() else ""
    resumed = "resuming from" in text
    text = text[text.rindex("resuming from"):] if resumed else text
    progress = [(int(inc), sum(int(v) * 60 ** k for k, v in enumerate(reversed(elapsed.split(":")))), int(slips))
                for inc, elapsed, slips in re.findall(
                    r"fem increments: (\d+)/\d+ increment .*?\[([\d:]+) elapsed.*?slips (\d+)\]", text)]
    return resumed, progress


def _resumed_at(study, solver, run):
    """The increment a simulation's last job resumed at (0 if it ran whole), from its log."""
    resumed, progress = _last_job_progress(study, solver, run)
    return progress[0][0] if resumed and progress else 0


def slipping_pace(study, solver, run):
    """The wall seconds per increment of a simulation once its interfaces slip, from its log's progress lines.

    A run's first increments load it to its first slip and cost a fraction of a slipping increment; a short run's
    mean CPU time per increment understates what a long one costs. Reads the part of the log after its last resume.

    Returns
    -------
    tuple or None
        (seconds per increment, the increment of the first progress line with a slip, the last increment), or None
        where the log has fewer than two progress lines after its first slip.
    """
    slipping = [(inc, seconds) for inc, seconds, slips in _last_job_progress(study, solver, run)[1] if slips > 0]
    if len(slipping) < 2 or slipping[-1][0] == slipping[0][0]:
        return None
    (first, start), (last, end) = slipping[0], slipping[-1]
    return (end - start) / (last - first), first, last




def per_increment(runs):
    """Per run: CPU seconds per increment of its simulation and per hold state of its thermal-events job."""
    rows = []
    for r in runs.itertuples():
        params = r.data.attrs.get("params", {})
        holds = r.holds.attrs["analysis_params"].get("states", math.nan) if r.holds is not None else math.nan
        rows.append({"N": r.N, "n": r.n, "phi": r.phi, "thermal": bool(r.thermal), "lam": r.strengthening,
                     "sim": _cpu(r.study, "sim", r.run) / (int(params.get("max_increments", 1))
                                                            - _resumed_at(r.study, "fem", r.run)),
                     "state": _cpu(r.study, "events/thermal-events", r.run) / holds})
    return pd.DataFrame(rows)


def _mean_rate(rates, **equal):
    """The mean CPU seconds per increment of the runs whose columns equal ``equal``."""
    return float(rates.loc[np.logical_and.reduce([rates[k] == v for k, v in equal.items()]), "sim"].mean())


def planned_cost_summary(runs, configs=PLANNED):
    """Section 10: the CPU time of the planned configs from the per-increment times measured here."""
    rates = per_increment(runs)
    athermal = rates[~rates["thermal"] & np.isclose(rates["phi"], PHI, rtol=0.05, atol=0.0) & rates["sim"].notna()]
    thermal = rates[rates["thermal"] & np.isclose(rates["phi"], PHI, rtol=0.05, atol=0.0) & (rates["N"] == 162)
                    & rates["sim"].notna()]
    size = _mean_rate(athermal, N=162, n=1) / _mean_rate(athermal, N=54, n=1)
    stack = {N: _mean_rate(athermal, N=N, n=3) / _mean_rate(athermal, N=N, n=1) for N in (54, 162)}
    if not (math.isfinite(size) and thermal["lam"].nunique()):
        return
    print("\n## 10. The planned configs' cost, from the CPU time per increment measured here (section 9)")
    print(f"- athermal, Phi = 5e-9: N = 162 / N = 54 per increment (n = 1) {size:.2f} (N = 486 taken as N = 162 times "
          f"the same factor); n = 3 / n = 1 " + ", ".join(f"{v:.2f} at N = {N}" for N, v in stack.items())
          + " (other n: the n = 3 factor times n / 3)")
    f3 = stack[162] if math.isfinite(stack[162]) else stack[54]
    per_lam = thermal[thermal["n"] == 1].groupby("lam")[["sim", "state"]].mean()
    print("- thermal, N = 162, n = 1: CPU-s per increment, per hold state: " + "; ".join(
        f"lambda {lam:g} {row.sim:.3f}, {row.state:.1f}" for lam, row in per_lam.iterrows()))
    for config in configs:
        if not Path(config).exists():
            continue
        study = Study(yaml.safe_load(Path(config).read_text()), [config])
        states = {name: (p.get("states", 0) * (1 + len(p.get("hold_loads", ()))), p.get("hold_interfaces", 1))
                  for name, p in study.analyses.items() if name.startswith("thermal-events")}
        sims = holds = longest = 0.0
        for sim in study.simulations:
            p = sim.params
            lam, n, N = float(p.get("junction_strengthening", 0.0)), int(p["plates"]) - 1, int(p["N"])
            base = per_lam.loc[per_lam.index[np.argmin(abs(per_lam.index - lam))]]
            factor = (size ** (math.log(N / 162) / math.log(3))) * (1.0 if n == 1 else f3 * n / 3)
            seconds = base.sim * factor * int(p["max_increments"])
            state_s = base.state * factor * sum(k for k, m in states.values() if m in (0, n))
            sims, holds, longest = sims + seconds, holds + state_s, max(longest, seconds + state_s)
        print(f"- {config}: {len(study.simulations)} runs, {sims / 3600:.1f} CPU-h of runs + {holds / 3600:.1f} CPU-h "
              f"of hold trials = {(sims + holds) / 3600:.1f} CPU-h; the longest run with its holds {longest / 3600:.1f} "
              "CPU-h")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="+", help="results directories (e.g. results/calibration)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", RuntimeWarning)
    runs = load_calibration_runs(args.studies)
    if runs.empty:
        runs = runs.assign(thermal=[], phi=[], strength=[])
    calibration = calibration_runs(runs)
    truth = truth_table(runs[runs["thermal"].astype(bool)])
    if not calibration.empty:
        cal_truth = truth[truth["strength"] == 1.0]
        alone, clocks = truth_summary(calibration, cal_truth)
        clock_summary(clocks)
        estimator_summary(seed_estimates(alone, clocks), cal_truth, "n = 1 slips, per lambda and seed")
        slips = run_slips(calibration)  # the n = 1 runs and the stacks
        stacked = set(zip(slips.loc[slips["n"] == 2, "strengthening"], slips.loc[slips["n"] == 2, "seed"]))
        both = slips[[key in stacked for key in zip(slips["strengthening"], slips["seed"])]]
        if both["n"].nunique() > 1:
            estimator_summary(seed_estimates(both, clocks), cal_truth,
                              "n = 1 and 2 pooled (the dissonance study's pool)")
        post_slip_summary(alone)
        stack_truth_summary(cal_truth)
        contrast_fem_summary(slips, cal_truth)
        drop_law_summary(runs, truth, clocks)
    if not runs.empty:
        pooling_fem_summary(runs, truth, clocks if not calibration.empty else {})
    twins = twin_slips(args.studies)
    twin_summary(twins)
    synthetic_pooling_summary()
    twin_match_summary(twins)
    if not runs.empty:
        precheck_summary(runs, args.studies)
    cost_summary(args.studies, runs)
    if not runs.empty:
        planned_cost_summary(runs)


if __name__ == "__main__":
    main()
