"""Fidelity of ``relaxation = exact`` against the paper's ``dynamic`` protocol (issue 8, checks a and b).

Usage::

    python benchmarks/fem_relaxation_fidelity.py reference [--tol 1e-5]
    python benchmarks/fem_relaxation_fidelity.py statistics --N 54 --plates 3 --k_drive 0.729 \\
        --increments 4000 --dir runs/
    python benchmarks/fem_relaxation_fidelity.py time-step --N 54 --plates 3 --k_drive 0.729 --dir runs/

``reference`` (check a): the N = 9 reference case (FixedLever_historic), both relaxations
from the same linear response (the dynamic one), increment by increment: where the
per-increment ``S_a1``, ``A_a1`` first differ, the largest relative difference of the
stress ``sigd`` after the kicks before that, and, after the first kick, how far the dynamic
end state is from the exact equilibrium of its own wells (the dynamic tolerance's error).

``time-step``: the same statistics from runs with ``dt_scale`` 1, 2 and 4 (default with
``relaxation = exact``), each compared with ``dt_scale = 1``.

``statistics`` (check b): one run per relaxation (real run files in ``--dir``, resumed if
present), then the steady-state slip events of each (:mod:`stickslip.events.extraction`):
rho(s) compared by a chi-square test of the two count vectors, P(Delta mu_a) by the
two-sample Kolmogorov-Smirnov and Anderson-Darling tests. Last line
``slips=<dynamic>,<exact> rho_p=<chi2 p> dmu_ks_p=<KS p> dmu_ad_p=<AD p>``.
"""

import argparse
import time
from pathlib import Path

import numpy as np
from scipy import stats

from stickslip import registry
from stickslip.events.extraction import classify_increments, slip_events, slip_interfaces
from stickslip.fem.observables import Observer
from stickslip.fem.output import read_increments, read_run_attrs
from stickslip.fem.parameters import FemParams
from stickslip.fem.system import System
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.params import parse_params

REFERENCE_CASE = {"N": 9, "plates": 2, "seed": 0, "k_drive": 1e-3, "nchunk": 200}


def _increments(system, count):
    """The protocol's increments (load step, kick) until the margin stop or ``count`` kicks; rows of observables."""
    observer = Observer(system)
    previous = observer.well_index()
    rows = []
    margin = system.params.margin
    for _ in range(count):
        system.event_step(False)
        if not (system.state.idx < system.model.epsy.shape[1] - margin).all():
            break
        rows.append(observer.observe(previous))
        previous = observer.well_index()
        if not system.kick(margin)[0]:
            break
        rows.append(observer.observe(previous))
        previous = observer.well_index()
    return rows


def reference(args):
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    case = {**REFERENCE_CASE, "tol": args.tol}
    response = System(FemParams(**case), mesh)
    response.compute_linear_response()
    linear = (response.delta_u, response.delta_eps, response.delta_target, response.delta_lever)
    out = {}
    for relaxation in ("dynamic", "exact"):
        system = System(FemParams(**case, relaxation=relaxation), mesh)
        system.set_linear_response(*linear)
        start = time.perf_counter()
        out[relaxation] = _increments(system, 1000)
        print(f"{relaxation}: {len(out[relaxation])} increments, {system.state.t[0] / system.model.dt:.0f} time "
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
    system = System(FemParams(**case), mesh)
    system.set_linear_response(*linear)
    system.event_step(False)
    system.kick(system.params.margin)
    u = system.state.u.copy()
    assert system.relax_in_wells()
    print(f"first kick: the dynamic end state is {np.abs(u - system.state.u).max() / np.abs(u).max():.2e} "
          f"(relative, max norm) from the exact equilibrium of its own wells")


def _run(params, path):
    plugin = registry.get("solver", "fem")
    start = time.perf_counter()
    plugin.run(parse_params(plugin.params, params), path, threads=1, inputs={})
    return time.perf_counter() - start


def _slip_statistics(label, params, directory):
    """Run (or resume) one simulation; its rho(s) counts and Delta mu_a values of the steady state."""
    name = "_".join(f"{key}{value}" for key, value in params.items() if key not in ("max_increments",))
    path = Path(directory) / f"{name}.h5"
    seconds = _run(params, path)
    table = read_increments(path)
    N, n = params["N"], params["plates"] - 1
    classified = classify_increments(table, N)
    slips = slip_events(classified, N)
    drops = slip_interfaces(classified, N)["dmu"].to_numpy()
    counts = np.array([(slips["s"] == s).sum() for s in range(1, n + 1)])
    steps = table["t"].iloc[-1] / read_run_attrs(path)["dt"] / max(int(table["kick"].iloc[1:].sum()), 1)
    print(f"{label}: {len(table)} increments ({seconds:.0f} s this call), {len(slips)} steady-state slip events, "
          f"counts by s = {counts.tolist()}, rho(s) = {np.round(counts / max(counts.sum(), 1), 3).tolist()}, "
          f"Delta mu_a: {drops.size} values, mean {drops.mean():.4f} std {drops.std():.4f} (sig0), "
          f"time steps per kick {steps:.0f}")
    return counts, drops


def _compare(first, second):
    """Two-sample tests of rho(s) (chi-square on the counts) and P(Delta mu_a) (KS, Anderson-Darling)."""
    (c1, d1), (c2, d2) = first, second
    used = (c1 + c2) > 0
    rho_p = stats.chi2_contingency(np.array([c1[used], c2[used]]))[1] if used.sum() > 1 else 1.0
    ks = stats.ks_2samp(d1, d2)
    ad = stats.anderson_ksamp([d1, d2], method=stats.PermutationMethod(n_resamples=2000, random_state=0))
    print(f"rho(s): chi-square p = {rho_p:.3f}; P(Delta mu_a): KS statistic {ks.statistic:.3f} p = {ks.pvalue:.3f}, "
          f"Anderson-Darling p = {ad.pvalue:.3f}")
    return f"slips={len(d1)},{len(d2)} rho_p={rho_p:.3f} dmu_ks_p={ks.pvalue:.3f} dmu_ad_p={ad.pvalue:.3f}"


def statistics(args):
    base = {"N": args.N, "plates": args.plates, "k_drive": args.k_drive, "seed": args.seed,
            "max_increments": args.increments}
    dynamic = _slip_statistics("dynamic", {**base, "relaxation": "dynamic"}, args.dir)
    exact = _slip_statistics("exact", {**base, "relaxation": "exact"}, args.dir)
    print(_compare(dynamic, exact))


def time_step(args):
    base = {"N": args.N, "plates": args.plates, "k_drive": args.k_drive, "seed": args.seed,
            "max_increments": args.increments, "relaxation": args.relaxation}
    runs = {scale: _slip_statistics(f"dt_scale={scale:g}", {**base, "dt_scale": scale}, args.dir)
            for scale in (1.0, 2.0, 4.0)}
    for scale in (2.0, 4.0):
        print(f"dt_scale={scale:g} against 1: {_compare(runs[1.0], runs[scale])}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="check", required=True)
    ref = sub.add_parser("reference", help="check a: the N = 9 reference case increment by increment")
    ref.add_argument("--tol", type=float, default=1e-5, help="minimisation tolerance of both relaxations")
    stat = sub.add_parser("statistics", help="check b: slip statistics of one run per relaxation")
    step = sub.add_parser("time-step", help="slip statistics with dt, 2 dt and 4 dt")
    step.add_argument("--relaxation", default="exact", choices=("dynamic", "exact"))
    for command in (stat, step):
        command.add_argument("--N", type=int, default=54)
        command.add_argument("--plates", type=int, default=3)
        command.add_argument("--k_drive", type=float, required=True)
        command.add_argument("--seed", type=int, default=0)
        command.add_argument("--increments", type=int, default=4000)
        command.add_argument("--dir", default="fidelity-runs", help="directory of the run files (resumed if present)")
    args = parser.parse_args(argv)
    {"reference": reference, "statistics": statistics, "time-step": time_step}[args.check](args)


if __name__ == "__main__":
    main()
