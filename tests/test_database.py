"""The results database: ingest (idempotent, atomic, concurrent), schema, queries."""

import multiprocessing
import sqlite3
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from stickslip.formats.event_table import read_slip_events
from stickslip.h5io import FileFormatError
from stickslip.lineage import Artifact
from stickslip.plugin_params import ParameterError, parse_params
from stickslip.provenance import ingest as ingest_module
from stickslip.provenance import query
from stickslip.provenance.database import SCHEMA_VERSION, create_schema, engine_for
from stickslip.provenance.ingest import find_records, ingest
from stickslip.provenance.record import read_record


def _counts(database):
    with sqlite3.connect(database) as connection:
        return {table: connection.execute(f"SELECT COUNT(*) FROM {table}").fetchone()[0]
                for table in ("runs", "artifacts", "simulations", "slip_events", "figures")}


def test_ingest_fills_every_table_from_records(toy_results):
    database = "results/default/stickslip.sqlite"
    counts = ingest(database, toy_results)
    assert counts["records"] == 5
    table = _counts(database)
    # 2 simulations + 2 analyses + 1 figure; artifacts: 2 + 2x2 + (4 inputs + 2 outputs)
    assert table == {"runs": 5, "artifacts": 12, "simulations": 2, "slip_events": 8, "figures": 1}
    runs = query.runs(database)
    assert sorted(runs["kind"]) == ["analysis", "analysis", "figure", "solver", "solver"]
    sims = query.runs(database, kind="solver")
    assert sorted(sims["seed"]) == [1, 2]
    # events: the slips of the table, one per slip, each equal to the file's values
    run = query.runs(database, kind="solver", seed=1)["run_id"].iloc[0]
    events = query.events(database, run_id=run)
    slips = read_slip_events(f"results/default/events/toy-slips/toy-spring-block/{run}.h5")
    np.testing.assert_array_equal(events["slip"].to_numpy(), slips["slip"].to_numpy())
    np.testing.assert_array_equal(events["time"].to_numpy(), slips["time"].to_numpy())
    assert set(events["seed"]) == {1} and set(events["interface"]) == {1}
    assert set(events["source"]) == {"numerical"}  # the source the toy-block format declares
    assert pd.isna(events["increment"]).all()  # a column the table leaves out is NULL
    # lineage: the figure's inputs name the runs that made them
    made_by = query.sql("SELECT role, made_by FROM artifacts AS a JOIN runs AS r ON r.run_id = a.run_id "
                        "WHERE r.kind = 'figure' AND a.direction = 'input' ORDER BY role, made_by", database)
    analyses = query.runs(database, kind="analysis")["run_id"]
    assert list(made_by["role"]) == ["analysis:toy-slips"] * 2 + ["simulation"] * 2
    assert set(made_by["made_by"][:2]) == set(analyses) and set(made_by["made_by"][2:]) == set(sims["run_id"])
    assert list(query.figures(database)["figure"]) == ["toy-force"]
    assert query.sql("SELECT value FROM schema_info WHERE key = 'schema_version'", database).iloc[0, 0] == str(
        SCHEMA_VERSION)


def test_runs_show_a_parameter_that_a_record_leaves_out_at_its_default(toy_results):
    """A record made before a parameter existed (or leaving an extension at its default out): runs() shows the
    default, not a missing value; a record of another code-hash scheme ingests as any (it is a text)."""
    import json

    database = "results/default/stickslip.sqlite"
    solver = next(path for path in toy_results if "/sim/" in path.as_posix())
    record = json.loads(solver.read_text())
    del record["params"]["disorder"]  # as a run made before the parameter existed records it
    record["code_hash"] = "an older scheme"
    solver.write_text(json.dumps(record))
    ingest(database, find_records("results/default"), rebuild=True)
    runs = query.runs(database, kind="solver").set_index("run_id")
    assert runs.loc[record["run_id"], "params.disorder"] == 0.2  # BlockParams' default
    assert runs.loc[record["run_id"], "code_hash"] == "an older scheme"
    assert runs["params.disorder"].notna().all() and sorted(runs["params.seed"]) == [1, 2]
    stored = query.sql(f"SELECT params FROM runs WHERE run_id = '{record['run_id']}'", database)
    assert "disorder" not in json.loads(stored["params"].iloc[0])  # the database keeps the record as it is


def test_ingest_is_idempotent_and_rebuild_matches(toy_results):
    database = "results/default/stickslip.sqlite"
    ingest(database, toy_results)
    first = _counts(database)
    ingest(database, toy_results)
    ingest(database, toy_results[:2])
    assert _counts(database) == first
    ingest(database, find_records("results/default"), rebuild=True)
    assert _counts(database) == first
    ingest(database, toy_results[:1], rebuild=True)  # a rebuild holds exactly its records
    assert _counts(database)["runs"] == 1


def test_an_interrupted_ingest_leaves_the_previous_database(toy_results, monkeypatch):
    database = "results/default/stickslip.sqlite"
    ingest(database, toy_results[:2])
    before = _counts(database)

    calls = []
    original = ingest_module._ingest_record

    def failing(session, record, record_file):
        calls.append(record_file)
        if len(calls) == 3:
            raise KeyboardInterrupt  # e.g. Ctrl-C in the middle of the ingest
        return original(session, record, record_file)

    monkeypatch.setattr(ingest_module, "_ingest_record", failing)
    with pytest.raises(KeyboardInterrupt):
        ingest(database, toy_results)
    assert _counts(database) == before
    monkeypatch.setattr(ingest_module, "_ingest_record", original)
    # a corrupted record: named, and the database is unchanged
    toy_results[-1].write_text("{")
    with pytest.raises(FileFormatError, match="toy-force.provenance.json: not a valid provenance record"):
        ingest(database, toy_results)
    assert _counts(database) == before
    assert [p.name for p in toy_results[0].parents[2].iterdir() if p.name.endswith(".tmp")] == []


def _ingest_one(args):
    database, record = args
    ingest(database, [record])


def _ingest_together(barrier, database, records):
    """Ingest ``records`` once every writer is ready, each record read slowly: the writers overlap."""
    read = ingest_module.read_record
    ingest_module.read_record = lambda path: (time.sleep(0.3), read(path))[1]
    barrier.wait(timeout=120)
    ingest(database, records)


def test_concurrent_ingests_lose_no_record(toy_results):
    database = "results/default/stickslip.sqlite"
    context = multiprocessing.get_context("spawn")
    barrier = context.Barrier(2)
    halves = [[str(r) for r in toy_results[:2]], [str(r) for r in toy_results[2:]]]
    writers = [context.Process(target=_ingest_together, args=(barrier, database, half)) for half in halves]
    for writer in writers:
        writer.start()
    for writer in writers:
        writer.join(timeout=300)
        assert writer.exitcode == 0
    assert _counts(database)["runs"] == len(toy_results)  # each writer's records: neither replaced the other's
    with multiprocessing.get_context("spawn").Pool(2) as pool:  # and the same records again change nothing
        pool.map(_ingest_one, [(database, str(r)) for r in toy_results * 2])
    assert _counts(database)["runs"] == len(toy_results)
    assert set(query.runs(database)["run_id"]) == {read_record(r)["run_id"] for r in toy_results}


def test_queries_are_read_only_and_filter(toy_results):
    database = "results/default/stickslip.sqlite"
    ingest(database, toy_results)
    with pytest.raises(query.QueryError, match="only reads"):
        query.sql("DELETE FROM runs", database)
    assert _counts(database)["runs"] == 5
    assert len(query.events(database, interface=2)) == 0
    assert len(query.events(database, solver="toy-spring-block", seed=2)) == 4
    assert len(query.runs(database, plugin="toy-slips")) == 2
    run = query.runs(database, kind="solver", seed=1).iloc[0]
    assert run["params.slips"] == 4 and run["params.seed"] == 1  # every parameter, a typed column
    assert len(query.runs(database, slips=4)) == 2 and query.runs(database, slips=5).empty  # a plugin parameter
    for bad, message in ((dict(kind="simulation"), "filter 'kind': 'simulation' is not allowed; expected one of"),
                         (dict(plugin="toy-slip"), "values in this database: 'toy-force', 'toy-slips', "
                                                   "'toy-spring-block' \\(did you mean 'toy-slips'\\?\\)"),
                         (dict(slips="many"), "filter 'slips': expected an integer"),
                         (dict(colour="red"), "unknown filter 'colour'")):
        with pytest.raises(ParameterError, match=message):
            query.runs(database, **bad)
    with pytest.raises(FileFormatError, match="no such database"):
        query.runs("results/missing.sqlite")


def test_ingest_reads_lineage_and_formats_not_paths(tmp_path, toy_plugins, monkeypatch):
    """Files under arbitrary names: events are keyed by the run id the lineage carries."""
    from stickslip import registry
    from stickslip.study_plan import Study
    from stickslip.workflow_api import run_analysis, run_simulation

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NUMBA_NUM_THREADS", "1")  # the jobs set it; restored after the test
    solver, analysis = registry.get("solver", "toy-spring-block"), registry.get("analysis", "toy-slips")
    run = registry.run_id(solver, parse_params(solver.params, {"seed": 3, "slips": 3}))
    sim = Artifact("anything/first.h5", run, solver.name, solver.produces)
    run_simulation(solver.name, '{"seed": 3, "slips": 3}', sim.path, "anything/first.provenance.json", "log1",
                   inputs={}, threads=1)
    run_analysis(analysis.name, "{}", Study.dumps(sim), "elsewhere/slips.h5", "elsewhere/slips.provenance.json",
                 "log2")
    ingest("db.sqlite", ["anything/first.provenance.json", "elsewhere/slips.provenance.json"])
    events = query.events("db.sqlite")
    assert list(query.runs("db.sqlite", kind="solver")["run_id"]) == [run]
    assert len(events) == 3 and set(events["simulation_run_id"]) == {run} and set(events["seed"]) == {3}
    assert set(events["solver"]) == {"toy-spring-block"}
    with pytest.raises(FileFormatError, match="a fem-run file; analysis 'toy-slips' reads toy-block"):
        wrong = Artifact("anything/first.h5", run, "fem", "fem-run")
        run_analysis(analysis.name, "{}", Study.dumps(wrong), "x.h5", "x.provenance.json", "log3")


def test_the_periodicity_of_a_numerical_run_goes_to_its_table_and_view(tmp_path, monkeypatch):
    """An event file's one-row ``periodicity`` table -> ``run_periodicity``; the view adds the simulation's columns."""
    from stickslip.events.plugin import NAME, VERSION, event_attrs, event_tables, write_event_file
    from stickslip.provenance.record import recording
    from test_events_extraction import EVENTS, N, history, run_attrs

    monkeypatch.chdir(tmp_path)
    simulation = Artifact("sim/abc.h5", "0123456789abcdef", "fem", "fem-run")
    simulation.path.parent.mkdir()
    simulation.path.write_bytes(b"a stand-in for the run file")
    tables = event_tables(history(N, EVENTS), N)
    with recording("events/abc.provenance.json", [("output", "events/abc.h5", "event-table")], run_id="fedcba9876543210",
                   kind="analysis", plugin=NAME, plugin_version=VERSION, code_hash="x", params={},
                   inputs=[("simulation", simulation)]):
        write_event_file(tables, event_attrs(run_attrs(N, 3, 1e-3), tables["increments"]),
                         "events/abc.h5", input=simulation.path)
    ingest("db.sqlite", ["events/abc.provenance.json"])
    row = query.sql("SELECT * FROM periodicity_full", "db.sqlite")
    expected = tables["periodicity"].iloc[0]
    assert len(row) == 1 and row["simulation_run_id"].iloc[0] == "0123456789abcdef"
    assert row["n_slips"].iloc[0] == expected["n_slips"] and row["n_multi"].iloc[0] == expected["n_multi"]
    assert row["interval_cv"].iloc[0] == pytest.approx(expected["interval_cv"])
    assert row["alternation_cv"].isna().iloc[0] == np.isnan(expected["alternation_cv"])  # NaN is NULL
    assert row["phi"].isna().iloc[0]  # the simulation itself was not ingested: its columns are NULL
    ingest("db.sqlite", ["events/abc.provenance.json"])  # idempotent
    assert len(query.sql("SELECT * FROM run_periodicity", "db.sqlite")) == 1


def test_a_schema_6_database_migrates_to_this_schema_keeping_its_rows(tmp_path):
    """stickslip db migrate: a database written by c47ca12 (tests/data/schema6.sql) reads as this schema's."""
    from stickslip.cli import main
    from stickslip.provenance.migrate import migrate

    database = tmp_path / "stickslip.sqlite"
    with sqlite3.connect(database) as connection:
        connection.executescript((Path(__file__).parent / "data" / "schema6.sql").read_text())
        old = {row[0]: row[1:] for row in connection.execute("SELECT id, dmu, time, source FROM slip_events")}
        connection.execute("INSERT INTO slip_events (id, analysis_run_id, simulation_run_id, analysis, solver, source, "
                           "event, interface, dmu, multi, time, increment, extra) SELECT 999, analysis_run_id, "
                           "simulation_run_id, 'thermal-events', solver, source, 0, 1, 0.5, 0, 12.5, 3, "
                           "'{\"T\": 2.0, \"B_a\": 0.7, \"mu_before\": 1.5, \"hold\": 0.0}' FROM slip_events "
                           "WHERE source = 'numerical' LIMIT 1")
        sims = connection.execute("SELECT run_id, a FROM simulations ORDER BY run_id").fetchall()
    with pytest.raises(query.QueryError, match="database schema version 6, expected 7: run `stickslip db migrate`"):
        query.events(database)
    assert migrate(database) == (6, SCHEMA_VERSION)
    events = query.events(database).set_index("id")
    for row, (dmu, time_, source) in old.items():
        numerical = source == "numerical"
        assert events.loc[row, "dmu_sig0" if numerical else "dmu"] == dmu
        assert pd.isna(events.loc[row, "dmu" if numerical else "dmu_sig0"])
        assert events.loc[row, "time"] == time_ if time_ is not None else pd.isna(events.loc[row, "time"])
    thermal = events.loc[999]
    assert (thermal["dmu_sig0"], thermal["t"], thermal["T_fe"], thermal["B_a_sig0"], thermal["mu_before_sig0"],
            thermal["hold"]) == (0.5, 12.5, 2.0, 0.7, 1.5, 0.0)
    assert pd.isna(thermal["dmu"]) and pd.isna(thermal["time"]) and pd.isna(thermal["T"])
    experimental = events[events["source"] == "experimental"]
    assert experimental["slip_from_dF"].notna().all() and "dR_from_dF" not in events.columns
    assert events["multi"].dtype == bool
    assert query.sql("SELECT run_id, driven_slab FROM simulations ORDER BY run_id", database).astype(object).where(
        lambda f: f.notna(), None).values.tolist() == [list(row) for row in sims]
    periodicity = query.sql("SELECT n_slips, n_multi, n_spanning FROM periodicity_full", database)
    assert len(periodicity) == 1 and periodicity["n_slips"].iloc[0] >= periodicity["n_multi"].iloc[0]
    # every table and view has this schema's columns (a migrated table may order them otherwise)
    fresh = tmp_path / "fresh.sqlite"
    create_schema(engine_for(fresh), "test")
    for table in ("runs", "artifacts", "simulations", "slip_events", "run_periodicity", "figures", "slip_events_full",
                  "periodicity_full"):
        columns = [query.sql(f"PRAGMA table_info({table})", path)["name"].tolist() for path in (database, fresh)]
        assert sorted(columns[0]) == sorted(columns[1]), table
    assert migrate(database) == (SCHEMA_VERSION, SCHEMA_VERSION)
    assert main(["db", "migrate", "--db", str(database)]) == 0
