"""Experimental figures: densities, run matching, and every figure drawn from a small virtual study."""

import dataclasses

import numpy as np
import pandas as pd
import pytest

from stickslip import registry
from stickslip.experiment.timeseries import read_timeseries
from stickslip.figures import experimental_data, plotting
from stickslip.h5io import FileFormatError
from stickslip.lineage import Artifact
from stickslip.params import parse_params

FIGURES = ("fig3", "fig4", "fig5", "fig6", "figS-individual", "figS-slip-distributions", "figS-aging-variations",
           "figS-slow-slip")


def test_density_is_normalised_on_linear_and_logarithmic_bins():
    rng = np.random.default_rng(0)
    values = rng.lognormal(3.0, 1.0, 5000)
    for edges in (plotting.linear_edges(values, 40), plotting.log_edges(values, 10)):
        centres, pdf = plotting.density(values, edges)
        inside = np.count_nonzero((values >= edges[0]) & (values <= edges[-1])) / values.size
        assert np.nansum(pdf * np.diff(edges)) == pytest.approx(inside)
        assert np.all((centres > edges[:-1]) & (centres < edges[1:]))
    # Logarithmic edges have geometric centres.
    centres, _ = plotting.density([2.0, 20.0], np.array([1.0, 10.0, 100.0]))
    np.testing.assert_allclose(centres, [np.sqrt(10.0), np.sqrt(1000.0)])


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """A small virtual study on the default study's virtual experiment (``rate-state-lever``; the
    workflow smoke test draws every figure from ``lever`` runs): stacks n = 1..5 and interfaces 1..4
    driven alone, analysed."""
    root = tmp_path_factory.mktemp("study")
    solver, analysis = registry.get("solver", "rate-state-lever"), registry.get("analysis", "experiment-events")
    runs = [{"n": n, "seed": n} for n in range(1, 6)]
    runs += [{"protocol": "individual", "a": a, "seed": 10 + a} for a in range(1, 5)]
    inputs = {experimental_data.EVENTS: []}
    for index, values in enumerate(runs):
        params = parse_params(solver.params, {**values, "duration": 2500.0})
        raw = Artifact(root / f"raw{index}.h5", registry.run_id(solver, params), solver.name, solver.produces)
        solver.run(params, raw.path, threads=1, inputs={})
        run_id = registry.derived_run_id(analysis, analysis.params(), [raw.run_id])
        events = Artifact(root / f"events{index}.h5", run_id, analysis.name, analysis.produces, raw)
        analysis.run(parse_params(analysis.params, {}), raw, events.path)
        inputs[experimental_data.EVENTS].append(events)
    return inputs


def test_example_run_is_the_events_file_parent(study):
    events = study[experimental_data.EVENTS]
    slips = experimental_data.load_slips(events)
    assert set(slips["n"]) == {1, 2, 3, 4, 5} and set(slips["protocol"]) == {"stack", "individual"}
    record, run_slips = experimental_data.example_run(slips, events, n=4)
    assert record.n == 4 and record.protocol == "stack"
    assert set(run_slips["n"]) == {4} and run_slips["file"].nunique() == 1
    chosen = next(item for item in events if str(item) == run_slips["file"].iloc[0])
    np.testing.assert_array_equal(record.F, read_timeseries(chosen.parent).F)
    orphans = [dataclasses.replace(item, parent=None) for item in events]
    with pytest.raises(FileFormatError, match="without the time series it was made from"):
        experimental_data.example_run(slips, orphans, n=4)


@pytest.mark.slow
@pytest.mark.parametrize("name", FIGURES)
def test_every_figure_is_drawn_reproducibly(study, tmp_path, name):
    plugin = registry.get("figure", name)
    inputs = {category: study[category] for category in plugin.inputs}
    params = parse_params(plugin.params, {})
    plugin.run(params, inputs, tmp_path / "a.pdf")
    plugin.run(params, inputs, tmp_path / "b.pdf")
    assert (tmp_path / "a.png").stat().st_size > 10_000
    assert (tmp_path / "a.pdf").read_bytes() == (tmp_path / "b.pdf").read_bytes()


def test_inputs_without_run_attributes_are_refused(tmp_path):
    from stickslip.formats import stamp
    from stickslip.h5io import open_file, write_table

    path = tmp_path / "other.h5"
    with open_file(path, "w") as f:
        write_table(f, "slips", pd.DataFrame({"a": [1]}))
    with pytest.raises(FileFormatError, match="no 'format' attribute"):
        experimental_data.load_slips([path])
    with open_file(path, "r+") as f:
        stamp(f, "event-table")
    with pytest.raises(FileFormatError, match="attribute 'n' is missing"):
        experimental_data.load_slips([path])
