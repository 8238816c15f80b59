"""The paper's numerical statements measured in a study, per system size N and time step.

    python benchmarks/numerical_claims.py results/size-series [results/default ...]

Reads every ``numerical-events`` and ``front-dynamics`` file under the given results trees
(``events/numerical-events/*/*.h5``, ``events/front-dynamics/*/*.h5``; runs at the paper's two Phi
only, :func:`stickslip.fem.stiffness.at_paper_phi`) and prints, per (N, dt_scale, regime, n), the
numbers of the table in docs/numerical-analysis.md, "The paper's numerical statements":

- rho(s) pooled over the seeds (the paper's Fig. 2c) and the multi-slip fraction per run;
- periodicity and synchronisation (:mod:`stickslip.events.periodicity`): mean +- standard error
  over the runs (seeds);
- the stress drops of compliant single slips against n = 1 (Fig. 2f):
  :func:`stickslip.summaries.size_series.drop_shift_by_size`;
- Delta gamma_1 between slips of interface 1 (the SI's P(Delta gamma_a)): median and mean;
- sequences (the SI's Fig. S3): fraction of slip events in single-slip sequences and in any sequence;
- the front speed c_f and the delay tau of the re-run multi-slips (SI "Front dynamics"):
  :func:`stickslip.summaries.size_series.front_speed_by_size`.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from stickslip.events.extraction import sequence_fractions, slip_fractions
from stickslip.events.analysis_files import read_analysis_file
from stickslip.summaries.size_series import (GROUP, drop_shift_by_size, front_speed_by_size, periodicity_by_size,
                                          run_key)
from stickslip.fem.stiffness import at_paper_phi
from stickslip.figures.numerical_common import run_phi


def read(trees, analysis, fmt, tables):
    """Analysis files (of format ``fmt``) of the runs at the paper's Phi under the results trees."""
    files = [read_analysis_file(path, fmt, tables) for tree in trees
             for path in sorted(Path(tree).glob(f"events/{analysis}/*/*.h5"))]
    return [item for item in files if at_paper_phi(run_phi(item.attrs))]


def pm(value, error, digits=2):
    """'value +- error' (error left out where undefined)."""
    if not math.isfinite(value):
        return "-"
    return f"{value:.{digits}f}" + (f" +- {error:.{digits}f}" if math.isfinite(error) else "")


def main(trees):
    events = read(trees, "numerical-events", "event-table", ("slips", "slip_interfaces", "sequences", "periodicity"))
    if not events:
        raise SystemExit(f"no numerical-events file at the paper's Phi under {', '.join(trees)}")
    groups = {}
    for item in events:
        key = run_key(item)
        groups.setdefault(tuple(key[k] for k in GROUP), []).append(item)
    summary = periodicity_by_size(events).set_index(list(GROUP))
    print("per (N, dt_scale, regime, n): runs, steady-state slip events; rho(s) pooled; mean +- standard error "
          "over the runs of: multi-slip fraction, system-spanning fraction, CV of Delta gamma between slips, "
          "CV of Delta Sigma, alternation CV, runs z; Delta gamma_1 median/mean [gamma0]; sequences (single, any)")
    for key, files in sorted(groups.items()):
        n = key[3]
        slips = pd.concat([f.tables["slips"] for f in files], ignore_index=True)
        per = pd.concat([f.tables["slip_interfaces"] for f in files], ignore_index=True)
        dgamma = per.loc[per["interface"] == 1, "dgamma"].dropna().to_numpy(dtype=float)
        sequences = sequence_fractions(pd.concat([f.tables["sequences"] for f in files], ignore_index=True))
        row = summary.loc[key]
        rho = ", ".join(f"{value:.2f}" for value in slip_fractions(slips, n))
        print(f"N={key[0]} dt_scale={key[1]:g} {key[2]} n={n}: runs={len(files)} slips={len(slips)} "
              f"rho(s)=[{rho}] multi={pm(row['multi_fraction'], row['multi_fraction_error'])} "
              f"spanning={pm(row['spanning_fraction'], row['spanning_fraction_error'])} "
              f"interval_cv={pm(row['interval_cv'], row['interval_cv_error'])} "
              f"drop_cv={pm(row['drop_cv'], row['drop_cv_error'])} "
              f"alternation_cv={pm(row['alternation_cv'], row['alternation_cv_error'])} "
              f"({int(row['alternation_cv_runs'])} runs) runs_z={pm(row['runs_z'], row['runs_z_error'])} "
              f"dgamma_1 median={np.median(dgamma) if dgamma.size else math.nan:.3f} "
              f"mean={dgamma.mean() if dgamma.size else math.nan:.3f} "
              f"sequences single={sequences['single']:.2f} any={sequences['any']:.2f}")
    print("\ncompliant single slips, Delta mu_a [sig0] against n = 1 (Welch on events; on run means):")
    for _, row in drop_shift_by_size(events).iterrows():
        print(f"N={int(row['N'])} dt_scale={row['dt_scale']:g} n={int(row['n'])}: seeds={int(row['seeds'])} "
              f"count={int(row['count'])} "
              f"mean={row['mean']:.4f} +- {row['run_mean_error']:.4f} (runs) shift={100 * row['shift']:+.1f} % "
              f"p={row['p_value']:.2g} detectable={100 * row['detectable_shift']:.1f} % p_runs={row['p_runs']:.2g}")
    fronts = read(trees, "front-dynamics", "front-table", ("fronts",))
    if fronts:
        print("\nfront speed c_f [c_s] of the re-run multi-slips (meaningful fits only) and tau [H/c_s]:")
        table = front_speed_by_size(fronts)
        for _, row in table[table["events"] > 0].iterrows():
            print(f"N={row['N']} dt_scale={row['dt_scale']:g} {row['regime']} n={row['n']}: events={row['events']} "
                  f"ok={row['ok']} flagged={row['flagged']} c_f median={row['c_f_median']:.2f} "
                  f"mean={pm(row['c_f_mean'], row['c_f_error'])} tau median={row['tau_median']:.2f} "
                  f"mean={row['tau_mean']:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:] or ["results/default"])
