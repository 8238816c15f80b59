"""`stickslip db`: runs, events, sql, ingest, rebuild, formats and errors."""

import io
import json
import os
import signal
import subprocess
import sys
import time
from contextlib import redirect_stdout
from pathlib import Path

import pandas as pd
import pytest
from conftest import time_to_stop

from stickslip.cli import main


def _run(*argv):
    out = io.StringIO()
    with redirect_stdout(out):
        status = main(list(argv))
    return status, out.getvalue()


def test_db_commands(toy_results, capsys):
    status, text = _run("db", "rebuild")
    assert status == 0 and "rebuilt from 5 records, 8 slip events" in text
    status, text = _run("db", "runs", "--kind", "solver", "--format", "csv")
    frame = pd.read_csv(io.StringIO(text))
    assert status == 0 and sorted(frame["seed"]) == [1, 2] and set(frame["solver"]) == {"toy-spring-block"}
    status, text = _run("db", "events", "--seed", "2", "--interface", "1", "--format", "json")
    rows = json.loads(text)
    assert status == 0 and len(rows) == 4 and all(r["seed"] == 2 and r["interface"] == 1 for r in rows)
    status, text = _run("db", "events", "--n", "3")
    assert status == 0 and text.strip() == "(no rows)"
    status, text = _run("db", "runs")
    assert status == 0 and "toy-force" in text and "run_id" in text.splitlines()[0]
    status, text = _run("db", "sql", "SELECT kind, COUNT(*) AS runs FROM runs GROUP BY kind ORDER BY kind",
                        "--format", "csv")
    assert text.splitlines() == ["kind,runs", "analysis,2", "figure,1", "solver,2"]
    status, text = _run("db", "ingest", *map(str, toy_results))
    assert status == 0 and "5 records" in text
    capsys.readouterr()
    status, _ = _run("db", "sql", "DROP TABLE runs")
    assert status == 2 and "only reads" in capsys.readouterr().err
    status, _ = _run("db", "runs", "--db", "nowhere.sqlite")
    assert status == 2 and "nowhere.sqlite: no such database" in capsys.readouterr().err


def test_db_options_before_or_after_the_sub_command(toy_results, tmp_path, monkeypatch):
    """``--workdir``, ``--study`` and ``--db`` work before the sub-command (``db --workdir DIR runs``) and after it,
    and after it they win."""
    _run("db", "rebuild")
    workflow = Path.cwd()
    (workflow / "Snakefile").write_text("")
    monkeypatch.chdir(tmp_path)  # no Snakefile at or above
    after = _run("db", "runs", "--workdir", str(workflow), "--format", "csv")
    before = _run("db", "--workdir", str(workflow), "runs", "--format", "csv")
    assert after == before and after[0] == 0 and len(pd.read_csv(io.StringIO(after[1]))) == 5
    assert _run("db", "--workdir", str(tmp_path), "runs", "--workdir", str(workflow), "--format", "csv") == after
    assert _run("db", "--study", "default", "--workdir", str(workflow), "events", "--seed", "2")[0] == 0
    assert _run("db", "--db", str(workflow / "results" / "default" / "stickslip.sqlite"), "runs")[0] == 0


def test_db_sql_only_reads(toy_results, capsys, tmp_path):
    assert _run("db", "rebuild")[0] == 0
    database = tmp_path / "results" / "default" / "stickslip.sqlite"
    before = database.read_bytes()
    capsys.readouterr()
    refused = {
        f"VACUUM INTO '{tmp_path / 'copy.sqlite'}'": "only reads",
        f"ATTACH DATABASE '{tmp_path / 'new.sqlite'}' AS new": "only reads",
        "PRAGMA writable_schema=ON": "only reads",
        "PRAGMA query_only=OFF": "only reads",
        "CREATE TEMP TABLE scratch(x)": "only reads",
        "DELETE FROM runs": "only reads",
        "": "empty query",
        "   ": "empty query",
    }
    for query, cause in refused.items():
        status, text = _run("db", "sql", query)
        err = capsys.readouterr().err
        assert status == 2 and text == "" and len(err.splitlines()) == 1 and cause in err, (query, err)
    assert not (tmp_path / "copy.sqlite").exists() and not (tmp_path / "new.sqlite").exists()
    assert database.read_bytes() == before
    status, text = _run("db", "sql", "PRAGMA table_info(runs)", "--format", "csv")
    assert status == 0 and "run_id" in pd.read_csv(io.StringIO(text))["name"].tolist()
    status, text = _run("db", "sql", "WITH RECURSIVE r(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM r WHERE i < 3) "
                                     "SELECT SUM(i) AS s FROM r", "--format", "csv")
    assert status == 0 and text.splitlines() == ["s", "6"]


def test_database_mode_schema_version_and_wrong_files(toy_results, capsys, tmp_path):
    import sqlite3
    import stat

    assert _run("db", "rebuild")[0] == 0
    database = tmp_path / "results" / "default" / "stickslip.sqlite"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(database.stat().st_mode) == 0o666 & ~umask  # a group can read it if the umask lets it
    assert not [p.name for p in database.parent.iterdir() if p.name.endswith(".tmp")]
    with sqlite3.connect(database) as connection:
        connection.execute("UPDATE schema_info SET value = '1' WHERE key = 'schema_version'")
    capsys.readouterr()
    for command in (["runs"], ["events"], ["sql", "SELECT 1"]):
        status, text = _run("db", *command)
        err = capsys.readouterr().err
        assert status == 2 and err.count("\n") == 1 and "schema version 1, expected" in err
        assert "stickslip db migrate" in err
    lab = tmp_path / "lab.h5"
    lab.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(100))
    assert _run("db", "runs", "--db", str(lab))[0] == 2
    assert capsys.readouterr().err == f"stickslip: error: {lab}: query failed: file is not a database\n"


def test_every_db_command_describes_itself():
    for command in ("runs", "events", "sql", "ingest", "rebuild"):
        out = io.StringIO()
        with redirect_stdout(out), pytest.raises(SystemExit):
            main(["db", command, "--help"])
        assert out.getvalue().split("\n\n")[1].strip()[0].isupper()  # the paragraph after the usage


#: A query that never ends by itself (its rows have no end), one that counts for minutes, and one
#: that needs gigabytes (a distinct set of 10^8 numbers).
ENDLESS = "WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM c) SELECT x FROM c"
SLOW = "WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM c WHERE x < 10000000000) SELECT COUNT(*) FROM c"
GREEDY = ("WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM c WHERE x < 100000000) "
          "SELECT COUNT(DISTINCT x) FROM c")


def test_db_sql_is_bounded_in_rows_time_and_memory(toy_results, capsys):
    assert _run("db", "rebuild")[0] == 0
    capsys.readouterr()
    for argv, bound, option in (((ENDLESS, "--max-rows", "50000"), "more than 50000 rows", "--max-rows N"),
                                ((SLOW, "--time-limit", "0.5"), "time limit of 0.5 s", "--time-limit SECONDS"),
                                ((GREEDY, "--memory-limit", "16"), "memory limit of 16 MiB", "--memory-limit MIB")):
        start = time.monotonic()
        status, text = _run("db", "sql", *argv)
        error = capsys.readouterr().err
        assert status == 2 and text == "" and bound in error and option in error, error
        assert len(error.strip().splitlines()) == 1 and time.monotonic() - start < 20
    status, text = _run("db", "sql", "SELECT COUNT(*) AS runs FROM runs", "--format", "csv")
    assert status == 0 and text.splitlines() == ["runs", "5"]  # bounds lifted again (SQLite's heap limit is global)


def test_db_sql_stops_at_ctrl_c_within_a_second(toy_results):
    assert _run("db", "rebuild")[0] == 0
    process = subprocess.Popen([sys.executable, "-m", "stickslip", "db", "sql", SLOW, "--time-limit", "0"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(4.0)  # started, and inside SQLite (the count takes minutes)
    assert process.poll() is None
    assert time_to_stop(process, signal.SIGINT, 10, "db sql") < 1.5 and process.returncode == 130


def test_a_mistyped_regime_is_refused_not_answered_with_no_rows(toy_results, capsys):
    assert _run("db", "rebuild")[0] == 0
    capsys.readouterr()
    for command in ("events", "runs"):
        with pytest.raises(SystemExit) as exited:
            _run("db", command, "--regime", "complaint")
        assert exited.value.code == 2
        assert "invalid choice: 'complaint' (choose from 'stiff', 'compliant')" in capsys.readouterr().err


@pytest.mark.parametrize("damage", ["not a database", "cut short"])
def test_ingest_into_a_damaged_database_is_one_line_and_leaves_it(toy_results, capsys, tmp_path, damage):
    # the audit of 575c37a (issue 59, item 4): a sqlalchemy DatabaseError traceback
    assert _run("db", "rebuild")[0] == 0
    database = tmp_path / "results" / "default" / "stickslip.sqlite"
    if damage == "cut short":
        database.write_bytes(database.read_bytes()[:3000])
    else:
        database.write_bytes(os.urandom(5000))
    before = database.read_bytes()
    capsys.readouterr()
    assert _run("db", "ingest", "--db", str(database), *map(str, toy_results))[0] == 2
    error = capsys.readouterr().err
    assert error.startswith(f"stickslip: error: {database}: not a readable SQLite database (")
    assert error.count("\n") == 1
    assert "`stickslip db rebuild` remakes it" in error and database.read_bytes() == before
