"""The event analyses on a real (small) fem run: consistency with the solver's own counts."""

import numpy as np
import pytest

from stickslip import registry
from stickslip.events.analysis_files import read_analysis_file
from stickslip.formats.fem_run import read_increments
from stickslip.lineage import Artifact
from stickslip.plugin_params import parse_params

pytestmark = pytest.mark.slow

N = 18


@pytest.fixture(scope="module")
def fem_run(tmp_path_factory):
    # k = 1e-3 at N = 18 drives like the paper's compliant regime: single slips after ~100 increments
    path = tmp_path_factory.mktemp("fem") / "run.h5"
    solver = registry.get("solver", "fem")
    params = parse_params(solver.params, {"N": N, "plates": 3, "k_drive": 1e-3, "seed": 0, "max_increments": 300})
    solver.run(params, path, threads=1, inputs={})
    return Artifact(path, registry.run_id(solver, params), solver.name, solver.produces)


def test_numerical_events_of_a_fem_run(fem_run, tmp_path):
    analysis = registry.get("analysis", "numerical-events")
    analysis.run(parse_params(analysis.params, {}), fem_run, tmp_path / "events.h5")
    result = read_analysis_file(tmp_path / "events.h5", "event-table", ("increments", "slips", "slip_interfaces"))
    assert result.attrs["regime"] == "compliant" and result.attrs["n_interfaces"] == 2
    increments, slips, per = (result.tables[k] for k in ("increments", "slips", "slip_interfaces"))
    raw = read_increments(fem_run)
    assert len(increments) == len(raw) == 301
    assert result.attrs["steady_state"] > 2 and len(slips) > 0
    # a slip is a kick after which every block of the slipping interface is in another well
    for _, slip in slips.iterrows():
        row = raw[raw["increment"] == slip["increment"]].iloc[0]
        assert row["kick"]
        assert [a for a in (1, 2) if row[f"A_a{a}"] == N] == [int(a) for a in slip["interfaces"].split(",")]
    # the slipping interface and the whole system relax in a slip
    assert (per["dmu_sig0"] > 0).all() and (slips["dsigma"] > 0).all()
    # load steps are elastic: nothing yields
    loads = raw[~raw["kick"].to_numpy(dtype=bool)]
    assert (loads[["A_a1", "A_a2", "S_a1", "S_a2"]].to_numpy() == 0).all()


def test_front_dynamics_reruns_reproduce_the_stored_counts(fem_run, tmp_path):
    analysis = registry.get("analysis", "front-dynamics")
    params = parse_params(analysis.params, {"events": "slip", "interfaces": 0, "max_events": 3})
    analysis.run(params, fem_run, tmp_path / "fronts.h5")
    result = read_analysis_file(tmp_path / "fronts.h5", "front-table", ("failures", "fronts"))
    failures, fronts = result.tables["failures"], result.tables["fronts"]
    raw = read_increments(fem_run).set_index("increment")
    assert len(fronts) == 3
    for increment in fronts["increment"]:
        events = failures[failures["increment"] == increment]
        for a in (1, 2):
            hops = events[events["a"] == a].groupby("block")["direction"].sum()
            assert hops.sum() == raw.loc[increment, f"S_a{a}"]  # signed hops
            assert (hops != 0).sum() == raw.loc[increment, f"A_a{a}"]  # blocks in another well
    assert (fronts["s"] >= 1).all()
    assert np.isclose(result.attrs["interface_spacing"], 3 * np.pi)  # N = 18: a 2-block plate + 1 block
