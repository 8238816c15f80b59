"""Does every run complete? The rate-and-state virtual experiment over a grid of seeds, in one process.

    python benchmarks/rate_state_robustness.py [FIRST LAST [PATH_DISORDERS]]

Runs ``rate-state-lever`` with its defaults (6000 s) on the stack n = 1..5 and the individual protocol
a = 1..5 for seeds FIRST..LAST (default 1..10) and each path_disorder of the comma-separated list
(default 0,0.02), and prints one line per run (accepted steps, CPU seconds of ``simulate``, slips, or
the integrator's error) and the number of failures.
"""

import sys
import time

from stickslip.experiment.virtual.rate_state_model import simulate
from stickslip.plugin_params import parse_params
from stickslip.solvers.rate_state_lever import RateStateLeverParams


def main(first, last, path_disorders):
    simulate(parse_params(RateStateLeverParams, {"n": 2, "duration": 20.0}))  # compile
    runs = [dict(protocol="stack", n=n, seed=seed, path_disorder=epsilon)
            for epsilon in path_disorders for seed in range(first, last + 1) for n in range(1, 6)]
    runs += [dict(protocol="individual", n=1, a=a, seed=seed, path_disorder=epsilon)
             for epsilon in path_disorders for seed in range(first, last + 1) for a in range(1, 6)]
    total, failures = 0.0, 0
    for values in runs:
        start = time.process_time()
        try:
            _, truth, _, integration = simulate(parse_params(RateStateLeverParams, values))
        except RuntimeError as error:
            failures += 1
            print(f"FAILED {values}: {error}", flush=True)
            continue
        cpu = time.process_time() - start
        total += cpu
        print(f"ok {values}: {integration['steps']} steps, {cpu:.2f} CPU-s, {len(truth)} slips", flush=True)
    print(f"{len(runs)} runs, {failures} failed, {total:.1f} CPU-s")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1, int(sys.argv[2]) if len(sys.argv) > 2 else 10,
         [float(e) for e in sys.argv[3].split(",")] if len(sys.argv) > 3 else [0.0, 0.02])
