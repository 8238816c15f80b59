"""The numerical-study figures run on synthetic analysis files and write PDF + PNG.

The synthetic study: stiff and compliant driving, n = 1, 2, 3 interfaces, random event
sequences (stiff: single and multi-slips alternate, compliant: single slips only), and
front-dynamics files for n = 2 with known front speed and delay.
"""

import numpy as np
import pandas as pd
import pytest

from stickslip import registry
from stickslip.events import fronts, plugin
from stickslip.figures import figs_sequences
from stickslip.events.results import group_runs, read_analysis_file
from stickslip.h5io import FileFormatError
from stickslip.params import parse_params
from test_events_extraction import history, run_attrs
from test_fronts import C_S, H_BLOCK, SPACING, rupture

N = 27
K_DRIVE = {"stiff": 1e-3 * (1458 / N) ** 2, "compliant": 1e-6 * (1458 / N) ** 2}  # the paper's, for N blocks


def random_events(n, regime, rng, count=80):
    """Random kicks: a few microscopic ones, then slips (multi-slips only when driven stiffly)."""
    # every interface slips once, alone: the steady state starts with the last of these
    events = [(tuple(N if b == a else 0 for b in range(n)), tuple(1.0 if b == a else 0.0 for b in range(n)))
              for a in range(n)]
    for _ in range(count):
        kind = rng.choice(["micro", "slip"], p=[0.6, 0.4])
        if kind == "micro":
            events.append(((int(rng.integers(1, N)),) * n, (0.0,) * n))
            continue
        if regime == "stiff" and n > 1 and rng.random() < 0.5:
            slipping = set(range(n))
        else:
            slipping = {int(rng.integers(n))}
        A = tuple(N if a in slipping else 0 for a in range(n))
        drop = tuple(float(rng.uniform(0.5, 1.5)) if a in slipping else 0.0 for a in range(n))
        events.append((A, drop))
    return events


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    root = tmp_path_factory.mktemp("study")
    rng = np.random.default_rng(7)
    event_files, front_files = [], []
    for regime in ("stiff", "compliant"):
        for n in (1, 2, 3):
            attrs = run_attrs(N, n + 1, K_DRIVE[regime], seed=0, c_s=C_S, h=H_BLOCK)
            tables = plugin.event_tables(history(N, random_events(n, regime, rng), load_gamma=0.7), N)
            path = root / f"events-{regime}-{n}.h5"
            plugin.write_event_file(tables, plugin.event_attrs(attrs, tables["increments"]), path, input=__file__)
            event_files.append(path)
            if n != 2:
                continue

            def rerun(increment):
                return pd.concat([rupture(N, 1, c_f=2.0, nucleation=increment % N, start=0.0, rng=rng),
                                  rupture(N, 2, c_f=2.0, nucleation=3, start=40.0, rng=rng)])

            params = parse_params(fronts.FrontParams, {"max_events": 5})
            failures, table = fronts.front_tables(tables["increments"], rerun, N=N, h=H_BLOCK, c_s=C_S,
                                                  spacing=SPACING, params=params)
            path = root / f"fronts-{regime}.h5"
            fronts.write_front_file(failures, table, {**plugin.event_attrs(attrs, tables["increments"]),
                                                      "interface_spacing": SPACING}, path, input=__file__)
            front_files.append(path)
    return {"analysis:numerical-events": event_files, "analysis:front-dynamics": front_files}


@pytest.mark.parametrize("name", ["fig2", "figS-dgamma", "figS-sequences", "figS-event-maps", "figS-tau",
                                  "figS-phi-sweep"])
def test_figure_writes_pdf_and_png(study, tmp_path, name):
    figure = registry.get("figure", name)
    inputs = {category: study[category] for category in figure.inputs}
    output = tmp_path / f"{name}.pdf"
    figure.run(parse_params(figure.params, {}), inputs, output)
    assert output.stat().st_size > 1000
    assert output.with_suffix(".png").stat().st_size > 1000


def test_figure_inputs_say_what_is_missing(study, tmp_path):
    tau = registry.get("figure", "figS-tau")
    with pytest.raises(FileFormatError, match="analysis:front-dynamics"):
        tau.run(parse_params(tau.params, {}), {}, tmp_path / "tau.pdf")
    # an event beyond those re-run: the panel says so, the figure is still drawn
    maps = registry.get("figure", "figS-event-maps")
    maps.run(parse_params(maps.params, {"events": "0,99"}), {"analysis:front-dynamics": study["analysis:front-dynamics"]},
             tmp_path / "maps.pdf")
    assert (tmp_path / "maps.png").is_file()


def test_sequence_fractions_plotted_are_the_pooled_ones(study):
    files = [read_analysis_file(p, "event-table", ("sequences",)) for p in study["analysis:numerical-events"]]
    n, single, any_ = figs_sequences.fractions_by_n(group_runs(files), "compliant")
    np.testing.assert_array_equal(n, [1, 2, 3])
    np.testing.assert_allclose(single, 1.0)  # compliant: only single slips, all in one sequence
    np.testing.assert_allclose(any_, 1.0)
    n, single, any_ = figs_sequences.fractions_by_n(group_runs(files), "stiff")
    assert single[0] == 1.0 and (single[1:] < 1.0).all() and (any_ >= single).all()


def test_paper_figures_leave_out_runs_away_from_the_paper_phi(study, tmp_path):
    from stickslip.figures.numerical_common import read_inputs

    attrs = run_attrs(N, 3, K_DRIVE["stiff"] / 30, seed=0, c_s=C_S, h=H_BLOCK)
    tables = plugin.event_tables(history(N, random_events(2, "stiff", np.random.default_rng(1)), load_gamma=0.7), N)
    sweep = tmp_path / "sweep.h5"
    plugin.write_event_file(tables, plugin.event_attrs(attrs, tables["increments"]), sweep, input=__file__)
    inputs = {"analysis:numerical-events": [*study["analysis:numerical-events"], sweep]}
    paper = read_inputs(inputs, "analysis:numerical-events", ("slips",), "fig2")
    assert len(paper) == 6 and str(sweep) not in {item.path for item in paper}
    assert len(read_inputs(inputs, "analysis:numerical-events", ("slips",), "x", paper_phi=False)) == 7
    with pytest.raises(FileFormatError, match="paper's Phi"):
        read_inputs({"analysis:numerical-events": [sweep]}, "analysis:numerical-events", ("slips",), "fig2")
