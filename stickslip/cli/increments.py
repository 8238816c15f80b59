"""``stickslip increments``: the per-increment observables of a ``fem`` run as CSV."""

from pathlib import Path

from ..formats.fem_run import read_increments
from ..output_safety.overwrite import write_text_output
from . import add_overwrite_option


def add_parser(subparsers):
    """Add the ``increments`` sub-command."""
    parser = subparsers.add_parser(
        "increments", help="per-increment observables of a fem run as CSV",
        description="Write one row per stored increment of a fem simulation file: increment, kick, "
                    "yield_element, t, gamma (units gamma0), epsd, sigd (units eps0, sig0), per layer l "
                    "epsd_l, sigd_l, ubar_l, fxdrive_l (target_x - ubar_x; 0 without spring), per interface a "
                    "S_a<a>, A_a<a>.")
    parser.add_argument("run", type=Path, help="fem simulation file (HDF5)")
    parser.add_argument("-o", "--output", required=True, type=Path,
                        help="output table (CSV; an existing one with other content is refused)")
    add_overwrite_option(parser)
    parser.set_defaults(func=run)


#: Rows formatted and written at a time: the text of a table is never held whole.
PIECE = 10_000


def run(args):
    """Read the observables and write the CSV, :data:`PIECE` rows at a time."""
    table = read_increments(args.run)
    pieces = (table.iloc[start:start + PIECE].to_csv(index=False, header=start == 0, float_format="%.17g")
              for start in range(0, max(len(table), 1), PIECE))
    write_text_output(args.output, pieces, overwrite=args.overwrite)
    print(f"{args.output}: {len(table)} increments, {len(table.columns)} columns")
    return 0
