"""``stickslip browse``: a study in the browser, read only (:mod:`stickslip.browse`).

Builds the study's pages (its runs as a table that filters and sorts, each run's and each figure's page) into a
temporary folder, or into ``--export DIR`` to keep them, and serves them on http://127.0.0.1:PORT/ until Ctrl-C.
"""

import sys
import tempfile
from pathlib import Path

from ..workdir import ENVIRONMENT

#: What ``stickslip browse --help`` says.
DESCRIPTION = ("Serve a study in the browser, read only, on the loopback address: its runs as a table that filters "
               "and sorts, each run's parameters, provenance, increments and events, each figure with the runs and "
               "events it was drawn from. The pages are made from the study's database and files; nothing served "
               "can write.")


def add_parser(subparsers):
    """Add the ``browse`` sub-command."""
    from .db import _study

    parser = subparsers.add_parser("browse", help="serve a study in the browser, read only", description=DESCRIPTION)
    parser.add_argument("--study", default="default", type=_study,
                        help="the study (results/STUDY in the workflow directory; default: default)")
    parser.add_argument("--workdir", type=Path, default=None, metavar="DIR",
                        help=f"the workflow directory (default: ${ENVIRONMENT}, else the nearest folder at or above "
                             "the current one with a Snakefile)")
    parser.add_argument("--port", type=int, default=0, help="port on 127.0.0.1 (default 0: a free one)")
    parser.add_argument("--export", type=Path, default=None, metavar="DIR",
                        help="write the pages into DIR (a static site: open DIR/index.html) and serve nothing")
    parser.set_defaults(func=run)


def run(args):
    """Build the pages, then serve them (or only write them with ``--export``)."""
    from ..api import study
    from ..browse.server import HOST, serve
    from ..browse.site import build_site

    def say(line):
        print(f"stickslip browse: {line}", file=sys.stderr, flush=True)

    results = study(args.study, workdir=args.workdir)
    if args.export is not None:
        index = build_site(results, args.export, progress=say)
        print(index)
        return 0
    with tempfile.TemporaryDirectory(prefix="stickslip-browse-") as folder:
        build_site(results, folder, progress=say)
        serve(folder, args.port, ready=lambda server: print(
            f"http://{HOST}:{server.server_port}/  (study {results.name}, read only; Ctrl-C stops)", flush=True))
    return 0
