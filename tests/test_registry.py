"""Plugin registry: registration checks, lookup, run ids."""

import dataclasses
import subprocess
import sys

import pytest

from stickslip import registry
from stickslip.plugin_params import param, parse_params


@dataclasses.dataclass(frozen=True)
class Params:
    x: int = param(1, "a number")


def test_malformed_plugins_are_refused():
    with pytest.raises(registry.PluginError, match="path component"):
        registry.register("solver", "Bad Name", "1", Params)(lambda params, output, *, threads, inputs: None)
    with pytest.raises(registry.PluginError, match="signature"):
        registry.register("solver", "test-wrong-signature", "1", Params, produces="fem-run")(lambda params, out: None)
    with pytest.raises(registry.PluginError, match="dataclass"):
        registry.register("analysis", "test-no-dataclass", "1", dict)(lambda params, input, output: None)

    @dataclasses.dataclass(frozen=True)
    class NoDefault:
        x: int

    with pytest.raises(registry.PluginError, match="without a default: x"):
        registry.register("figure", "test-no-default", "1", NoDefault)(lambda params, inputs, output: None)


def test_register_get_and_run_id():
    def solve(params, output, *, threads, inputs):
        """Test solver."""

    registry.register("solver", "test-solver", "1.0", Params, produces="fem-run")(solve)
    plugin = registry.get("solver", "test-solver")
    assert plugin.summary == "Test solver."
    assert "test-solver" in registry.available("solver")
    a = registry.run_id(plugin, parse_params(Params, {"x": 1}))
    assert a == registry.run_id(plugin, parse_params(Params, {}))  # defaults filled: same id
    assert a != registry.run_id(plugin, parse_params(Params, {"x": 2}))
    with pytest.raises(registry.PluginError, match="already registered"):
        registry.register("solver", "test-solver", "1.0", Params, produces="fem-run")(
            lambda params, output, *, threads, inputs: None)
    with pytest.raises(registry.PluginError, match="unknown solver 'nope'"):
        registry.get("solver", "nope")


def test_a_plugin_without_parameters_needs_no_class_and_a_choice_names_a_parameter():
    registry.register("analysis", "test-no-parameters", "1", consumes=("fem-run",), produces="event-table")(_analysis)
    plugin = registry.get("analysis", "test-no-parameters")
    assert plugin.params is registry.NoParameters and parse_params(plugin.params, {}) == registry.NoParameters()
    with pytest.raises(Exception, match="'x'"):
        parse_params(plugin.params, {"x": 1})  # no parameter at all
    parts = {"a": Params, "b": dict}
    choice = registry.Choice("x", {"one": Params})
    assert choice.modules() == {__name__} and choice.module(Params(x="one")) == __name__
    with pytest.raises(registry.PluginError, match="choices name parameters it does not have: y"):
        registry.register("solver", "test-bad-choice", "1", Params, produces="fem-run",
                          choices=(registry.Choice("y", parts),))(lambda params, output, *, threads, inputs: None)
    with pytest.raises(registry.PluginError, match="choices must be Choice objects of a solver"):
        registry.register("analysis", "test-choice", "1", Params, consumes=("fem-run",), produces="event-table",
                          choices=(registry.Choice("x", parts),))(_analysis)


def _analysis(params, input, output):
    """Test analysis."""


@pytest.mark.parametrize("contract, message", [
    ({}, "declare the format it produces"),
    ({"produces": "event-table"}, "declare the one format it consumes"),
    ({"consumes": ("no-such-format",), "produces": "event-table"}, "unknown format 'no-such-format'"),
    ({"consumes": ("fem-run",), "produces": "event-table", "inputs": ("analysis:x",)}, "only figures declare inputs"),
    ({"consumes": ("fem-run",), "produces": "event-table", "replay": print}, "replay must be a callable of a solver"),
])
def test_plugins_declare_the_formats_they_consume_and_produce(contract, message):
    with pytest.raises(registry.PluginError, match=message):
        registry.register("analysis", "test-contract", "1", Params, **contract)(_analysis)


def test_figure_inputs_are_analyses_or_formats():
    with pytest.raises(registry.PluginError, match="expected 'analysis:<name>' or 'format:<name>'"):
        registry.register("figure", "test-figure-inputs", "1", Params, inputs=("solver:fem",))(
            lambda params, inputs, output: None)


def test_derived_run_ids_follow_the_lineage():
    registry.register("analysis", "test-derived", "1", Params, consumes=("fem-run",), produces="event-table")(
        _analysis)
    plugin = registry.get("analysis", "test-derived")
    params = parse_params(Params, {})
    a = registry.derived_run_id(plugin, params, ["0123456789abcdef", "fedcba9876543210"])
    assert a == registry.derived_run_id(plugin, params, ["fedcba9876543210", "0123456789abcdef"])
    assert a != registry.derived_run_id(plugin, params, ["0123456789abcdef"])
    assert a != registry.derived_run_id(plugin, parse_params(Params, {"x": 2}), ["0123456789abcdef",
                                                                                 "fedcba9876543210"])


def _imports_after(statement):
    """Which heavy modules a fresh interpreter has imported after ``statement``."""
    probe = ("import sys\n" + statement + "\n"
             "print(sorted(m for m in ('matplotlib', 'stickslip.solvers.fem', 'stickslip.figures.fig2') "
             "if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return done.stdout.strip()


def test_a_job_given_its_plugin_module_imports_only_that_module():
    lever = "from stickslip import registry; p = registry.get('solver', 'lever', 'stickslip.solvers.lever')"
    assert _imports_after(lever + "; assert p.module == 'stickslip.solvers.lever'") == "[]"
    # without the module, or with one that does not register the name, every plugin is loaded
    everything = "['matplotlib', 'stickslip.figures.fig2', 'stickslip.solvers.fem']"
    assert _imports_after("from stickslip import registry; registry.get('solver', 'lever')") == everything
    wrong = "from stickslip import registry; p = registry.get('solver', 'lever', 'stickslip.experiment.aging')"
    assert _imports_after(wrong + "; assert p.name == 'lever'") == everything


def test_plugins_command_lists_every_format_with_its_reader(toy_plugins, capsys):
    from stickslip.cli import main

    assert main(["plugins", "--kind", "format"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "formats:"
    listed = {line.split()[0]: line.strip() for line in lines[1:]}
    # the built-in formats and the one an entry-point package registers, each with its module
    assert set(listed) == {"mesh", "fem-run", "timeseries", "event-table", "front-table", "toy-block"}
    assert listed["fem-run"].startswith("fem-run 2 ") and listed["fem-run"].endswith("(stickslip.formats.fem_run)")
    assert "[numerical]" in listed["fem-run"] and "[experimental]" in listed["timeseries"]
    assert listed["toy-block"].endswith("(stickslip_toy)")
    assert main(["plugins", "--kind", "solver"]) == 0
    assert "formats:" not in capsys.readouterr().out
