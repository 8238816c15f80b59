"""``stickslip simulate``: run one solver on parameters given as KEY=VALUE."""

import argparse
import os
from pathlib import Path

from ..arithmetic import CONTINUE_VARIABLE
from ..plugin_params import parse_assignments
from ..solver_run import run_solver
from . import add_overwrite_option


def add_parser(subparsers):
    """Add the ``simulate`` sub-command."""
    parser = subparsers.add_parser(
        "simulate", help="run one simulation",
        description="Run one solver plugin and write its output file. "
                    "`stickslip plugins --params` lists every solver parameter with its default.")
    parser.add_argument("--solver", required=True, help="solver plugin name (see `stickslip plugins`)")
    parser.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                        help="one parameter (repeat); the others keep their defaults")
    parser.add_argument("--threads", type=positive_int, default=1, help="threads for parallel kernels (default 1)")
    parser.add_argument("-o", "--output", required=True, type=Path,
                        help="output file (HDF5); an existing one of the same run is resumed (fem) or written "
                             "again, one of another run is refused")
    add_overwrite_option(parser)
    parser.add_argument("--resume-other-arithmetic", action="store_true",
                        help="resume a run although the packages that decide its bits (numpy, scipy, numba, "
                             "llvmlite, qdldl, h5py, Python, libm) differ from those it was started with; the file "
                             f"records from which increment (also: {CONTINUE_VARIABLE}=1)")
    parser.set_defaults(func=run)


def positive_int(text):
    """An argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}")
    return value


def run(args):
    """Validate the parameters and the output, then run the solver (:func:`stickslip.solver_run.run_solver`)."""
    if args.resume_other_arithmetic:
        os.environ[CONTINUE_VARIABLE] = "1"
    run_solver(args.solver, args.output, parse_assignments(args.param), threads=args.threads,
               overwrite=args.overwrite)
    return 0
