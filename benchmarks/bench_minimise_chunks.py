"""The cost of the minimisation's chunks: :data:`STEPS_PER_CALL` time steps per call of the compiled loop
(so that Ctrl-C and SIGTERM stop a run within a call) against one call for the whole minimisation.

Usage::

    python benchmarks/bench_minimise_chunks.py            # N = 162, 3 plates, 20 increments, 3 alternations

Both settings run in one process, alternated from the same state (a shared machine's load affects both
alike), on the ``structured`` backend with each relaxation; prints the CPU time [s] of every repetition and
the ratio of the medians (chunks / one call) per relaxation. The trajectories are the same bit for bit
(tests/test_no_hang.py), only the returns to Python differ.
"""

import argparse
import time

import numpy as np

from stickslip.fem.backends import make_backend
from stickslip.fem.backends.cpu import minimise
from stickslip.fem.parameters import FemParams
from stickslip.fem.simulation import Simulation, make_protocol
from stickslip.plugin_params import parse_params
from stickslip.solvers.fem import stack_mesh

#: One call for any minimisation: more time steps than any run makes.
ONE_CALL = 10**12


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--N", default="162")
    parser.add_argument("--plates", default="3")
    parser.add_argument("--k_drive", default="0.081")
    parser.add_argument("--increments", type=int, default=20)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    chunk = minimise.STEPS_PER_CALL
    for relaxation in ("exact", "dynamic"):
        params = parse_params(FemParams, {"N": args.N, "plates": args.plates, "k_drive": args.k_drive,
                                          "relaxation": relaxation})
        simulation = Simulation(params, stack_mesh(params, None), make_backend("structured"))
        start = simulation.stack.stored()
        times = {chunk: [], ONE_CALL: []}
        for _ in range(args.repeat):
            for per_call in times:
                minimise.STEPS_PER_CALL = per_call
                simulation.stack.restore(start)
                protocol = make_protocol(simulation)  # at increment 0: a load comes next
                begin = time.process_time()
                for increment in range(1, args.increments + 1):
                    protocol.step(params.margin, increment)
                times[per_call].append(time.process_time() - begin)
        minimise.STEPS_PER_CALL = chunk
        ratio = np.median(times[chunk]) / np.median(times[ONE_CALL])
        print(f"{relaxation}: chunks of {chunk} steps {[round(t, 3) for t in times[chunk]]} s, one call "
              f"{[round(t, 3) for t in times[ONE_CALL]]} s CPU; ratio of medians {ratio:.4f}")


if __name__ == "__main__":
    main()
