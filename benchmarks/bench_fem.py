"""Benchmark of the fem solver: time per time step (after a kick, blocks yielding), or one whole event.

Usage::

    python benchmarks/bench_fem.py --N 1458 --plates 2 --threads 1 --steps 2000
    python benchmarks/bench_fem.py --N 162 --plates 2 --threads 1 --event

The last line printed is ``time_per_step_us=<value>`` (with ``--event`` also the
number of steps and the seconds of the event: load step + kick + minimisation).
Compilation is excluded (warm-up first); numba's cache makes later runs start fast. The
per-step mode loads along an affine shear instead of the (costly, minutes for N = 1458)
linear response: the cost of a step does not depend on it.
"""

import argparse
import time

import numpy as np

from stickslip.fem.dynamics import time_step
from stickslip.fem.event_driven import autoscale
from stickslip.fem.parameters import FemParams
from stickslip.fem.system import System
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.numba_options import njit, set_num_threads


@njit
def _steps(model, state, fe, n):
    for _ in range(n):
        time_step(model, state, fe)


def _affine_response(system):
    """Set an affine simple shear (gamma = eps0) as the loading direction, scaled like the true response."""
    u = np.zeros(system.model.ndof)
    eps0 = system.params.eps0
    u[system.mesh.dofs[:, 0]] = 2.0 * eps0 * system.mesh.coor[:, 1]
    system.restore(u, 2.0 * eps0 * system.heights, 0.0, 0.0)
    eps = system.state.eps.copy()
    scale = autoscale(system.model.epsy, eps)
    system.set_linear_response(scale * u, scale * eps, scale * 2.0 * eps0 * system.heights, 0.0)
    system.restore(np.zeros(system.model.ndof), np.zeros(system.mesh.nlayer), 0.0, 0.0)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--N", type=int, default=1458, help="blocks per interface")
    parser.add_argument("--plates", type=int, default=2)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--steps", type=int, default=2000, help="time steps to time")
    parser.add_argument("--event", action="store_true", help="time one event (load, kick, minimisation)")
    args = parser.parse_args(argv)
    threads = set_num_threads(args.threads)
    mesh = build_stack_mesh(MeshParams(N=args.N, plates=args.plates))
    system = System(FemParams(N=args.N, plates=args.plates, nchunk=200), mesh, threads=threads)
    print(f"N={args.N} plates={args.plates} elements={mesh.nelem} dofs={system.model.ndof} threads={threads}")
    start = time.perf_counter()
    if args.event:
        system.compute_linear_response()
    else:  # timing steps needs no equilibrium: an affine shear is a valid loading direction, and cheap
        _affine_response(system)
    print(f"linear response: {time.perf_counter() - start:.1f} s (includes compilation)")
    system.event_step(kick=False)
    if args.event:
        start = time.perf_counter()
        system.event_step(kick=False)
        system.event_step(kick=True)
        t0 = system.state.t[0]
        niter, _ = system.minimise(margin=5)
        seconds = time.perf_counter() - start
        nsteps = int(round((system.state.t[0] - t0) / system.model.dt))
        print(f"event: steps={nsteps} seconds={seconds:.3f} niter={niter}")
        print(f"time_per_step_us={seconds / nsteps * 1e6:.1f}")
        return
    index = system.state.idx.copy()
    system.event_step(kick=True)
    _steps(system.model, system.state, system._fe, 10)  # warm up (compiles if not cached)
    start = time.perf_counter()
    _steps(system.model, system.state, system._fe, args.steps)
    seconds = time.perf_counter() - start
    yielded = int(np.count_nonzero(system.state.idx != index))
    per_step = seconds / args.steps * 1e6
    print(f"steps={args.steps} seconds={seconds:.3f} gauss_points_yielded={yielded} "
          f"ns_per_element_step={per_step * 1e3 / mesh.nelem:.1f}")
    print(f"time_per_step_us={per_step:.1f}")


if __name__ == "__main__":
    main()
