"""``stickslip simulate``: run one solver on parameters given as KEY=VALUE."""

import argparse
import os
from pathlib import Path

from .. import registry
from ..arithmetic import CONTINUE_VARIABLE
from ..numba_options import set_num_threads
from ..output_safety.atomic import check_output
from ..output_safety.overwrite import claimed_output
from ..params import params_to_dict, parse_assignments, parse_params
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


def run_identity(plugin, params):
    """What a solver's output file stores about its run (root attributes): format, solver, version, parameters."""
    return {"format": plugin.produces, "solver": plugin.name, "solver_version": plugin.version,
            "params": params_to_dict(params)}


def run(args):
    """Validate the parameters and the output, then run the solver."""
    plugin = registry.get("solver", args.solver)
    params = parse_params(plugin.params, parse_assignments(args.param), owner=f"solver '{plugin.name}'")
    threads = set_num_threads(args.threads)
    check_output(args.output)
    if args.resume_other_arithmetic:
        os.environ[CONTINUE_VARIABLE] = "1"
    with claimed_output(args.output, run_identity(plugin, params), overwrite=args.overwrite):
        plugin.run(params, args.output, threads=threads, inputs={})
    return 0
