"""The numerical-study figures run on synthetic analysis files and draw the numbers of their inputs.

The synthetic study: stiff and compliant driving, n = 1, 2, 3 interfaces, random event
sequences (stiff: single and multi-slips alternate, compliant: single slips only), and
front-dynamics files for n = 2 with known front speed and delay.
"""

import numpy as np
import pandas as pd
import pytest
from matplotlib.text import Text

from stickslip import registry
from stickslip.events import fronts, plugin
from stickslip.events.extraction import slip_fractions
from stickslip.events.analysis_files import group_runs, pooled, read_analysis_file
from stickslip.figures import figs_sequences
from stickslip.h5io import FileFormatError
from stickslip.plugin_params import parse_params
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


def _read(study, category, tables):
    fmt = "front-table" if category == "analysis:front-dynamics" else "event-table"
    return [read_analysis_file(path, fmt, tables) for path in study[category]]


def _stiff_multi_fraction(study):
    """rho(2) of the stiff n = 2 run, from its file."""
    files = [f for f in _read(study, "analysis:numerical-events", ("slips",)) if (f.regime, f.n) == ("stiff", 2)]
    return slip_fractions(pooled(files, "slips"), 2)[1]


def _data_lines(ax):
    return [line for line in ax.get_lines() if len(line.get_xdata())]


def _check_fig2(figure, study):
    # panel c, rho(s): the stiff n = 2 line (dashed, two points) is the run's rho(1), rho(2)
    stiff = [line for line in _data_lines(figure.axes[2]) if line.get_linestyle() == "--" and len(line.get_xdata()) == 2]
    expected = _stiff_multi_fraction(study)
    assert 0 < expected < 1
    np.testing.assert_allclose(stiff[0].get_ydata(), [1 - expected, expected])


def _check_dgamma(figure, study):
    # stiff panel, n = 1: the legend counts the finite slip-to-slip increments of interface 1
    files = _read(study, "analysis:numerical-events", ("slip_interfaces",))
    per = pooled([f for f in files if (f.regime, f.n) == ("stiff", 1)], "slip_interfaces")
    count = int(np.isfinite(per["dgamma"][per["interface"] == 1]).sum())
    assert count > 10
    assert f"$n = 1$ ({count})" in [text.get_text() for text in figure.axes[0].get_legend().get_texts()]


def _check_sequences(figure, study):
    # stiff panel: the single-slip-sequence line is fractions_by_n of the files
    groups = group_runs(_read(study, "analysis:numerical-events", ("sequences",)))
    n, single, _ = figs_sequences.fractions_by_n(groups, "stiff")
    line = next(line for line in _data_lines(figure.axes[0]) if line.get_marker() == "o")
    np.testing.assert_array_equal(line.get_xdata(), n)
    np.testing.assert_allclose(line.get_ydata(), single)


def _check_event_maps(figure, study):
    # the synthetic fronts run at c_f = 2 c_s: the fitted speed printed on event (a)
    speeds = [text.get_text() for text in figure.findobj(Text) if text.get_text().startswith("$c_f")]
    assert speeds and speeds[0].startswith("$c_f = 2.00\\,c_s$ (")  # N = 27: one branch is too short
    assert "paper: $c_f \\approx 2\\,c_s$ ($N = 1458$)" in speeds[0]


def _check_tau(figure, study):
    # the dashed line marks the mean delay of the n = 2 runs' fronts
    tau = pooled(_read(study, "analysis:front-dynamics", ("fronts",)), "fronts")["tau"].to_numpy()
    means = [line.get_xdata()[0] for line in _data_lines(figure.axes[0]) if line.get_linestyle() == "--"]
    assert np.isfinite(tau).sum() == 5 and means == [pytest.approx(np.nanmean(tau))]  # the stiff run: 5 multi-slips
    assert means[0] == pytest.approx(40.0 * C_S / SPACING)  # the second interface fails 40 time units later


def _check_phi_sweep(figure, study):
    # panel a: rho(s > 1) of n = 2 at the compliant and the stiff Phi
    containers = figure.axes[0].containers  # one errorbar per n, in order 1, 2, 3
    data = containers[1].lines[0]
    np.testing.assert_allclose(data.get_ydata(), [0.0, _stiff_multi_fraction(study)])


def _check_size_series(figure, study):
    # panel c: the stiff n = 2 fronts of the synthetic study run at 2 c_s; panel a: the stiff multi-slip fraction
    speed = figure.axes[2].containers[0].lines[0]
    np.testing.assert_allclose(speed.get_ydata(), [2.0], rtol=1e-6)
    multi = figure.axes[0].containers[0].lines[0]
    np.testing.assert_allclose(multi.get_ydata(), [_stiff_multi_fraction(study)])


CHECKS = {"fig2": _check_fig2, "figS-dgamma": _check_dgamma, "figS-sequences": _check_sequences,
          "figS-event-maps": _check_event_maps, "figS-tau": _check_tau, "figS-phi-sweep": _check_phi_sweep,
          "figS-size-series": _check_size_series}


@pytest.mark.parametrize("name", list(CHECKS))
def test_figure_draws_the_numbers_of_its_inputs(study, tmp_path, name, drawn_figures):
    figure = registry.get("figure", name)
    inputs = {category: study[category] for category in figure.inputs}
    output = tmp_path / f"{name}.pdf"
    figure.run(parse_params(figure.params, {}), inputs, output)
    assert output.is_file() and output.with_suffix(".png").is_file()
    assert len(drawn_figures) == 1
    CHECKS[name](drawn_figures[0], study)


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
