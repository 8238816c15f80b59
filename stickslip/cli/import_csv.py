"""``stickslip import-csv``: convert a lab export (force CSV + positions CSV) into a time-series file.

Each file is checked against the apparatus it claims (:mod:`stickslip.experiment.plausibility`: the force's
loading rate, the positions' travel); an implausible one (a unit mistake) is written, with a one-line
warning naming the CSV file.
"""

import sys
from pathlib import Path

from ..experiment.csv_import import UNITS, import_csv
from ..experiment.plausibility import force_range_warning, force_rate_warning, travel_warning
from ..experiment.timeseries import PROTOCOLS
from . import add_overwrite_option


def add_parser(subparsers):
    """Add the ``import-csv`` sub-command."""
    parser = subparsers.add_parser(
        "import-csv", help="convert lab CSV exports into an experimental time-series file",
        description="Read a force CSV (columns 't [s]', 'F [N]') and a positions CSV (columns 't [s]', "
                    "'x1 [mm]' ... 'x<n_slabs> [mm]', x1 the lowest slab) and write the HDF5 time-series "
                    "file that `stickslip analyze-experiment` reads. Lines starting with '#' are comments.")
    parser.add_argument("--force", required=True, type=Path, metavar="FORCE.csv", help="force CSV file")
    parser.add_argument("--positions", required=True, type=Path, metavar="POSITIONS.csv",
                        help="slab positions CSV file")
    parser.add_argument("-o", "--output", required=True, type=Path, help="output file (HDF5)")
    add_overwrite_option(parser)
    parser.add_argument("--n", required=True, type=int, help="driven slabs (1 for the individual protocol)")
    parser.add_argument("--n-slabs", type=int, default=5, help="slabs in the stack (default 5)")
    parser.add_argument("--protocol", choices=PROTOCOLS, default="stack", help="driving protocol (default stack)")
    parser.add_argument("--driven-slab", type=int, default=0, metavar="A",
                        help="slab a driven alone (individual protocol; default 0; the file attribute a)")
    parser.add_argument("--normal-force", type=float, default=49.0, metavar="NEWTON",
                        help="normal force N [N] (default 49)")
    parser.add_argument("--k-spring", type=float, default=55.0, metavar="N_PER_MM",
                        help="spring stiffness K [N/mm] (default 55)")
    parser.add_argument("--slab-thickness", type=float, default=10.0, metavar="MM",
                        help="slab thickness h [mm] (default 10; the file attribute h)")
    parser.add_argument("--lever-height", type=float, default=100.0, metavar="MM",
                        help="lever height H [mm] (default 100; the file attribute H)")
    parser.add_argument("--lever-speed", type=float, default=0.01, metavar="MM_PER_S",
                        help="lever-top speed V imposed during the run [mm/s] (default 0.01; the file attribute V)")
    parser.add_argument("--time-unit", choices=list(UNITS["time"]), help="unit of time columns without one")
    parser.add_argument("--force-unit", choices=list(UNITS["force"]), help="unit of force columns without one")
    parser.add_argument("--position-unit", choices=list(UNITS["length"]),
                        help="unit of position columns without one")
    parser.set_defaults(func=run)


def run(args):
    """Import the two CSV files."""
    record = import_csv(args.force, args.positions, args.output, n=args.n, n_slabs=args.n_slabs,
                        protocol=args.protocol, a=args.driven_slab, normal_force=args.normal_force,
                        k_spring=args.k_spring, h=args.slab_thickness, H=args.lever_height, V=args.lever_speed,
                        time_unit=args.time_unit, force_unit=args.force_unit,
                        position_unit=args.position_unit, overwrite=args.overwrite)
    print(f"{args.output}: {record.t_F.size} force samples, {record.t_x.size} frames of {record.n_slabs} slabs")
    for warning in (force_range_warning(record, str(args.force)), force_rate_warning(record, str(args.force)),
                    travel_warning(record, str(args.positions))):
        if warning:
            print(f"stickslip: warning: {warning}", file=sys.stderr)
    return 0
