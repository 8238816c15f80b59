"""``stickslip plugins``: list the registered solvers, analyses and figures, with their contracts."""

from .. import registry
from ..params import describe

PLURAL = {"solver": "solvers", "analysis": "analyses", "figure": "figures"}


def add_parser(subparsers):
    """Add the ``plugins`` sub-command."""
    parser = subparsers.add_parser("plugins", help="list the plugins",
                                   description="List every registered plugin by kind, with its version.")
    parser.add_argument("--kind", choices=registry.KINDS, help="only this kind")
    parser.add_argument("--params", action="store_true", help="also list each plugin's parameters")
    parser.set_defaults(func=run)


def run(args):
    """Print the plugins (and their parameters with --params)."""
    for kind in [args.kind] if args.kind else registry.KINDS:
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
    return 0
