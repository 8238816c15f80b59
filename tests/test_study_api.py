"""The study API on a real study's data (the ci study): the tutorial's idioms, typed tables with units, keyword
filters that refuse what does not exist, bulk access, and a study found from any folder below the workflow."""

import inspect
import io
import shutil

import pandas as pd
import pytest

import stickslip
from stickslip import vocabulary
from stickslip.cli import main
from stickslip.errors import RunNotFoundError, StudyNotFoundError
from stickslip.h5io import FileFormatError
from stickslip.plugin_params import ParameterError
from stickslip.workdir import ENVIRONMENT

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def workflow(ci_study, tmp_path_factory):
    """A copy of the ci study's workflow directory (Snakefile, results/ci), with an empty notebooks/ folder."""
    folder = tmp_path_factory.mktemp("workflow") / "repository"
    shutil.copytree(ci_study, folder, symlinks=True, ignore=shutil.ignore_patterns(".snakemake"))
    (folder / "notebooks" / "deeper").mkdir(parents=True)
    return folder


@pytest.fixture
def study(workflow, monkeypatch):
    monkeypatch.delenv(ENVIRONMENT, raising=False)
    monkeypatch.chdir(workflow / "notebooks" / "deeper")
    return stickslip.study("ci")


def test_a_study_is_found_from_a_subfolder_an_argument_or_the_environment(workflow, study, monkeypatch, tmp_path,
                                                                         capsys):
    assert study.root == workflow / "results" / "ci" and study.database.is_file()
    assert study.config_file == workflow / "workflow" / "config" / "ci.yaml" and study.config["threads"] == 1
    assert "nearest folder above" in study.workdir.how
    assert stickslip.study("workflow/config/ci.yaml").root == study.root  # a config, relative to the workflow
    monkeypatch.chdir(tmp_path)  # no Snakefile at or above
    with pytest.raises(StudyNotFoundError, match="the workflow directory is .* \\(the current folder: no folder at "
                                                 "or above it holds a Snakefile\\) \\(another: workdir= or "
                                                 f"\\${ENVIRONMENT}\\)") as error:
        stickslip.study("ci")
    assert isinstance(error.value, FileNotFoundError) and isinstance(error.value, FileFormatError)
    assert stickslip.study("ci", workdir=workflow).root == study.root
    monkeypatch.setenv(ENVIRONMENT, str(workflow))
    assert stickslip.study("ci").root == study.root and stickslip.study("ci").workdir.how == f"${ENVIRONMENT}"
    monkeypatch.delenv(ENVIRONMENT)
    # stickslip db finds it the same way
    monkeypatch.chdir(workflow / "notebooks")
    capsys.readouterr()
    assert main(["db", "runs", "--study", "ci", "--kind", "solver", "--format", "csv"]) == 0
    assert len(pd.read_csv(io.StringIO(capsys.readouterr().out))) == 6
    monkeypatch.chdir(tmp_path)
    assert main(["db", "runs", "--study", "ci"]) == 2
    assert "no database of study 'ci'" in capsys.readouterr().err
    assert main(["db", "runs", "--study", "ci", "--workdir", str(workflow)]) == 0


def test_the_tutorials_idioms_work_on_the_studys_events(study):
    events = study.events()
    assert events["multi"].dtype == bool  # not 0/1: ~events["multi"] selects the single slips
    single = events[~events["multi"]]
    assert len(single) == len(study.events(multi=False)) and not study.events(multi=True)["multi"].any()
    fem = study.events(plates=2, k_drive=1.472e-2)
    assert len(fem) == 3 and set(fem["solver"]) == {"fem"} and fem["dmu_sig0"].notna().all() and fem["dmu"].isna().all()
    pd.testing.assert_frame_equal(fem, study.events(solver="fem"))
    assert study.events(k_drive=1.4720001e-2).equals(fem)  # a float to 6 significant digits
    assert study.events(phi=(1e-7, 1e-6)).equals(fem) and study.events(phi=(1e-4, 1e-3)).empty
    lab = study.events(source="experimental", n=[2, 3], interface=1)
    assert set(lab["n"]) == {2, 3} and set(lab["interface"]) == {1} and lab["dmu"].notna().any()
    assert {"T", "dF", "B_a", "slip_from_dF"} <= set(lab.columns)  # the analysis's further columns, expanded
    assert pd.api.types.is_float_dtype(lab["T"]) and lab.attrs["units"]["T"] == "s"
    assert len(study.events(t_exclude=100.0)) == len(study.events(source="experimental"))  # an analysis parameter
    assert study.events(t_exclude=50.0).empty


def test_every_table_is_typed_with_its_units(study):
    runs = study.runs(wide=True)
    assert not [c for c in runs.columns if runs[c].map(lambda v: isinstance(v, str) and v.startswith("{")).any()]
    assert isinstance(runs["started_at"].dtype, pd.DatetimeTZDtype) and runs["git_dirty"].dtype == bool
    assert str(runs["blocks"].dtype) == "Int64" and str(runs["n"].dtype) == "Int64"
    fem = runs[runs["plugin"] == "fem"].iloc[0]
    assert fem["params.N"] == fem["blocks"] == 9 and fem["params.max_increments"] == 200
    # extensions at their default, which the records leave out, show their value; a lever run has none
    assert (fem["params.interface_law"], fem["params.backend"], fem["params.law_params"]) == ("cusp", "structured", [])
    assert runs.loc[runs["plugin"] == "lever", "params.interface_law"].isna().all()
    units = runs.attrs["units"]
    assert units["params.k_drive"] == "G/h^2" == units["k_drive"] and units["params.duration"] == "s"
    for name, frame in (("runs", runs), ("events", study.events()), ("figures", study.figures()),
                        ("sql", study.sql("SELECT * FROM slip_events_full"))):
        assert set(frame.attrs["units"]) == set(frame.columns), name
        for column in frame.columns:
            quantity = vocabulary.quantity(column)
            if quantity is not None and name != "sql":
                assert vocabulary.dtype_matches(frame[column].dtype, quantity.dtype), (name, column)
                assert frame.attrs["units"][column] == quantity.unit, (name, column)
    average = study.sql("SELECT n, AVG(multi) AS multi FROM slip_events_full GROUP BY n")
    assert average["multi"].dtype == float and average.attrs["units"]["multi"] is None  # not the bool multi


@pytest.mark.parametrize("filters, message", [
    ({"source": "lab"}, "filter 'source': 'lab' is not allowed; expected one of: 'numerical', 'experimental'"),
    ({"regime": "stif"}, "filter 'regime': 'stif' is not allowed; expected one of: 'stiff', 'compliant' "
                         "\\(did you mean 'stiff'\\?\\)"),
    ({"solver": "fme"}, "filter 'solver': 'fme' is not allowed; values in this database: 'fem', 'lever'"),
    ({"plates": "two"}, "filter 'plates': expected an integer"),
    ({"k_drive": (2.0, 1.0)}, "filter 'k_drive': a range \\(low, high\\) needs low <= high"),
    ({"colour": 1}, "unknown filter 'colour'"),
    ({"backend": "gpu"}, "filter 'backend': 'gpu' is not allowed"),
])
def test_a_bad_filter_is_one_line_not_an_empty_table(study, capsys, filters, message):
    with pytest.raises(ParameterError, match=message):
        study.events(**filters)
    name, value = next(iter(filters.items()))
    if name in ("source", "regime"):  # the command line refuses the same (argparse's choices)
        with pytest.raises(SystemExit) as exit_:
            main(["db", "events", "--study", "ci", f"--{name}", value])
        assert exit_.value.code == 2
    elif name == "solver":
        assert main(["db", "events", "--study", "ci", "--solver", value]) == 2
        assert capsys.readouterr().err.strip().endswith(f"values in this database: 'fem', 'lever' "
                                                         "(did you mean 'fem'?)")


def test_runs_are_opened_in_bulk_and_as_context_managers(study):
    solvers = study.runs(kind="solver", n=3)
    opened = list(study.open_runs(solvers))
    assert [run.path.stem for run in opened] == list(solvers["run_id"])
    found = list(study.find(solver="lever", protocol="individual"))
    assert sorted(run.header["a"] for run in found) == [1, 2]
    by_events = list(study.open_runs(study.events(interface=2)))  # each simulation once
    assert len(by_events) == len(set(study.events(interface=2)["simulation_run_id"]))
    with study.open_run(solvers["run_id"].iloc[0]) as run:
        assert run.record.n == 3
    with pytest.raises(RunNotFoundError, match="holds no simulation 0123456789abcdef") as error:
        study.open_run("0123456789abcdef")
    assert isinstance(error.value, LookupError) and isinstance(error.value, ValueError)
    analysis = study.runs(kind="analysis")["run_id"].iloc[0]
    with pytest.raises(LookupError):
        list(study.open_runs([analysis]))
    for method in (study.runs, study.events, study.find):  # explicit keywords: help() and tab completion show them
        assert {"plates", "blocks", "k_drive", "phi", "regime", "temperature"} <= set(inspect.signature(method).parameters)
