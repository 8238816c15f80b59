"""Smoke test: the real ci study (workflow/config/ci.yaml) end to end with `snakemake --cores 2`."""

import sqlite3

import pytest
import yaml

from conftest import REPO, copy_workflow
from stickslip.provenance.record import REQUIRED_FIELDS, read_record
from test_workflow import snakemake


@pytest.mark.slow
def test_ci_study_end_to_end(tmp_path):
    directory = copy_workflow(tmp_path)
    config = yaml.safe_load((REPO / "workflow" / "config" / "ci.yaml").read_text())
    snakemake(directory, "--cores", "2", "--configfile", "workflow/config/ci.yaml")
    results = directory / "results"
    n_runs = sum(len(sweep["grid"].get("n", [1])) * len(sweep["grid"].get("a", [1])) * len(sweep["grid"]["seed"])
                 for solver in config["solvers"].values() for sweep in solver)
    sims = sorted(results.glob("sim/*/*.h5"))
    events = sorted(results.glob("events/*/*/*.h5"))
    assert len(sims) == n_runs and len(events) == n_runs * len(config["analyses"])
    for figure in config["figures"]:
        assert (results / "figures" / f"{figure}.pdf").stat().st_size > 1000
        assert (results / "figures" / f"{figure}.png").stat().st_size > 1000
    records = sorted(results.rglob("*.provenance.json"))
    assert len(records) == len(sims) + len(events) + len(config["figures"])
    for path in records:
        record = read_record(path)
        assert set(REQUIRED_FIELDS) <= set(record)
        assert record["outputs"] and all(len(entry["sha256"]) == 64 for entry in record["outputs"])
        assert record["wall_time_s"] > 0 and record["peak_memory_mib"] > 0
        assert record["versions"]["numba"] and record["host"]
    with sqlite3.connect(results / "stickslip.sqlite") as connection:
        runs = dict(connection.execute("SELECT kind, COUNT(*) FROM runs GROUP BY kind").fetchall())
        sims_db = connection.execute("SELECT COUNT(*) FROM simulations WHERE source = 'experimental'").fetchone()[0]
        events_db = connection.execute("SELECT COUNT(*), COUNT(DISTINCT simulation_run_id) FROM slip_events "
                                       "WHERE source = 'experimental' AND interface >= 1").fetchone()
    assert runs == {"solver": len(sims), "analysis": len(events), "figure": len(config["figures"])}
    assert sims_db == len(sims)
    assert events_db[0] > 10 * n_runs and events_db[1] == n_runs
    again = snakemake(directory, "-n", "--cores", "2", "--configfile", "workflow/config/ci.yaml")
    assert "Nothing to be done" in again.stdout + again.stderr
