"""What the fem model shows at a finite temperature: the numbers of docs/numerical-analysis.md, "Finite temperature".

    python benchmarks/thermal_findings.py results/thermal [--drive-rate 2e-8]

Reads a thermal study's ``thermal-events`` outputs (``STUDY/events/thermal-events/fem/*.h5``) and its
``experiment-events`` outputs (the virtual experiment, if any) with the helpers of the figure
``figS-thermal`` and prints, each with the number of slips, states or holds behind it:

- per fem run: events (hops, athermal kicks, failed and backward hops), steady-state slips per interface,
  mean drop and peak stress of the single slips (standard errors);
- the runs with hold cycles: Delta mu against the waiting time through both aging fits, and per hold;
- the stacks at ``--drive-rate``: the aging fits (origin, intercept; T0 = 1 / attempt_rate) pooled per n
  and per interface, B_a per interface, std(B_a) normalised by n = 1; the same of the virtual experiment
  (stacks n <= 3, T0 = 1 s) with its R_slow;
- Delta mu_a / <Delta mu>_(n=1) against T_a / <T_a>_(n=1): the intercept fit of numerics and experiment;
- R_slow per interface, thermal and athermal; peak and drop against the drive rate (n = 1);
- the hold trials of every thermal n = 1 run: peak(T_w) - peak(0) with the slope in ln T_w, and pooled
  over the runs; creep per e-fold of time; blocks below the barriers ln(nu T_w) at the start and end.
"""

import argparse
import glob
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from stickslip.experiment.aging import fit_aging, spread_of_aging_rate
from stickslip.figures import figs_thermal
from stickslip.figures.experimental_data import load_interfaces, load_slips
from stickslip.formats.fem_run import read_increments
from stickslip.plugin_params import parse_params


def fits(T, dmu, t0):
    """Both aging fits, as text."""
    out = []
    for kind in ("origin", "intercept"):
        try:
            fit = fit_aging(T, dmu, t0=t0, fit=kind)
            text = f"{kind} B = {fit.B:.4f} ± {fit.B_error:.4f}"
            text += f", c = {fit.c:.3f} ± {fit.c_error:.3f}" if kind == "intercept" else ""
            out.append(f"{text} ({fit.n_slips} slips, {len(fit.bins)} bins)")
        except ValueError as error:
            out.append(f"{kind}: {error}")
    return "; ".join(out)


def runs_summary(runs, study):
    for _, run in runs.sort_values(["thermal", "n", "drive_rate"]).iterrows():
        table = read_increments(Path(study) / "sim" / "fem" / Path(run["file"]).name)
        kicks = table[table["kick"]].iloc[1:]
        thermal = "hop_block" in table
        hops = int((kicks["hop_block"] >= 0).sum()) if thermal else 0
        slips = run["data"].tables["slip_events"]
        print(f"{Path(run['file']).stem}: n = {run['n']}, T = {run['temperature']:g}, drive rate {run['drive_rate']:g}, "
              f"holds {run['holds']}: {len(table) - 1} increments, {len(kicks)} events ({hops} hops, "
              f"{len(kicks) - hops} athermal kicks, {int(table['failed_hops'].sum()) if thermal else 0} failed, "
              f"{int((kicks['hop_direction'] < 0).sum()) if thermal else 0} backward), {len(slips)} steady-state slips "
              f"({int(slips['multi'].sum())} in multi-slips)")
        for a, part in slips[~slips["multi"].to_numpy(dtype=bool)].groupby("interface"):
            sem = np.sqrt(len(part))
            print(f"    a = {a}: {len(part)} single slips, drop {part['dmu_sig0'].mean():.4f} ± "
                  f"{part['dmu_sig0'].std() / sem:.4f}, peak {part['mu_before_sig0'].mean():.4f} ± "
                  f"{part['mu_before_sig0'].std() / sem:.4f}")


def stacks(runs, params, events):
    print(f"== stacks at drive rate {params.drive_rate:g}: aging fits, B_a")
    spread = []
    for _, run in runs[figs_thermal._at_rate(runs, params)].sort_values("n").iterrows():
        slips = run["data"].tables["slip_events"]
        slips = slips[~slips["multi"].to_numpy(dtype=bool) & np.isfinite(slips["T_fe"].to_numpy(dtype=float))]
        print(f"n = {run['n']}, pooled: {fits(slips['T_fe'].to_numpy(), slips['dmu_sig0'].to_numpy(), run['T0'])}")
        for a, part in slips.groupby("interface"):
            print(f"    a = {a}: {len(part)} slips, T median {part['T_fe'].median():.3g}, B_a "
                  f"{part['B_a_sig0'].mean():.5f} (std {part['B_a_sig0'].std():.5f}); "
                  f"{fits(part['T_fe'].to_numpy(), part['dmu_sig0'].to_numpy(), run['T0'])}")
            spread.append(pd.DataFrame({"interface": a, "n": run["n"], "protocol": "stack",
                                        "B_a": part["B_a_sig0"].to_numpy()}))
    if spread:
        print(spread_of_aging_rate(pd.concat(spread)).to_string(index=False))
    if not events:
        return
    print("== virtual experiment, stacks n <= 3")
    slips = load_slips(events)
    slips = slips[(slips["protocol"] == "stack") & (slips["n"] <= 3) & ~slips["multi"].to_numpy(dtype=bool)
                  & np.isfinite(slips["T"].to_numpy(dtype=float))]
    for n, part in slips.groupby("n"):
        print(f"n = {n}, pooled: {fits(part['T'].to_numpy(), part['dmu'].to_numpy(), 1.0)}")
        for a, mine in part.groupby("interface"):
            print(f"    a = {a}: {len(mine)} slips, T median {mine['T'].median():.3g} s, B_a {mine['B_a'].mean():.4f} "
                  f"(std {mine['B_a'].std():.4f})")
    print(spread_of_aging_rate(slips[["interface", "n", "protocol", "B_a", "seed"]]).to_string(index=False))
    interfaces = load_interfaces(events)
    interfaces = interfaces[(interfaces["protocol"] == "stack") & (interfaces["n"] <= 3) & interfaces["driven"]]
    print("R_slow (mean, sem over seeds):")
    print(interfaces.groupby(["n", "interface"])["R_slow"].agg(["mean", "sem", "size"]).to_string())


def cycles(runs):
    """The runs with hold cycles: Delta mu against the waiting time (aging fits), and per hold time."""
    for _, run in runs[runs["thermal"] & runs["holds"]].iterrows():
        slips = run["data"].tables["slip_events"]
        slips = slips[~slips["multi"].to_numpy(dtype=bool) & np.isfinite(slips["T_fe"].to_numpy(dtype=float))]
        T = slips["T_fe"].to_numpy()
        print(f"== hold cycles, {Path(run['file']).stem}: {len(slips)} single slips with a T, nu T from "
              f"{T.min() / run['T0']:.3g} to {T.max() / run['T0']:.3g}")
        print(f"    {fits(T, slips['dmu_sig0'].to_numpy(), run['T0'])}")
        held = slips.assign(hold=np.where(slips["hold"] > 0, slips["hold"], 0.0).round(-3))
        print(held.groupby("hold").agg(slips=("dmu_sig0", "size"), dmu=("dmu_sig0", "mean"),
                                       dmu_std=("dmu_sig0", "std"), peak=("mu_before_sig0", "mean")).to_string())


def comparisons(runs, params, events):
    print("== Delta mu_a / <Delta mu>_(n=1) against T_a / <T_a>_(n=1), intercept fit")
    table = figs_thermal.scaled_slips(runs, params, load_slips(events) if events else None)
    for source, part in table.groupby("source"):
        fit = fit_aging(part["T_scaled"].to_numpy(float), part["dmu_scaled"].to_numpy(float), t0=1.0, fit="intercept")
        low, high = np.percentile(part["T_scaled"], [5, 95])
        print(f"{source}: {len(part)} slips, slope {fit.B:.3f} ± {fit.B_error:.3f}, c = {fit.c:.3f} ± {fit.c_error:.3f}; "
              f"T_a / <T_a> from {low:.2f} to {high:.2f} (5-95 %)")
    print("== slow slip R_slow (plastic slip in well hops outside slip events)")
    print(figs_thermal.slow_slip_table(runs, params, None).to_string(index=False))
    print("== n = 1 against the drive rate (single slips; NaN: athermal)")
    print(figs_thermal.rate_table(runs).to_string(index=False))


def holds(runs):
    pooled = []
    for _, run in runs[runs["thermal"] & (runs["n"] == 1)].iterrows():
        tables = run["data"].tables
        trials = tables["holds"]
        if trials.empty:
            continue
        table = figs_thermal.hold_differences(trials)
        slope, error, _ = figs_thermal.hold_slope(table)
        interface = tables["interfaces"].set_index("interface").loc[1]
        slip = interface["dR_sum"] / interface["n_slips"]
        times = np.geomspace(1.0 * run["T0"], trials["hold_time"].max(), 60)
        rate, rate_error, _ = figs_thermal.creep_rate(trials, tables["creep"], times)
        print(f"== holds of {Path(run['file']).stem} (drive rate {run['drive_rate']:g}, hold cycles {run['holds']}): "
              f"{trials['state'].nunique()} states, {len(trials)} trials; peak(0) {trials.loc[trials['hold_time'] == 0, 'peak'].mean():.4f}")
        print(table.to_string(index=False))
        print(f"    slope {slope:.5f} ± {error:.5f} sig0 per e-fold of T_w; hops in the hold (mean): "
              f"{trials.groupby('hold_time')['hold_hops'].mean().round(1).to_dict()}")
        print(f"    creep {rate:.1f} ± {rate_error:.1f} well hops per e-fold of t ({rate / slip:.4f} ± {rate_error / slip:.4f} "
              f"of a slip event, {slip:.0f} hops)")
        grid = np.log(np.array([1e6, 1e8, 1e10, 1e12]))
        counts = figs_thermal.barrier_counts(trials, tables["barriers"], grid)
        T0 = run["T0"]
        names = {key: "start" if key == "start" else f"after {key / T0:.0e}" for key in counts}
        print(f"    blocks per state below E = ln(nu T_w) = {np.round(grid, 1).tolist()} T: "
              + "; ".join(f"{names[key]} {np.round(value, 2).tolist()}" for key, value in counts.items()))
        pooled.append(trials.assign(state=trials["state"] + 10**9 * len(pooled)))
    if pooled:
        table = figs_thermal.hold_differences(pd.concat(pooled))
        slope, error, _ = figs_thermal.hold_slope(table)
        print(f"== holds pooled over {len(pooled)} runs")
        print(table.to_string(index=False))
        print(f"    slope {slope:.5f} ± {error:.5f} sig0 per e-fold of T_w")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("study", help="the study's results directory, e.g. results/thermal")
    parser.add_argument("--drive-rate", type=float, default=2e-8)
    args = parser.parse_args()
    warnings.simplefilter("ignore", RuntimeWarning)
    pd.set_option("display.width", 200)
    runs = figs_thermal.load_runs(glob.glob(f"{args.study}/events/thermal-events/fem/*.h5"))
    events = sorted(glob.glob(f"{args.study}/events/experiment-events/*/*.h5"))
    params = parse_params(figs_thermal.FigsThermalParams, {"drive_rate": args.drive_rate})
    runs_summary(runs, args.study)
    stacks(runs, params, events)
    cycles(runs)
    comparisons(runs, params, events)
    holds(runs)


if __name__ == "__main__":
    main()
