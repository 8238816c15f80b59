"""``stickslip analyze-experiment``: slips of experimental recordings to CSV, and the aging fit."""

from pathlib import Path

import pandas as pd

from ..experiment.aging import fit_aging
from ..experiment.analysis import ExperimentEventsParams, analyse_record
from ..experiment.timeseries import read_timeseries
from ..params import ParameterError, parse_assignments, parse_params


def add_parser(subparsers):
    """Add the ``analyze-experiment`` sub-command."""
    parser = subparsers.add_parser(
        "analyze-experiment", help="detect and measure the slips of experimental recordings",
        description="Detect every slip of one or more experimental time-series files (lab or `lever` runs), "
                    "write one row per slip to CSV (columns t [s], a, n, protocol, dF [N], dmu, T [s], dR [mm], "
                    "dR_from_dF [mm], B_a, multi, ...) and/or fit the aging law dmu = B ln(T/T0) on all single "
                    "slips with a waiting time.")
    parser.add_argument("runs", nargs="+", type=Path, metavar="RUN.h5", help="time-series files")
    parser.add_argument("-o", "--output", type=Path, help="CSV file of the slips")
    parser.add_argument("--aging", action="store_true",
                        help="fit the aging law; the last line printed is `B=<value> +- <error>`")
    parser.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                        help="analysis parameter (repeat); see `stickslip plugins --params`")
    parser.set_defaults(func=run)


def run(args):
    """Analyse every file, then write the CSV and/or print the aging fit."""
    if args.output is None and not args.aging:
        raise ParameterError("nothing to do: give -o EVENTS.csv and/or --aging")
    params = parse_params(ExperimentEventsParams, parse_assignments(args.param),
                          owner="analysis 'experiment-events'")
    tables = []
    for path in args.runs:
        slips, _ = analyse_record(read_timeseries(path), params)
        tables.append(slips.assign(run=str(path)))
    slips = pd.concat(tables, ignore_index=True)
    if args.output is not None:
        args.output.parent.mkdir(parents=True, exist_ok=True)
        slips.to_csv(args.output, index=False)
        print(f"{len(slips)} slips ({int(slips['multi'].sum())} in multi-interface events) -> {args.output}")
    if args.aging:
        try:
            fit = fit_aging(slips["T"], slips["dmu"], t0=params.t0)
        except ValueError as error:
            raise ParameterError(f"aging fit: {error}") from None
        print(f"aging fit on {fit.n_slips} slips in {len(fit.bins)} logarithmic bins of T (T0 = {params.t0} s)")
        print(f"B={fit.B:.4g} +- {fit.B_error:.2g}")
    return 0
