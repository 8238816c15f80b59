"""Plugin registry: registration checks, lookup, run ids."""

import dataclasses

import pytest

from stickslip import registry
from stickslip.params import param, parse_params


@dataclasses.dataclass(frozen=True)
class Params:
    x: int = param(1, "a number")


def test_malformed_plugins_are_refused():
    with pytest.raises(registry.PluginError, match="path component"):
        registry.register("solver", "Bad Name", "1", Params)(lambda params, output, *, threads, inputs: None)
    with pytest.raises(registry.PluginError, match="signature"):
        registry.register("solver", "test-wrong-signature", "1", Params)(lambda params, out: None)
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

    registry.register("solver", "test-solver", "1.0", Params)(solve)
    plugin = registry.get("solver", "test-solver")
    assert plugin.summary == "Test solver."
    assert "test-solver" in registry.available("solver")
    a = registry.run_id(plugin, parse_params(Params, {"x": 1}))
    assert a == registry.run_id(plugin, parse_params(Params, {}))  # defaults filled: same id
    assert a != registry.run_id(plugin, parse_params(Params, {"x": 2}))
    with pytest.raises(registry.PluginError, match="already registered"):
        registry.register("solver", "test-solver", "1.0", Params)(lambda params, output, *, threads, inputs: None)
    with pytest.raises(registry.PluginError, match="unknown solver 'nope'"):
        registry.get("solver", "nope")
