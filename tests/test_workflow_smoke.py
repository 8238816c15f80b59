"""Smoke test: the real ci study (workflow/config/ci.yaml) end to end with `snakemake --cores 2`."""

import re
import sqlite3

import pytest
import yaml

from conftest import REPO
from stickslip.provenance.record import REQUIRED_FIELDS, read_record
from stickslip.study_plan import Study
from test_workflow import snakemake


@pytest.mark.slow
def test_ci_study_end_to_end(ci_study):
    directory = ci_study
    study = Study(yaml.safe_load((REPO / "workflow" / "config" / "ci.yaml").read_text()), ["ci.yaml"])
    assert {sim.solver for sim in study.simulations} >= {"lever", "fem"}
    results = directory / "results" / "ci"
    for path in study.outputs():
        assert (directory / path).stat().st_size > 0, path
    # every job's log shows its progress, ending with the whole work done
    for sim in study.simulations:
        log = (directory / study.log(f"sim/{sim.solver}/{sim.run_id}")).read_text()
        done = {"fem": r"fem increments: 200/200 increment \(100%\)",
                "lever": r"virtual experiment: (\d+)/\1 s simulated \(100%\)"}
        assert re.search(done[sim.solver], log), log
    records_count = len(study.records())
    assert f"ingest: {records_count}/{records_count} record (100%)" in (directory / study.log("database")).read_text()
    records = sorted(results.rglob("*.provenance.json"))
    assert [p.relative_to(directory).as_posix() for p in records] == study.records()
    for path in records:
        record = read_record(path)
        assert set(REQUIRED_FIELDS) <= set(record)
        assert record["outputs"] and all(len(entry["sha256"]) == 64 for entry in record["outputs"])
        assert record["wall_time_s"] > 0 and record["peak_memory_mib"] > 0
        assert record["versions"]["numba"] and record["host"]
    with sqlite3.connect(results / "stickslip.sqlite") as connection:
        runs = dict(connection.execute("SELECT kind, COUNT(*) FROM runs GROUP BY kind").fetchall())
        sources = dict(connection.execute("SELECT solver, source FROM simulations").fetchall())
        events = dict(connection.execute("SELECT source, COUNT(DISTINCT simulation_run_id) FROM slip_events "
                                         "WHERE interface >= 1 GROUP BY source").fetchall())
    assert runs == {"mesh": len(study.meshes), "solver": len(study.simulations),
                    "analysis": len(study.analysis_jobs), "figure": len(study.figures)}
    assert sources == {"lever": "experimental", "fem": "numerical"}
    # every run has slip events (the seeds are fixed: this holds for the ci sizes)
    assert events == {"experimental": sum(sim.solver == "lever" for sim in study.simulations),
                      "numerical": sum(sim.solver == "fem" for sim in study.simulations)}
    again = snakemake(directory, "-n", "--cores", "2", "--configfile", "workflow/config/ci.yaml")
    assert "Nothing to be done" in again.stdout + again.stderr
