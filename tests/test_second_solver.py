"""Acceptance: a second fem-run solver, added through an entry point only, runs through the whole study.

``fem-twin`` (tests/toy_plugin/stickslip_femtwin.py) is registered by an installed
distribution's entry point; nothing in the package names it. The study wires
numerical-events and front-dynamics to it by format, the replay comes from the solver
that wrote the file, the database ingests its runs and events, and the numerical
figures draw them.
"""

import sqlite3

import pytest

from conftest import copy_workflow
from stickslip.formats.fem_run import read_run_attrs
from stickslip.provenance.record import read_record
from test_workflow import snakemake

TWIN_YAML = """\
solvers:
  fem-twin:
    - params: {N: 9, max_increments: 200, k_drive: 1.472e-2}  # Phi = 5e-7: the paper figures take it
      grid: {plates: [3], seed: [1]}
analyses:
  numerical-events: {}
  front-dynamics: {events: slip, interfaces: 0, max_events: 2}
figures:
  figS-mesh: {plates: 3}
  fig2: {n_trace: 2}
  figS-dgamma: {}
  figS-sequences: {}
  figS-event-maps: {n: 2}
  figS-tau: {}
"""


@pytest.mark.slow
def test_a_second_solver_needs_no_edit_of_the_package(tmp_path, toy_distribution):
    directory = copy_workflow(tmp_path)
    (directory / "twin.yaml").write_text(TWIN_YAML)
    snakemake(directory, "--cores", "2", "--configfile", "twin.yaml", distribution=toy_distribution)
    results = directory / "results" / "twin"
    (sim,) = (results / "sim" / "fem-twin").glob("*.h5")
    attrs = read_run_attrs(sim)
    assert (attrs["format"], attrs["solver"], attrs["solver_version"]) == ("fem-run", "fem-twin", "1")
    for name in ("fig2", "figS-dgamma", "figS-sequences", "figS-event-maps", "figS-tau", "figS-mesh"):
        assert (results / "figures" / f"{name}.pdf").stat().st_size > 1000, name
    record = read_record(results / "events" / "front-dynamics" / "fem-twin" / sim.with_suffix(".provenance.json").name)
    assert [(e["role"], e["plugin"], e["format"], e["run_id"]) for e in record["inputs"]] == [
        ("simulation", "fem-twin", "fem-run", sim.stem)]
    with sqlite3.connect(results / "stickslip.sqlite") as connection:
        simulations = connection.execute("SELECT solver, format, source, n, blocks, regime FROM simulations").fetchall()
        events = connection.execute("SELECT solver, source, COUNT(*) FROM slip_events GROUP BY solver").fetchall()
        fronts = connection.execute("SELECT COUNT(*) FROM runs WHERE plugin = 'front-dynamics'").fetchone()[0]
        periodicity = connection.execute("SELECT solver, blocks, regime, dt_scale, n_slips FROM periodicity_full").fetchall()
    assert simulations == [("fem-twin", "fem-run", "numerical", 2, 9, "compliant")]
    assert len(events) == 1 and events[0][:2] == ("fem-twin", "numerical") and events[0][2] > 0
    assert fronts == 1
    assert len(periodicity) == 1 and periodicity[0][:4] == ("fem-twin", 9, "compliant", 1.0)
