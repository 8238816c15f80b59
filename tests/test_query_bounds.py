"""Bounds of one read-only query that hold for the process and are local to the query (issue 45, items 3, 4, 11-14).

The audit of c47ca12: ``db sql``'s memory bound covered SQLite's heap only (2 000 blobs of 1 MB came back, 2.1 GB),
it was process-wide and never lifted (a later default query and an unrelated sqlite3 connection failed), bad bound
values were tracebacks or accepted, a blob in JSON was a UnicodeDecodeError, ``study().sql()`` took no bounds,
``fts3_tokenizer`` was allowed (it returns a pointer), and a database path with ``?``, ``#`` or ``%`` broke the URI.
"""

import io
import json
import sqlite3
from contextlib import redirect_stdout

import pytest
from sqlalchemy import text

from stickslip.cli import main
from stickslip.provenance.database import create_schema, engine_for
from stickslip.provenance.query import QueryError, sql

#: 2 000 blobs of 1 MB: 2 GB of rows from a query that SQLite runs in a few MB of its own heap.
BLOBS = ("WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM c LIMIT 2000) "
         "SELECT randomblob(1000000) AS b FROM c")

#: One string of 40 MB in SQLite's heap (20 000 hexadecimal texts of 2 000 characters, comma-separated).
CONCAT = ("SELECT length(group_concat(hex(randomblob(1000)))) AS n FROM (WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL "
          "SELECT x + 1 FROM c LIMIT 20000) SELECT x FROM c)")


def _database(path):
    """An empty database of this package's schema at ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    engine = engine_for(path)
    create_schema(engine, "test")
    engine.dispose()
    return path


@pytest.fixture
def database(tmp_path):
    return _database(tmp_path / "results" / "default" / "stickslip.sqlite")


def _db(*argv):
    """``stickslip db ARGV``: (exit status, stdout); a refused argument exits as argparse does (status 2)."""
    out = io.StringIO()
    with redirect_stdout(out):
        try:
            status = main(["db", *argv])
        except SystemExit as exit:
            status = exit.code
    return status, out.getvalue()


def _error_line(capsys):
    """The one line that says what was wrong (argparse prints its usage before it)."""
    return capsys.readouterr().err.strip().splitlines()[-1]


def test_the_memory_bound_covers_the_rows_fetched(database):
    with pytest.raises(QueryError) as stopped:
        sql(BLOBS, database, memory_limit_mib=64)
    message = str(stopped.value)
    assert "memory limit of 64 MiB" in message and "\n" not in message
    # the rows are counted as they stream: the query stopped near its bound, not after holding 2 GB
    assert "after" in message and int(message.split("after ")[1].split(" rows")[0]) < 100


def test_a_bound_is_local_to_its_query(database):
    with pytest.raises(QueryError):
        sql(CONCAT, database, memory_limit_mib=30)
    # after it: a default query that needs more than 30 MiB of SQLite's heap, and another connection of the process
    assert int(sql(CONCAT, database)["n"].iloc[0]) == 20_000 * 2_000 + 19_999
    assert sqlite3.connect(":memory:").execute("SELECT length(randomblob(200000000))").fetchone() == (200_000_000,)


def test_study_sql_takes_the_bounds(database, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "Snakefile").write_text("")
    import stickslip

    study = stickslip.study("default")
    with pytest.raises(QueryError, match="more than 1 rows"):
        study.sql("SELECT 1 UNION ALL SELECT 2", max_rows=1)
    assert len(study.sql("SELECT 1 UNION ALL SELECT 2", max_rows=2)) == 2


@pytest.mark.parametrize("option, value", [("--memory-limit", "nan"), ("--memory-limit", "inf"),
                                           ("--memory-limit", "-1"), ("--time-limit", "-1"),
                                           ("--time-limit", "nan"), ("--max-rows", "-1"), ("--max-rows", "1.5")])
def test_bad_bounds_are_one_line(database, option, value, capsys):
    status, _ = _db("sql", "SELECT 1", "--db", str(database), option, value)
    error = _error_line(capsys)
    assert status == 2 and option in error, error
    name = option.lstrip("-").replace("-", "_") + ("_mib" if "memory" in option else "")
    with pytest.raises(QueryError, match=name):
        sql("SELECT 1", database, **{name: float(value)})


def test_zero_rows_bound_means_none_and_blobs_come_out_as_hex(database):
    status, out = _db("sql", "SELECT x'00ff10' AS b, 1 AS one", "--db", str(database), "--format", "json",
                      "--max-rows", "0")
    assert status == 0 and json.loads(out) == [{"b": "00ff10", "one": 1}]
    status, out = _db("sql", "SELECT x'00ff10' AS b", "--db", str(database), "--format", "csv")
    assert status == 0 and out.splitlines() == ["b", "00ff10"]


@pytest.mark.parametrize("function", ["fts3_tokenizer('simple')", "load_extension('x')"])
def test_functions_that_reach_past_sql_are_refused(database, function):
    with pytest.raises(QueryError, match="only reads"):
        sql(f"SELECT {function}", database)


@pytest.mark.parametrize("folder", ["n?y", "a#b", "p%20q"])
def test_database_paths_with_uri_characters(tmp_path, monkeypatch, folder):
    monkeypatch.chdir(tmp_path)
    database = _database(tmp_path / folder / "stickslip.sqlite")
    assert sql("SELECT value FROM schema_info WHERE key = 'schema_version'", database).shape == (1, 1)
    status, out = _db("sql", "SELECT COUNT(*) AS n FROM runs", "--db", str(database), "--format", "csv")
    assert status == 0 and out.splitlines() == ["n", "0"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [folder]  # no stray file named by a cut URI
    # read connections stay read-only
    with engine_for(database, readonly=True).connect() as connection:
        with pytest.raises(Exception, match="readonly"):
            connection.execute(text("CREATE TABLE t(x)"))


def test_study_option_is_a_name_under_results(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "Snakefile").write_text("")
    for name in ("../..", "a/b", ".."):
        status, _ = _db("ingest", "--study", name, str(tmp_path / "nothing.provenance.json"))
        error = _error_line(capsys)
        assert status == 2 and "--study" in error and "results/" in error, error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Snakefile"]
