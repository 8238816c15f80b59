"""The API's frictions met by a new user on 575c37a, each held here on the ci study (issue 58).

Filters take numpy scalars and refuse what cannot match; ``a`` is the interface everywhere (the lever's driven slab
is ``driven_slab``, its old name mapped with a warning); units follow each column through ``merge`` and ``concat``
(:class:`stickslip.vocabulary.UnitFrame`); ``runs()`` is narrow unless asked for the wide form, and a missing value
is spelt one way (``pd.NA``); a run made with ``stickslip.simulate`` carries its run id and provenance and joins a
study (``study.add``), also after the workflow's next database rule.
"""

import shutil
import subprocess
import sys
import warnings

import numpy as np
import pandas as pd
import pytest

import stickslip
from stickslip.h5io import FileFormatError
from stickslip.plugin_params import ParameterError, RenamedParameterWarning
from stickslip.provenance.query import RUN_COLUMNS
from stickslip.vocabulary import UnitFrame

pytestmark = pytest.mark.slow

#: A short virtual run (seconds).
SHORT_LEVER = {"n": 2, "seed": 7, "duration": 300.0}


@pytest.fixture(scope="module")
def workflow(ci_study, tmp_path_factory):
    """A copy of the ci study's workflow directory, its Snakemake metadata included (the database rule reruns)."""
    folder = tmp_path_factory.mktemp("frictions") / "repository"
    shutil.copytree(ci_study, folder, symlinks=True)
    return folder


@pytest.fixture(scope="module")
def study(workflow):
    return stickslip.study("ci", workdir=workflow)


def test_filters_take_numpy_scalars_and_refuse_what_cannot_match(study):
    runs = study.runs(kind="solver", wide=True)
    n = runs["n"].unique()[0]  # a numpy integer, as pandas hands them out
    assert isinstance(n, np.integer)
    assert len(study.runs(n=n)) == len(study.runs(n=int(n))) > 0
    assert len(study.events(n=n)) == len(study.events(n=int(n))) > 0
    assert len(study.events(n=np.array([n]))) == len(study.events(n=[int(n)]))
    assert len(study.runs(n=float(n))) == len(study.runs(n=int(n)))  # 3.0 from a column with missing values
    assert len(study.events(multi=np.bool_(False))) == len(study.events(multi=False)) > 0
    seed = runs["seed"].iloc[0]
    assert len(study.runs(seed=seed, solver=np.str_(runs["solver"].iloc[0]))) > 0
    for bad in (np.float64(2.5), "2", np.datetime64("2020-01-01")):
        with pytest.raises(ParameterError, match="filter 'n': expected an integer.*no row can match"):
            study.runs(n=bad)


def test_a_is_the_interface_and_the_driven_slab_is_driven_slab(study, tmp_path):
    assert study.events(a=1).equals(study.events(interface=1)) and len(study.events(a=1)) > 0
    with pytest.raises(ParameterError, match="a is the interface.*driven_slab"):
        study.runs(a=1)
    assert "driven_slab" in stickslip.params("lever").index and "a" not in stickslip.params("lever").index
    assert "driven_slab" in stickslip.params("rate-state-lever").index
    with pytest.warns(RenamedParameterWarning, match="parameter 'a' of solver 'lever' is called 'driven_slab'"):
        old = stickslip.simulate("lever", tmp_path / "old.h5", protocol="individual", a=2, n=1, duration=200.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        new = stickslip.simulate("lever", tmp_path / "new.h5", protocol="individual", driven_slab=2, n=1,
                                 duration=200.0)
    assert old.params["driven_slab"] == new.params["driven_slab"] == 2 and old.run_id == new.run_id
    with pytest.raises(ParameterError, match="'a' of solver 'lever' is 'driven_slab' now"):
        stickslip.simulate("lever", tmp_path / "both.h5", protocol="individual", a=2, driven_slab=2, n=1)
    assert study.runs(kind="solver", protocol="individual")["driven_slab"].ge(1).all()


def test_units_follow_each_column_through_merge_and_concat(study):
    runs, events = study.runs(kind="solver"), study.events()
    merged = events.merge(runs[["run_id", "wall_time_s", "finished_at"]], left_on="simulation_run_id",
                          right_on="run_id")
    assert isinstance(merged, UnitFrame) and len(merged) == len(events)
    units = merged.attrs["units"]
    assert units["dmu"] == "1" and units["slip"] == "mm" and units["wall_time_s"] == "s" and units["k_drive"] == "G/h^2"
    assert set(units) == set(merged.columns)
    both = events.merge(runs, left_on="simulation_run_id", right_on="run_id")  # shared names get suffixes
    assert both.attrs["units"]["seed_x"] == both.attrs["units"]["seed_y"] == "" and \
        both.attrs["units"]["phi_y"] == "1"
    stacked = pd.concat([study.events(source="experimental"), study.events(source="numerical")])
    assert isinstance(stacked, UnitFrame) and stacked.attrs["units"]["dmu_sig0"] == "sig0"
    assert stacked.attrs["units"]["dmu"] == "1" and stacked.attrs["units"]["time"] == "s"
    renamed = events.rename(columns={"slip": "dR"})[["dR", "interface"]]
    assert renamed.attrs["units"] == {"dR": "mm", "interface": ""}  # a column keeps its unit under a new name
    assert events.assign(ratio=events["dmu"] * 2).attrs["units"]["ratio"] is None  # a new column: unknown


def test_runs_are_narrow_unless_asked_and_missing_is_spelt_once(study):
    narrow, wide = study.runs(), study.runs(wide=True)
    assert list(narrow.columns) == list(RUN_COLUMNS) and len(wide.columns) > 60
    assert any(column.startswith("params.") for column in wide.columns)
    assert narrow.equals(wide[list(RUN_COLUMNS)]) and set(narrow.attrs["units"]) == set(RUN_COLUMNS)
    with pytest.raises(ParameterError, match="wide: expected True or False"):
        study.runs(wide="yes")
    for frame in (wide, study.events(), study.figures()):
        spellings = {type(value).__name__ for column in frame.columns for value in frame[column]
                     if pd.api.types.is_scalar(value) and pd.isna(value)}
        assert spellings <= {"NAType", "NaTType"}, spellings
    assert str(narrow["k_drive"].dtype) == "Float64" and str(narrow["blocks"].dtype) == "Int64"


def test_a_simulated_run_carries_its_id_and_provenance_and_joins_the_study(study, workflow, tmp_path):
    run = stickslip.simulate("lever", tmp_path / "mine.h5", **SHORT_LEVER)
    record = run.provenance
    assert run.run_id == record["run_id"] and len(run.run_id) == 16
    assert record["plugin"] == "lever" and record["params"]["seed"] == 7 and record["git_commit"] is not None
    assert record["outputs"][0]["sha256"] and record["code_hash"]
    assert stickslip.open_run(tmp_path / "mine.h5").run_id == run.run_id
    assert study.add(run) == run.run_id
    added = study.runs(run_id=run.run_id)
    assert len(added) == 1 and added["n"].iloc[0] == 2 and added["seed"].iloc[0] == 7
    with study.open_run(run.run_id) as again:
        assert again.record.F.tolist() == run.record.F.tolist()
    assert study.add(run) == run.run_id  # again: nothing changes
    # the workflow's database rule (rebuilding the database from the records) keeps it
    before = len(study.runs())
    rerun = subprocess.run([sys.executable, "-m", "snakemake", "results/ci/stickslip.sqlite", "--cores", "1",
                            "--configfile", "workflow/config/ci.yaml"], cwd=workflow, capture_output=True, text=True)
    assert rerun.returncode == 0, rerun.stderr[-3000:]
    assert "rule database:" in rerun.stdout + rerun.stderr  # the added record is an input: the database was rebuilt
    assert len(study.runs()) == before and len(study.runs(run_id=run.run_id)) == 1
    copy = tmp_path / "copy.h5"
    shutil.copyfile(run.path, copy)
    with pytest.raises(FileFormatError, match="no provenance record"):
        study.add(stickslip.open_run(copy))


def test_a_study_config_with_the_old_name_is_mapped_with_a_warning():
    import jsonschema
    import yaml

    from stickslip.study_plan import Study, normalise, plugin_sections

    config = yaml.safe_load("study: old\nsolvers:\n  lever:\n    - params: {protocol: individual, n: 1}\n"
                            "      grid: {a: [1, 2]}\nanalyses: {}\nfigures: {}\n")
    normalise(config)
    for _, section, schema in plugin_sections(config):
        jsonschema.validate(section, schema)  # the schema of the config accepts the old name (no default filled)
    with pytest.warns(RenamedParameterWarning, match="'a' of solver 'lever' is called 'driven_slab'"):
        study = Study(config, ["old.yaml"])
    assert sorted(sim.params["driven_slab"] for sim in study.simulations) == [1, 2]
    assert not any("a" in sim.params for sim in study.simulations)
