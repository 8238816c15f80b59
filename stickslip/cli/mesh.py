"""``stickslip mesh``: build the layered mesh of parameters given as KEY=VALUE and write it."""

from pathlib import Path

from ..mesh import MeshParams, mesh_id, read_mesh, write_mesh
from ..output_safety.overwrite import claimed_output
from ..plugin_params import describe, parse_assignments, parse_params
from . import add_overwrite_option


def add_parser(subparsers):
    """Add the ``mesh`` sub-command."""
    fields = ", ".join(f"{name} (default {default})" for name, _, default, _, _ in describe(MeshParams))
    parser = subparsers.add_parser(
        "mesh", help="build a layered mesh",
        description=f"Build the layered Quad4 mesh of the numerical model and write it as HDF5. Parameters: {fields}.")
    parser.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                        help="one mesh parameter (repeat); the others keep their defaults")
    parser.add_argument("-o", "--output", required=True, type=Path, help="output file (HDF5)")
    add_overwrite_option(parser)
    parser.set_defaults(func=run)


def run(args):
    """Validate the parameters, write the mesh, print a one-line summary."""
    params = parse_params(MeshParams, parse_assignments(args.param), owner="mesh")
    with claimed_output(args.output, {"format": "mesh", "mesh_id": mesh_id(params)}, overwrite=args.overwrite):
        write_mesh(params, args.output)
    mesh = read_mesh(args.output)
    print(f"{args.output}: mesh {mesh_id(params)}, N={mesh.N}, plates={mesh.plates}, "
          f"{mesh.nelem} elements, {mesh.nnode} nodes, {mesh.ndof} DOFs, height {mesh.height / mesh.h:g} h")
    return 0
