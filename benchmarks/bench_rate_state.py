"""Integrators of the rate-and-state lever: steps, time per step and results, RODAS4 against scipy's methods.

    python benchmarks/bench_rate_state.py [DURATION]

One slab driven alone (individual protocol, a = 1, default parameters, seed 1) for DURATION seconds
(default 800: two slips); prints, per method, the accepted steps, the wall time (second call, after
numba's compilation), the time per step, and the recurrence time and slip of the second slip.
scipy's methods integrate the same equations with the same analytic Jacobian.
"""

import sys
import time

import numpy as np

from stickslip.experiment.virtual import Apparatus
from stickslip.experiment.virtual.slab_dynamics import METHODS, SlabDynamics
from stickslip.plugin_params import parse_params
from stickslip.experiment.virtual.rate_state_model import law_of
from stickslip.solvers.rate_state_lever import RateStateLeverParams


def main(duration):
    params = parse_params(RateStateLeverParams, {"protocol": "individual", "n": 1, "a": 1, "seed": 1})
    apparatus = Apparatus.from_protocol("individual", n=1, a=1, n_slabs=5, k_spring=params.k_spring,
                                        normal_force=params.normal_force, h=params.h, H=params.H, V=params.V,
                                        gamma_start=params.gamma_start)
    dynamics = SlabDynamics(apparatus, law_of(params), params.slab_mass, params.load_mass)
    _, y0 = dynamics.initial_state(params.V_start, params.theta_start, params.gamma_start)
    print(f"{'method':8s} {'steps':>8s} {'wall [s]':>9s} {'us/step':>8s} {'T [s]':>9s} {'dR [mm]':>8s}")
    for method in METHODS:
        try:
            dynamics.integrate(y0, 1.0, apparatus.shear_rate, method=method)  # compile
            start = time.perf_counter()
            t, y, dydt = dynamics.integrate(y0, duration, apparatus.shear_rate, method=method)
            wall = time.perf_counter() - start
        except RuntimeError as error:
            print(f"{method:8s} failed: {error}")
            continue
        fast = dydt[:, 0] > params.slip_velocity
        onsets = np.flatnonzero(np.diff(fast.astype(int)) == 1)
        ends = np.flatnonzero(np.diff(fast.astype(int)) == -1)
        T = t[onsets[1]] - t[onsets[0]] if onsets.size > 1 else float("nan")
        dR = y[ends[1], 0] - y[onsets[1], 0] if ends.size > 1 else float("nan")
        print(f"{method:8s} {t.size - 1:8d} {wall:9.2f} {1e6 * wall / (t.size - 1):8.1f} {T:9.3f} {dR:8.4f}")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 800.0)
