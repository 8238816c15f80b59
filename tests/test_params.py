"""Plugin parameter dataclasses: conversion, validation messages, schema."""

import dataclasses

import pytest

from stickslip.plugin_params import (ParameterError, describe, json_schema, param, params_to_dict, parse_assignments,
                              parse_params)


@dataclasses.dataclass(frozen=True)
class Example:
    N: int = param(9, "blocks per interface", minimum=1)
    k_drive: float = param(1e-3, "drive stiffness", unit="G/l0^2", exclusive_minimum=0)
    drive: str = param("fixed-lever", "drive", choices=("fixed-lever", "free-lever"))
    creep: bool = param(False, "creep on")
    B: tuple[float, ...] = param((0.05, 0.06), "aging rates", minimum=0)

    def check(self):
        if self.N % 3 and self.N != 1:
            raise ParameterError(f"parameter 'N': expected a multiple of 3, got {self.N}")


def test_defaults_and_conversion_from_strings():
    p = parse_params(Example, {"N": "27", "k_drive": "1e-6", "creep": "yes", "B": "0.1,0.2,0.3"})
    assert (p.N, p.k_drive, p.creep, p.B) == (27, 1e-6, True, (0.1, 0.2, 0.3))
    assert p.drive == "fixed-lever"
    assert params_to_dict(p)["B"] == [0.1, 0.2, 0.3]


@pytest.mark.parametrize("values, words", [
    ({"Nx": 3}, ["'Nx'", "allowed: N, k_drive, drive, creep, B", "(did you mean 'N'?)"]),
    ({"k_drvie": 1.0}, ["unknown parameter 'k_drvie' (did you mean 'k_drive'?); allowed: N, k_drive"]),
    ({"N": "nine"}, ["'N'", "integer", "'nine'"]),
    ({"N": 2.5}, ["'N'", "integer"]),
    ({"N": 0}, ["'N'", ">= 1"]),
    ({"k_drive": 0}, ["'k_drive'", "> 0"]),
    ({"k_drive": "nan"}, ["'k_drive'", "finite"]),
    ({"drive": "lever"}, ["'drive'", "'fixed-lever'", "'free-lever'"]),
    ({"creep": "maybe"}, ["'creep'", "true or false"]),
    ({"B": "0.1,-1"}, ["'B'", ">= 0"]),
    ({"N": 10}, ["'N'", "multiple of 3"]),
])
def test_errors_name_the_field_and_the_expectation(values, words):
    with pytest.raises(ParameterError) as error:
        parse_params(Example, values)
    for word in words:
        assert word in str(error.value)


def test_assignments():
    assert parse_assignments(["N=9", "drive = free-lever"]) == {"N": "9", "drive": "free-lever"}
    with pytest.raises(ParameterError, match="KEY=VALUE"):
        parse_assignments(["N9"])
    with pytest.raises(ParameterError, match="twice"):
        parse_assignments(["N=9", "N=27"])


def test_schema_and_description_follow_the_dataclass():
    schema = json_schema(Example)
    assert schema["additionalProperties"] is False
    assert schema["properties"]["N"] == {"type": "integer", "minimum": 1, "default": 9,
                                         "description": "blocks per interface"}
    assert schema["properties"]["drive"]["enum"] == ["fixed-lever", "free-lever"]
    assert schema["properties"]["B"]["type"] == "array"
    assert schema["properties"]["k_drive"]["exclusiveMinimum"] == 0
    assert [row[0] for row in describe(Example)] == ["N", "k_drive", "drive", "creep", "B"]


def test_an_extension_field_at_its_default_leaves_the_stored_parameters_and_the_id_alone():
    from stickslip.registry import Plugin, run_id

    @dataclasses.dataclass(frozen=True)
    class Extended(Example):
        law: str = param("cusp", "interface law", choices=("cusp", "smooth"), extension=True)

    before, after = parse_params(Example, {"N": 27}), parse_params(Extended, {"N": 27})
    assert params_to_dict(after) == params_to_dict(before)
    plugin = Plugin(kind="solver", name="x", version="1", params=Example, run=None, summary="")
    assert run_id(plugin, after) == run_id(plugin, before)
    changed = parse_params(Extended, {"N": 27, "law": "smooth"})
    assert params_to_dict(changed) == {**params_to_dict(before), "law": "smooth"}
    assert run_id(plugin, changed) != run_id(plugin, before)
    assert parse_params(Extended, params_to_dict(changed)) == changed  # stored and read back


def test_an_extension_field_tied_to_another_is_stored_whenever_either_is_set():
    @dataclasses.dataclass(frozen=True)
    class Thermal(Example):
        temperature: float = param(0.0, "temperature", minimum=0.0, extension=True)
        rate: float = param(1.0, "attempt rate", exclusive_minimum=0.0, extension="temperature")

    base = params_to_dict(parse_params(Example, {"N": 27}))
    assert params_to_dict(parse_params(Thermal, {"N": 27})) == base
    hot = parse_params(Thermal, {"N": 27, "temperature": 0.5})
    assert params_to_dict(hot) == {**base, "temperature": 0.5, "rate": 1.0}  # the default rate is stated
    assert params_to_dict(parse_params(Thermal, {"N": 27, "rate": 2.0})) == {**base, "rate": 2.0}
    assert parse_params(Thermal, params_to_dict(hot)) == hot
