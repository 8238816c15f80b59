"""Benchmark: the whole virtual experimental study, end to end, and its phenomenology.

Generates the paper's experimental study with the ``lever`` solver (stacks n = 1..5 and interfaces
a = 1..5 driven alone, ``--runs`` seeds each, 6000 s per run), analyses every run with
``experiment-events``, draws every experimental figure, and prints the wall time of each stage and
the numbers the paper discusses: P(T_a) for a = 1 against n, the width of P(dmu_a) against n,
std(B_a) against n, R_slow, and the aging fit.

Usage::

    python benchmarks/experimental_study.py [--runs 10] [--workers 2] [--output DIR]
"""

import argparse
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from stickslip import registry
from stickslip.experiment.aging import fit_aging, spread_of_aging_rate
from stickslip.figures.experimental_data import EVENTS, load_interfaces, load_slips
from stickslip.lineage import Artifact
from stickslip.plugin_params import parse_params

FIGURES = ("fig3", "fig4", "fig5", "fig6", "figS-individual", "figS-slip-distributions", "figS-aging-variations",
           "figS-slow-slip")


def _simulate_and_analyse(job):
    name, values, root = job
    solver, analysis = registry.get("solver", "lever"), registry.get("analysis", "experiment-events")
    params = parse_params(solver.params, values)
    raw = Artifact(root / "raw" / f"{name}.h5", registry.run_id(solver, params), solver.name, solver.produces)
    solver.run(params, raw.path, threads=1, inputs={})
    run_id = registry.derived_run_id(analysis, analysis.params(), [raw.run_id])
    events = Artifact(root / "events" / f"{name}.h5", run_id, analysis.name, analysis.produces, raw)
    analysis.run(parse_params(analysis.params, {}), raw, events.path)
    return events


def _figure(job):
    name, inputs, root = job
    plugin = registry.get("figure", name)
    plugin.run(parse_params(plugin.params, {}), {c: inputs[c] for c in plugin.inputs}, root / "figures" / f"{name}.pdf")
    return name


def phenomenology(events):
    """Print the numbers of the paper's experimental phenomenology from the events files."""
    slips = load_slips(events)
    single = slips[~slips["multi"].astype(bool)]
    stack = single[single["protocol"] == "stack"]
    print("\nP(T_a), a = 1 (stack), single slips:  n  count  mean  median  q10  q90 [s]  peaks of P(log10 T)")
    for n, part in stack[stack["interface"] == 1].groupby("n"):
        T = part["T"].dropna().to_numpy()
        counts, edges = np.histogram(np.log10(T), bins=np.arange(0.5, 3.3, 0.1))
        peaks = [f"{10 ** (0.5 * (edges[k] + edges[k + 1])):.0f}" for k in range(1, len(counts) - 1)
                 if counts[k] >= max(counts[k - 1], counts[k + 1]) and counts[k] >= 0.05 * T.size]
        print(f"  {n}  {T.size:5d}  {T.mean():6.1f}  {np.median(T):6.1f}  {np.quantile(T, 0.1):6.1f}  "
              f"{np.quantile(T, 0.9):6.1f}   {', '.join(peaks)}")
    print("\nstd(dmu_a) per n (stack; columns a = 1..4); individual protocol in the last row")
    table = stack.groupby(["n", "interface"])["dmu"].std().unstack()
    print(table.loc[:, [a for a in (1, 2, 3, 4) if a in table.columns]].round(4).to_string())
    alone = single[single["protocol"] == "individual"]
    print("individual", alone.groupby("interface")["dmu"].std().round(4).to_dict(),
          "mean dmu", alone.groupby("interface")["dmu"].mean().round(3).to_dict())
    print("\nstd(B_a) / std(B_a)_{n=1}")
    spread = spread_of_aging_rate(slips)
    print(spread.pivot(index="n", columns="interface", values="std_normalised").round(2).to_string())
    interfaces = load_interfaces(events)
    driven = interfaces[(interfaces["protocol"] == "stack") & interfaces["driven"].astype(bool)]
    print("\nR_slow (mean over runs)")
    print(driven.groupby(["n", "interface"])["R_slow"].mean().unstack().round(3).to_string())
    fit = fit_aging(stack["T"], stack["dmu"])
    print(f"\naging fit on {fit.n_slips} stack slips: B = {fit.B:.4f} +- {fit.B_error:.4f}")
    print(f"multi-interface slips: {int(slips['multi'].sum())} of {len(slips)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="seeds per n and per individual interface")
    parser.add_argument("--workers", type=int, default=2, help="processes")
    parser.add_argument("--output", type=Path, default=None, help="directory (default: a temporary one)")
    args = parser.parse_args()
    root = args.output or Path(tempfile.mkdtemp(prefix="stickslip-experimental-"))
    jobs = [(f"stack_n{n}_s{s}", {"n": n, "seed": s}, root) for n in range(1, 6) for s in range(args.runs)]
    jobs += [(f"individual_a{a}_s{s}", {"protocol": "individual", "a": a, "seed": 100 + s}, root)
             for a in range(1, 6) for s in range(args.runs)]
    start = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        events = list(pool.map(_simulate_and_analyse, jobs))
        simulated = time.perf_counter()
        inputs = {EVENTS: events}
        list(pool.map(_figure, [(name, inputs, root) for name in FIGURES]))
    done = time.perf_counter()
    print(f"{len(jobs)} runs simulated and analysed in {simulated - start:.1f} s; {len(FIGURES)} figures in "
          f"{done - simulated:.1f} s; total {done - start:.1f} s ({args.workers} workers) -> {root}")
    phenomenology(inputs[EVENTS])


if __name__ == "__main__":
    main()
