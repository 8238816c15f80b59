"""``stickslip db``: query and (re)build the results database.

Sub-commands: ``runs`` and ``events`` (filters, ``--format table|csv|json``),
``sql "SELECT ..."`` (read-only connection; Ctrl-C stops it at once; time, rows and memory bounded by
default, ``--time-limit``, ``--max-rows``, ``--memory-limit``), ``ingest RECORD...`` (add records),
``rebuild`` (recreate the database from the records under the results directory), ``migrate`` (bring a
database of an older schema to this one, keeping its rows).
Each study has its own database, ``results/{study}/stickslip.sqlite`` in the workflow directory (found from
any folder below it, :mod:`stickslip.workdir`): ``--study NAME`` chooses it (default: ``default``),
``--workdir DIR`` the workflow directory, ``--db FILE`` names any file. The filters of ``runs`` and ``events``
are those of ``stickslip.study(...).runs/events`` (:mod:`stickslip.provenance.filters`).
"""

import argparse
import csv
import json
import math
import os
import sys
from pathlib import Path

import pandas as pd

from ..h5io import FileFormatError
from ..plugin_params import ParameterError, parse_assignments
from ..provenance import query
from ..provenance.filters import EVENT_FILTERS, RUN_FILTERS
from ..provenance.ingest import find_records, ingest
from ..provenance.migrate import migrate
from ..provenance.query import MAX_ROWS, MEMORY_LIMIT_MIB, TIME_LIMIT_S
from ..study_plan import check_study_name
from ..vocabulary import quantity
from ..workdir import ENVIRONMENT, find_workdir

FORMATS = ("table", "csv", "json")

#: What ``stickslip db --help`` says.
DESCRIPTION = ("Query and (re)build the results database of a study: results/STUDY/stickslip.sqlite in the "
               "workflow directory (the nearest folder with a Snakefile at or above the current one, or "
               f"--workdir, or ${ENVIRONMENT}).")

#: Columns shown by ``db runs`` in table format (``--all-columns`` shows every column): the API's narrow ``runs()``.
RUN_COLUMNS = query.RUN_COLUMNS

EVENT_COLUMNS = ("simulation_run_id", "analysis", "source", "solver", "n", "regime", "seed", "event",
                 "interface", "slip", "dmu", "dmu_sig0", "multi", "time", "t", "increment")


def _study(name):
    """``--study``: a study's name, a directory under results/ (``..`` or a path would leave it)."""

    try:
        return check_study_name(name, "a study name")
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def _database_options(parser, defaults=True):
    """``--study``, ``--workdir``, ``--db``: on ``db`` (with their defaults) and on each of its sub-commands, where
    they default to what was given before the sub-command (``db --workdir DIR runs`` and ``db runs --workdir DIR``)."""
    def default(value):
        return value if defaults else argparse.SUPPRESS

    parser.add_argument("--study", default=default("default"), type=_study,
                        help="study whose database to use: results/STUDY/stickslip.sqlite in the workflow directory "
                             "(default: default)")
    parser.add_argument("--workdir", type=Path, default=default(None), metavar="DIR",
                        help=f"the workflow directory (default: ${ENVIRONMENT}, else the nearest folder at or above "
                             "the current one with a Snakefile)")
    parser.add_argument("--db", type=Path, default=default(None), help="database file (overrides --study)")


def _results(args):
    """The results tree of ``--study`` in the workflow directory."""
    return find_workdir(args.workdir).path / "results" / args.study


def _database(args, *, exists=True):
    """The database file of the arguments: ``--db``, else the study's (one line if ``exists`` and there is none)."""
    if args.db is not None:
        return args.db
    database = _results(args) / "stickslip.sqlite"
    if exists and not database.is_file():
        raise FileFormatError(f"{database}: no database of study {args.study!r} (run `snakemake --cores 2` with its "
                              f"config there); the workflow directory is {find_workdir(args.workdir)} (another: "
                              f"--workdir or ${ENVIRONMENT})")
    return database


_CONVERT = {"int": int, "float": float, "str": str}


def _bool(text):
    """``--multi`` values: true/false (as the ``--param`` values of a bool)."""
    value = text.strip().lower()
    if value not in ("true", "false", "yes", "no", "1", "0"):
        raise ValueError(text)
    return value in ("true", "yes", "1")


_bool.__name__ = "true or false"  # argparse's message: "invalid true or false value: 'x'"


def _filter_options(parser, specs):
    """One option per filter (``--k-drive``), with the filter's type, choices and help; ``--param NAME=VALUE``."""
    for spec in specs:
        choices = spec.choices if isinstance(spec.choices, tuple) else None
        metavar = None if choices else "true|false" if spec.kind == "bool" else spec.name.upper()
        parser.add_argument(f"--{spec.name.replace('_', '-')}", dest=spec.name, type=_CONVERT.get(spec.kind, _bool),
                            choices=choices, metavar=metavar, help=spec.doc)
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a parameter of a plugin (repeatable), e.g. --param backend=cpu (stickslip plugins "
                             "--params)")


def _filters(args, specs):
    """The filter values given on the command line, with the ``--param`` ones."""
    given = {spec.name: getattr(args, spec.name) for spec in specs}
    parameters = parse_assignments(args.param)
    clash = sorted(set(parameters) & set(given))
    if clash:
        raise ParameterError(f"--param {clash[0]}: a column; use --{clash[0].replace('_', '-')}")
    return {**given, **parameters}


def _common(parser, default_format="table"):
    _database_options(parser, defaults=False)
    parser.add_argument("--format", choices=FORMATS, default=default_format, help="output format (default table)")
    parser.add_argument("--all-columns", action="store_true", help="every column (table format shows the main ones)")


def add_parser(subparsers):
    """Add the ``db`` sub-command and its own sub-commands."""
    parser = subparsers.add_parser("db", help="query or rebuild the results database", description=DESCRIPTION)
    _database_options(parser)
    commands = parser.add_subparsers(dest="db_command", required=True, metavar="DB_COMMAND")

    def command(name, summary):
        """A sub-command whose ``--help`` starts with its one-line summary."""
        return commands.add_parser(name, help=summary, description=summary[0].upper() + summary[1:] + ".")

    runs = command("runs", "list runs with their parameters")
    _common(runs)
    _filter_options(runs, RUN_FILTERS)
    runs.set_defaults(func=run_runs)

    events = command("events", "list slip events with their simulation's parameters")
    _common(events)
    _filter_options(events, EVENT_FILTERS)
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
    _database_options(ingest, defaults=False)
    ingest.set_defaults(func=run_ingest)

    rebuild = command("rebuild", "recreate the database from every record under the results")
    _database_options(rebuild, defaults=False)
    rebuild.add_argument("--results", type=Path, default=None,
                         help="results tree whose records to read (default results/STUDY)")
    rebuild.set_defaults(func=run_rebuild)

    migrate = command("migrate", "bring a database of an older schema to this one, keeping its rows")
    _database_options(migrate, defaults=False)
    migrate.set_defaults(func=run_migrate)


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
    blobs = [k for k in range(frame.shape[1]) if frame.dtypes.iloc[k] == object
             and frame.iloc[:, k].map(type).eq(bytes).any()]
    if not blobs:
        return frame
    frame = frame.copy()
    for k in blobs:
        frame.isetitem(k, frame.iloc[:, k].map(lambda v: v.hex() if isinstance(v, bytes) else v))
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
            records = piece.to_json(orient="records", indent=1, date_format="iso")[1:-1].strip("\n")
            sys.stdout.write(("," if start and records else "") + ("\n" + records if records else ""))
        else:
            with pd.option_context("display.max_rows", None, "display.max_columns", None, "display.width", 200):
                print(piece.to_string(index=False))
    if args.format == "json":
        sys.stdout.write("\n]\n" if len(frame) else "]\n")


def _query(args, name, columns=None, *positional, **filters):
    """Run ``query.<name>`` on the database of ``args`` and print it; a failed query is one line, exit 2."""
    try:
        frame = getattr(query, name)(*positional, _database(args), **filters)
    except query.QueryError as error:
        print(f"stickslip: error: {error}", file=sys.stderr)
        return 2
    return _print(frame, args, columns)


def run_runs(args):
    """``db runs``."""
    return _query(args, "runs", RUN_COLUMNS, **_filters(args, RUN_FILTERS))


def run_events(args):
    """``db events``."""
    return _query(args, "events", EVENT_COLUMNS, **_filters(args, EVENT_FILTERS))


def run_sql(args):
    """``db sql``: errors of SQL (syntax, an attempt to write) are user errors: one line, exit 2.

    The table format shows the result as one bounded table (:func:`stickslip.provenance.query.sql`); CSV and
    JSON are streamed (:func:`stickslip.provenance.query.sql_pieces`): every row is written as it is fetched,
    never a table of the whole result, and the time limit covers the writing.
    """
    bounds = {"time_limit": args.time_limit, "max_rows": args.max_rows, "memory_limit_mib": args.memory_limit}
    if args.format == "table":
        return _query(args, "sql", None, args.query, **bounds)
    written = 0
    try:
        with query.sql_pieces(args.query, _database(args), **bounds) as pieces:
            for rows in streamed_text(pieces, args.format):
                written += rows
    except query.QueryError as error:
        kept = f" (the output holds the {written} rows before it)" if written else ""
        print(f"stickslip: error: {error}{kept}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `stickslip db sql ... | head`: the reader stopped, not an error
        sys.stdout = open(os.devnull, "w")
    return 0


def streamed_text(pieces, fmt):
    """Write the rows of a query to stdout as CSV or JSON, piece by piece; yield the rows of each piece written.

    Values as SQLite gives them, a blob as its hexadecimal text; the columns of the vocabulary that are booleans
    (``multi``, ``git_dirty``, ...) as true and false (CSV: ``True``, ``False``, as pandas writes them); NULL as
    an empty field (CSV) or ``null`` (JSON, also for a non-finite number).
    """
    convert = [_value_converter(name) for name in pieces.columns]
    if fmt == "csv":
        writer = csv.writer(sys.stdout, lineterminator="\n")
        writer.writerow(pieces.columns)
    else:
        sys.stdout.write("[")
    written = 0
    for piece in pieces:
        rows = [[c(v) for c, v in zip(convert, row)] for row in piece]
        if fmt == "csv":
            writer.writerows([["" if v is None else v for v in row] for row in rows])
        elif rows:
            sys.stdout.write(",\n" if written else "\n")
            sys.stdout.write(",\n".join(json.dumps(dict(zip(pieces.columns, map(_finite, row))), allow_nan=False)
                                        for row in rows))
        written += len(rows)
        yield len(rows)
    if fmt == "json":
        sys.stdout.write("\n]\n" if written else "]\n")


def _finite(value):
    """A value for JSON, which has no infinity: a non-finite number as None."""
    return None if isinstance(value, float) and not math.isfinite(value) else value


def _value_converter(name):
    """How a value of column ``name`` is written: a blob as hexadecimal text, a boolean of the vocabulary as a
    bool (where it is 0 or 1)."""
    found = quantity(name)
    boolean = found is not None and found.dtype == "bool"

    def convert(value):
        if isinstance(value, bytes):
            return value.hex()
        if boolean and value in (0, 1) and not isinstance(value, str):
            return bool(value)
        return value

    return convert


def run_ingest(args):
    """``db ingest``."""
    counts = ingest(_database(args, exists=False), args.records)
    print(", ".join(f"{count} {name}" for name, count in counts.items()) + " ingested")
    return 0


def run_rebuild(args):
    """``db rebuild``."""
    results = args.results or _results(args)
    records = find_records(results)
    if not records:
        raise FileFormatError(f"{results}: no provenance records (*.provenance.json) found")
    database = args.db or results / "stickslip.sqlite"
    counts = ingest(database, records, rebuild=True)
    print(f"{database}: rebuilt from " + ", ".join(f"{count} {name}" for name, count in counts.items()))
    return 0


def run_migrate(args):
    """``db migrate``."""
    database = _database(args)
    before, after = migrate(database)
    print(f"{database}: schema {before}" + (f" migrated to {after}" if before != after else ", nothing to migrate"))
    return 0
