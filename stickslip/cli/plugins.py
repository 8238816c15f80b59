"""``stickslip plugins``: list the registered solvers, analyses and figures, with their contracts, and the formats."""

from .. import formats, registry
from ..plugin_params import describe

PLURAL = {"solver": "solvers", "analysis": "analyses", "figure": "figures"}


def add_parser(subparsers):
    """Add the ``plugins`` sub-command."""
    parser = subparsers.add_parser("plugins", help="list the plugins",
                                   description="List every registered plugin by kind, with its version, then every "
                                               "artifact format (name, version, source, reader/writer module).")
    parser.add_argument("--kind", choices=(*registry.KINDS, "format"), help="only this kind (or only the formats)")
    parser.add_argument("--params", action="store_true", help="also list each plugin's parameters")
    parser.set_defaults(func=run)


def run(args):
    """Print the plugins (and their parameters with --params), then the formats."""
    for kind in registry.KINDS if args.kind is None else [kind for kind in registry.KINDS if kind == args.kind]:
        print(f"{PLURAL[kind]}:")
        for name, plugin in registry.available(kind).items():
            contract = ([f"consumes {', '.join(plugin.consumes)}"] if plugin.consumes else [])
            contract += [f"produces {plugin.produces}"] if plugin.produces else []
            contract += [f"inputs {', '.join(plugin.inputs)}"] if plugin.inputs else []
            contract += ["replays events"] if plugin.replay else []
            contract = f" [{'; '.join(contract)}]" if contract else ""
            print(f"  {name} {plugin.version}  {plugin.summary}{contract}  ({plugin.module})")
            if args.params:
                for pname, ptype, default, unit, doc in describe(plugin.params):
                    unit = f" [{unit}]" if unit else ""
                    print(f"      {pname} ({ptype}, default {default!r}){unit}: {doc}")
    if args.kind in (None, "format"):
        registry.available("solver")  # loads every plugin, and with them the formats they register
        print("formats:")
        for name, fmt in formats.available_formats().items():
            source = f" [{fmt.source}]" if fmt.source else ""
            print(f"  {name} {fmt.version}  {fmt.summary}{source}  ({fmt.module})")
    return 0
