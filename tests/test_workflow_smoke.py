"""Smoke test: the real ci study (workflow/config/ci.yaml) end to end with `snakemake --cores 2`."""

import os
import re
import shutil
import sqlite3
import subprocess
import sys

import pytest
import yaml

from conftest import REPO, TOY, python_path
from stickslip.provenance.record import REQUIRED_FIELDS, read_record
from stickslip.study_plan import Study
from test_workflow import planned_jobs, snakemake


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


@pytest.mark.slow
def test_an_unused_extension_reruns_nothing_a_change_in_the_cusp_law_reruns_the_fem_runs_and_what_follows(
        ci_study, tmp_path):
    """After a complete run: Snakemake plans no job for a new law, backend, plugin or vocabulary entry that no job
    uses, and exactly the fem runs and what reads them for a change inside the cusp law (docs/workflow.md)."""
    directory = tmp_path / "workflow"
    shutil.copytree(ci_study, directory, symlinks=True)
    site = tmp_path / "site"  # a copy of the package, first on the jobs' path, that this test changes
    package = site / "stickslip"
    shutil.copytree(REPO / "stickslip", package, ignore=shutil.ignore_patterns("__pycache__"))

    def planned():
        result = snakemake(directory, "-n", "--cores", "2", "--configfile", "workflow/config/ci.yaml",
                           distribution=site)
        text = result.stdout + result.stderr
        return {} if "Nothing to be done" in text else planned_jobs(text)

    assert planned() == {}  # the copy's sources are the package's: the same hashes
    laws = package / "fem" / "laws"
    (laws / "cusp_copy.py").write_text("from .cusp import Cusp\nfrom .generic import register_law\n\n\n@register_law\n"
                                       "class CuspCopy(Cusp):\n    __slots__ = ()\n    name = \"cusp-copy\"\n")
    (package / "fem" / "backends" / "structured_copy.py").write_text(
        "from .base import register_backend\nfrom .cpu.structured import StructuredBackend\n\n\n@register_backend\n"
        "class StructuredCopy(StructuredBackend):\n    name = \"structured-copy\"\n")
    shutil.copy(TOY, package / "solvers" / "toy.py")  # a solver, an analysis, a figure and a format
    vocabulary = package / "vocabulary.py"
    vocabulary.write_text(vocabulary.read_text().replace(
        '    "kind": _q(', '    "new_quantity": _q("float64", "1", "a quantity no job names"),\n    "kind": _q(', 1))
    listed = subprocess.run([sys.executable, "-c", "from stickslip import registry; from stickslip.fem.laws import "
                             "INTERFACE_LAWS; from stickslip.fem.backends import BACKENDS; "
                             "print(sorted(INTERFACE_LAWS), sorted(BACKENDS), sorted(registry.available('solver')))"],
                            env={**os.environ, "PYTHONPATH": python_path(site)}, cwd=tmp_path, capture_output=True,
                            text=True)
    assert "'cusp-copy'" in listed.stdout and "'structured-copy'" in listed.stdout and "'toy-spring-block'" in \
        listed.stdout, listed.stderr  # registered: found in their packages
    assert planned() == {}

    cusp = laws / "cusp.py"
    cusp.write_text(cusp.read_text() + "# a change\n")
    study = Study(yaml.safe_load((REPO / "workflow" / "config" / "ci.yaml").read_text()), ["ci.yaml"])
    fem = {sim.path for sim in study.simulations if sim.solver == "fem"}
    analyses = {job.path for job in study.analysis_jobs if job.simulation.path in fem}
    figures = [name for name, job in study.figures.items() if set(job.files()) & (fem | analyses)]
    assert fem and analyses and figures and len(figures) < len(study.figures)
    assert planned() == {"simulate": len(fem), "events": len(analyses), "database": 1, "all": 1,
                         **{f"figure_{name.replace('-', '_')}": 1 for name in figures}}
