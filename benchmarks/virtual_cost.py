"""CPU cost of one virtual-experiment run: the threshold ``lever`` against the ``rate-state-lever``.

    python benchmarks/virtual_cost.py [SEED [PATH_DISORDER]]

The runs of the default study's virtual part (workflow/config/default.yaml: stack n = 1..5,
individual protocol a = 1..5, default duration 6000 s) for one seed (default 1), each solver with
its defaults. Prints, per run, the CPU seconds of ``simulate`` (``time.process_time``, numba's
compilation excluded by a first short run; CPU time is less distorted by other processes than wall
time), the slips of the ground truth and, for rate-and-state, the accepted integrator steps (a count
that load does not change); last, the totals and their ratio. Writing the file and the analysis are
not included (they cost the same for both solvers). With ``PATH_DISORDER`` the rate-and-state runs
have that ``path_disorder`` (heterogeneity along the slip path; default 0).
"""

import sys
import time

from stickslip.experiment.virtual.model import simulate as lever_simulate
from stickslip.plugin_params import parse_params
from stickslip.solvers.lever import LeverParams
from stickslip.experiment.virtual.rate_state_model import simulate as rate_state_simulate
from stickslip.solvers.rate_state_lever import RateStateLeverParams

RUNS = [{"protocol": "stack", "n": n} for n in range(1, 6)] + \
       [{"protocol": "individual", "n": 1, "a": a} for a in range(1, 6)]


def cost(simulate, params_class, values):
    """CPU seconds, slips and steps (None for lever) of one run."""
    params = parse_params(params_class, values)
    start = time.process_time()
    out = simulate(params)
    return time.process_time() - start, len(out[1]), out[3]["steps"] if len(out) > 3 else None


def main(seed, path_disorder=0.0):
    for simulate, params_class in ((lever_simulate, LeverParams), (rate_state_simulate, RateStateLeverParams)):
        cost(simulate, params_class, {"protocol": "stack", "n": 2, "seed": seed, "duration": 50.0})  # compile
    print(f"{'run':16s} {'lever CPU [s]':>13s} {'slips':>6s} {'rate-state CPU [s]':>18s} {'slips':>6s} {'steps':>8s}")
    totals = [0.0, 0.0]
    for run in RUNS:
        values = dict(run, seed=seed)
        lever_cpu, lever_slips, _ = cost(lever_simulate, LeverParams, values)
        rs_cpu, rs_slips, steps = cost(rate_state_simulate, RateStateLeverParams,
                                       dict(values, path_disorder=path_disorder))
        totals[0] += lever_cpu
        totals[1] += rs_cpu
        name = f"stack n={run['n']}" if run["protocol"] == "stack" else f"individual a={run['a']}"
        print(f"{name:16s} {lever_cpu:13.2f} {lever_slips:6d} {rs_cpu:18.2f} {rs_slips:6d} {steps:8d}", flush=True)
    print(f"{'total':16s} {totals[0]:13.2f} {'':6s} {totals[1]:18.2f}   ratio {totals[1] / totals[0]:.0f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1, float(sys.argv[2]) if len(sys.argv) > 2 else 0.0)
