"""The public API (stickslip.simulate, open_run, study, plugins, params) gives what the command line gives."""

import hashlib
import inspect
import io
import math
import subprocess
import sys
from contextlib import redirect_stdout
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest

import stickslip
from stickslip import registry
from stickslip.cli import main
from stickslip.events.analysis_files import read_analysis_file
from stickslip.formats import fem_run, get_format
from stickslip.h5io import FileFormatError, UnreadableFileError, read_table
from stickslip.lineage import Artifact
from stickslip.mesh import interface_layer
from stickslip.output_safety.overwrite import OutputExistsError
from stickslip.plugin_params import ParameterError, describe, parse_params
from stickslip.provenance import query
from stickslip.provenance.ingest import find_records, ingest

#: A small compliant fem run with slips (steady-state slips at increments 30, 44, ...), 80 increments.
FEM = {"N": 9, "plates": 2, "k_drive": 1.472e-2, "seed": 2, "max_increments": 80}
LEVER = {"n": 3, "seed": 1, "duration": 3000.0}


def _cli(*argv):
    """Run the command line in this process; its exit status and stdout."""
    out = io.StringIO()
    with redirect_stdout(out):
        status = main([str(arg) for arg in argv])
    return status, out.getvalue()


def _assignments(values):
    return [item for key, value in values.items() for item in ("--param", f"{key}={value}")]


def _sha256(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def fem_runs(tmp_path_factory):
    """The same fem run made by `stickslip simulate` and by stickslip.simulate: (cli file, api run)."""
    folder = tmp_path_factory.mktemp("fem")
    assert _cli("simulate", "--solver", "fem", *_assignments(FEM), "-o", folder / "cli.h5")[0] == 0
    return folder / "cli.h5", stickslip.simulate("fem", folder / "api.h5", **FEM)


@pytest.fixture(scope="module")
def lever_runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lever")
    assert _cli("simulate", "--solver", "lever", *_assignments(LEVER), "-o", folder / "cli.h5")[0] == 0
    return folder / "cli.h5", stickslip.simulate("lever", folder / "api.h5", **LEVER)


@pytest.mark.slow
@pytest.mark.parametrize("runs", ["fem_runs", "lever_runs"])
def test_simulate_writes_the_bytes_the_command_writes(runs, request):
    # a run file has no timestamp (stickslip.h5io): the same call gives the same bytes, whoever makes it
    cli, api = request.getfixturevalue(runs)
    assert _sha256(api.path) == _sha256(cli)


@pytest.mark.slow
def test_a_fem_run_reads_as_the_commands_and_the_workflow_write_it(fem_runs, tmp_path):
    cli, run = fem_runs
    assert run.header == fem_run.read_run_attrs(cli) and run.params == {**FEM, **run.params}
    assert run.header["completed"] and run.header["nstored"] == FEM["max_increments"] + 1
    # increments: what `stickslip increments` writes (17 significant digits: exact)
    assert _cli("increments", cli, "-o", tmp_path / "increments.csv")[0] == 0
    written = pd.read_csv(tmp_path / "increments.csv")
    pd.testing.assert_frame_equal(run.increments, written, check_dtype=False)
    assert run.increments["kick"].dtype == bool
    # events: the tables of the numerical-events analysis, as the workflow writes them
    analysis = registry.get("analysis", "numerical-events")
    analysis.run(parse_params(analysis.params, {}), Artifact(cli, "0" * 16, "fem", "fem-run"), tmp_path / "ev.h5")
    tables = run.events()
    stored = read_analysis_file(tmp_path / "ev.h5", "event-table", list(tables)).tables
    for name, table in tables.items():
        pd.testing.assert_frame_equal(table.reset_index(drop=True), stored[name], check_dtype=False, obj=name)
    slips = run.slip_events()
    assert list(slips["increment"][:2]) == [30, 44] and (slips["dmu_sig0"] > 0).all()


@pytest.mark.slow
def test_a_fem_state_is_the_stored_state_with_the_fields_the_run_observed(fem_runs):
    cli, run = fem_runs
    increments = run.increments.set_index("increment")
    N, sig0 = run.header["N"], run.header["sig0"]
    previous = run.state(43)
    state = run.state(44)  # a slip: every block changed well
    with h5py.File(cli, "r") as file:
        stored = fem_run.RunFile(file).state(44)
    u = stored.u
    assert np.array_equal(state.u, u) and np.array_equal(state.target, stored.target) and state.t == stored.t
    assert state.displacement.shape == (run.mesh.nnode, 2)
    assert np.array_equal(state.displacement, u[run.mesh.dofs])
    assert state.eps.shape == state.sig.shape == (1, N, 4, 3) and state.well.shape == (1, N, 4)
    # the wells give the run's own counts: S_a (net hops) and A_a (blocks that moved), at Gauss point 0
    hops = state.well[0, :, 0] - previous.well[0, :, 0]
    assert hops.sum() == increments.loc[44, "S_a1"] and np.count_nonzero(hops) == increments.loc[44, "A_a1"] == N
    # the stresses give the interface's observable: equivalent stress of the mean stress (equal blocks)
    for inc in (43, 44):
        xx, yy, xy = run.state(inc).sig[0].reshape(-1, 3).mean(axis=0)
        sigd = 2.0 * math.sqrt((0.5 * (xx - yy)) ** 2 + xy ** 2) / sig0
        assert sigd == pytest.approx(increments.loc[inc, f"sigd_{interface_layer(1)}"], rel=1e-12)
    with pytest.raises(IndexError, match=f"{cli.parent / 'api.h5'}: increment 81 is not stored \\(0 ... 80\\)") as err:
        run.state(81)
    assert isinstance(err.value, FileFormatError)  # as before this error class


@pytest.mark.slow
def test_a_replayed_event_is_the_stored_event(fem_runs):
    _, run = fem_runs
    failures = run.failures(44)
    assert list(failures.columns) == ["interface", "block", "t", "hop_direction"]
    assert failures.attrs["units"] == {"interface": "", "block": "", "t": "time", "hop_direction": ""}
    assert (np.diff(failures["t"]) >= 0).all() and set(failures["block"]) == set(range(FEM["N"]))
    net = failures.groupby("block")["hop_direction"].sum()
    assert int(net.sum()) == run.increments.loc[44, "S_a1"]
    with pytest.raises(FileFormatError, match="increment 43 is not a stored kick increment"):
        run.failures(43)  # a load step
    with pytest.raises(IndexError, match="increment -1 is not stored"):
        run.failures(-1)


@pytest.mark.slow
def test_a_virtual_experiment_reads_as_analyze_experiment_writes_it(lever_runs, tmp_path):
    cli, run = lever_runs
    assert run.solver == "lever" and run.params["n"] == 3 and run.record.n == 3
    status, text = _cli("analyze-experiment", cli, "-o", tmp_path / "slips.csv", "--aging")
    assert status == 0
    slips = run.events()["slips"]
    written = pd.read_csv(tmp_path / "slips.csv").drop(columns="path")
    pd.testing.assert_frame_equal(slips, written, check_dtype=False, rtol=1e-15)
    fit = run.aging()
    assert text.splitlines()[-1] == f"B={fit.B:.4g} +- {fit.B_error:.2g}"
    assert 0.02 < fit.B < 0.08  # the lever's aging rates are 0.018-0.039, plus its strength offset
    # the experiment-events analysis writes the same tables
    analysis = registry.get("analysis", "experiment-events")
    analysis.run(parse_params(analysis.params, {}), cli, tmp_path / "ev.h5")
    with h5py.File(tmp_path / "ev.h5", "r") as file:
        stored = {name: read_table(file, name) for name in file}
    for name, table in run.events().items():
        pd.testing.assert_frame_equal(table, stored[name], check_dtype=False, obj=name)
    assert run.truth() is not None and len(run.truth("interfaces")) == 5
    per = run.aging(per_interface=True)  # the driven interfaces a = 1 ... n slip
    assert set(per) == {1, 2, 3} and per[1].n_slips + per[2].n_slips < fit.n_slips


@pytest.mark.parametrize("values, parameter", [({"N": 1}, "'N': expected a value >= 3, got 1"),
                                               ({"Nx": 9}, "unknown parameter 'Nx' of solver 'fem'"),
                                               ({"drive": "wheel"}, "'drive': 'wheel' is not allowed")])
def test_a_bad_parameter_is_the_commands_error(values, parameter, tmp_path, capsys):
    with pytest.raises(ValueError, match=parameter) as error:
        stickslip.simulate("fem", tmp_path / "run.h5", **values)
    assert isinstance(error.value, ParameterError)
    assert _cli("simulate", "--solver", "fem", *_assignments(values), "-o", tmp_path / "run.h5")[0] == 2
    assert capsys.readouterr().err.strip() == f"stickslip: error: {error.value}"
    assert not (tmp_path / "run.h5").exists()


def test_a_bad_analysis_parameter_is_the_commands_error(tmp_path, capsys):
    lab = _lever_file(tmp_path)
    with pytest.raises(ParameterError, match="parameter 'threshold': expected a value > 0, got 0.0") as error:
        stickslip.open_run(lab).events(threshold=0.0)
    capsys.readouterr()
    assert _cli("analyze-experiment", lab, "--aging", "--param", "threshold=0.0")[0] == 2
    assert capsys.readouterr().err.strip() == f"stickslip: error: {error.value}"


def _lever_file(folder):
    path = folder / "lab.h5"
    if not path.exists():
        stickslip.simulate("lever", path, n=1, seed=1, duration=400.0)
    return path


def test_a_file_of_another_format_is_the_readers_error_naming_it(tmp_path):
    mesh = tmp_path / "mesh.h5"
    assert _cli("mesh", "--param", "N=9", "--param", "plates=2", "-o", mesh)[0] == 0
    with pytest.raises(FileFormatError, match=f"{mesh}: a mesh file version 1, expected a simulation file: "
                                              f"fem-run version {get_format('fem-run').version}, timeseries "
                                              f"version {get_format('timeseries').version}"):
        stickslip.open_run(mesh)
    text = tmp_path / "notes.txt"
    text.write_text("not HDF5")
    with pytest.raises(UnreadableFileError, match=f"{text}: not a readable HDF5 file"):
        stickslip.open_run(text)
    with pytest.raises(FileFormatError, match=f"{tmp_path / 'none.h5'}: no such file"):
        stickslip.open_run(tmp_path / "none.h5")
    lab = _lever_file(tmp_path)
    with pytest.raises(FileFormatError, match=f"{lab}: a timeseries file version 1, expected fem-run"):
        stickslip.runs.FemRun(lab)


def test_simulate_never_replaces_another_run_unless_told(tmp_path):
    lab = _lever_file(tmp_path)
    before = _sha256(lab)
    version = registry.get("solver", "lever").version
    with pytest.raises(OutputExistsError, match=f"{lab}: holds a timeseries file of solver lever {version} with "
                                                "other parameters: seed = 1 \\(this run: 2\\); pass overwrite=True"):
        stickslip.simulate("lever", lab, n=1, seed=2, duration=400.0)
    assert _sha256(lab) == before
    again = stickslip.simulate("lever", lab, n=1, seed=1, duration=400.0)  # the same run: written again
    assert _sha256(lab) == before and again.params["seed"] == 1
    replaced = stickslip.simulate("lever", lab, n=1, seed=2, duration=400.0, overwrite=True)
    assert replaced.params["seed"] == 2 and _sha256(lab) != before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lab.h5", "lab.provenance.json"]  # nothing left aside


@pytest.mark.slow
def test_simulate_resumes_an_interrupted_fem_run_to_the_same_bytes(fem_runs, tmp_path):
    cli, _ = fem_runs
    # a run interrupted after increment 40: its committed increments, not completed (what a kill leaves)
    partial = tmp_path / "run.h5"
    partial.write_bytes(cli.read_bytes())
    with h5py.File(partial, "r+") as file:
        file.attrs["nstored"] = 41
    fem_run.rewrite(partial, completed=False, stop_reason="")
    assert stickslip.open_run(partial).header["nstored"] == 41
    resumed = stickslip.simulate("fem", partial, **FEM)
    assert resumed.header["completed"] and _sha256(partial) == _sha256(cli)


def test_plugins_and_params_are_what_the_plugins_command_prints():
    status, text = _cli("plugins", "--params")
    assert status == 0
    lines = text.splitlines()
    table = stickslip.plugins()
    assert set(table["kind"]) == set(registry.KINDS)
    for row in table.itertuples():
        assert any(line.startswith(f"  {row.name} {row.version}  {row.summary}") for line in lines), row.name
        for name, row_ in stickslip.params(row.name, kind=row.kind).iterrows():
            unit = f" [{row_.unit}]" if row_.unit else ""
            assert f"      {name} ({row_.type}, default {row_.default!r}){unit}: {row_.doc}" in lines
    solvers = stickslip.plugins("solver")
    assert {"fem", "lever", "rate-state-lever"} <= set(solvers["name"])
    assert solvers.set_index("name").loc["fem", "replay"] and not solvers.set_index("name").loc["lever", "replay"]
    fem = stickslip.params("fem")
    assert list(fem.index) == [row[0] for row in describe(registry.get("solver", "fem").params)]
    assert fem.loc["N", "default"] == 1458 and fem.loc["k_drive", "unit"] == "G/h^2"
    formats = stickslip.plugins("format").set_index("name")
    assert formats.loc["fem-run", "module"] == "stickslip.formats.fem_run"
    with pytest.raises(ValueError, match="parameter 'kind': 'solvers' is not allowed"):
        stickslip.plugins("solvers")
    with pytest.raises(registry.PluginError, match="unknown solver 'femm'"):
        stickslip.params("femm")


def test_a_study_queries_its_database_as_the_db_command_does(toy_results, tmp_path):
    results = tmp_path / "results" / "default"
    ingest(results / "stickslip.sqlite", find_records(results), rebuild=True)
    study = stickslip.study()
    assert study.name == "default" and study.root.resolve() == results and study.config is None
    database = results / "stickslip.sqlite"
    pd.testing.assert_frame_equal(study.runs(kind="solver", wide=True), query.runs(database, kind="solver"))
    pd.testing.assert_frame_equal(study.runs(kind="solver"), query.runs(database, kind="solver")[list(query.RUN_COLUMNS)])
    pd.testing.assert_frame_equal(study.events(seed=2), query.events(database, seed=2))
    pd.testing.assert_frame_equal(study.figures(), query.figures(database))
    status, text = _cli("db", "runs", "--format", "csv")
    assert status == 0 and sorted(pd.read_csv(io.StringIO(text))["run_id"]) == sorted(study.runs()["run_id"])
    assert list(study.sql("SELECT COUNT(*) AS n FROM slip_events")["n"]) == [8]
    with pytest.raises(query.QueryError, match="only reads"):
        study.sql("DELETE FROM runs")
    run_id = study.runs(kind="solver")["run_id"].iloc[0]
    with pytest.raises(FileFormatError, match="a toy-block file version 1, expected a simulation file"):
        study.open_run(run_id)  # the toy's own format is no simulation format of open_run
    with pytest.raises(ValueError, match="run_id: expected 16 hexadecimal characters, got 'x'"):
        study.open_run("x")
    assert stickslip.study(results).root == results  # a results tree
    with pytest.raises(FileFormatError, match="no results of study 'nothing'"):
        stickslip.study("nothing")


def test_a_study_from_its_config_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "workflow" / "config").mkdir(parents=True)
    config = tmp_path / "workflow" / "config" / "mine.yaml"
    config.write_text("study: sweep-2\nsolvers: {lever: [{params: {n: 1}}]}\n")
    study = stickslip.study(config)
    assert study.name == "sweep-2" and study.root.as_posix() == "results/sweep-2"
    assert study.config["solvers"]["lever"][0]["params"] == {"n": 1} and study.config_file == config
    (tmp_path / "workflow" / "config" / "sweep-2.yaml").write_text("threads: 1\n")
    (tmp_path / "results" / "sweep-2").mkdir(parents=True)
    assert stickslip.study("sweep-2").config == {"threads": 1}
    with pytest.raises(FileFormatError, match="sweep-2/stickslip.sqlite: no such database"):
        stickslip.study("sweep-2").runs()


def test_the_public_surface_and_a_light_import():
    assert stickslip.__all__ == ["__version__", "simulate", "open_run", "study", "plugins", "params"]
    # no name of the API is a module of the package (a submodule imported later would not replace it, and a reader
    # finds one thing per name)
    modules = {path.stem for path in Path(stickslip.__file__).parent.iterdir()
               if path.suffix == ".py" or (path / "__init__.py").is_file()}
    assert not modules & set(stickslip.__all__), modules & set(stickslip.__all__)
    assert all(inspect.isfunction(getattr(stickslip, name)) for name in stickslip.__all__[1:])
    probe = ("import sys, stickslip\n"
             "print(sorted(m for m in ('numba', 'matplotlib', 'sqlalchemy', 'stickslip.fem', 'stickslip.solvers.fem')"
             " if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
