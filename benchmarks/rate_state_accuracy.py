"""Event catalogue of the rate-and-state virtual experiment against a tight-tolerance reference integration.

    python benchmarks/rate_state_accuracy.py [SEED] [DURATION]

Runs ``rate-state-lever`` (seed default 1, ``DURATION`` default 6000 s) on the individual protocol
(a = 1) and the stack n = 5 with each compiled method at rtol = 1e-4 (the default) and with RODAS4
at rtol = 1e-8 (the reference; the absolute tolerances scale with rtol), and compares the
ground-truth slips with the reference's. Prints, per integration: accepted steps, CPU seconds of
``simulate`` (compilation excluded), slips, and

- ``agrees until``: the onset [s] of the first reference slip without a slip of the same interface
  within 0.02 s (one force sample) in this run (``end``: none); the stack is chaotic, so every
  integration, the reference at 1e-9 too, parts from the reference at some time;
- the largest differences of onset [s], ``dmu`` and ``dR`` [mm] of the slips before that time,
  against the sensor resolution: force 50 Hz (0.02 s), force noise 0.01 N (``sum mu`` to 0.002 at
  N = 49 N, h/H = 0.1), camera noise 0.002 mm;
- over the whole run, per interface, the mean ``dmu`` and mean recurrence time ``T`` [s] minus the
  reference's (printed with their standard errors, which is what the statistics of a chaotic run
  can be compared with).
"""

import sys
import time

import numpy as np

from stickslip.plugin_params import parse_params
from stickslip.experiment.virtual.rate_state_model import simulate
from stickslip.solvers.rate_state_lever import RateStateLeverParams

RUNS = (("RODAS4", 1e-3), ("RODAS4", 3e-4), ("RODAS4", 1e-4), ("RODAS4", 1e-5), ("RODAS4", 1e-9))
REFERENCE = ("RODAS4", 1e-8)
PROTOCOLS = ({"protocol": "individual", "n": 1, "a": 1}, {"protocol": "stack", "n": 5})
#: One force sample [s].
SAMPLE = 0.02


def catalogue(values, method, rtol):
    """Ground truth, steps and CPU seconds of one run."""
    params = parse_params(RateStateLeverParams, dict(values, method=method, rtol=rtol))
    start = time.process_time()
    _, truth, _, integration = simulate(params)
    return truth, integration["steps"], time.process_time() - start


def agreement(truth, reference):
    """Onset of the first reference slip without a counterpart in ``truth`` (inf: none), and the largest
    |differences| of onset, dmu, dR of the reference slips before it, [3]."""
    worst = np.zeros(3)
    for row in reference.sort_values("t_start").itertuples():
        same = truth[truth["a"] == row.a]
        distance = (same["t_start"] - row.t_start).abs()
        if len(same) == 0 or distance.min() > SAMPLE:
            return row.t_start, worst
        k = distance.idxmin()
        worst = np.maximum(worst, np.abs([same.at[k, "t_start"] - row.t_start, same.at[k, "dmu"] - row.dmu,
                                          same.at[k, "dR"] - row.dR]))
    return np.inf, worst


def statistics(truth):
    """Per interface: mean and standard error of dmu and of T, [a] x 4."""
    grouped = truth.groupby("a")
    return grouped.agg(dmu=("dmu", "mean"), dmu_sem=("dmu", "sem"), T_mean=("T", "mean"), T_sem=("T", "sem"))


def main(seed, duration):
    for method, _ in RUNS:
        catalogue({"protocol": "stack", "n": 2, "seed": seed, "duration": 20.0}, method, 1e-4)  # compile
    for protocol in PROTOCOLS:
        values = dict(protocol, seed=seed, duration=duration)
        reference, steps, cpu = catalogue(values, *REFERENCE)
        ref = statistics(reference)
        print(f"\n{protocol}, seed {seed}, {duration:g} s; reference {REFERENCE[0]} rtol={REFERENCE[1]:g}: {steps} steps, "
              f"{cpu:.2f} CPU-s, {len(reference)} slips")
        print("reference per interface: mean dmu, mean T [s] (standard errors): " + ", ".join(
            f"a={a}: {r.dmu:.4f} ({r.dmu_sem:.4f}), {r.T_mean:.1f} ({r.T_sem:.1f})" for a, r in ref.iterrows()))
        print(f"{'method':8s} {'rtol':>6s} {'steps':>8s} {'CPU [s]':>8s} {'slips':>6s} {'agrees until [s]':>16s} "
              f"{'max|dt| [s]':>11s} {'max|ddmu|':>9s} {'max|ddR| [mm]':>13s}  mean dmu, mean T minus the reference's")
        for method, rtol in RUNS:
            truth, steps, cpu = catalogue(values, method, rtol)
            until, worst = agreement(truth, reference)
            own = statistics(truth)
            shift = own - ref
            shifts = " ".join(f"a={a}: {shift.at[a, 'dmu']:+.4f},{shift.at[a, 'T_mean']:+.1f}" for a in ref.index)
            until_text = "end" if np.isinf(until) else f"{until:.1f}"
            print(f"{method:8s} {rtol:6.0e} {steps:8d} {cpu:8.2f} {len(truth):6d} {until_text:>16s} {worst[0]:11.1e} "
                  f"{worst[1]:9.1e} {worst[2]:13.1e}  {shifts}", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1, float(sys.argv[2]) if len(sys.argv) > 2 else 6000.0)
