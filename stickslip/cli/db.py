"""``stickslip db``: query and (re)build the results database.

Sub-commands: ``runs`` and ``events`` (filters, ``--format table|csv|json``),
``sql "SELECT ..."`` (read-only connection; Ctrl-C stops it at once; time, rows and memory bounded by
default, ``--time-limit``, ``--max-rows``, ``--memory-limit``), ``ingest RECORD...`` (add records),
``rebuild`` (recreate the database from the records under the results directory).
Each study has its own database, ``results/{study}/stickslip.sqlite``: ``--study NAME``
chooses it (default: ``default``), ``--db FILE`` names any file.
"""

import argparse
import os
import sys
from pathlib import Path

import pandas as pd

from ..formats.fem_run import REGIMES
from ..h5io import FileFormatError
from ..provenance.query import MAX_ROWS, MEMORY_LIMIT_MIB, TIME_LIMIT_S

FORMATS = ("table", "csv", "json")

#: Columns shown by ``db runs`` in table format (``--all-columns`` shows every column).
RUN_COLUMNS = ("run_id", "kind", "plugin", "plugin_version", "solver", "protocol", "n", "a", "blocks", "phi", "regime",
               "temperature", "seed", "wall_time_s", "peak_memory_mib", "git_commit", "git_dirty")

EVENT_COLUMNS = ("simulation_run_id", "analysis", "source", "solver", "n", "regime", "seed", "event",
                 "interface", "slip", "dmu", "multi", "time", "increment")


def _study(name):
    """``--study``: a study's name, a directory under results/ (``..`` or a path would leave it)."""
    from ..study import check_study_name

    try:
        return check_study_name(name, "a study name")
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def _database_options(parser):
    parser.add_argument("--study", default="default", type=_study,
                        help="study whose database to use: results/STUDY/stickslip.sqlite (default: default)")
    parser.add_argument("--db", type=Path, default=None, help="database file (overrides --study)")


def _database(args):
    """The database file of the arguments: ``--db``, else the study's."""
    return args.db or Path("results") / args.study / "stickslip.sqlite"


def _common(parser, default_format="table"):
    _database_options(parser)
    parser.add_argument("--format", choices=FORMATS, default=default_format, help="output format (default table)")
    parser.add_argument("--all-columns", action="store_true", help="every column (table format shows the main ones)")


def add_parser(subparsers):
    """Add the ``db`` sub-command and its own sub-commands."""
    parser = subparsers.add_parser("db", help="query or rebuild the results database",
                                   description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="db_command", required=True, metavar="DB_COMMAND")

    def command(name, summary):
        """A sub-command whose ``--help`` starts with its one-line summary."""
        return commands.add_parser(name, help=summary, description=summary[0].upper() + summary[1:] + ".")

    runs = command("runs", "list runs with their parameters")
    _common(runs)
    runs.add_argument("--kind", choices=("solver", "analysis", "figure", "mesh"))
    runs.add_argument("--plugin")
    runs.add_argument("--solver")
    runs.add_argument("--n", type=int, help="number of driven interfaces")
    runs.add_argument("--regime", choices=REGIMES)
    runs.add_argument("--seed", type=int)
    runs.set_defaults(func=run_runs)

    events = command("events", "list slip events with their simulation's parameters")
    _common(events)
    events.add_argument("--solver")
    events.add_argument("--analysis")
    events.add_argument("--source", choices=("numerical", "experimental"))
    events.add_argument("--n", type=int, help="number of driven interfaces")
    events.add_argument("--interface", type=int, help="interface (slab) a, 1 = lowest")
    events.add_argument("--regime", choices=REGIMES)
    events.add_argument("--seed", type=int)
    events.add_argument("--run-id", help="one simulation")
    events.set_defaults(func=run_events)

    sql = command("sql", "run SQL on a read-only connection")
    _common(sql)
    sql.add_argument("query", help='e.g. "SELECT n, COUNT(*) FROM simulations GROUP BY n"')
    sql.add_argument("--time-limit", type=float, default=TIME_LIMIT_S, metavar="SECONDS",
                     help=f"stop the query after this long (default {TIME_LIMIT_S:g}; 0: no limit); Ctrl-C stops it "
                          "at any time")
    sql.add_argument("--max-rows", type=int, default=MAX_ROWS, metavar="N",
                     help=f"refuse a result of more rows (default {MAX_ROWS}; 0: no limit)")
    sql.add_argument("--memory-limit", type=float, default=MEMORY_LIMIT_MIB, metavar="MIB",
                     help=f"SQLite's memory, sorts and temporary tables included (default {MEMORY_LIMIT_MIB}; "
                          "0: no limit)")
    sql.set_defaults(func=run_sql)

    ingest = command("ingest", "add provenance records to the database (idempotent)")
    ingest.add_argument("records", nargs="+", type=Path, help="*.provenance.json files")
    _database_options(ingest)
    ingest.set_defaults(func=run_ingest)

    rebuild = command("rebuild", "recreate the database from every record under the results")
    _database_options(rebuild)
    rebuild.add_argument("--results", type=Path, default=None,
                         help="results tree whose records to read (default results/STUDY)")
    rebuild.set_defaults(func=run_rebuild)


def _print(frame, args, columns=None):
    try:
        _write(frame, args, columns)
    except BrokenPipeError:  # `stickslip db events | head`: the reader stopped, not an error
        sys.stdout = open(os.devnull, "w")
    return 0


#: Rows formatted and written at a time: the text of a result is never held whole.
PIECE = 10_000


def _text_of_blobs(frame):
    """``frame`` with every bytes value (an SQL blob) as its hexadecimal text (JSON and CSV have no bytes)."""
    blobs = [c for c in frame.columns if frame[c].dtype == object and frame[c].map(type).eq(bytes).any()]
    if not blobs:
        return frame
    frame = frame.copy()
    for column in blobs:
        frame[column] = frame[column].map(lambda v: v.hex() if isinstance(v, bytes) else v)
    return frame


def _write(frame, args, columns):
    """Write ``frame`` in the format of ``args``, :data:`PIECE` rows at a time (blobs as hexadecimal text)."""
    if args.format == "table" and columns is not None and not args.all_columns:
        frame = frame[[c for c in columns if c in frame.columns]]
    if frame.empty and args.format == "table":
        print("(no rows)")
        return
    if args.format == "json":
        sys.stdout.write("[")
    for start in range(0, max(len(frame), 1), PIECE):
        piece = _text_of_blobs(frame.iloc[start:start + PIECE])
        if args.format == "csv":
            piece.to_csv(sys.stdout, index=False, header=start == 0)
        elif args.format == "json":
            records = piece.to_json(orient="records", indent=1)[1:-1].strip("\n")
            sys.stdout.write(("," if start and records else "") + ("\n" + records if records else ""))
        else:
            with pd.option_context("display.max_rows", None, "display.max_columns", None, "display.width", 200):
                print(piece.to_string(index=False))
    if args.format == "json":
        sys.stdout.write("\n]\n" if len(frame) else "]\n")


def _query(args, name, columns=None, *positional, **filters):
    """Run ``query.<name>`` on the database of ``args`` and print it; a failed query is one line, exit 2."""
    from ..provenance import query

    try:
        frame = getattr(query, name)(*positional, _database(args), **filters)
    except query.QueryError as error:
        print(f"stickslip: error: {error}", file=sys.stderr)
        return 2
    return _print(frame, args, columns)


def run_runs(args):
    """``db runs``."""
    return _query(args, "runs", RUN_COLUMNS, kind=args.kind, plugin=args.plugin, solver=args.solver, n=args.n,
                  regime=args.regime, seed=args.seed)


def run_events(args):
    """``db events``."""
    return _query(args, "events", EVENT_COLUMNS, solver=args.solver, analysis=args.analysis, source=args.source,
                  n=args.n, interface=args.interface, regime=args.regime, seed=args.seed, run_id=args.run_id)


def run_sql(args):
    """``db sql``: errors of SQL (syntax, an attempt to write) are user errors: one line, exit 2."""
    return _query(args, "sql", None, args.query, time_limit=args.time_limit, max_rows=args.max_rows,
                  memory_limit_mib=args.memory_limit)


def run_ingest(args):
    """``db ingest``."""
    from ..provenance.ingest import ingest

    counts = ingest(_database(args), args.records)
    print(", ".join(f"{count} {name}" for name, count in counts.items()) + " ingested")
    return 0


def run_rebuild(args):
    """``db rebuild``."""
    from ..provenance.ingest import find_records, ingest

    results = args.results or Path("results") / args.study
    records = find_records(results)
    if not records:
        raise FileFormatError(f"{results}: no provenance records (*.provenance.json) found")
    database = args.db or results / "stickslip.sqlite"
    counts = ingest(database, records, rebuild=True)
    print(f"{database}: rebuilt from " + ", ".join(f"{count} {name}" for name, count in counts.items()))
    return 0
