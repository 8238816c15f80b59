"""Benchmark of the fem solver: time per time step, consecutive events with both relaxations, linear response.

Usage::

    python benchmarks/bench_fem.py --N 1458 --plates 2 --threads 1 --steps 2000
    python benchmarks/bench_fem.py --N 162 --plates 3 --event --events 100 --k_drive 0.081
    python benchmarks/bench_fem.py --N 1458 --plates 6 --linear-response

Per-step mode: time steps right after a kick (blocks yielding), with the ``assembled`` backend
(the CSR plate product, the reference) and with the ``structured`` one (the default); then the cost of each component of a
step (plate product, interface elements incl. the well search, drive, the two Verlet updates,
and the residual that a minimisation adds per step), as wall time and as CPU time of this
process (less distorted when the machine is shared); last lines
``kernel_speedup=<assembled/structured>`` and ``time_per_step_us=<structured>`` (wall time), after
``kernel_speedup_cpu`` (the same ratio in CPU time). It loads
along an affine shear instead of the linear response: the cost of a step does not depend on it.

``--event``: ``--events`` consecutive events (elastic load step, kick, minimisation with
the whole-element fallback, i.e. two increments of the protocol) from one seed, once with
``relaxation = dynamic`` on the ``assembled`` backend (the solver before issue 8) and
once with ``exact`` on the ``structured`` one (both start from the same linear response, the
first run's). Prints per relaxation the total and median time steps and
the wall time per event (mean and median), for all events and by size ``A`` (blocks whose Gauss point 0
changed well, all interfaces), and last
``steps_ratio=<dynamic/exact, all> small_steps_ratio=<dynamic/exact, A < 10>
time_ratio=<dynamic (assembled) / exact (structured) wall time>``.

``--exact-only`` with ``--event``: the exact relaxation alone (to compare two versions of its
solve: run them alternately, each its own process).

``--solve``: the exact relaxation's factorisation and one solve ``A^-1 b`` alone (random ``b``, 300
solves, CPU time of this process); last line ``solve_cpu_us=<value>``.

``--linear-response``: the direct solve of the linear response (factorisation included);
last line ``linear_response_s=<value>``.

Compilation is always excluded (a warm-up first; numba's cache makes later runs start fast).
"""

import argparse
import time

import numpy as np

from stickslip.fem.backends import make_backend
from stickslip.fem.backends.cpu.dynamics import _correct, _predict, residual
from stickslip.fem.backends.cpu.forces import drive_force, interface_forces
from stickslip.fem.backends.cpu.plates import plate_force
from stickslip.fem.constants import derived_constants
from stickslip.fem.equilibrium import WellEquilibrium
from stickslip.fem.event_driven import autoscale
from stickslip.fem.linear_response import LinearResponse
from stickslip.fem.parameters import FemParams
from stickslip.fem.simulation import Simulation
from stickslip.fem.stack import stack_model
from stickslip.fem.yield_strains import interface_initstate, narrowest_well
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.numba_options import njit, set_num_threads

#: Events with fewer blocks yielding than this are "small" in the summary.
SMALL = 10


def affine_response(params, mesh):
    """An affine simple shear (gamma = eps0) as the loading direction, scaled like the true response (timing only:
    no solve; computed on the host's ``structured`` backend, whatever ``params.backend``)."""
    model, wells = stack_model(params, mesh, derived_constants(params, mesh))
    backend = make_backend().prepare(model, mesh, wells.epsy)
    u = np.zeros(model.ndof)
    u[mesh.dofs[:, 0]] = 2.0 * params.eps0 * mesh.coor[:, 1]
    target = 2.0 * params.eps0 * np.asarray(mesh.layer_mid_height)
    backend.set_state(u, target, 0.0, 0.0)
    eps = backend.read("eps")[0].copy()
    scale = autoscale(narrowest_well(interface_initstate(params.seed, mesh.N, mesh.n_interfaces), params.nchunk,
                                     params.eps0, params.eps_offset, params.weibull_k), eps)
    return LinearResponse(scale * u, scale * eps, scale * target, 0.0)


def _loaded_simulation(args, mesh, threads, backend):
    """A simulation right after a kick (blocks yielding), loaded along an affine shear, and its wells before the kick."""
    params = FemParams(N=args.N, plates=args.plates, nchunk=200, backend=backend)
    sim = Simulation(params, mesh, make_backend(backend, threads), response=affine_response(params, mesh))
    sim.loading.step(kick=False)
    index = sim.backend.read("idx")[0].copy()
    sim.loading.step(kick=True)
    return sim, index


def _time_steps(args, mesh, threads, backend):
    sim, index = _loaded_simulation(args, mesh, threads, backend)
    cpu_backend = sim.backend
    cpu_backend.advance(10)  # warm up (compiles if not cached)
    start, cpu = time.perf_counter(), time.process_time()
    cpu_backend.advance(args.steps)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    yielded = int(np.count_nonzero(cpu_backend.read("idx")[0] != index))
    per_step = seconds / args.steps * 1e6
    print(f"{backend}: steps={args.steps} seconds={seconds:.3f} gauss_points_yielded={yielded} "
          f"time_per_step_us={per_step:.1f} cpu_per_step_us={cpu / args.steps * 1e6:.1f} "
          f"ns_per_element_step={per_step * 1e3 / mesh.nelem:.1f}")
    return per_step, cpu


@njit
def _repeat_plates(model, work, state, n):
    for _ in range(n):
        plate_force(work.plates, work.nblock, state.u, state.f)


@njit
def _repeat_interfaces(model, work, state, n):
    for _ in range(n):
        interface_forces(model, work, state, True)


@njit
def _repeat_drive(model, work, state, n):
    for _ in range(n):
        drive_force(model, state)


@njit
def _repeat_predict(model, work, state, n):
    for _ in range(n):
        _predict(0, model.ndof, 0.0, state.u, state.v, state.a)  # dt = 0: same work, state unchanged


@njit
def _repeat_correct(model, work, state, n):
    for _ in range(n):
        _correct(0, model.ndof, model.dt, model.mass_inv, model.damping, state.f, state.v, state.a)


@njit
def _repeat_residual(model, work, state, n):
    total = 0.0
    for _ in range(n):
        total += residual(model, state)
    return total


def _breakdown(args, mesh, threads):
    """Time of each component of a step, serial kernels as in a step (``threads`` as given)."""
    components = (("plates", _repeat_plates), ("interfaces", _repeat_interfaces), ("drive", _repeat_drive),
                  ("predict", _repeat_predict), ("correct", _repeat_correct), ("residual", _repeat_residual))
    repeat = max(1, args.steps // 4)
    for backend in ("assembled", "structured"):
        cpu_backend = _loaded_simulation(args, mesh, threads, backend)[0].backend
        model, work, state = cpu_backend.model, cpu_backend.work, cpu_backend.state
        parts = []
        for name, kernel in components:
            if backend == "structured" or name == "plates":
                kernel(model, work, state, 2)  # compile if not cached
                start, cpu = time.perf_counter(), time.process_time()
                kernel(model, work, state, repeat)
                parts.append(f"{name}={(time.perf_counter() - start) / repeat * 1e6:.1f}/"
                             f"{(time.process_time() - cpu) / repeat * 1e6:.1f}")
        print(f"breakdown {backend} (us per step, wall/cpu): " + " ".join(parts))


def _per_step(args, mesh, threads):
    assembled, assembled_cpu = _time_steps(args, mesh, threads, "assembled")
    structured, structured_cpu = _time_steps(args, mesh, threads, "structured")
    _breakdown(args, mesh, threads)
    print(f"kernel_speedup_cpu={assembled_cpu / structured_cpu:.2f} (CPU time of this process: less distorted on a "
          f"shared machine; one thread only)")
    print(f"kernel_speedup={assembled / structured:.2f}")
    print(f"time_per_step_us={structured:.1f}")


def _events(sim, count):
    """Run ``count`` events; returns arrays (steps, seconds, A, CPU seconds of this process) per event."""
    steps, seconds, sizes, cpu = [], [], [], []
    stack = sim.stack
    dt = sim.model.dt
    for _ in range(count):
        sim.loading.step(kick=False)
        before = stack.well_index()[:, 0]
        t0 = stack.time
        start, cpu_start = time.perf_counter(), time.process_time()
        converged, _ = sim.protocol.kick(sim.params.margin)
        seconds.append(time.perf_counter() - start)
        cpu.append(time.process_time() - cpu_start)
        if not converged:
            raise SystemExit("a block reached the end of its yield strains: use fewer --events or a larger --nchunk")
        steps.append(int(round((stack.time - t0) / dt)))
        sizes.append(int(np.count_nonzero(stack.well_index()[:, 0] != before)))
    return np.array(steps), np.array(seconds), np.array(sizes), np.array(cpu)


def _summary(name, steps, seconds, sizes, cpu):
    for label, keep in (("all", sizes >= 0), (f"A<{SMALL}", sizes < SMALL), (f"A>={SMALL}", sizes >= SMALL)):
        if not keep.any():
            print(f"{name:8s} {label:6s} events=0")
            continue
        print(f"{name:8s} {label:6s} events={keep.sum():4d} steps_total={steps[keep].sum():10d} "
              f"steps_median={np.median(steps[keep]):9.0f} seconds_per_event={seconds[keep].mean():.4f} "
              f"seconds_median={np.median(seconds[keep]):.4f} cpu_per_event={cpu[keep].mean():.4f} "
              f"cpu_median={np.median(cpu[keep]):.4f}")


def _event_mode(args, mesh, threads):
    _compile_kernels()
    runs = {}
    response = None
    relaxations = (("dynamic", "assembled"), ("exact", "structured"))
    for relaxation, backend in relaxations[1:] if args.exact_only else relaxations:
        params = FemParams(N=args.N, plates=args.plates, k_drive=args.k_drive, nchunk=args.nchunk, seed=args.seed,
                           relaxation=relaxation, backend=backend)
        if response is None:
            start = time.perf_counter()
            response = Simulation(params, mesh, make_backend(backend, threads)).loading.response
            print(f"linear response (the first run's relaxation, includes compilation): "
                  f"{time.perf_counter() - start:.2f} s")
        sim = Simulation(params, mesh, make_backend(backend, threads), response=response)
        if relaxation == "exact":
            _ = sim.relaxation.equilibrium  # factorise outside the timing (once per run)
        runs[relaxation] = _events(sim, args.events)
        _summary(relaxation, *runs[relaxation])
    if args.exact_only:
        return
    dyn, fast = runs["dynamic"], runs["exact"]
    same = int(np.argmin(dyn[2] == fast[2])) if not np.array_equal(dyn[2], fast[2]) else args.events
    print(f"event sizes A equal for the first {same} of {args.events} events")
    small = fast[2] < SMALL
    small_dyn = dyn[2] < SMALL
    small_ratio = (dyn[0][small_dyn].mean() / fast[0][small].mean()) if small.any() and small_dyn.any() else np.nan
    print(f"steps_ratio={dyn[0].sum() / fast[0].sum():.2f} small_steps_ratio={small_ratio:.2f} "
          f"time_ratio={dyn[1].sum() / fast[1].sum():.2f}")


def _compile_kernels():
    """Run a few events of a small system with both relaxations (compiles every kernel not cached)."""
    for relaxation in ("dynamic", "exact"):
        for backend in ("assembled", "structured"):
            warm = Simulation(FemParams(N=9, plates=2, nchunk=200, relaxation=relaxation, backend=backend),
                              build_stack_mesh(MeshParams(N=9)), make_backend(backend))
            _events(warm, 3)


def _solve_mode(args, mesh, threads):
    params = FemParams(N=args.N, plates=args.plates, k_drive=args.k_drive, relaxation="exact")
    model, _ = stack_model(params, mesh, derived_constants(params, mesh))
    start = time.process_time()
    equilibrium = WellEquilibrium(model)
    factorised = time.process_time() - start
    b = np.random.default_rng(0).standard_normal(equilibrium.free.size)
    equilibrium.solve(b)  # warm-up (compiles if not cached)
    repeat = 300
    start = time.process_time()
    for _ in range(repeat):
        equilibrium.solve(b)
    per_solve = (time.process_time() - start) / repeat * 1e6
    print(f"free_dofs={equilibrium.free.size} factorisation_cpu_s={factorised:.3f}")
    print(f"solve_cpu_us={per_solve:.1f}")


def _linear_response_mode(args, mesh, threads):
    _compile_kernels()
    start = time.perf_counter()
    Simulation(FemParams(N=args.N, plates=args.plates, nchunk=args.nchunk, relaxation="exact"), mesh,
               make_backend("structured", threads))
    print(f"linear_response_s={time.perf_counter() - start:.2f}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--N", type=int, default=1458, help="blocks per interface")
    parser.add_argument("--plates", type=int, default=2)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--steps", type=int, default=2000, help="time steps to time (per-step mode)")
    parser.add_argument("--event", action="store_true", help="consecutive events with both relaxations")
    parser.add_argument("--exact-only", action="store_true",
                        help="--event with the exact relaxation only (to compare versions of it)")
    parser.add_argument("--events", type=int, default=100, help="number of events (--event)")
    parser.add_argument("--k_drive", type=float, default=1e-3, help="drive stiffness per unit volume (--event)")
    parser.add_argument("--seed", type=int, default=0, help="realisation (--event)")
    parser.add_argument("--nchunk", type=int, default=1000, help="yield strains per block (--event)")
    parser.add_argument("--linear-response", action="store_true", help="time the direct linear response")
    parser.add_argument("--solve", action="store_true", help="time the exact relaxation's factorisation and solve")
    args = parser.parse_args(argv)
    threads = set_num_threads(args.threads)
    mesh = build_stack_mesh(MeshParams(N=args.N, plates=args.plates))
    print(f"N={args.N} plates={args.plates} elements={mesh.nelem} dofs={2 * mesh.nnode} threads={threads}")
    if args.event:
        _event_mode(args, mesh, threads)
    elif args.linear_response:
        _linear_response_mode(args, mesh, threads)
    elif args.solve:
        _solve_mode(args, mesh, threads)
    else:
        _per_step(args, mesh, threads)


if __name__ == "__main__":
    main()
