"""Which aging estimator recovers what on the rate-and-state virtual experiment (issue 12, item 3).

The twin's ground truth holds, for every slip, the friction just before it (the static friction
mu_s) and just after it, so the slope of the slip drop dmu against ln T splits into the aging of
mu_s and the deepening of the undershoot. Measured on these four runs (a = 1..4, intercept fits):
dmu slope 0.030 / 0.022 / 0.025 / 0.026 from the truth, recovered from the recordings within
0.002; mu_s ages at 0.010-0.014 per e-fold of T, below the interfaces' b = 0.017-0.021 (their
contact age grows as T^0.54-0.78 while they creep); the friction after the slip falls by
0.012-0.016 per e-fold. The paper's fit through the origin reads the intercept as aging.
"""

import numpy as np
import pandas as pd
import pytest

from stickslip import registry
from stickslip.experiment.aging import fit_aging, fit_aging_per_interface
from stickslip.experiment.analysis import analyse_record
from stickslip.experiment.timeseries import read_timeseries, read_truth
from stickslip.plugin_params import parse_params

TRANSIENT = 300.0  # s, the analysis' default t_exclude


def _stack_runs(tmp_path):
    """Stack n = 4, 5 with seeds 1, 2 (6000 s each): detected and true single slips after the transient,
    and each interface's b averaged over the runs (the seeds' quenched disorder differs)."""
    plugin = registry.get("solver", "rate-state-lever")
    detected, truth, interfaces = [], [], []
    for n in (4, 5):
        for seed in (1, 2):
            path = tmp_path / f"stack{n}-{seed}.h5"
            plugin.run(parse_params(plugin.params, {"n": n, "seed": seed}), path, threads=1, inputs={})
            detected.append(analyse_record(read_timeseries(path))[0])
            truth.append(read_truth(path).rename(columns={"a": "interface"}))  # the vocabulary's name
            interfaces.append(read_truth(path, "interfaces"))

    def single(slips):
        slips = pd.concat(slips)
        return slips[~slips["multi"].astype(bool) & slips["T"].notna() & (slips["t_start"] > TRANSIENT)]

    return single(detected), single(truth), pd.concat(interfaces).groupby("a")["b"].mean()


@pytest.mark.slow
def test_the_intercept_fit_recovers_the_slip_drop_growth_which_is_not_static_aging(tmp_path):
    """``pytest -s`` prints the table of docs/experiment-model-rate-state.md, "What the aging fits
    measure here"."""
    detected, truth, b = _stack_runs(tmp_path)
    from_recordings = fit_aging_per_interface(detected, fit="intercept")
    true_drop = fit_aging_per_interface(truth, fit="intercept")
    static = fit_aging_per_interface(truth.assign(dmu=truth["mu_before"]), fit="intercept")
    after = fit_aging_per_interface(truth.assign(dmu=truth["mu_after"]), fit="intercept")
    state = fit_aging_per_interface(truth.assign(dmu=np.log(truth["theta_before"])), fit="intercept")
    print("\na  b  dmu(recordings)  dmu(truth)  mu_s(truth)  mu_after(truth)  dln(theta)/dln(T)")
    for a in (1, 2, 3, 4):
        print(a, f"{b[a]:.4f}", *(f"{fit[a].B:.4f}+-{fit[a].B_error:.4f}"
                                   for fit in (from_recordings, true_drop, static, after, state)))
        assert from_recordings[a].B == pytest.approx(true_drop[a].B, rel=0.15)
        assert 0.3 < state[a].B < 1.0  # a creeping interface's contact age grows slower than T ...
        assert 0.3 * b[a] < static[a].B < b[a]  # ... so mu_s ages slower than b ln T
        assert after[a].B + 3 * after[a].B_error < 0  # the undershoot deepens with T
        assert true_drop[a].B > b[a]  # so the drop grows faster than b ln T
    origin = fit_aging(detected["T"], detected["dmu"], fit="origin")
    intercept = fit_aging(detected["T"], detected["dmu"], fit="intercept")
    print(f"pooled over a: origin B = {origin.B:.4f}, intercept B = {intercept.B:.4f} c = {intercept.c:.4f}")
    assert intercept.c > 3 * intercept.c_error
    assert origin.B > intercept.B + 3 * intercept.B_error
