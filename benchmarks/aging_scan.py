"""What the aging estimators measure, against rate-and-state twins of known b; why mean B_a rises with n.

    python benchmarks/aging_scan.py OUT [SEEDS]      # run the scan into OUT, print, draw the figure
    python benchmarks/aging_scan.py --study STUDY    # the mechanism of mean B_a(n) in a study's results

The scan: ``rate-state-lever`` stack runs n = 1..5, seeds 1..SEEDS (default 3), 6000 s, path_disorder
0.02, with one (rs_a, rs_b) for every interface, at the pairs of :data:`PAIRS`: b varied at fixed
b - a = 0.006 (the defaults' mean, 0.019 - 0.013) and at fixed a = 0.013. Each run is simulated and
analysed (``experiment-events``, the default parameters) in this process, its files written to OUT
(no workflow: ~1 CPU-s a run instead of ~8 with two jobs' start-up), and the figure
``figS-aging-recovery`` is drawn from them (OUT/figS-aging-recovery.pdf). Prints, per pair:

- the fits through the origin and with a free intercept on every single stack slip (the recordings),
  and the interfaces' mean b (the ground truth's ``interfaces`` table: the seeds' quenched disorder);
- from the ground truth, the growth of the static friction (``mu_before``) and of the friction after
  the slip (``mu_after``) per e-fold of T (intercept fits): what the drop's growth is made of;
- the mechanism table below for interface 1.

The mechanism (also ``--study``: the study's ``experiment-events`` files, shuffled runs left out), per
interface a, from the recordings' single stack slips: the mean B_a = dmu_a / ln(T_a / 1 s) per n; the
same predicted from one line dmu = c + B ln T fitted on all n (what the shorter T at larger n alone
does, with the intercept c > 0); and the offsets c_n of a fit with one slope and an intercept per n
(dmu higher at the same T), next to the direct effect a ln(r_n / r_1) of the n-fold faster loading r_n
(the interface's mu loading rate, ``kinematics.mu_loading_rate``); and the mean B_a had the aging time scale
been T0 = exp(-c/B) (where the line reaches dmu = 0) instead of the paper's 1 s.
"""

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from stickslip import registry
from stickslip.experiment import kinematics
from stickslip.experiment.aging import fit_aging
from stickslip.experiment.timeseries import read_truth
from stickslip.figures import experimental_data
from stickslip.figures.experimental_panels import single_slips
from stickslip.figures.figs_aging_recovery import recovery, run_pairs
from stickslip.lineage import Artifact
from stickslip.plugin_params import parse_params

#: (rs_a, rs_b): b - a = 0.006 from a = 0.005 (the published smooth-PMMA direct effect) to 0.022, and a = 0.013
#: with b - a = 0.003 to 0.012.
PAIRS = ((0.005, 0.011), (0.008, 0.014), (0.013, 0.019), (0.017, 0.023), (0.022, 0.028),
         (0.013, 0.016), (0.013, 0.022), (0.013, 0.025))
TRANSIENT = 300.0


def run_scan(out, seeds):
    """Simulate and analyse every run of the scan into ``out``; the events artifacts (with their parents)."""
    solver, analysis = registry.get("solver", "rate-state-lever"), registry.get("analysis", "experiment-events")
    events = []
    out.mkdir(parents=True, exist_ok=True)
    for rs_a, rs_b in PAIRS:
        start = time.process_time()
        for n in range(1, 6):
            for seed in range(1, seeds + 1):
                params = parse_params(solver.params, {"n": n, "seed": seed, "path_disorder": 0.02, "rs_a": rs_a,
                                                      "rs_b": rs_b})
                run_id = registry.run_id(solver, params)
                raw = Artifact(out / f"{run_id}.h5", run_id, solver.name, solver.produces)
                if not raw.path.exists():
                    try:
                        solver.run(params, raw.path, threads=1, inputs={})
                    except RuntimeError as error:          # an integrator failure: said, and the run left out
                        print(f"FAILED a = {rs_a}, b = {rs_b}, n = {n}, seed {seed}: {error}", flush=True)
                        continue
                derived = registry.derived_run_id(analysis, analysis.params(), [run_id])
                item = Artifact(out / f"{derived}.events.h5", derived, analysis.name, analysis.produces, raw)
                if not item.path.exists():
                    analysis.run(analysis.params(), raw, item.path)
                events.append(item)
        print(f"a = {rs_a}, b = {rs_b}: {5 * seeds} runs, {time.process_time() - start:.0f} CPU-s", flush=True)
    return events


def mechanism(slips, a):
    """Rows per n of interface ``a``: observed mean B_a (+- sem over runs), its prediction from one line
    over all n, the per-n offset of a common-slope fit, and the direct effect of the faster loading."""
    part = slips[(slips["interface"] == a) & np.isfinite(slips["T"].to_numpy(dtype=float))]
    x, y = np.log(part["T"].to_numpy()), part["dmu"].to_numpy()
    line = fit_aging(part["T"], part["dmu"], fit="intercept")
    ns = sorted(part["n"].unique())
    design = np.column_stack([x] + [(part["n"] == n).to_numpy(float) for n in ns])
    coefficients = np.linalg.lstsq(design, y, rcond=None)[0]
    rows = []
    for k, n in enumerate(ns):
        own = part[part["n"] == n]
        per_run = own.groupby("file")["B_a"].mean()
        first = part.iloc[0]
        rate = kinematics.mu_loading_rate(a, n, "stack", k_spring=first["k_spring"], h=first["h"], H=first["H"],
                                          V=first["V"], normal_force=first["normal_force"])
        rows.append({"n": n, "slips": len(own), "B_a": own["B_a"].mean(), "sem": per_run.sem(),
                     "B_a_T0": np.mean(own["dmu"] / (np.log(own["T"]) + line.c / line.B)),
                     "from_T": np.mean((line.c + line.B * np.log(own["T"])) / np.log(own["T"])),
                     "mean_lnT": np.log(own["T"]).mean(), "offset": coefficients[1 + k], "rate": rate})
    table = pd.DataFrame(rows)
    table["offset"] -= table["offset"].iloc[0]
    table["rate_ratio"] = table["rate"] / table["rate"].iloc[0]
    return table, line, coefficients[0]


def print_mechanism(slips, a, rs_a):
    table, line, slope = mechanism(slips, a)
    print(f"  a = {a}: one line over all n: c = {line.c:.4f} +- {line.c_error:.4f}, B = {line.B:.4f} +- "
          f"{line.B_error:.4f}; common slope {slope:.4f}")
    print(f"     n  slips  mean B_a +- sem   from T alone   dmu offset at equal T   rs_a ln(r_n/r_1)   "
          f"mean B_a with T0 = exp(-c/B) = {np.exp(-line.c / line.B):.3f} s")
    for row in table.itertuples():
        print(f"     {row.n}  {row.slips:5d}  {row.B_a:.4f} +- {row.sem:.4f}   {row.from_T:.4f}        "
              f"{row.offset:+.4f}                {rs_a * np.log(row.rate_ratio):+.4f}            {row.B_a_T0:.4f}")


def truth_growth(events):
    """Intercept-fit slopes per e-fold of T of the true drop, mu_before and mu_after (single slips of
    every interface, after the transient), and the interfaces' mean b."""
    truths, bs = [], []
    for item in events:
        truth = read_truth(item.parent.path)
        truths.append(truth[~truth["multi"] & truth["T"].notna() & (truth["t_start"] > TRANSIENT)])
        table = read_truth(item.parent.path, "interfaces")
        bs.append(table.loc[table["slippable"], "b"].to_numpy())
    truth = pd.concat(truths)
    slopes = {column: fit_aging(truth["T"], truth[column], fit="intercept") for column in ("dmu", "mu_before",
                                                                                          "mu_after")}
    return slopes, float(np.mean(np.concatenate(bs)))


def main_scan(out, seeds):
    events = run_scan(out, seeds)
    slips = experimental_data.load_slips(events)
    stack = single_slips(slips, "stack")
    fits, rates = recovery(slips, run_pairs(events))
    print("\n rs_a   rs_b  mean b | origin B       | intercept B     c              | truth (intercept fits, "
          "per e-fold of T): dmu, mu_before, mu_after")
    pair_of = {row.file: (row.rs_a, row.rs_b) for row in run_pairs(events).itertuples()}
    for fit in fits.itertuples():
        chosen = [item for item in events if pair_of[str(item)] == (fit.rs_a, fit.rs_b)]
        slopes, b = truth_growth(chosen)
        print(f" {fit.rs_a:.3f}  {fit.rs_b:.3f}  {b:.4f} | {fit.B_origin:.4f} +- {fit.B_origin_error:.4f} | "
              f"{fit.B_intercept:.4f} +- {fit.B_intercept_error:.4f}  {fit.c:.4f} +- {fit.c_error:.4f} | "
              f"{slopes['dmu'].B:.4f}  {slopes['mu_before'].B:.4f}  {slopes['mu_after'].B:.4f}")
    print("\nmean B_1 against n, relative to n = 1 (+- sem over the seeds):")
    for (rs_a, rs_b), part in rates.groupby(["rs_a", "rs_b"]):
        print(f"  a = {rs_a}, b = {rs_b}: " + "  ".join(f"n={r.n}: {r.relative:.3f}+-{r.relative_error:.3f}"
                                                       for r in part.itertuples()))
    print("\nmechanism, interface 1, per pair:")
    files = run_pairs(events)
    for rs_a, rs_b in PAIRS:
        chosen = files[(files["rs_a"] == rs_a) & (files["rs_b"] == rs_b)]["file"]
        print(f" rs_a = {rs_a}, rs_b = {rs_b}")
        print_mechanism(stack[stack["file"].isin(chosen)], 1, rs_a)
    figure = registry.get("figure", "figS-aging-recovery")
    figure.run(figure.params(), {experimental_data.EVENTS: events}, out / "figS-aging-recovery.pdf")
    print(f"\nfigure: {out / 'figS-aging-recovery.pdf'}")


def main_study(study):
    paths = sorted((Path(study) / "events" / "experiment-events").glob("*/*.h5"))
    slips = experimental_data.load_slips(paths)
    stack = single_slips(slips, "stack")
    print(f"{study}: {len(stack)} single stack slips")
    for a in range(1, 6):
        print_mechanism(stack, a, 0.013)


if __name__ == "__main__":
    if sys.argv[1] == "--study":
        main_study(sys.argv[2])
    else:
        main_scan(Path(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 3)
