"""What emerges in a virtual study, measured against the paper's experimental findings.

    python benchmarks/rate_state_emergence.py results/rate-state

Reads the study's results database (``STUDY/stickslip.sqlite``, table ``slip_events_full``: every
slip the ``experiment-events`` analysis detected, with its run's protocol, n and seed) and, for the
slow slip, the ``interfaces`` tables of the study's ``experiment-events`` files (R_slow is not in the
database). Prints the numbers of the emergence table of docs/experiment-model-rate-state.md, each
with its counting error (standard error of a mean or median, ``std / sqrt(2 (N - 1))`` for a standard
deviation, sqrt(N) for a count; over seeds for R_slow):

- the individual protocol: mean dmu_a and T_a per interface;
- P(T_1) against n: median, counts per 0.2 decade (peaks);
- P(dmu_1) against n: mean, standard deviation, most populated 0.02 bin;
- the aging fit (origin and free intercept) on all stack slips, and per n;
- mean and standard deviation of B_a per interface and n, the latter normalised by n = 1; and the
  standard deviation within one seed (the paper's situation: one apparatus), median over the seeds,
  normalised by the same of the individual protocol;
- R_slow per interface and n, and with the slabs shuffled (the runs with a ``slab_order`` are left out
  of everything else);
- slips in multi-slip events.
Slips in the first ``t_exclude`` = 300 s are already left out by the analysis.
"""

import json
import sqlite3
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from stickslip.experiment.aging import aging_rate, fit_aging, spread_of_aging_rate
from stickslip.figures.experimental_data import load_interfaces


def load(study):
    """Slips of the study's database, the runs with the slabs shuffled left out: columns a, n,
    protocol, seed, run, dmu, T, B_a, multi."""
    with sqlite3.connect(Path(study) / "stickslip.sqlite") as db:
        rows = pd.read_sql("SELECT e.simulation_run_id AS run, e.interface AS a, e.dmu, e.multi, e.extra, e.protocol, "
                           "e.n, e.seed, r.params FROM slip_events_full AS e JOIN runs AS r "
                           "ON r.run_id = e.simulation_run_id WHERE e.analysis = 'experiment-events'", db)
    shuffled = np.array([bool(json.loads(text).get("slab_order")) for text in rows.pop("params")], dtype=bool)
    rows = rows[~shuffled].reset_index(drop=True)
    extra = pd.DataFrame([json.loads(text) for text in rows.pop("extra")], index=rows.index)
    slips = rows.assign(T=extra["T"].astype(float))
    slips["B_a"] = aging_rate(slips["dmu"], slips["T"])
    slips.loc[slips["protocol"] == "individual", "n"] = 1
    return slips


def sem(values):
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return values.std(ddof=1) / np.sqrt(values.size) if values.size > 1 else np.nan


def std_error(values):
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return values.std(ddof=1) / np.sqrt(2 * (values.size - 1)) if values.size > 2 else np.nan


def main(study):
    slips = load(study)
    stack = slips[slips["protocol"] == "stack"]
    print(f"{len(slips)} slips, {slips['run'].nunique()} runs, seeds {sorted(stack['seed'].unique())}")

    print("\nindividual protocol: a, slips, mean dmu_a +- sem, mean T_a +- sem [s]")
    for a, part in slips[slips["protocol"] == "individual"].groupby("a"):
        print(f"  a={a}: {len(part):4d}  dmu {part['dmu'].mean():.3f} +- {sem(part['dmu']):.3f}"
              f"  T {part['T'].mean():6.1f} +- {sem(part['T']):.1f}")

    edges = 10 ** np.arange(0.4, 3.01, 0.2)
    print(f"\nP(T_1), stack: n, slips, median T_1 +- 1.25 sem [s], counts per 0.2 decade from 10^0.4 s")
    for n, part in stack[stack["a"] == 1].groupby("n"):
        T = part["T"].dropna()
        counts, _ = np.histogram(T, edges)
        print(f"  n={n}: {len(T):4d}  median {T.median():6.1f} +- {1.2533 * sem(T):4.1f}  {' '.join(map(str, counts))}")

    print("\nP(dmu_1), stack: n, mean +- sem, std +- err, most populated 0.02 bin, counts per 0.02 bin")
    dmu_edges = np.arange(0.0, 0.5001, 0.02)
    for n, part in stack[stack["a"] == 1].groupby("n"):
        counts, _ = np.histogram(part["dmu"], dmu_edges)
        mode = dmu_edges[np.argmax(counts)]
        print(f"  n={n}: mean {part['dmu'].mean():.3f} +- {sem(part['dmu']):.3f}  std {part['dmu'].std(ddof=1):.3f}"
              f" +- {std_error(part['dmu']):.3f}  mode [{mode:.2f}, {mode + 0.02:.2f})  counts per 0.02 from 0.10: "
              f"{' '.join(map(str, counts[5:18]))}")

    print("\naging fit dmu = c + B ln(T/1 s) on log bins, all stack slips with a T, and per n")
    valid = stack.dropna(subset=["T"])
    for fit in ("origin", "intercept"):
        result = fit_aging(valid["T"], valid["dmu"], fit=fit)
        per_n = []
        for n, part in valid.groupby("n"):
            try:
                per_n.append(f"n={n}: {fit_aging(part['T'], part['dmu'], fit=fit).B:.3f}")
            except ValueError:
                per_n.append(f"n={n}: -")
        print(f"  {fit:9s}: B = {result.B:.4f} +- {result.B_error:.4f}, c = {result.c:.4f} +- {result.c_error:.4f}"
              f"  ({'; '.join(per_n)})")

    print("\nB_a = dmu_a / ln(T_a / 1 s): mean +- sem per a (rows) and n (columns; n = 1: individual protocol)")
    table = slips.dropna(subset=["B_a"])
    for a, part in table.groupby("a"):
        cells = [f"n={n}: {g['B_a'].mean():.4f}+-{sem(g['B_a']):.4f}" for n, g in part.groupby("n")]
        print(f"  a={a}: " + "  ".join(cells))
    print("\nstd(B_a) +- err per a and n, and normalised by its n = 1 value +- jackknife error over the seeds "
          "(spread_of_aging_rate)")
    spread = spread_of_aging_rate(slips.rename(columns={"a": "interface"}))
    for a, part in table.groupby("a"):
        errors = {n: std_error(g["B_a"]) for n, g in part.groupby("n")}
        rows = spread[spread["interface"] == a]
        cells = [f"n={r.n}: {r.std:.4f}+-{errors.get(r.n, np.nan):.4f} ({r.std_normalised:.2f}"
                 f"+-{r.std_normalised_error:.2f}x, N={r.count})" for r in rows.itertuples()]
        print(f"  a={a}: " + "  ".join(cells))

    print("\nstd(B_a) within one seed (one apparatus: the seeds' quenched disorder left out): median over the seeds "
          "per a and n, normalised by that of the individual protocol (n = 1, also within one seed)")
    individual = table[table["protocol"] == "individual"].groupby(["a", "seed"])["B_a"].std().groupby("a").median()
    for a, part in table[table["protocol"] == "stack"].groupby("a"):
        cells = [f"n={n}: {g.groupby('seed')['B_a'].std().median():.4f}"
                 f" ({g.groupby('seed')['B_a'].std().median() / individual.get(a, np.nan):.1f}x)"
                 for n, g in part.groupby("n") if n > 1]
        print(f"  a={a}: n=1: {individual.get(a, np.nan):.4f}  " + "  ".join(cells))

    paths = sorted((Path(study) / "events" / "experiment-events").glob("*/*.h5"))
    interfaces = load_interfaces(paths, shuffled=True)
    driven = interfaces[(interfaces["protocol"] == "stack") & (interfaces["interface"] <= interfaces["n"])]
    print("\nR_slow = 1 - sum(dR)/R_tot, stack, mean +- sem over seeds, per a (rows) and n (columns); 'shuffled':"
          " n = 5 with the slabs shuffled (a is the position)")
    for a, part in driven.groupby("interface"):
        cells = [f"n={n}: {g['R_slow'].mean():.3f}+-{sem(g['R_slow']):.3f}" for n, g in
                 part[~part["shuffled"]].groupby("n")]
        moved = part[part["shuffled"]]
        if len(moved):
            cells.append(f"shuffled ({moved['slab_order'].iloc[0]}): {moved['R_slow'].mean():.3f}+-"
                         f"{sem(moved['R_slow']):.3f}")
        print(f"  a={a}: " + "  ".join(cells))

    multi = int(slips["multi"].astype(bool).sum())
    print(f"\nslips in multi-slip events: {multi} of {len(slips)} (+- {np.sqrt(multi):.0f})")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "results/rate-state")
