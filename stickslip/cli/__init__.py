"""The ``stickslip`` command line: one module per sub-command in this package.

Each module in :data:`COMMANDS` defines ``add_parser(subparsers)``, which adds its
sub-command and sets ``func(args) -> int`` as the parser default. Errors of the
user's making (bad parameter, unknown plugin, unreadable file) are printed as one
line ``stickslip: error: ...`` with exit status 2, never as a traceback.
"""

import argparse
import importlib
import sys

from ..h5io import FileFormatError
from ..params import ParameterError
from ..registry import PluginError

__all__ = ["main", "COMMANDS"]

#: Sub-command modules, in the order of ``stickslip --help``.
COMMANDS = ("mesh", "simulate", "increments", "analyze_experiment", "import_csv", "plugins", "db")

USER_ERRORS = (ParameterError, PluginError, FileFormatError)


def build_parser():
    """Return the top-level argument parser with every sub-command."""
    from .. import __version__

    parser = argparse.ArgumentParser(prog="stickslip", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"stickslip {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").add_parser(subparsers)
    return parser


def main(argv=None):
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args) or 0
    except USER_ERRORS as error:
        print(f"stickslip: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
