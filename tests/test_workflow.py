"""The workflow machinery: study expansion, config errors, entry-point plugins, Snakemake runs.

The Snakemake runs use the toy plugins of tests/toy_plugin (registered through entry points of
an installed distribution), so they test the machinery independently of the real solvers; the
smoke test (test_workflow_smoke.py) runs the real ci study.
"""

import copy
import os
import re
import sqlite3
import subprocess
import sys
import zipfile
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import copy_workflow, python_path
from stickslip import registry
from stickslip.plugin_params import ParameterError, parse_params
from stickslip.provenance.record import REQUIRED_FIELDS, read_record
from stickslip.study_plan import Study, check_sweeps

TOY_CONFIG = {
    "threads": 1,
    "solvers": {"toy-spring-block": [{"params": {"slips": 4}, "grid": {"seed": [1, 2, 3]}},
                                     {"params": {"slips": 4, "seed": 1}, "grid": {}}]},
    "analyses": {"toy-slips": None},
    "figures": {"toy-force": {"width": 5.0}},
}


def test_entry_point_plugins_are_discovered(toy_plugins):
    assert registry.get("solver", "toy-spring-block").module == "stickslip_toy"
    assert registry.get("analysis", "toy-slips").consumes == ("toy-block",)
    assert "toy-force" in registry.available("figure")


def test_toy_solver_slips_match_the_closed_form(toy_plugins):
    import stickslip_toy as toy

    params = parse_params(toy.BlockParams, {"seed": 3, "slips": 6})
    t, x, F = toy.simulate(params)
    moving = np.diff(x) > 0
    starts = np.flatnonzero(moving & ~np.r_[False, moving[:-1]])
    ends = np.flatnonzero(moving & ~np.r_[moving[1:], False]) + 1
    expected = toy.slip_amplitude(toy.thresholds(params), params)
    np.testing.assert_allclose(x[ends] - x[starts], expected, rtol=1e-5)
    # the force at each slip onset is the contact's threshold
    np.testing.assert_allclose(F[starts], toy.thresholds(params), rtol=1e-12)


def test_study_expands_grids_and_resolves_inputs(toy_plugins):
    study = Study(copy.deepcopy(TOY_CONFIG))
    assert sorted(sim.params["seed"] for sim in study.simulations) == [1, 2, 3]  # the repeated run once
    assert all(sim.params["slips"] == 4 and sim.params["k"] == 1.0 for sim in study.simulations)
    assert len(study.analysis_jobs) == 3
    figure = study.figures["toy-force"]
    assert figure.params == {"width": 5.0}
    pairs = {(item.path.as_posix(), item.parent.path.as_posix()) for item in figure.inputs["analysis:toy-slips"]}
    assert pairs == {(job.path, job.simulation.path) for job in study.analysis_jobs}
    assert figure.files() == sorted(job.path for job in study.analysis_jobs) + sorted(sim.path for sim in
                                                                                    study.simulations)
    assert len(study.records()) == 3 + 3 + 1
    sim = study.simulations[0]
    assert study.name == "default" and sim.path == f"results/default/sim/toy-spring-block/{sim.run_id}.h5"


@pytest.mark.parametrize("change, message", [
    (lambda c: c["solvers"]["toy-spring-block"][0]["grid"].update(seed=[1, "x"]),
     r"config solvers.toy-spring-block\[0\]: parameter 'seed': expected an integer, got 'x'"),
    (lambda c: c["solvers"]["toy-spring-block"][1]["params"].update(F_d=0.95),
     r"config solvers.toy-spring-block\[1\]: parameter 'F_d': must be below"),
    (lambda c: c["solvers"].update(nope=[]), r"config solvers.nope: unknown solver 'nope'"),
    (lambda c: c["figures"].update({"toy-force": {"height": 1}}), r"config figures.toy-force: unknown parameter"),
    (lambda c: c["solvers"].pop("toy-spring-block"),
     r"config analyses.toy-slips: it reads toy-block files, which no solver of the study produces"),
])
def test_study_errors_name_the_config_key(toy_plugins, change, message):
    config = copy.deepcopy(TOY_CONFIG)
    change(config)
    with pytest.raises(ParameterError, match=message):
        Study(config)


@pytest.mark.parametrize("change, message", [
    (lambda c: c["solvers"]["toy-spring-block"][0]["params"].update(seed=4),
     r"config solvers.toy-spring-block\[0\]: parameter 'seed' is in both params \(4\) and grid \(\[1, 2, 3\]\); "
     r"expected it in one of them"),
    (lambda c: c["solvers"]["toy-spring-block"][0]["grid"].update(seed=[1, 2, 1]),
     r"config solvers.toy-spring-block\[0\].grid.seed: value 1 is listed twice; expected each value once"),
    (lambda c: c["solvers"]["toy-spring-block"][0]["grid"].update(seed=1),
     r"config solvers.toy-spring-block\[0\].grid.seed: expected a list of values, got 1 \(write \[1\], or put it "
     r"in params\)"),
])
def test_a_sweep_names_each_parameter_and_value_once(change, message):
    config = copy.deepcopy(TOY_CONFIG)
    check_sweeps(config)
    change(config)
    with pytest.raises(ParameterError, match=message):
        check_sweeps(config)


# Snakemake in a subprocess ------------------------------------------------------------------------

TOY_YAML = """\
solvers:
  toy-spring-block:
    - params: {slips: 4}
      grid: {seed: [1, 2, 3]}
analyses:
  toy-slips:
figures:
  toy-force: {width: 5.0}
"""


def snakemake(directory, *args, distribution=None, check=True):
    env = dict(os.environ, PYTHONPATH=python_path(*([distribution] if distribution else [])))
    result = subprocess.run(["snakemake", *args], cwd=directory, env=env, capture_output=True, text=True,
                            timeout=600)
    if check and result.returncode != 0:
        raise AssertionError(f"snakemake {' '.join(args)} failed:\n{result.stdout}\n{result.stderr}")
    return result


def planned_jobs(output):
    """Job counts from the 'Job stats' table of a dry run."""
    table = output.split("Job stats:", 1)[1].split("total", 1)[0]
    return dict((name, int(count)) for name, count in re.findall(r"^(\S+)\s+(\d+)$", table, re.M))


def test_bad_config_value_stops_before_any_job(tmp_path, toy_distribution):
    copy_workflow(tmp_path)
    (tmp_path / "bad.yaml").write_text(TOY_YAML.replace("slips: 4", "slips: -4"))
    result = snakemake(tmp_path, "-n", "--configfile", "bad.yaml", distribution=toy_distribution, check=False)
    assert result.returncode != 0
    text = result.stdout + result.stderr
    assert "config key solvers.toy-spring-block[0].params.slips: -4 is less than the minimum of 1" in text
    assert "Failed validating" not in text and len(text.splitlines()) < 15  # not the whole schema
    (tmp_path / "bad.yaml").write_text(TOY_YAML + "thread: 2\n")
    result = snakemake(tmp_path, "-n", "--configfile", "bad.yaml", distribution=toy_distribution, check=False)
    assert result.returncode != 0
    assert ("config key thread: not a key of the config (did you mean 'threads'?); allowed: study, threads, "
            "gpu_batch, solvers, analyses, figures") in result.stdout + result.stderr
    (tmp_path / "bad.yaml").write_text(TOY_YAML.replace("params: {slips: 4}", "params: {slips: 4, seed: 2}"))
    result = snakemake(tmp_path, "-n", "--configfile", "bad.yaml", distribution=toy_distribution, check=False)
    assert result.returncode != 0
    assert ("config solvers.toy-spring-block[0]: parameter 'seed' is in both params (2) and grid ([1, 2, 3])"
            in result.stdout + result.stderr)
    assert not (tmp_path / "results").exists()


@pytest.fixture(scope="module")
def toy_workflow(tmp_path_factory, toy_distribution):
    """The toy study run once with `snakemake --cores 2`; returns (directory, first run's output)."""
    directory = copy_workflow(tmp_path_factory.mktemp("toy-workflow"))
    (directory / "toy.yaml").write_text(TOY_YAML)
    result = snakemake(directory, "--cores", "2", "--configfile", "toy.yaml", distribution=toy_distribution)
    return directory, result.stdout + result.stderr


@pytest.mark.slow
def test_toy_workflow_outputs_records_and_database(toy_workflow):
    directory, _ = toy_workflow
    results = directory / "results" / "toy"  # the study is named after its config file
    sims = sorted((results / "sim" / "toy-spring-block").glob("*.h5"))
    events = sorted((results / "events" / "toy-slips" / "toy-spring-block").glob("*.h5"))
    assert len(sims) == 3 and len(events) == 3
    assert (results / "figures" / "toy-force.pdf").stat().st_size > 1000
    assert (results / "figures" / "toy-force.png").stat().st_size > 1000
    records = sorted(results.rglob("*.provenance.json"))
    assert len(records) == 7
    for path in records:
        record = read_record(path)
        assert all(record[field] is not None for field in REQUIRED_FIELDS if field not in ("seed", "git_commit",
                                                                                          "git_dirty"))
        for entry in record["outputs"]:
            assert (directory / entry["path"]).is_file()
    sim_record = read_record(sims[0].with_suffix(".provenance.json"))
    with h5py.File(sims[0]) as file:
        assert file.attrs["seed"] == sim_record["seed"] == sim_record["params"]["seed"]
    assert sim_record["run_id"] == sims[0].stem and sim_record["threads"] == 1
    # the database holds every record (two jobs ran at a time: none lost) and every slip
    with sqlite3.connect(results / "stickslip.sqlite") as connection:
        run_ids = {row[0] for row in connection.execute("SELECT run_id FROM runs")}
        n_events = connection.execute("SELECT COUNT(*) FROM slip_events").fetchone()[0]
    assert run_ids == {read_record(path)["run_id"] for path in records}
    assert n_events == 3 * 4
    assert (results / "logs" / "benchmarks" / "sim" / "toy-spring-block" / f"{sims[0].stem}.tsv").is_file()
    assert (results / "logs" / "figures" / "toy-force.log").is_file()
    assert sorted(p.name for p in (directory / "results").iterdir()) == ["toy"]


@pytest.mark.slow
def test_toy_workflow_second_run_and_single_figure(toy_workflow, toy_distribution):
    directory, _ = toy_workflow
    again = snakemake(directory, "-n", "--cores", "2", "--configfile", "toy.yaml", distribution=toy_distribution)
    assert "Nothing to be done" in again.stdout + again.stderr
    for script in (directory / "workflow" / "scripts").glob("*.py"):  # as a fresh clone's newer scripts are
        script.touch()
    again = snakemake(directory, "-n", "--cores", "2", "--configfile", "toy.yaml", distribution=toy_distribution)
    assert "Nothing to be done" in again.stdout + again.stderr  # only a changed plugin code hash reruns
    # the README's command: the figure again, and the database's record of it; then nothing is left to do
    forced = snakemake(directory, "--cores", "2", "--configfile", "toy.yaml", "--forcerun", "figure_toy_force",
                       distribution=toy_distribution)
    assert planned_jobs(forced.stdout + forced.stderr) == {"all": 1, "database": 1, "figure_toy_force": 1}
    again = snakemake(directory, "-n", "--cores", "2", "--configfile", "toy.yaml", distribution=toy_distribution)
    assert "Nothing to be done" in again.stdout + again.stderr


@pytest.mark.slow
def test_toy_workflow_lint_and_report(toy_workflow, toy_distribution):
    directory, _ = toy_workflow
    lint = snakemake(directory, "--lint", "--configfile", "toy.yaml", distribution=toy_distribution)
    assert "Congratulations, your workflow is in a good condition!" in lint.stdout + lint.stderr
    snakemake(directory, "--configfile", "toy.yaml", "--report", "report.zip", distribution=toy_distribution)
    with zipfile.ZipFile(directory / "report.zip") as archive:
        html = archive.read("report/report.html").decode()
    # the caption is the figure plugin's summary, rendered for the job
    assert "Spring force against time of every spring-block run" in html and "toy-force.png" in html


@pytest.mark.slow
def test_corrupted_input_gives_a_clear_error(toy_workflow, toy_distribution, tmp_path):
    directory, _ = toy_workflow
    broken = copy_workflow(tmp_path)
    (broken / "toy.yaml").write_text(TOY_YAML)
    sim = sorted((directory / "results" / "toy" / "sim" / "toy-spring-block").glob("*.h5"))[0]
    target = broken / "results" / "toy" / "sim" / "toy-spring-block" / sim.name
    target.parent.mkdir(parents=True)
    target.write_bytes(sim.read_bytes()[:200])  # a truncated file
    (broken / "results/toy/sim/toy-spring-block" / f"{sim.stem}.provenance.json").write_text("{}")
    event = f"results/toy/events/toy-slips/toy-spring-block/{sim.stem}.h5"
    result = snakemake(broken, event, "--cores", "1", "--configfile", "toy.yaml", "--allowed-rules", "events",
                       distribution=toy_distribution, check=False)
    assert result.returncode != 0
    assert f"results/toy/sim/toy-spring-block/{sim.name}: not a readable HDF5 file" in result.stdout + result.stderr
    assert not (broken / event).exists()


def test_job_environment_reaches_numba(tmp_path):
    code = ("from stickslip.workflow_api import prepare_environment\n"
            "cache = prepare_environment(2, 'job')\n"
            "import numba\n"
            "print(numba.config.NUMBA_NUM_THREADS, numba.config.CACHE_DIR == cache, cache)\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                            env=dict(os.environ, TMPDIR=str(tmp_path)), timeout=120)
    threads, same, cache = result.stdout.split()
    assert threads == "2" and same == "True" and cache.startswith(str(tmp_path))
    assert not Path(cache).exists()  # removed when the job ends
    code = ("from stickslip.workflow_api import prepare_environment\n"
            "prepare_environment(1, 'node')\n")  # e.g. a typo in STICKSLIP_SLURM_NUMBA_CACHE (profiles/slurm)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 1
    assert result.stderr.splitlines()[-1] == "ValueError: numba_cache must be 'shared' or 'job', got 'node'"


def test_solvers_that_read_a_mesh_share_one_mesh_job():
    import dataclasses

    from stickslip import mesh
    from stickslip.plugin_params import param

    @dataclasses.dataclass(frozen=True)
    class MeshedParams:
        N: int = param(9, "blocks per interface")
        plates: int = param(3, "plates")
        seed: int = param(0, "seed")

    def solve(params, output, *, threads, inputs):
        """Test solver reading a mesh."""

    registry.register("solver", "test-meshed", "1", MeshedParams, consumes=("mesh",), produces="fem-run")(solve)
    study = Study({"solvers": {"test-meshed": [{"params": {}, "grid": {"seed": [1, 2]}},
                                               {"params": {"N": 27}, "grid": {}}]}})
    expected = {mesh.mesh_id(parse_params(mesh.MeshParams, {"N": N, "plates": 3})): N for N in (9, 27)}
    assert {key: value["N"] for key, value in study.meshes.items()} == expected
    inputs = [study.solver_inputs(sim.solver, sim.run_id)["mesh"].path.as_posix() for sim in study.simulations]
    assert sorted(set(inputs)) == sorted(f"results/default/mesh/{key}.h5" for key in expected)
    assert len(study.records()) == 2 + 3


def test_study_name_is_the_config_key_else_the_config_file_stem(toy_plugins):
    assert Study(copy.deepcopy(TOY_CONFIG), ["workflow/config/ci.yaml"]).root == "results/ci"
    named = Study({**copy.deepcopy(TOY_CONFIG), "study": "sweep-2"}, ["ci.yaml"])
    assert named.name == "sweep-2"
    assert named.path("database") == "results/sweep-2/stickslip.sqlite"
    assert named.log("sim/{solver}/{run_id}") == "results/sweep-2/logs/sim/{solver}/{run_id}.log"
    assert all(path.startswith("results/sweep-2/") for path in named.outputs() + named.records())
    with pytest.raises(ParameterError, match="config key study: expected a name"):
        Study({**copy.deepcopy(TOY_CONFIG), "study": "../elsewhere"})


@pytest.mark.slow
def test_two_studies_in_one_clone_keep_their_results(toy_workflow, toy_distribution):
    directory, _ = toy_workflow
    (directory / "toy2.yaml").write_text(TOY_YAML.replace("seed: [1, 2, 3]", "seed: [4]"))
    database = directory / "results" / "toy" / "stickslip.sqlite"
    figure = directory / "results" / "toy" / "figures" / "toy-force.pdf"
    before = database.read_bytes(), figure.read_bytes()
    snakemake(directory, "--cores", "2", "--configfile", "toy2.yaml", distribution=toy_distribution)
    assert (database.read_bytes(), figure.read_bytes()) == before
    with sqlite3.connect(directory / "results" / "toy2" / "stickslip.sqlite") as connection:
        assert connection.execute("SELECT COUNT(*) FROM simulations").fetchone()[0] == 1
    again = snakemake(directory, "-n", "--cores", "2", "--configfile", "toy.yaml", distribution=toy_distribution)
    assert "Nothing to be done" in again.stdout + again.stderr


def test_labelled_config_keys_are_more_parameterisations(toy_plugins):
    config = copy.deepcopy(TOY_CONFIG)
    config["analyses"]["toy-slips@coarse"] = {"threshold": 0.5}
    config["figures"]["toy-force@coarse"] = {}
    study = Study(config)
    fine = {job.path for job in study.analysis_jobs if job.analysis == "toy-slips"}
    coarse = {job.path for job in study.analysis_jobs if job.analysis == "toy-slips@coarse"}
    assert len(fine) == len(coarse) == 3 and all("/events/toy-slips@coarse/" in path for path in coarse)
    assert {job.run_id for job in study.analysis_jobs if job.analysis == "toy-slips@coarse"}.isdisjoint(
        {job.run_id for job in study.analysis_jobs if job.analysis == "toy-slips"})
    # the labelled figure reads the analysis labelled alike, the plain one the plain analysis
    assert {str(item) for item in study.figures["toy-force@coarse"].inputs["analysis:toy-slips"]} == coarse
    assert {str(item) for item in study.figures["toy-force"].inputs["analysis:toy-slips"]} == fine
    assert study.figures["toy-force@coarse"].path == "results/default/figures/toy-force@coarse.pdf"
    with pytest.raises(ParameterError, match="the label after '@' must match"):
        Study({**copy.deepcopy(TOY_CONFIG), "analyses": {"toy-slips@": {}}})


@pytest.mark.slow
def test_labelled_keys_make_their_own_jobs(tmp_path, toy_distribution):
    copy_workflow(tmp_path)
    labelled = TOY_YAML.replace("  toy-slips:\n", "  toy-slips:\n  toy-slips@coarse: {threshold: 0.5}\n")
    (tmp_path / "labels.yaml").write_text(labelled + "  toy-force@coarse: {}\n")
    result = snakemake(tmp_path, "-n", "--configfile", "labels.yaml", distribution=toy_distribution)
    assert planned_jobs(result.stdout + result.stderr) == {"all": 1, "database": 1, "events": 6,
                                                           "figure_toy_force": 1, "figure_toy_force_coarse": 1,
                                                           "simulate": 3}
    snakemake(tmp_path, "--cores", "2", "--configfile", "labels.yaml", distribution=toy_distribution)
    results = tmp_path / "results" / "labels"
    assert (results / "figures" / "toy-force@coarse.png").stat().st_size > 1000
    with sqlite3.connect(results / "stickslip.sqlite") as connection:
        analyses = connection.execute("SELECT plugin, COUNT(*) FROM runs WHERE kind = 'analysis' "
                                      "GROUP BY plugin").fetchall()
        params = {row[0] for row in connection.execute("SELECT params FROM runs WHERE kind = 'analysis'")}
    assert analyses == [("toy-slips", 6)] and len(params) == 2


def test_thermal_runs_and_then_analyses_come_first_in_the_schedule():
    from stickslip.study_plan import ANALYSIS_PRIORITY

    study = Study({"solvers": {"fem": [{"params": {"N": 9, "plates": 2}, "grid": {"temperature": [0.0, 1e-3]}}]}})
    priorities = {sim.params.get("temperature", 0.0): study.run_priority(sim.solver, sim.run_id)
                  for sim in study.simulations}
    assert priorities == {0.0: 0, 1e-3: 1}
    assert ANALYSIS_PRIORITY > max(priorities.values())
