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
import itertools
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

from ..h5io import FileFormatError
from .database import SCHEMA_VERSION, Figure, Run, Simulation, engine_for

__all__ = ["DEFAULT_DATABASE", "QueryError", "READ_ONLY_PRAGMAS", "DENIED_FUNCTIONS", "TIME_LIMIT_S", "MAX_ROWS",
           "MEMORY_LIMIT_MIB", "CHECK_EVERY", "runs", "events", "figures", "sql", "check_bounds"]

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


#: Integer columns that an outer join may fill with NULL: kept as integers (pandas "Int64").
INTEGER_COLUMNS = ("n", "a", "plates", "blocks", "seed", "threads", "event", "interface", "increment")


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
        raise QueryError(f"{database}: database schema version {found}, expected {SCHEMA_VERSION}: "
                         f"run `stickslip db rebuild`")


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

    def take(self, piece):
        """Count a piece of fetched rows; raise QueryError past a bound (rows, bytes, time)."""
        self.rows += len(piece)
        self.bytes += _row_bytes(piece)
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


def _rows(connection, statement, bounds):
    """The rows of ``statement`` as a DataFrame, fetched in pieces that the bounds count (:meth:`_Bounds.take`).

    A piece holds up to :data:`_FETCH` rows and about :data:`_PIECE_BYTES`: rows of large values (blobs) are
    fetched a few at a time, so that no piece passes the memory bound by much.
    """
    result = connection.execute(statement)
    columns = list(result.keys())
    rows, size = [], 16
    while True:
        piece = result.fetchmany(size)
        try:
            bounds.take(piece)
        except BaseException:
            result.close()
            raise
        rows += piece
        if len(piece) < size:
            return pd.DataFrame.from_records(rows, columns=columns, coerce_float=True)
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


def _frame(database, statement, only_reading=False, time_limit=None, max_rows=None, memory_limit_mib=None):
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
                    frame = _rows(connection, statement, bounds)
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
        if "authoriz" in str(cause):  # "not authorized", "authorization denied"
            cause = f"refused ({cause}): `db sql` only reads (SELECT, WITH, PRAGMA {', '.join(READ_ONLY_PRAGMAS)})"
        raise QueryError(f"{database}: query failed: {cause}") from None
    finally:
        engine.dispose()
    for column in INTEGER_COLUMNS:
        if column in frame.columns:
            frame[column] = frame[column].astype("Int64")
    return frame


def _where(statement, filters):
    for column, value in filters:
        if value is not None:
            statement = statement.where(column == value)
    return statement


def runs(database=DEFAULT_DATABASE, *, kind=None, plugin=None, solver=None, n=None, regime=None, seed=None):
    """Return the runs, with their simulation parameters where they are simulations.

    Parameters
    ----------
    database : str or pathlib.Path
    kind : {"solver", "analysis", "figure", "mesh"}, optional
    plugin : str, optional
    solver : str, optional
        Only simulations of this solver.
    n : int, optional
        Only simulations with this number of driven interfaces.
    regime : str, optional
        Only simulations in this driving regime.
    seed : int, optional

    Returns
    -------
    pandas.DataFrame
        One row per run: the ``runs`` columns, then ``solver``, ``source``,
        ``protocol``, ``n``, ``a``, ``plates``, ``blocks``, ``k_drive``, ``phi``, ``regime``, ``temperature``,
        ``attempt_rate``, ``drive_rate``, ``junction_strengthening``, ``junction_glass_temperature``,
        ``junction_attempt_rate`` (NULL for runs that are not simulations); ordered by kind, plugin, run id.

    Notes
    -----
    Cost: one indexed query; linear in the number of runs returned.
    """
    columns = [Simulation.solver, Simulation.source, Simulation.protocol, Simulation.n, Simulation.a,
               Simulation.plates, Simulation.blocks, Simulation.k_drive, Simulation.phi, Simulation.regime,
               Simulation.temperature, Simulation.attempt_rate, Simulation.drive_rate, Simulation.junction_strengthening,
               Simulation.junction_glass_temperature, Simulation.junction_attempt_rate]
    statement = (select(Run, *columns).outerjoin(Simulation, Simulation.run_id == Run.run_id)
                 .order_by(Run.kind, Run.plugin, Run.run_id))
    statement = _where(statement, [(Run.kind, kind), (Run.plugin, plugin), (Simulation.solver, solver),
                                   (Simulation.n, n), (Simulation.regime, regime), (Run.seed, seed)])
    return _frame(database, statement)


def events(database=DEFAULT_DATABASE, *, solver=None, analysis=None, source=None, n=None, interface=None,
           regime=None, seed=None, run_id=None):
    """Return slip events with the parameters of their simulation.

    Parameters
    ----------
    database : str or pathlib.Path
    solver, analysis : str, optional
    source : {"numerical", "experimental"}, optional
    n : int, optional
        Number of driven interfaces of the simulation.
    interface : int, optional
        Interface (slab) ``a`` (1 = lowest).
    regime : str, optional
    seed : int, optional
    run_id : str, optional
        Only the events of this simulation.

    Returns
    -------
    pandas.DataFrame
        The ``slip_events_full`` view: one row per slip of one interface in one
        event, with ``protocol``, ``n``, ``a``, ``plates``, ``blocks``, ``k_drive``, ``phi``,
        ``regime``, ``seed``; ordered by simulation, event, interface.

    Notes
    -----
    Cost: one query using the indexes on solver, interface and simulation;
    linear in the number of events returned (a paper-size study has ~10^5-10^6).
    """
    conditions = {"solver": solver, "analysis": analysis, "source": source, "n": n, "interface": interface,
                  "regime": regime, "seed": seed, "simulation_run_id": run_id}
    used = {key: value for key, value in conditions.items() if value is not None}
    where = " AND ".join(f"{key} = :{key}" for key in used)
    statement = text("SELECT * FROM slip_events_full" + (f" WHERE {where}" if where else "")
                     + " ORDER BY simulation_run_id, event, interface").bindparams(**used)
    return _frame(database, statement)


def figures(database=DEFAULT_DATABASE):
    """Return the figures with the run that drew them (plugin version, code hash, time).

    Notes
    -----
    Cost: one query; one row per figure.
    """
    statement = (select(Figure, Run.plugin_version, Run.code_hash, Run.finished_at, Run.git_commit)
                 .join(Run, Run.run_id == Figure.run_id).order_by(Figure.figure))
    return _frame(database, statement)


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
        Memory [MiB] of SQLite (heap, temporary tables and sorts included), and of the rows fetched
        (the table built from them takes up to as much again); None or 0: no limit.

    Returns
    -------
    pandas.DataFrame

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
    time_limit, max_rows, memory_limit_mib = check_bounds(time_limit, max_rows, memory_limit_mib)
    if not isinstance(query, str) or not query.strip():
        raise QueryError(f"{database}: empty query; expected one SQL query (SELECT ...)")
    return _frame(database, text(query), only_reading=True, time_limit=time_limit, max_rows=max_rows,
                  memory_limit_mib=memory_limit_mib)
