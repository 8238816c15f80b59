"""`stickslip db`: runs, events, sql, ingest, rebuild, formats and errors."""

import io
import json
from contextlib import redirect_stdout

import pandas as pd

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
    assert status == 2 and "readonly" in capsys.readouterr().err
    status, _ = _run("db", "runs", "--db", "nowhere.sqlite")
    assert status == 2 and "nowhere.sqlite: no such database" in capsys.readouterr().err
