"""Fidelity of ``relaxation = exact`` against the paper's ``dynamic`` protocol (issue 8, checks a and b).

Usage::

    python benchmarks/fem_relaxation_fidelity.py reference [--tol 1e-5]
    python benchmarks/fem_relaxation_fidelity.py time-step --N 54 --plates 3 --phi 5e-4 \\
        --increments 4000 --dir runs/ [--scales 1 2 4] [--relaxation exact]
    python benchmarks/fem_relaxation_fidelity.py statistics --N 54 --plates 3 --phi 5e-4 \\
        --increments 4000 --dir runs/ [--stored]
    python benchmarks/fem_relaxation_fidelity.py paired --N 54 --plates 3 --phi 5e-4 --increments 4000 \\
        --dir runs/ --start 100 --kicks 40 --variants dynamic:200:1 exact:200:1 exact:1000:1
    python benchmarks/fem_relaxation_fidelity.py stability --N 54 --plates 3 [--scales 1 2 4 8]

``reference`` (check a): the N = 9 reference case (FixedLever_historic), both relaxations
from the same linear response (the dynamic one), increment by increment: where the
per-increment ``S_a1``, ``A_a1`` first differ, the largest relative difference of the
stress ``sigd`` after the kicks before that, and, after the first kick, how far the dynamic
end state is from the exact equilibrium of its own wells (the dynamic tolerance's error).

``statistics`` (check b): one run per relaxation (real run files in ``--dir``, resumed if
present; the exact one is the ``time-step`` run with ``dt_scale`` 1), then the steady-state
slip statistics of each (:mod:`stickslip.events.extraction`): rho(s), P(Delta mu_a) and the
sizes ``S`` (well changes, all interfaces) of all steady-state events, compared by the tests
of :mod:`stickslip.statistics.sample_comparison`, each with the difference it could detect. Last
line ``slips=<dynamic>,<exact> rho_p=<chi2 p> dmu_ks_p=<KS p> dmu_ad_p=<AD p>
size_ad_p=<AD p>``. ``--stored`` analyses the files as they are (a run still going, or
stopped before ``--increments``, is read up to its last committed increment). ``--start K``
takes the statistics from increment K on instead of the extraction's steady state (which
needs a slip, ``A_a = N``, of every interface: rare for some interfaces at N = 54).

``time-step``: the same statistics from runs with ``dt_scale`` 1, 2 and 4 (``--scales``;
default with ``relaxation = exact``), each compared with the first.

``paired``: ``--kicks`` stored states before a kick (evenly spread from ``--start`` over the
exact ``dt_scale`` 1 run, which must exist), each kicked and minimised with every variant
``relaxation:quiet_steps:dt_scale``; against the first variant: in how many events every Gauss
point ends in the same well, whether the event size ``S`` is equal, larger or smaller (Wilcoxon
signed-rank test of the differences: a systematic sign), the mean ``S``, and the relative
difference of the stress after the event. Pairs need no slip statistics: tens of events show a
systematic difference that run-against-run tests would need thousands of events for.

``stability``: the explicit stability limit of the time step, ``2 / omega_max`` with
``omega_max^2`` the largest eigenvalue of ``M^-1 A`` (lumped mass ``M``, ``A`` the plates
and the interfaces with the elastic law, their stiffest state; the drive is negligible),
in units of the paper's dt; then, from the same kicked state, ``--steps`` time steps with
each ``dt_scale`` of ``--scales`` and with 0.95 and 1.05 times the limit: stable, or the
kinetic energy blows up (1e3 times the largest with the first scale).
"""

import argparse
import time
from pathlib import Path

import numpy as np
from scipy import sparse, stats
from scipy.sparse.linalg import eigsh

from stickslip import registry
from stickslip.events.extraction import classify_increments, slip_interfaces, steady_slips
from stickslip.statistics.sample_comparison import SlipSample, compare_slip_samples
from stickslip.fem.backends import make_backend
from stickslip.fem.observables import Observer
from stickslip.fem.parameters import FemParams
from stickslip.fem.stiffness import stiffness_ratio
from stickslip.fem.simulation import Simulation
from stickslip.formats.fem_run import RunFile, read_increments, read_run_attrs
from stickslip.h5io import open_file
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.plugin_params import parse_params

REFERENCE_CASE = {"N": 9, "plates": 2, "seed": 0, "k_drive": 1e-3, "nchunk": 200}


def _increments(sim, count):
    """The protocol's increments (load step, kick) until the margin stop or ``count`` kicks; rows of observables."""
    observer = Observer(sim)
    previous = observer.well_index()
    rows = []
    margin = sim.params.margin
    for _ in range(count):
        sim.loading.step(False)
        if not sim.stack.within_margin(margin):
            break
        rows.append(observer.observe(previous))
        previous = observer.well_index()
        if not sim.protocol.kick(margin)[0]:
            break
        rows.append(observer.observe(previous))
        previous = observer.well_index()
    return rows


def reference(args):
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    case = {**REFERENCE_CASE, "tol": args.tol}
    linear = Simulation(FemParams(**case), mesh, make_backend()).loading.response
    out = {}
    for relaxation in ("dynamic", "exact"):
        sim = Simulation(FemParams(**case, relaxation=relaxation), mesh, make_backend(), response=linear)
        start = time.perf_counter()
        out[relaxation] = _increments(sim, 1000)
        print(f"{relaxation}: {len(out[relaxation])} increments, {sim.stack.time / sim.model.dt:.0f} time "
              f"steps, {time.perf_counter() - start:.1f} s")
    a, b = out["dynamic"], out["exact"]
    n = min(len(a), len(b))
    same = [(a[i]["S_a1"], a[i]["A_a1"]) == (b[i]["S_a1"], b[i]["A_a1"]) for i in range(n)]
    first = same.index(False) if not all(same) else n
    kicks = list(range(1, first, 2))  # rows 1, 3, ... are kicks (row i is increment i + 1)
    rel = np.array([abs(a[i]["sigd"] - b[i]["sigd"]) / abs(a[i]["sigd"]) for i in kicks])
    print(f"S_a1 and A_a1 equal on increments 1..{first} of {n}"
          + (f"; first difference at increment {first + 1}" if first < n else ""))
    print(f"stress after the kicks while equal: max relative difference {rel.max():.2e}, median {np.median(rel):.2e}")
    for i in range(max(first - 2, 0), min(first + 2, n)):
        print(f"  increment {i + 1}: (S_a1, A_a1, sigd) dynamic {a[i]['S_a1']}, {a[i]['A_a1']}, {a[i]['sigd']:.9f}; "
              f"exact {b[i]['S_a1']}, {b[i]['A_a1']}, {b[i]['sigd']:.9f}")
    sim = Simulation(FemParams(**case), mesh, make_backend(), response=linear)
    sim.loading.step(False)
    sim.protocol.kick(sim.params.margin)
    u = sim.backend.read("u")[0].copy()
    exact = Simulation(FemParams(**case, relaxation="exact"), mesh, make_backend(), response=linear).relaxation
    assert exact.solve_in_wells(sim.backend)
    distance = np.abs(u - sim.backend.read("u")[0]).max() / np.abs(u).max()
    print(f"first kick: the dynamic end state is {distance:.2e} "
          f"(relative, max norm) from the exact equilibrium of its own wells")


def _run(params, path):
    plugin = registry.get("solver", "fem")
    start = time.perf_counter()
    plugin.run(parse_params(plugin.params, params), path, threads=1, inputs={})
    return time.perf_counter() - start


def _params(args, relaxation, dt_scale):
    """Solver parameters of one run; the exact run with dt_scale 1 is shared by both checks."""
    return {"N": args.N, "plates": args.plates, "k_drive": args.k_drive, "seed": args.seed,
            "max_increments": args.increments, "relaxation": relaxation, "dt_scale": dt_scale}


def _run_path(params, directory):
    name = "_".join(f"{key}{value}" for key, value in params.items() if key != "max_increments")
    path = Path(directory) / f"{name}.h5"
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _slip_sample(label, params, args):
    """Run (or resume) one simulation unless ``--stored``; the SlipSample of its steady state."""
    path = _run_path(params, args.dir)
    seconds = 0.0 if args.stored else _run(params, path)
    table = read_increments(path)
    N, n = params["N"], params["plates"] - 1
    classified = classify_increments(table, N)
    if args.start is not None:  # instead of the extraction's steady state (needs every interface to slip once)
        classified["steady"] = classified["increment"].to_numpy() >= args.start
    slips = steady_slips(classified, N)
    counts = np.array([(slips["s"] == s).sum() for s in range(1, n + 1)])
    drops = slip_interfaces(classified, N)["dmu_sig0"].to_numpy()
    events = classified["kick"].to_numpy() & classified["steady"].to_numpy(dtype=bool)
    sizes = classified.loc[events, [f"S_a{a}" for a in range(1, n + 1)]].sum(axis=1).to_numpy()
    if not events.any():
        raise SystemExit(f"{path}: no steady state in {len(table)} increments; run more (--increments)")
    kicks = max(int(table["kick"].iloc[1:].sum()), 1)
    steps = table["t"].iloc[-1] / read_run_attrs(path)["dt"] / kicks
    print(f"{label}: {len(table)} increments ({seconds:.0f} s this call), steady state from increment "
          f"{classified['increment'][classified['steady']].min()}, {events.sum()} steady-state events "
          f"(size S: mean {sizes.mean():.1f}, median {np.median(sizes):.0f}, max {sizes.max()}), {len(slips)} "
          f"slip events, counts by s = {counts.tolist()}, Delta mu_a: {drops.size} values, mean "
          f"{drops.mean():.4f} std {drops.std():.4f} (sig0), time steps per kick {steps:.0f}")
    return SlipSample(counts, drops, sizes)


def _compare(first, second):
    """Print the two-sample tests (:func:`stickslip.statistics.sample_comparison.compare_slip_samples`); summary line."""
    r = compare_slip_samples(first, second)
    d, z = r["dmu"], r["size"]
    print(f"  rho(s): {np.round(r['rho_1'], 3).tolist()} against {np.round(r['rho_2'], 3).tolist()}, chi-square "
          f"{r['rho_chi2']:.2f} p = {r['rho_p']:.3f}; rho(s>1) {r['multi_1']:.3f} against {r['multi_2']:.3f}, "
          f"detectable difference {r['multi_resolution']:.3f}")
    print(f"  P(Delta mu_a): {d['count_1']} against {d['count_2']} values, KS D = {d['ks']:.3f} p = {d['ks_p']:.3f} "
          f"(D significant above {d['ks_resolution']:.3f}), Anderson-Darling p = {d['ad_p']:.3f}, mean shift "
          f"{d['shift']:+.3f} p = {d['shift_p']:.3f} (detectable {d['detectable_shift']:.3f})")
    print(f"  P(S) of all steady-state events: {z['count_1']} against {z['count_2']}, KS D = {z['ks']:.3f} "
          f"p = {z['ks_p']:.3f} (D significant above {z['ks_resolution']:.3f}), Anderson-Darling p = {z['ad_p']:.3f}")
    return (f"slips={d['count_1']},{d['count_2']} rho_p={r['rho_p']:.3f} dmu_ks_p={d['ks_p']:.3f} "
            f"dmu_ad_p={d['ad_p']:.3f} size_ad_p={z['ad_p']:.3f}")


def statistics(args):
    samples = {relaxation: _slip_sample(relaxation, _params(args, relaxation, 1.0), args)
               for relaxation in ("exact", "dynamic")}
    print("dynamic against exact:")
    print(_compare(samples["dynamic"], samples["exact"]))


def time_step_study(args):
    runs = {scale: _slip_sample(f"dt_scale={scale:g}", _params(args, args.relaxation, scale), args)
            for scale in args.scales}
    for scale in args.scales[1:]:
        print(f"dt_scale={scale:g} against {args.scales[0]:g}:")
        print(_compare(runs[args.scales[0]], runs[scale]))


def _kick_outcomes(params, mesh, response, states):
    """Kick and minimise every stored state with ``params``; per state (S, global well indices, sigd)."""
    sim = Simulation(FemParams(**params), mesh, make_backend(), response=response)
    observer = Observer(sim)
    out = []
    for state in states:
        sim.stack.restore(state)
        previous = observer.well_index()
        if not sim.protocol.kick(sim.params.margin)[0]:
            raise SystemExit("a kick reached the margin")
        row = observer.observe(previous)
        size = sum(value for key, value in row.items() if key.startswith("S_a"))
        out.append((size, sim.stack.well_index(), row["sigd"]))
    return out


def paired(args):
    """The same stored states (before a kick) kicked with each variant; outcomes against the first variant."""
    path = _run_path(_params(args, "exact", 1.0), args.dir)
    with open_file(path) as file:
        run = RunFile(file)
        kick = file["increments"]["kick"][: run.nstored]
        before = [i for i in range(args.start or 2, run.nstored - 1) if not kick[i]]
        chosen = before[:: max(len(before) // args.kicks, 1)][: args.kicks]
        states = [run.state(i) for i in chosen]
        response, mesh = run.linear_response(), run.mesh
    base = {"N": args.N, "plates": args.plates, "k_drive": args.k_drive, "seed": args.seed}
    outcomes = {}
    for variant in args.variants:
        relaxation, quiet, scale = variant.split(":")
        start = time.perf_counter()
        outcomes[variant] = _kick_outcomes({**base, "relaxation": relaxation, "quiet_steps": int(quiet),
                                            "dt_scale": float(scale)}, mesh, response, states)
        print(f"{variant}: {len(states)} kicks from the stored states {chosen[0]} ... {chosen[-1]} of {path.name}, "
              f"{time.perf_counter() - start:.0f} s")
    reference = outcomes[args.variants[0]]
    ref_size = np.array([o[0] for o in reference])
    for variant in args.variants[1:]:
        size = np.array([o[0] for o in outcomes[variant]])
        same = np.array([np.array_equal(a[1], b[1]) for a, b in zip(reference, outcomes[variant])])
        stress = np.array([abs(a[2] - b[2]) / abs(a[2]) for a, b in zip(reference, outcomes[variant])])
        diff = size - ref_size
        sign_p = stats.wilcoxon(diff).pvalue if np.any(diff) else 1.0
        print(f"{variant} against {args.variants[0]}: same wells after the event in {same.sum()} of {same.size}; "
              f"event size S equal in {np.sum(diff == 0)}, larger in {np.sum(diff > 0)}, smaller in "
              f"{np.sum(diff < 0)} (Wilcoxon signed-rank p = {sign_p:.3g}); mean S {size.mean():.1f} against "
              f"{ref_size.mean():.1f}; stress after the event: relative difference median "
              f"{np.median(stress):.1e}, max {stress.max():.1e}; where the wells agree: max "
              f"{stress[same].max() if same.any() else float('nan'):.1e}")


def _kinetic_energy(backend):
    free = backend.model.mass_inv > 0
    return 0.5 * float(np.sum(backend.read("v")[0][free] ** 2 / backend.model.mass_inv[free]))


def stability(args):
    """The explicit stability limit of the time step: computed, then tried after a kick."""
    mesh = build_stack_mesh(MeshParams(N=args.N, plates=args.plates))
    params = {"N": args.N, "plates": args.plates, "k_drive": args.k_drive, "relaxation": "exact"}
    sim = Simulation(FemParams(**params), mesh, make_backend())
    equilibrium, model = sim.relaxation.equilibrium, sim.model
    stiffness = equilibrium.matrix  # plates + interfaces with the elastic (stiffest) law, free DOFs
    weight = sparse.diags(np.sqrt(model.mass_inv[equilibrium.free]))
    omega = float(np.sqrt(eigsh(weight @ stiffness @ weight, k=1, which="LA", return_eigenvectors=False)[0]))
    limit = 2.0 / omega / model.dt
    print(f"omega_max = {omega:.4f} (lumped mass, elastic stiffness without the drive): velocity Verlet is "
          f"stable (undamped) for dt < 2 / omega_max = {limit:.2f} dt")
    sim.loading.step(False)
    sim.loading.step(True)
    kicked = sim.stack.stored()
    bound = np.inf  # 1e3 times the largest kinetic energy with the first dt_scale
    for scale in (*args.scales, 0.95 * limit, 1.05 * limit):
        trial = Simulation(FemParams(**params, dt_scale=scale), mesh, make_backend(), response=sim.loading.response)
        trial.stack.restore(kicked)
        energy = np.empty(args.steps)
        for i in range(args.steps):
            trial.backend.advance(1)
            energy[i] = _kinetic_energy(trial.backend)
            if not energy[i] < bound:
                break
        stable = i + 1 == args.steps
        print(f"dt_scale={scale:.2f}: {i + 1} time steps ({(i + 1) * scale:.0f} dt), kinetic energy max "
              f"{energy[: i + 1].max():.3e}, last {energy[i]:.3e}: "
              f"{'stable' if stable else 'BLOWS UP (1e3 times the largest kinetic energy with dt_scale 1)'}")
        bound = min(bound, 1e3 * energy.max()) if stable else bound


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="check", required=True)
    ref = sub.add_parser("reference", help="check a: the N = 9 reference case increment by increment")
    ref.add_argument("--tol", type=float, default=1e-5, help="minimisation tolerance of both relaxations")
    stat = sub.add_parser("statistics", help="check b: slip statistics of one run per relaxation")
    step = sub.add_parser("time-step", help="slip statistics with dt, 2 dt and 4 dt")
    step.add_argument("--relaxation", default="exact", choices=("dynamic", "exact"))
    pair = sub.add_parser("paired", help="stored states kicked with each variant (relaxation:quiet_steps:dt_scale)")
    pair.add_argument("--variants", nargs="+", default=["dynamic:200:1", "exact:200:1"],
                      help="relaxation:quiet_steps:dt_scale, the first is the reference")
    pair.add_argument("--kicks", type=int, default=50, help="stored states to kick (evenly spread)")
    for command in (stat, step, pair):
        command.add_argument("--N", type=int, default=54)
        command.add_argument("--plates", type=int, default=3)
        drive = command.add_mutually_exclusive_group(required=True)
        drive.add_argument("--k_drive", type=float, help="drive stiffness per unit volume")
        drive.add_argument("--phi", type=float, help="rigidity ratio Phi (5e-4 stiff, 5e-7 compliant); sets k_drive")
        command.add_argument("--seed", type=int, default=0)
        command.add_argument("--increments", type=int, default=4000)
        command.add_argument("--dir", default="fidelity-runs", help="directory of the run files (resumed if present)")
        command.add_argument("--start", type=int, help="statistics from this increment on (default: the steady "
                             "state of stickslip.events.extraction)")
        command.add_argument("--stored", action="store_true",
                             help="analyse the run files as stored (also while running or stopped), run nothing")
    step.add_argument("--scales", type=float, nargs="+", default=[1.0, 2.0, 4.0],
                      help="dt_scale values; the first is the one the others are compared with")
    stable = sub.add_parser("stability", help="explicit stability limit of the time step, computed and tried")
    stable.add_argument("--N", type=int, default=54)
    stable.add_argument("--plates", type=int, default=3)
    stable.add_argument("--phi", type=float, default=5e-4, help="rigidity ratio Phi; sets k_drive")
    stable.add_argument("--steps", type=int, default=4000, help="time steps after the kick per dt_scale")
    stable.add_argument("--scales", type=float, nargs="+", default=[1.0, 2.0, 4.0, 8.0])
    args = parser.parse_args(argv)
    if getattr(args, "phi", None) is not None:
        args.k_drive = float(f"{args.phi / stiffness_ratio(1.0, args.N):.6g}")
    {"reference": reference, "statistics": statistics, "time-step": time_step_study, "stability": stability,
     "paired": paired}[args.check](args)


if __name__ == "__main__":
    main()
