"""Round-off at large accumulated displacement: a translated equilibrium against the original.

Usage::

    python benchmarks/fem_precision.py --N 18 --plates 3 --increments 40

A run (``relaxation = exact``) is made for ``--increments`` increments; its last state
(at equilibrium) is then translated rigidly in x by ``T`` (every node, the fixed bottom
included, and the drive targets): the same physical state, but the displacements are as
large as after a long run (the top plates carry the accumulated slip of every interface
below them). For each ``T`` the script prints the relative residual ``|f_res| / |f_ext|``
of the translated state (the protocol's criteria: ``tol = 1e-5`` for the dynamics,
``tol^2 = 1e-10`` for the exact solve), the relative change of the macroscopic stress
``sigd`` and of the drive forces, and whether the exact solve still converges; and the
displacement of the top plate per slip of the run, to convert ``T`` into slips
(last line ``slips_at_floor_1e-10=<T at which the residual floor reaches 1e-10, in slips>``).
"""

import argparse

import numpy as np

from stickslip.fem.backends import make_backend
from stickslip.fem.observables import Observer
from stickslip.fem.parameters import FemParams
from stickslip.fem.simulation import Simulation
from stickslip.mesh import MeshParams, build_stack_mesh


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--N", type=int, default=18)
    parser.add_argument("--plates", type=int, default=3)
    parser.add_argument("--k_drive", type=float, default=1e-3)
    parser.add_argument("--increments", type=int, default=40)
    args = parser.parse_args(argv)
    params = FemParams(N=args.N, plates=args.plates, k_drive=args.k_drive, relaxation="exact", seed=1)
    sim = Simulation(params, build_stack_mesh(MeshParams(N=args.N, plates=args.plates)), make_backend())
    stack = sim.stack
    observer = Observer(sim)
    start = observer.well_index()
    for _ in range(args.increments // 2):
        sim.loading.step(False)
        sim.protocol.kick(params.margin)
    hops = observer.well_index() - start
    slips = max(int(np.sum(hops.min(axis=1) > 0)), 1)
    top = float(stack.read("ubar")[0][-1])
    per_slip = top / max(hops.min(axis=1).sum(), 1)  # top-plate displacement per well hop of a whole interface
    stored = stack.stored()
    x = sim.mesh.dofs[:, 0]
    base = observer.observe(observer.well_index())
    print(f"N={args.N} plates={args.plates}: top plate moved {top:.3e} in {hops.min(axis=1).sum()} "
          f"interface-wide well hops ({per_slip:.3e} per hop; slips >= {slips})")
    print(f"{'T':>8} {'hops':>10} {'residual':>10} {'d sigd':>10} {'d fxdrive':>10} exact-solve")
    floor_T = None
    for T in [0.0, 1.0, 1e1, 1e2, 1e3, 1e4, 1e5]:
        moved = stored.u.copy()
        moved[np.unique(x)] += T
        stack.restore(stored._replace(u=moved, target=stored.target + T))
        r = sim.backend.residual()
        row = observer.observe(observer.well_index())
        dsig = abs(row["sigd"] / base["sigd"] - 1.0)
        drive = [k for k in row if k.startswith("fxdrive_") and base[k] != 0.0]
        dfx = max(abs(row[k] / base[k] - 1.0) for k in drive)
        solved = sim.relaxation.solve_in_wells(sim.backend)
        print(f"{T:8.0e} {T / per_slip:10.2e} {r:10.2e} {dsig:10.2e} {dfx:10.2e} {'ok' if solved else 'FAILS'}")
        if floor_T is None and r > 1e-10:
            floor_T = T
    print(f"slips_at_floor_1e-10={(floor_T or float('inf')) / per_slip:.3e}")


if __name__ == "__main__":
    main()
