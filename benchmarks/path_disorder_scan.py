"""Widths of the n = 1 reference against the amplitude of the heterogeneity along the slip path.

    python benchmarks/path_disorder_scan.py [SEEDS [EPSILONS]]

For each ``path_disorder`` epsilon (default 0, 0.01, 0.02, 0.03, 0.04) runs ``rate-state-lever`` with
its defaults (6000 s) on the individual protocol a = 1..5 and the stack n = 5, seeds 1..SEEDS
(default 10), and reads the ground truth's single slips after the analysis's transient (300 s).
Prints, per epsilon and interface:

- the individual protocol (the paper's n = 1 reference): mean dmu_a, its scatter within one run
  (standard deviation, median over the seeds) absolute and relative to the mean, and that of T_a;
- the paper's bound on that scatter: the interfaces' mean dmu_a range over 0.15-0.3, "with the
  differences in mean values larger than the scatter", i.e. below the mean spacing of five means over
  that range, 0.0375;
- std(B_a) (``B_a = dmu_a / ln(T_a / 1 s)``) of the individual protocol and of the stack n = 5, both
  within one run (median over the seeds, the paper's single apparatus) and pooled over the seeds (the
  figures' Fig. 6b), and their ratio (Fig. 6b at n = 5).

Slips are the ground truth (the figures read the recordings; the analysis recovers dmu to ~0.003).
"""

import sys
import time

import numpy as np

from stickslip.experiment.aging import aging_rate
from stickslip.experiment.virtual.rate_state_model import simulate
from stickslip.plugin_params import parse_params
from stickslip.solvers.rate_state_lever import RateStateLeverParams

TRANSIENT = 300.0
#: The paper's individual means span 0.15-0.3 over five interfaces: their mean spacing.
BOUND = (0.3 - 0.15) / 4


def slips(values):
    """Single slips after the transient, with B_a."""
    truth = simulate(parse_params(RateStateLeverParams, values))[1]
    truth = truth[~truth["multi"] & (truth["t_start"] > TRANSIENT) & truth["T"].notna()].copy()
    truth["B_a"] = aging_rate(truth["dmu"], truth["T"])
    return truth


def main(n_seeds, epsilons):
    simulate(parse_params(RateStateLeverParams, {"n": 2, "duration": 20.0}))  # compile
    seeds = range(1, n_seeds + 1)
    for epsilon in epsilons:
        start = time.process_time()
        alone = {a: [slips({"protocol": "individual", "n": 1, "a": a, "seed": s, "path_disorder": epsilon})
                     for s in seeds] for a in range(1, 6)}
        stack = [slips({"n": 5, "seed": s, "path_disorder": epsilon}) for s in seeds]
        print(f"\npath_disorder = {epsilon:g} ({n_seeds} seeds, {time.process_time() - start:.0f} CPU-s)")
        print("  a  mean dmu  std dmu (rel)     std T [s] (rel)   std B_a: n=1 run/pooled   n=5 run/pooled"
              "   ratio run/pooled")
        within = []
        for a in range(1, 6):
            runs = alone[a]
            dmu_std = np.median([r["dmu"].std(ddof=1) for r in runs])
            T_std = np.median([r["T"].std(ddof=1) for r in runs])
            mean_dmu = np.mean([r["dmu"].mean() for r in runs])
            mean_T = np.mean([r["T"].mean() for r in runs])
            within.append(dmu_std)
            B1 = (np.median([r["B_a"].std(ddof=1) for r in runs]),
                  np.concatenate([r["B_a"] for r in runs]).std(ddof=1))
            own = [r[r["a"] == a]["B_a"] for r in stack]
            B5 = (np.median([b.std(ddof=1) for b in own]), np.concatenate(own).std(ddof=1))
            print(f"  {a}  {mean_dmu:.4f}   {dmu_std:.4f} ({dmu_std / mean_dmu:5.1%})   {T_std:6.1f} "
                  f"({T_std / mean_T:5.1%})    {B1[0]:.4f} / {B1[1]:.4f}        {B5[0]:.4f} / {B5[1]:.4f}"
                  f"    {B5[0] / B1[0]:5.1f} / {B5[1] / B1[1]:5.1f}")
        print(f"  scatter within a run, largest over a: {max(within):.4f}; the paper's bound {BOUND:.4f}: "
              f"{'below' if max(within) < BOUND else 'above'}", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10,
         [float(e) for e in sys.argv[2].split(",")] if len(sys.argv) > 2 else [0.0, 0.01, 0.02, 0.03, 0.04])
