"""Read the results database into pandas DataFrames (read-only connections).

Every function opens the SQLite file read-only (``mode=ro``), so a query can
never change it, and returns a :class:`pandas.DataFrame`. Filters left at
``None`` are not applied.

Every query stops on Ctrl-C (SIGINT) within a fraction of a second, also in the middle of
SQLite's work (a progress handler checks every :data:`CHECK_EVERY` virtual-machine
instructions), and :func:`sql` (``stickslip db sql``) is bounded by default: its time
(:data:`TIME_LIMIT_S`: SQLite's work and the fetching of the rows), the rows it returns
(:data:`MAX_ROWS`) and its memory (:data:`MEMORY_LIMIT_MIB`): SQLite's heap, temporary tables and
sorts included (which are kept in memory), and the rows fetched, counted in bytes as they stream;
a query past a bound stops with a :class:`QueryError` naming the bound and how to raise it.

The bounds belong to one query: SQLite's heap limit is process-wide in SQLite, so it is set for
the query (other SQLite connections of the process share it meanwhile) and the limit set before
is restored after it (:class:`_Heap`).
"""

import _sqlite3
import ctypes
import dataclasses
import itertools
import json
import math
import numbers
import signal
import sqlite3
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import pandas as pd
import sqlalchemy.exc
from sqlalchemy import select, text

from .. import registry
from ..h5io import FileFormatError
from ..plugin_params import params_to_dict, parse_value
from ..vocabulary import UnitFrame, dtype_matches, expand_json, missing_as_na, quantity, typed
from . import filters as _filters
from .database import SCHEMA_HINT, SCHEMA_VERSION, Figure, Run, SlipEvent, engine_for

__all__ = ["DEFAULT_DATABASE", "RUN_COLUMNS", "QueryError", "READ_ONLY_PRAGMAS", "DENIED_FUNCTIONS", "TIME_LIMIT_S",
           "MAX_ROWS", "MEMORY_LIMIT_MIB", "CHECK_EVERY", "runs", "events", "figures", "sql", "sql_pieces", "Pieces",
           "unique_names", "check_bounds"]

#: Where the workflow writes the database of the default study (relative to the workflow directory);
#: a study named S has ``results/S/stickslip.sqlite``.
DEFAULT_DATABASE = "results/default/stickslip.sqlite"


#: Default bounds of :func:`sql`: seconds, rows returned, MiB of SQLite's memory (None: unbounded).
TIME_LIMIT_S = 60.0
MAX_ROWS = 1_000_000
MEMORY_LIMIT_MIB = 1024
#: SQLite virtual-machine instructions between two checks for Ctrl-C and the time limit (~1 ms).
CHECK_EVERY = 10_000
#: Rows fetched at a time at most (the bounds are checked between fetches) ...
_FETCH = 10_000
#: ... and about as many bytes at most (rows of large values are fetched a few at a time).
_PIECE_BYTES = 8 * 2**20


class QueryError(ValueError):
    """A query failed (bad SQL, or an attempt to write through the read-only connection)."""


def _engine(database):
    path = Path(database)
    if not path.is_file():
        raise FileFormatError(f"{path}: no such database (run the workflow, or `stickslip db rebuild`)")
    return engine_for(path, readonly=True)


#: PRAGMAs that ``db sql`` allows: they only describe the schema, whatever their argument.
READ_ONLY_PRAGMAS = ("table_info", "table_xinfo", "table_list", "index_list", "index_info", "index_xinfo",
                     "foreign_key_list", "database_list")

#: SQLite authorizer actions of a query that only reads.
_READING = (sqlite3.SQLITE_SELECT, sqlite3.SQLITE_READ, sqlite3.SQLITE_FUNCTION, sqlite3.SQLITE_RECURSIVE)


#: SQL functions that ``db sql`` refuses: they hand out or take pointers (``fts3_tokenizer``, ``fts5``) or load code.
DENIED_FUNCTIONS = ("fts3_tokenizer", "fts5", "load_extension")


def _only_reading(action, name, argument, _database, _trigger):
    """SQLite authorizer: allow reading, deny everything else (ATTACH, VACUUM INTO, temporary tables, PRAGMA writes,
    the functions of :data:`DENIED_FUNCTIONS`)."""
    if action == sqlite3.SQLITE_FUNCTION and str(argument).lower() in DENIED_FUNCTIONS:
        return sqlite3.SQLITE_DENY
    if action in _READING or (action == sqlite3.SQLITE_PRAGMA and name in READ_ONLY_PRAGMAS):
        return sqlite3.SQLITE_OK
    return sqlite3.SQLITE_DENY


def _check_schema(database, connection):
    """Raise QueryError unless the database has this package's schema version."""
    found = connection.execute(text("SELECT value FROM schema_info WHERE key = 'schema_version'")).scalar()
    if found is None or int(found) != SCHEMA_VERSION:
        raise QueryError(f"database schema version {found}, expected {SCHEMA_VERSION}: {SCHEMA_HINT}")


class _Heap:
    """SQLite's process-wide heap limit (``sqlite3_hard_heap_limit64``), set for one query and restored after.

    The ``hard_heap_limit`` PRAGMA can only lower the limit, never lift it, so a query that set it would cap
    every later SQLite connection of the process; the C functions, reached through the library Python's
    ``sqlite3`` module uses, set and restore it. Where they cannot be reached (an SQLite built without them),
    ``available`` is False and no heap limit is set (the rows are still bounded, :class:`_Bounds`).
    """

    lock = threading.Lock()  # bounded queries in threads take turns with the process-wide limit

    def __init__(self):
        try:
            library = ctypes.CDLL(_sqlite3.__file__)
            self.hard, self.soft = library.sqlite3_hard_heap_limit64, library.sqlite3_soft_heap_limit64
            self.highwater = library.sqlite3_memory_highwater
        except (OSError, AttributeError):
            self.hard = self.soft = self.highwater = None
        for function in (self.hard, self.soft):
            if function is not None:
                function.restype, function.argtypes = ctypes.c_int64, [ctypes.c_int64]
        if self.highwater is not None:
            self.highwater.restype, self.highwater.argtypes = ctypes.c_int64, [ctypes.c_int]

    @property
    def available(self):
        """Whether the limit can be set and restored."""
        return None not in (self.hard, self.soft, self.highwater)

    @contextmanager
    def limited(self, nbytes):
        """Within the block SQLite's heap is limited to ``nbytes`` (or the limit set before, if lower)."""
        if nbytes is None or not self.available:
            yield
            return
        with self.lock:
            hard, soft = self.hard(-1), self.soft(-1)  # -1: ask, change nothing
            self.hard(min(nbytes, hard) if hard > 0 else nbytes)
            self.highwater(1)  # from here: the most SQLite held during the query
            try:
                yield
            finally:
                self.hard(hard)
                self.soft(soft)  # lowering the hard limit lowered the soft one too

    def exhausted(self, nbytes):
        """Whether SQLite's heap came near ``nbytes`` during the query (a MemoryError was its limit, not the machine's)."""
        return self.available and nbytes is not None and self.highwater(0) > 0.5 * nbytes


_HEAP = _Heap()


class _Bounds:
    """The bounds of one query: Ctrl-C, time (SQLite's work and the fetching), rows, and memory.

    Memory: SQLite's heap (:class:`_Heap`, temporary tables and sorts kept in memory) and the rows fetched,
    counted in bytes as they stream (the Python objects of every value and row, :func:`_row_bytes`); each
    bounded by ``memory_limit_mib``.
    """

    def __init__(self, time_limit=None, max_rows=None, memory_limit_mib=None):
        self.time_limit, self.max_rows, self.memory_limit_mib = time_limit, max_rows, memory_limit_mib
        self.memory = None if memory_limit_mib is None else int(memory_limit_mib * 2**20)
        self.deadline = None if time_limit is None else time.monotonic() + time_limit
        self.stop, self.rows, self.bytes = "", 0, 0

    def check(self):
        """SQLite's progress handler, and between fetches: 1 (stop) past the deadline or after Ctrl-C."""
        if not self.stop and self.deadline is not None and time.monotonic() > self.deadline:
            self.stop = "time"
        return 1 if self.stop else 0

    @contextmanager
    def applied(self, driver):
        """Within the block a query on the sqlite3 connection ``driver`` stops at the bounds (Ctrl-C: raised)."""
        def interrupted(_signum, _frame):
            self.stop = "interrupt"  # seen by check() at SQLite's next CHECK_EVERY instructions

        main = threading.current_thread() is threading.main_thread()
        previous = signal.signal(signal.SIGINT, interrupted) if main else None
        driver.set_progress_handler(self.check, CHECK_EVERY)
        if self.memory is not None:
            driver.execute("PRAGMA temp_store = MEMORY")  # temporary tables and sorts count against the limit
        try:
            with _HEAP.limited(self.memory):
                yield self
        finally:
            driver.set_progress_handler(None, 0)
            if main:
                signal.signal(signal.SIGINT, previous)
            if self.stop == "interrupt":
                raise KeyboardInterrupt

    def take(self, piece, columns, kept=True):
        """Count a piece of fetched rows; raise QueryError past a bound (rows, bytes, time).

        ``kept``: the rows stay in memory until the query ends and a table of ``columns`` is made of them (their
        bytes add up, with 16 bytes a value for the table); else only the piece is held (a stream: it is
        bounded alone).
        """
        self.rows += len(piece)
        held = _row_bytes(piece) + (16 * len(piece) * len(columns) if kept else 0)
        self.bytes = self.bytes + held if kept else held
        if self.max_rows is not None and self.rows > self.max_rows:
            raise QueryError(f"the query returns more than {self.max_rows} rows (the bound on rows: add LIMIT, or "
                             f"raise it with `db sql --max-rows N`, max_rows= in Python)")
        if self.memory is not None and self.bytes > self.memory:
            raise QueryError(f"the query's rows reached the memory limit of {self.memory_limit_mib:g} MiB after "
                             f"{self.rows} rows (raise it with `db sql --memory-limit MIB`, memory_limit_mib= in "
                             f"Python; 0: no limit)")
        if self.check():
            raise _Stopped

    def error(self, database, cause):
        """The QueryError of a query that a bound stopped (``cause``: SQLite's error, or None), or None."""
        if self.stop == "time":
            return QueryError(f"{database}: the query ran into the time limit of {self.time_limit:g} s (raise it "
                              f"with `db sql --time-limit SECONDS`, time_limit= in Python; 0: no limit)")
        if "out of memory" in str(cause) and self.memory is not None:
            return QueryError(f"{database}: the query reached SQLite's memory limit of {self.memory_limit_mib:g} MiB "
                              f"(raise it with `db sql --memory-limit MIB`, memory_limit_mib= in Python; 0: no limit)")
        return None


class _Stopped(Exception):
    """A bound (time, Ctrl-C) seen between two fetches."""


def _row_bytes(rows):
    """Bytes that fetched rows hold in Python: every value's object and every row's tuple."""
    values = itertools.chain.from_iterable(rows)
    return sum(map(sys.getsizeof, values)) + sum(map(sys.getsizeof, rows))


def unique_names(names):
    """Column names made unique: a name seen before gets ``.1``, ``.2``, ... (as :func:`pandas.read_csv` does).

    Parameters
    ----------
    names : Iterable[str]

    Returns
    -------
    list[str]
    """
    seen, out = set(), []
    for name in map(str, names):
        unique, k = name, 0
        while unique in seen:
            k += 1
            unique = f"{name}.{k}"
        seen.add(unique)
        out.append(unique)
    return out


class Pieces:
    """The rows of a running query, fetched in pieces that its bounds count (:meth:`_Bounds.take`).

    A piece holds up to :data:`_FETCH` rows and about :data:`_PIECE_BYTES`: rows of large values (blobs) are
    fetched a few at a time, so that no piece passes the memory bound by much. The time between two pieces
    (what the reader does with one) counts against the time limit.

    Attributes
    ----------
    columns : list[str]
        The result's column names, made unique (:func:`unique_names`).
    """

    def __init__(self, result, bounds, kept):
        self._result, self._bounds, self._kept = result, bounds, kept
        self.columns = unique_names(result.keys())

    def __iter__(self):
        """Lists of row tuples, in order; the last may be empty."""
        size = 16
        while True:
            piece = self._result.fetchmany(size)
            self._bounds.take(piece, self.columns, self._kept)
            yield piece
            if len(piece) < size:
                return
            row_bytes = max(1, _row_bytes(piece) // len(piece))
            size = int(min(_FETCH, max(1, _PIECE_BYTES // row_bytes)))


def check_bounds(time_limit=TIME_LIMIT_S, max_rows=MAX_ROWS, memory_limit_mib=MEMORY_LIMIT_MIB):
    """The bounds of :func:`sql` checked, each None where there is none (None or 0).

    Raises
    ------
    QueryError
        If a bound is not a number >= 0 (``max_rows`` an integer), naming it.
    """
    def number(name, option, value, integer=False):
        kinds = (numbers.Integral,) if integer else (numbers.Real,)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, kinds) or not math.isfinite(value) or value < 0:
            what = "an integer" if integer else "a number"
            raise QueryError(f"{name} ({option}): expected {what} >= 0 (0: no limit), got {value!r}")
        return value or None

    return (number("time_limit", "--time-limit SECONDS", time_limit),
            number("max_rows", "--max-rows N", max_rows, integer=True),
            number("memory_limit_mib", "--memory-limit MIB", memory_limit_mib))


@contextmanager
def _pieces(database, statement, only_reading=False, time_limit=None, max_rows=None, memory_limit_mib=None, kept=True):
    """Run ``statement`` under the bounds; the block reads its rows from the :class:`Pieces` it is given.

    Every failure of the query, its bounds included, also while the block reads the rows, ends as one
    :class:`QueryError` naming the database (Ctrl-C as KeyboardInterrupt).
    """
    engine = _engine(database)
    bounds = _Bounds(time_limit, max_rows, memory_limit_mib)
    try:
        with engine.connect() as connection:
            _check_schema(database, connection)
            driver = connection.connection.driver_connection
            with bounds.applied(driver):
                if only_reading:
                    driver.set_authorizer(_only_reading)
                try:
                    result = connection.execute(statement)
                    try:
                        yield Pieces(result, bounds, kept)
                    finally:
                        result.close()
                finally:
                    driver.set_authorizer(None)
    except _Stopped:
        if bounds.stop == "interrupt":
            raise KeyboardInterrupt from None
        raise bounds.error(database, None) from None
    except sqlalchemy.exc.ResourceClosedError:
        raise QueryError(f"{database}: the statement returns no rows; `db sql` runs queries (SELECT)") from None
    except QueryError as error:
        raise QueryError(f"{database}: {error}") from None
    except UnicodeDecodeError as error:  # SQLite keeps no checksums: a flipped bit in a text value
        raise _damaged(database, f"{error.reason} at byte {error.start}") from None
    except MemoryError:  # SQLITE_NOMEM at the heap limit, or the machine's memory
        if not _HEAP.exhausted(bounds.memory):
            raise QueryError(f"{database}: the machine ran out of memory during the query, after {bounds.rows} rows "
                             f"({bounds.bytes / 2**20:.0f} MiB); add LIMIT or lower `db sql --memory-limit MIB`, "
                             "memory_limit_mib= in Python") from None
        raise bounds.error(database, "out of memory") from None
    except (pd.errors.DatabaseError, sqlalchemy.exc.DBAPIError) as error:
        cause = getattr(error.__cause__, "orig", None) or getattr(error, "orig", None) or error.__cause__ or error
        bound = bounds.error(database, cause)
        if bound is not None:
            raise bound from None
        if "decode to UTF-8" in str(cause):  # a text value of a column the driver decodes itself
            raise _damaged(database, str(cause).split(" with text ")[0]) from None
        if "authoriz" in str(cause):  # "not authorized", "authorization denied"
            cause = f"refused ({cause}): `db sql` only reads (SELECT, WITH, PRAGMA {', '.join(READ_ONLY_PRAGMAS)})"
        raise QueryError(f"{database}: query failed: {cause}") from None
    finally:
        engine.dispose()


def _damaged(database, detail):
    """The QueryError of a text value that is not UTF-8 (SQLite keeps no checksums: a flipped bit in a value)."""
    return QueryError(f"{database}: a text value is not UTF-8 ({detail}): the database is damaged; `stickslip db "
                      "rebuild` remakes it from the provenance records")


def _frame(database, statement, **bounds):
    """The rows of ``statement`` as one typed DataFrame, the rows and the table counted by the bounds."""
    with _pieces(database, statement, **bounds) as pieces:
        rows = [row for piece in pieces for row in piece]
        frame = pd.DataFrame.from_records(rows, columns=pieces.columns, coerce_float=True)
    return typed(frame)


#: The simulation columns of ``runs()`` (the run's own ``seed`` is the runs table's).
SIMULATION_COLUMNS = ("solver", "source", "format", "path", "protocol", "n", "driven_slab", "plates", "blocks",
                      "k_drive", "phi", "regime", "temperature", "attempt_rate", "drive_rate", "junction_strengthening",
                      "junction_glass_temperature", "junction_attempt_rate")

#: The columns of the narrow form of ``runs()`` (:meth:`stickslip.study_results.StudyResults.runs`; ``stickslip db
#: runs`` in table format): who ran, on what physics, at what cost, from which commit.
RUN_COLUMNS = ("run_id", "kind", "plugin", "plugin_version", "solver", "source", "protocol", "n", "driven_slab",
               "plates", "blocks", "k_drive", "phi", "regime", "temperature", "seed", "wall_time_s", "peak_memory_mib",
               "finished_at", "git_commit", "git_dirty")

#: The tables of the filters whose values the database holds (``choices="database"``).
_HELD = {"plugin": "runs", "solver": "simulations", "analysis": "slip_events"}


def _parameters(names):
    """For each plugin parameter name: [(plugin, its value's parser, its default)] of every plugin declaring it."""
    found = {}
    for kind in registry.KINDS:
        for plugin in registry.available(kind).values():
            for field in dataclasses.fields(plugin.params):
                if field.name in names:
                    default = list(field.default) if isinstance(field.default, tuple) else field.default
                    found.setdefault(field.name, []).append(
                        (plugin.name, lambda value, cls=plugin.params, name=field.name, owner=f"{kind} '{plugin.name}'":
                         parse_value(cls, name, value, owner=owner), default))
    return found


def _checked(database, specs, filters):
    """:func:`.filters.check` with the database's values and the plugins' parameters it needs."""
    given = {name: value for name, value in filters.items() if value is not None}
    known = {name: list(_frame(database, text(f"SELECT DISTINCT {name} FROM {_HELD[name]} WHERE {name} IS NOT NULL "
                                              f"ORDER BY {name}"))[name])
             for name in given if name in _HELD and any(spec.name == name for spec in specs)}
    columns = {spec.name for spec in specs}
    others = [name for name in given if name not in columns]
    return _filters.check(specs, given, known=known, parameters=_parameters(others) if others else None)


def _units(frame):
    """A query's frame as a :class:`~stickslip.vocabulary.UnitFrame`, its missing values ``pd.NA``
    (:func:`~stickslip.vocabulary.missing_as_na`), ``attrs["units"]`` the vocabulary's unit of every column in the
    vocabulary's dtype."""
    frame = UnitFrame(missing_as_na(frame))
    units = {}
    for column in frame.columns:
        found = quantity(column)
        units[str(column)] = found.unit if found is not None and dtype_matches(frame[column].dtype, found.dtype) \
            else None
    frame.attrs["units"] = units
    return frame


def _defaults_filled(frame):
    """``frame`` (columns ``kind``, ``plugin``, ``params``: JSON) with every parameter of a registered plugin in its
    ``params``: one that a run's record leaves out (an extension at its default, a parameter added after the run was
    made) gets its default, so that it is shown as the value it had (``interface_law`` "cusp"), not as missing.

    Rows of a plugin not registered here (a mesh, another package's plugin not installed) are left as they are.
    """
    defaults = {}
    for kind, plugin in set(zip(frame["kind"], frame["plugin"])):
        if kind in registry.KINDS and plugin in registry.available(kind):
            defaults[kind, plugin] = params_to_dict(registry.get(kind, plugin).params(), every=True)
    frame["params"] = [text if (kind, plugin) not in defaults or not isinstance(text, str)
                       else json.dumps({**defaults[kind, plugin], **json.loads(text)})
                       for kind, plugin, text in zip(frame["kind"], frame["plugin"], frame["params"])]
    return frame


def runs(database=DEFAULT_DATABASE, **filters):
    """Return the runs, with their simulation parameters where they are simulations.

    Parameters
    ----------
    database : str or pathlib.Path
    **filters
        :data:`stickslip.provenance.filters.RUN_FILTERS` (``kind``, ``plugin``, ``solver``, ``n``, ``plates``,
        ``blocks``, ``k_drive``, ``phi``, ``regime``, ``temperature``, ``seed``, ...) and any plugin parameter
        (``backend="cpu"``): :mod:`stickslip.provenance.filters`.

    Returns
    -------
    pandas.DataFrame
        One row per run: ``run_id``, ``kind``, ``plugin``, ``plugin_version``, the simulation's
        :data:`SIMULATION_COLUMNS` (missing for other runs), ``seed``, ``threads``, the code and machine
        (``code_hash``, ``package_version``, ``git_commit``, ``git_dirty``, ``python_version``, ...,
        ``host``), ``started_at``, ``finished_at`` (UTC datetimes), ``wall_time_s``, ``peak_memory_mib``,
        ``record_path``, then one column ``params.<name>`` per parameter of the runs' plugins (missing where a
        plugin has no such parameter; a parameter its record leaves out, as an extension at its default or one
        added later, has its default: ``params.interface_law`` "cusp"). Typed (:func:`stickslip.vocabulary.typed`), ``attrs["units"]``
        (``params.<name>``: None; :func:`stickslip.study` gives the plugins' units); ordered by kind, plugin,
        run id.

    Raises
    ------
    stickslip.plugin_params.ParameterError
        A filter that does not exist or a value that does not fit it (one line naming it).

    Notes
    -----
    Cost: one indexed query; linear in the number of runs returned.
    """
    checked = _checked(database, _filters.RUN_FILTERS, filters)
    where, bound = _filters.conditions(checked, ["r.run_id"])
    own = [c.name for c in Run.__table__.columns if c.name not in ("params", "versions", "seed")]
    head, tail = own[:4], own[4:]
    columns = ([f"r.{c}" for c in head] + [f"s.{c}" for c in SIMULATION_COLUMNS] + ["r.seed", "r.params"]
               + [f"r.{c}" for c in tail])
    statement = text(f"SELECT {', '.join(columns)} FROM runs AS r LEFT JOIN simulations AS s ON s.run_id = r.run_id"
                     f"{where} ORDER BY r.kind, r.plugin, r.run_id").bindparams(**bound)
    return _units(typed(expand_json(_defaults_filled(_frame(database, statement)), "params", prefix="params.")))


def events(database=DEFAULT_DATABASE, **filters):
    """Return slip events with the parameters of their simulation.

    Parameters
    ----------
    database : str or pathlib.Path
    **filters
        :data:`stickslip.provenance.filters.EVENT_FILTERS` (``solver``, ``analysis``, ``source``, ``n``,
        ``interface``, ``multi``, ``plates``, ``blocks``, ``k_drive``, ``phi``, ``regime``, ``seed``, ``run_id`` (of
        the simulation), ...) and any plugin parameter of the simulation or the analysis
        (:mod:`stickslip.provenance.filters`).

    Returns
    -------
    pandas.DataFrame
        The ``slip_events_full`` view: one row per slip of one interface in one event, with the parameters of its
        simulation (``protocol``, ``n``, ``driven_slab``, ``plates``, ``blocks``, ``k_drive``, ``phi``, ``regime``,
        ``seed``, ...), the JSON column ``extra`` expanded into one column per key (``dF``, ``T``, ``B_a``,
        ``dgamma``, ... ; a key named like another column gets the prefix ``extra.``); typed, with
        ``attrs["units"]``; ordered by simulation, event, interface.

    Raises
    ------
    stickslip.plugin_params.ParameterError
        A filter that does not exist or a value that does not fit it.

    Notes
    -----
    Cost: one query using the indexes on solver, interface and simulation;
    linear in the number of events returned (a paper-size study has ~10^5-10^6).
    """
    checked = _checked(database, _filters.EVENT_FILTERS, filters)
    where, bound = _filters.conditions(checked, ["s.simulation_run_id", "s.analysis_run_id"])
    statement = text(f"SELECT s.* FROM slip_events_full AS s{where} "
                     "ORDER BY s.simulation_run_id, s.event, s.interface").bindparams(**bound)
    frame = expand_json(_frame(database, statement), "extra")
    own = [c.name for c in SlipEvent.__table__.columns if c.name in frame.columns]  # a migrated table's order differs
    return _units(typed(frame[own + [c for c in frame.columns if c not in own]]))


def figures(database=DEFAULT_DATABASE):
    """Return the figures with the run that drew them (plugin version, code hash, time).

    Returns
    -------
    pandas.DataFrame
        ``run_id``, ``figure``, ``pdf``, ``png``, ``plugin_version``, ``code_hash``, ``finished_at`` (UTC),
        ``git_commit``; with ``attrs["units"]``.

    Notes
    -----
    Cost: one query; one row per figure.
    """
    statement = (select(Figure, Run.plugin_version, Run.code_hash, Run.finished_at, Run.git_commit)
                 .join(Run, Run.run_id == Figure.run_id).order_by(Figure.figure))
    return _units(_frame(database, statement))


def _checked_query(query, database, time_limit, max_rows, memory_limit_mib):
    """The bounds of :func:`sql` checked (:func:`check_bounds`), and the query not empty."""
    bounds = check_bounds(time_limit, max_rows, memory_limit_mib)
    if not isinstance(query, str) or not query.strip():
        raise QueryError(f"{database}: empty query; expected one SQL query (SELECT ...)")
    return dict(zip(("time_limit", "max_rows", "memory_limit_mib"), bounds))


def sql(query, database=DEFAULT_DATABASE, *, time_limit=TIME_LIMIT_S, max_rows=MAX_ROWS,
        memory_limit_mib=MEMORY_LIMIT_MIB):
    """Run one SQL query on a read-only connection and return the result.

    Besides the read-only connection (``mode=ro``), an SQLite authorizer allows only
    reading: ``SELECT`` and ``WITH`` queries and the schema PRAGMAs of
    :data:`READ_ONLY_PRAGMAS`. ``ATTACH`` and ``VACUUM INTO`` (which would write other
    files), temporary tables and every other PRAGMA are refused.

    Parameters
    ----------
    query : str
        One SQL query (``SELECT ...``).
    database : str or pathlib.Path
    time_limit : float or None
        Stop the query after this many seconds [s]; None or 0: no limit.
    max_rows : int or None
        Refuse a result of more rows; None or 0: no limit.
    memory_limit_mib : float or None
        Memory [MiB] of SQLite (heap, temporary tables and sorts included), and of the result: the rows
        fetched and the table made of them (16 bytes a value), counted as they come; None or 0: no limit.

    Returns
    -------
    pandas.DataFrame
        Columns named as the query names them, a name repeated made unique (``x``, ``x.1``: :func:`unique_names`),
        those of the vocabulary in their dtype (:func:`stickslip.vocabulary.typed`: ``multi`` a bool,
        ``started_at`` a datetime, ...); ``attrs["units"]`` gives their units (None for the others).

    Raises
    ------
    QueryError
        If the SQL is empty or wrong, returns no rows, does anything but read, or runs into a bound; or a
        bound is not a number >= 0.
    KeyboardInterrupt
        On Ctrl-C (SIGINT), within a fraction of a second.

    Notes
    -----
    Cost: whatever the query costs, within the bounds; the indexes are listed in docs/database.md.
    """
    bounds = _checked_query(query, database, time_limit, max_rows, memory_limit_mib)
    return _units(_frame(database, text(query), only_reading=True, **bounds))


@contextmanager
def sql_pieces(query, database=DEFAULT_DATABASE, *, time_limit=TIME_LIMIT_S, max_rows=MAX_ROWS,
               memory_limit_mib=MEMORY_LIMIT_MIB):
    """Run one SQL query as :func:`sql` does, and stream its rows: the block reads them from the :class:`Pieces`.

    What the block does with a piece (formats it, writes it) counts against the time limit; memory is bounded
    for SQLite and for each piece, which is all that is held (``stickslip db sql --format csv|json``).

    Parameters
    ----------
    query, database, time_limit, max_rows, memory_limit_mib
        As :func:`sql`.

    Yields
    ------
    Pieces
        ``columns``, and lists of row tuples (values as SQLite gives them: int, float, str, bytes, None).

    Raises
    ------
    QueryError
        As :func:`sql`, also while the block reads (a bound reached after some rows were handed out).
    """
    bounds = _checked_query(query, database, time_limit, max_rows, memory_limit_mib)
    with _pieces(database, text(query), only_reading=True, kept=False, **bounds) as pieces:
        yield pieces
