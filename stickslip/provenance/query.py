"""Read the results database into pandas DataFrames (read-only connections).

Every function opens the SQLite file read-only (``mode=ro``), so a query can
never change it, and returns a :class:`pandas.DataFrame`. Filters left at
``None`` are not applied.

Every query stops on Ctrl-C (SIGINT) within a fraction of a second, also in the middle of
SQLite's work (a progress handler checks every :data:`CHECK_EVERY` virtual-machine
instructions), and :func:`sql` (``stickslip db sql``) is bounded by default: its time
(:data:`TIME_LIMIT_S`), the rows it returns (:data:`MAX_ROWS`) and SQLite's memory
(:data:`MEMORY_LIMIT_MIB`, temporary tables and sorts included, which are kept in memory); a
query past a bound stops with a :class:`QueryError` naming the bound and how to raise it.
"""

import signal
import sqlite3
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import pandas as pd
import sqlalchemy.exc
from sqlalchemy import select, text

from ..h5io import FileFormatError
from .database import SCHEMA_VERSION, Figure, Run, Simulation, engine_for

__all__ = ["DEFAULT_DATABASE", "QueryError", "READ_ONLY_PRAGMAS", "TIME_LIMIT_S", "MAX_ROWS", "MEMORY_LIMIT_MIB",
           "CHECK_EVERY", "runs", "events", "figures", "sql"]

#: Where the workflow writes the database of the default study (relative to the workflow directory);
#: a study named S has ``results/S/stickslip.sqlite``.
DEFAULT_DATABASE = "results/default/stickslip.sqlite"


#: Default bounds of :func:`sql`: seconds, rows returned, MiB of SQLite's memory (None: unbounded).
TIME_LIMIT_S = 60.0
MAX_ROWS = 1_000_000
MEMORY_LIMIT_MIB = 1024
#: SQLite virtual-machine instructions between two checks for Ctrl-C and the time limit (~1 ms).
CHECK_EVERY = 10_000
#: Rows fetched at a time (the row bound is checked between fetches).
_FETCH = 10_000


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


def _only_reading(action, name, argument, _database, _trigger):
    """SQLite authorizer: allow reading, deny everything else (ATTACH, VACUUM INTO, temporary tables, PRAGMA writes)."""
    if action in _READING or (action == sqlite3.SQLITE_PRAGMA and name in READ_ONLY_PRAGMAS):
        return sqlite3.SQLITE_OK
    return sqlite3.SQLITE_DENY


def _check_schema(database, connection):
    """Raise QueryError unless the database has this package's schema version."""
    found = connection.execute(text("SELECT value FROM schema_info WHERE key = 'schema_version'")).scalar()
    if found is None or int(found) != SCHEMA_VERSION:
        raise QueryError(f"{database}: database schema version {found}, expected {SCHEMA_VERSION}: "
                         f"run `stickslip db rebuild`")


@contextmanager
def _stoppable(driver, time_limit, memory_limit_mib):
    """Let a query on the sqlite3 connection ``driver`` stop on Ctrl-C, at ``time_limit`` [s] and past
    ``memory_limit_mib`` of SQLite's heap; yields a dict whose ``"stop"`` says why it stopped ("" if not)."""
    state = {"stop": ""}
    deadline = None if time_limit is None else time.monotonic() + time_limit

    def check():
        if not state["stop"] and deadline is not None and time.monotonic() > deadline:
            state["stop"] = "time"
        return 1 if state["stop"] else 0

    def interrupted(_signum, _frame):
        state["stop"] = "interrupt"  # seen by check() at SQLite's next CHECK_EVERY instructions

    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, interrupted) if main else None
    driver.set_progress_handler(check, CHECK_EVERY)
    if memory_limit_mib is not None:
        driver.execute("PRAGMA temp_store = MEMORY")  # temporary tables and sorts count against the limit
        driver.execute(f"PRAGMA hard_heap_limit = {int(memory_limit_mib * 2**20)}")
    try:
        yield state
    finally:
        if memory_limit_mib is not None:
            driver.execute("PRAGMA hard_heap_limit = 0")  # process-wide in SQLite: lift it again
        driver.set_progress_handler(None, 0)
        if main:
            signal.signal(signal.SIGINT, previous)
        if state["stop"] == "interrupt":
            raise KeyboardInterrupt


def _rows(connection, statement, max_rows):
    """The rows of ``statement`` as a DataFrame, fetched in pieces; raises QueryError past ``max_rows``."""
    result = connection.execute(statement)
    columns = list(result.keys())
    rows = []
    while True:
        piece = result.fetchmany(_FETCH)
        rows += piece
        if max_rows is not None and len(rows) > max_rows:
            result.close()
            raise QueryError(f"the query returns more than {max_rows} rows (the bound on rows: add LIMIT, or raise "
                             f"it with `db sql --max-rows N`, max_rows= in Python)")
        if len(piece) < _FETCH:
            return pd.DataFrame.from_records(rows, columns=columns, coerce_float=True)


def _bound_error(database, stop, cause, time_limit, memory_limit_mib):
    """The QueryError of a query that a bound stopped, or None."""
    if stop == "time":
        return QueryError(f"{database}: the query ran into the time limit of {time_limit:g} s (raise it with "
                          f"`db sql --time-limit SECONDS`, time_limit= in Python; 0: no limit)")
    if "out of memory" in str(cause) and memory_limit_mib is not None:
        return QueryError(f"{database}: the query reached SQLite's memory limit of {memory_limit_mib:g} MiB (raise it "
                          f"with `db sql --memory-limit MIB`, memory_limit_mib= in Python; 0: no limit)")
    return None


def _frame(database, statement, only_reading=False, time_limit=None, max_rows=None, memory_limit_mib=None):
    engine = _engine(database)
    state = {"stop": ""}
    try:
        with engine.connect() as connection:
            _check_schema(database, connection)
            driver = connection.connection.driver_connection
            with _stoppable(driver, time_limit, memory_limit_mib) as state:
                if only_reading:
                    driver.set_authorizer(_only_reading)
                try:
                    frame = _rows(connection, statement, max_rows)
                finally:
                    driver.set_authorizer(None)
    except sqlalchemy.exc.ResourceClosedError:
        raise QueryError(f"{database}: the statement returns no rows; `db sql` runs queries (SELECT)") from None
    except QueryError as error:
        raise QueryError(f"{database}: {error}") from None
    except MemoryError:  # SQLITE_NOMEM: the heap limit (Python's own rows are bounded by max_rows)
        if memory_limit_mib is None:
            raise
        raise _bound_error(database, "", "out of memory", time_limit, memory_limit_mib) from None
    except (pd.errors.DatabaseError, sqlalchemy.exc.DBAPIError) as error:
        cause = getattr(error.__cause__, "orig", None) or getattr(error, "orig", None) or error.__cause__ or error
        bound = _bound_error(database, state["stop"], cause, time_limit, memory_limit_mib)
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
        ``attempt_rate``, ``drive_rate`` (NULL for runs that are not simulations); ordered by kind, plugin, run id.

    Notes
    -----
    Cost: one indexed query; linear in the number of runs returned.
    """
    columns = [Simulation.solver, Simulation.source, Simulation.protocol, Simulation.n, Simulation.a,
               Simulation.plates, Simulation.blocks, Simulation.k_drive, Simulation.phi, Simulation.regime,
               Simulation.temperature, Simulation.attempt_rate, Simulation.drive_rate]
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
        SQLite's memory (heap, temporary tables and sorts included) [MiB]; None or 0: no limit.

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    QueryError
        If the SQL is empty or wrong, returns no rows, does anything but read, or runs into a bound.
    KeyboardInterrupt
        On Ctrl-C (SIGINT), within a fraction of a second.

    Notes
    -----
    Cost: whatever the query costs, within the bounds; the indexes are listed in docs/database.md.
    """
    if not query.strip():
        raise QueryError(f"{database}: empty query; expected one SQL query (SELECT ...)")
    return _frame(database, text(query), only_reading=True, time_limit=time_limit or None, max_rows=max_rows or None,
                  memory_limit_mib=memory_limit_mib or None)
