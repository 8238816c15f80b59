"""The ``stickslip`` command line: one module per sub-command in this package.

Each module in :data:`COMMANDS` defines ``add_parser(subparsers)``, which adds its
sub-command and sets ``func(args) -> int`` as the parser default. Errors of the
user's making (bad parameter, unknown plugin, unreadable file, a run the solver cannot make with the
parameters given) are printed as one line ``stickslip: error: ...`` with exit status 2, never as a
traceback; so is a command that runs out of memory (naming the command and the sizes to lower). Every command that writes a file refuses an existing output that holds another run unless
given ``--overwrite``. Ctrl-C and
SIGTERM end a command cleanly (files closed, what a run stored is kept) with exit
status 130 (SIGINT) or 143 (SIGTERM). Warnings of the package (parameters outside the studied regime)
are one line ``stickslip: warning: ...``.
"""

import argparse
import importlib
import sys
import textwrap
import warnings

from .. import __version__
from ..errors import SolverError
from ..h5io import FileFormatError
from ..machine_memory import process_memory, size_text
from ..output_safety.errors import OutputError
from ..plugin_params import ParameterError, ParameterWarning
from ..registry import PluginError
from ..termination import exit_status, interrupts_raised, interruption

__all__ = ["main", "COMMANDS", "add_overwrite_option"]

#: Sub-command modules, in the order of ``stickslip --help``.
COMMANDS = ("mesh", "simulate", "increments", "analyze_experiment", "import_csv", "plugins", "db", "browse")

#: Errors of the user's making, printed as one line (exit 2): a bad parameter, plugin, file or output, and a run
#: that the parameters ask for but the solver cannot make (:class:`stickslip.errors.SolverError`).
USER_ERRORS = (ParameterError, PluginError, FileFormatError, OutputError, SolverError)

#: What ``stickslip --help`` says first: what the tool is for, in the user's terms.
DESCRIPTION = textwrap.fill("Stick-slip in a stack of elastic slabs: run the paper's simulations (finite elements, a virtual "
               "lever experiment), analyse lab or simulated recordings (slips, force drops, aging), and query the "
               "results database. The whole study runs with `snakemake --cores 2`; these commands run or inspect "
               "one piece of it.", 100)

#: What ``stickslip --help`` says last: where to start.
EPILOG = ("examples:\n"
          "  stickslip plugins --params                       the solvers and their parameters\n"
          "  stickslip simulate --solver fem --param N=162 -o run.h5\n"
          "  stickslip increments run.h5 -o run.csv           the increments of a run, also while it runs\n"
          "  stickslip import-csv --force F.csv --positions X.csv --n 3 -o lab.h5\n"
          "  stickslip analyze-experiment lab.h5 -o slips.csv --aging\n"
          "  stickslip db events --regime stiff               slip events of the study's database\n"
          "  stickslip browse --study ci                      the study in the browser, read only\n"
          "`stickslip COMMAND --help` describes each command; README.md and docs/ the study.")


def add_overwrite_option(parser):
    """Add ``--overwrite`` to a command that writes a file: without it, an existing output that holds another
    run is refused (:mod:`stickslip.output_safety.overwrite`)."""
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing output that holds another run (kept aside until the new one is "
                             "complete)")


def build_parser():
    """Return the top-level argument parser with every sub-command."""
    parser = argparse.ArgumentParser(prog="stickslip", description=DESCRIPTION, epilog=EPILOG,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"stickslip {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").add_parser(subparsers)
    return parser


def _one_line_warning(message, category, filename, lineno, line=None):
    """``warnings`` output: the package's own warnings as one line, others as Python prints them."""
    if issubclass(category, ParameterWarning):
        return f"stickslip: warning: {message}\n"
    return _python_warning(message, category, filename, lineno, line)


_python_warning = warnings.formatwarning


def out_of_memory(args, error):
    """The one line of a command that ran out of memory: what ran out, how much was asked (where Python says) and
    what to do."""
    asked = f" ({' '.join(str(error).split())})" if str(error) else ""
    return (f"{args.command}: out of memory{asked}, more than this process can have ({size_text(process_memory())}); "
            "use smaller sizes (a simulation: smaller N, plates, window, nchunk or niter_tol) or a machine with more "
            "memory")


def main(argv=None):
    """Run the command line; return the exit status."""
    warnings.formatwarning = _one_line_warning
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with interrupts_raised():
            return args.func(args) or 0
    except USER_ERRORS as error:
        print(f"stickslip: error: {' '.join(str(error).split())}", file=sys.stderr)
        return 2
    except MemoryError as error:
        print(f"stickslip: error: {out_of_memory(args, error)}", file=sys.stderr)
        return 2
    except BaseException as error:
        interrupt = interruption(error)
        if interrupt is None:
            raise
        cause = str(interrupt) or "interrupted"
        print(f"stickslip: {cause}; what was stored is kept (a simulation resumes when rerun)", file=sys.stderr)
        return exit_status(interrupt)


if __name__ == "__main__":
    sys.exit(main())
