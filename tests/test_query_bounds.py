"""Bounds of one read-only query that hold for the process and are local to the query (issue 45, items 3, 4, 11-14).

The audit of 575c37a (issue 59, items 2, 3): results that were wide passed both bounds (1e6 rows of 31 columns
exited 0 after 99 s at 2.3 GB: a DataFrame was built and formatted outside them), and repeated column names were an
AttributeError traceback. ``db sql --format csv|json`` now streams its rows, the time limit covers the writing,
``sql()`` counts the table it returns.

The audit of c47ca12: ``db sql``'s memory bound covered SQLite's heap only (2 000 blobs of 1 MB came back, 2.1 GB),
it was process-wide and never lifted (a later default query and an unrelated sqlite3 connection failed), bad bound
values were tracebacks or accepted, a blob in JSON was a UnicodeDecodeError, ``study().sql()`` took no bounds,
``fts3_tokenizer`` was allowed (it returns a pointer), and a database path with ``?``, ``#`` or ``%`` broke the URI.
"""

import io
import json
import sqlite3
import subprocess
import sys
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


def _wide(rows, columns=31):
    """The audit's wide result (issue 59, item 2): ``rows`` rows of ``columns`` integer columns."""
    named = ", ".join(f"x AS c{i}" for i in range(columns))
    return f"WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM c LIMIT {rows}) SELECT {named} FROM c"


STREAM = """
import os, resource, sys
from stickslip.cli import main
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
sys.stdout = open(os.devnull, "w")
status = main(["db", "sql", sys.argv[1], "--db", sys.argv[2], "--format", sys.argv[3], "--time-limit", "0"])
print(status, (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base) / 1024, file=sys.stderr)
"""


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["csv", "json"])
def test_csv_and_json_stream_a_wide_result_in_the_memory_of_a_piece(database, fmt):
    # 100 000 rows of 31 columns: held whole, their rows and table take ~230 MiB (the audit: 1e6 rows, 2.3 GB)
    done = subprocess.run([sys.executable, "-c", STREAM, _wide(100_000), str(database), fmt], capture_output=True,
                          text=True, check=True)
    status, grown = done.stderr.split()[-2:]
    assert status == "0" and float(grown) < 120, done.stderr


def test_the_time_limit_covers_the_writing_and_the_output_keeps_the_rows_before_it(database, capsys):
    status, out = _db("sql", _wide(1_000_000), "--db", str(database), "--format", "csv", "--time-limit", "0.5")
    error = _error_line(capsys)
    assert status == 2 and "time limit of 0.5 s" in error, error
    written = int(error.split("(the output holds the ")[1].split(" rows")[0])
    assert 0 < written < 1_000_000 and len(out.splitlines()) == written + 1


def test_sql_counts_the_table_it_returns_against_the_memory_bound(database):
    # 100 000 rows of 31 numbers: ~92 MiB of fetched rows, ~47 MiB more for the DataFrame made of them
    with pytest.raises(QueryError, match="memory limit of 120 MiB"):
        sql(_wide(100_000), database, memory_limit_mib=120)
    assert sql(_wide(1_000), database, memory_limit_mib=120).shape == (1_000, 31)


@pytest.mark.parametrize("fmt", ["csv", "json", "table"])
def test_repeated_column_names_are_made_unique(database, fmt):
    # the audit (issue 59, item 3): an AttributeError traceback in every format
    status, out = _db("sql", "SELECT 1 AS x, 2 AS x, x'ff' AS x", "--db", str(database), "--format", fmt)
    assert status == 0
    if fmt == "json":
        assert json.loads(out) == [{"x": 1, "x.1": 2, "x.2": "ff"}]
    elif fmt == "csv":
        assert out.splitlines() == ["x,x.1,x.2", "1,2,ff"]
    else:
        assert out.splitlines()[0].split() == ["x", "x.1", "x.2"]
    assert list(sql("SELECT 1 AS x, 2 AS x", database).columns) == ["x", "x.1"]
    status, _ = _db("sql", "SELECT * FROM runs a JOIN runs b USING(run_id) LIMIT 1", "--db", str(database),
                    "--format", fmt)
    assert status == 0
