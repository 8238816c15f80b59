"""``stickslip analyze-experiment``: slips of experimental recordings to CSV, and the aging fit.

A record implausible for the apparatus it claims (:mod:`stickslip.experiment.plausibility`: a unit
mistake) gets a one-line warning; if no slip is found at all, the command then fails (exit 2) instead
of writing an empty result, and so does a record whose slips mostly have no measured force drop (its
force and positions cover other times: one line naming the file and the likely unit).
"""

import sys
from pathlib import Path

import pandas as pd

from ..experiment.aging import FITS, fit_single_slips
from ..experiment.analysis import ExperimentEventsParams, analyse_record
from ..experiment.plausibility import (force_range_warning, force_rate_warning, missing_drop_error, no_slip_warning,
                                      travel_warning)
from ..experiment.timeseries import read_timeseries
from ..output_safety.overwrite import write_text_output
from ..plugin_params import ParameterError, parse_assignments, parse_params
from ..progress import iterate
from . import add_overwrite_option


def add_parser(subparsers):
    """Add the ``analyze-experiment`` sub-command."""
    parser = subparsers.add_parser(
        "analyze-experiment", help="detect and measure the slips of experimental recordings",
        description="Detect every slip of one or more experimental time-series files (lab or `lever` runs), "
                    "write one row per slip to CSV (columns t [s], a, n, protocol, dF [N], dmu, T [s], dR [mm], "
                    "dR_from_dF [mm], B_a, multi, ...) and/or fit the aging law dmu = B ln(T/T0) on all single "
                    "slips with a waiting time: through the origin (the paper's fit) or with a free intercept c "
                    "(dmu = c + B ln(T/T0)), over all interfaces or per interface.")
    parser.add_argument("runs", nargs="+", type=Path, metavar="RUN.h5", help="time-series files")
    parser.add_argument("-o", "--output", type=Path,
                        help="CSV file of the slips (an existing one with other content is refused)")
    add_overwrite_option(parser)
    parser.add_argument("--aging", action="store_true",
                        help="fit the aging law; the last line printed is `B=<value> +- <error>` (origin) or "
                             "`B=<value> +- <error> c=<value> +- <error>` (intercept)")
    parser.add_argument("--fit", choices=FITS, default="origin",
                        help="aging law: through the origin dmu = B ln(T/T0) (the paper's) or with a free "
                             "intercept dmu = c + B ln(T/T0) (default: origin)")
    parser.add_argument("--per-interface", action="store_true",
                        help="fit each interface separately: one line `a=<i> B=<value> +- <error> c=<value> "
                             "+- <error>` per interface (c = 0 through the origin)")
    parser.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                        help="analysis parameter (repeat); see `stickslip plugins --params`")
    parser.set_defaults(func=run)


def run(args):
    """Analyse every file, then write the CSV and/or print the aging fit."""
    if args.output is None and not args.aging:
        raise ParameterError("nothing to do: give -o EVENTS.csv and/or --aging")
    params = parse_params(ExperimentEventsParams, parse_assignments(args.param),
                          owner="analysis 'experiment-events'")
    tables, warnings = [], []
    for path in iterate(args.runs, desc="analyze-experiment", unit="run"):
        record = read_timeseries(path)
        slips, _ = analyse_record(record, params)
        tables.append(slips.assign(path=str(path)))
        missing = missing_drop_error(record, slips, str(path))
        if missing:
            raise ParameterError(missing)
        found = (force_range_warning(record, str(path)), force_rate_warning(record, str(path)),
                 travel_warning(record, str(path)), no_slip_warning(record, len(slips), str(path)))
        warnings += [line for line in found if line]
    for line in warnings:
        print(f"stickslip: warning: {line}", file=sys.stderr)
    slips = pd.concat(tables, ignore_index=True)
    if warnings and slips.empty:
        raise ParameterError("no slip found, and the records are implausible for their apparatus (warnings above); "
                             "nothing written")
    if args.output is not None:
        write_text_output(args.output, slips.to_csv(index=False), overwrite=args.overwrite)
        print(f"{len(slips)} slips ({int(slips['multi'].sum())} in multi-interface events) -> {args.output}")
    if args.aging:
        print(f"aging fit ({args.fit}) on the single slips in logarithmic bins of T (T0 = {params.t0} s)")
        if args.per_interface:
            for a, fit in fit_single_slips(slips, t0=params.t0, fit=args.fit, per_interface=True).items():
                print(f"a={a} " + (_fit_line(fit, intercept=True) if not isinstance(fit, ValueError)
                                   else f"no fit: {fit}"))
        else:
            try:
                fit = fit_single_slips(slips, t0=params.t0, fit=args.fit)
            except ValueError as error:
                hint = "; the records are implausible for their apparatus (warnings above)" if warnings else ""
                raise ParameterError(f"{error}{hint}") from None
            print(f"{fit.n_slips} slips in {len(fit.bins)} bins")
            print(_fit_line(fit, intercept=args.fit == "intercept"))
    return 0


def _fit_line(fit, *, intercept):
    """``B=<value> +- <error>``, followed by ``c=<value> +- <error>`` if ``intercept``."""
    line = f"B={fit.B:.4g} +- {fit.B_error:.2g}"
    return line + f" c={fit.c:.4g} +- {fit.c_error:.2g}" if intercept else line
