"""Interfaces of different strength (``interface_strength``, issue 56): every well of an interface scaled.

- The default leaves every run id and every yield strain bit for bit; a scale multiplies an interface's yield
  strains exactly (a power of two) and leaves the other interfaces' bits alone.
- The physics: the cusp model is linear between yield strains, so scaling every yield strain of a stack by s scales
  every strain and stress of its athermal run by s, event for event (only the kick, a fixed 1e-4 eps0, does not
  scale: the peaks agree to far below a drop).
- Bad input is refused with the field named.
"""

import numpy as np
import pytest

from stickslip import registry
from stickslip.fem.parameters import FemParams
from stickslip.fem.yield_strains import HeldYieldStrains, element_scale, interface_initstate, narrowest_well
from stickslip.plugin_params import ParameterError, parse_params


def test_the_default_strength_changes_no_run_id():
    solver = registry.get("solver", "fem")
    plain = parse_params(solver.params, {"N": 9, "plates": 3})
    assert registry.run_id(solver, parse_params(solver.params, {"N": 9, "plates": 3, "interface_strength": []})) == \
        registry.run_id(solver, plain)
    assert registry.run_id(solver, parse_params(solver.params, {"N": 9, "plates": 3, "interface_strength": [2.0]})) != \
        registry.run_id(solver, plain)


def test_a_scale_multiplies_its_interfaces_yield_strains_and_no_others():
    initstate = interface_initstate(seed=4, N=9, n_interfaces=2)
    plain = HeldYieldStrains(initstate, 40, 5e-5, 1e-6, 2.0)
    ones = HeldYieldStrains(initstate, 40, 5e-5, 1e-6, 2.0, element_scale([], 9, 2))
    scaled = HeldYieldStrains(initstate, 40, 5e-5, 1e-6, 2.0, element_scale([1.0, 2.0], 9, 2))
    assert np.array_equal(ones.epsy, plain.epsy)
    assert np.array_equal(scaled.epsy[:9], plain.epsy[:9]) and np.array_equal(scaled.epsy[9:], 2.0 * plain.epsy[9:])
    for wells in (plain, scaled):  # sliding and widening draw on with the same scale
        wells.slide(np.full(18, 7)), wells.widen(5)
    assert np.array_equal(scaled.epsy[9:], 2.0 * plain.epsy[9:]) and np.array_equal(scaled.epsy[:9], plain.epsy[:9])
    assert narrowest_well(initstate, 40, 5e-5, 1e-6, 2.0, element_scale([0.5], 9, 2)) == \
        0.5 * narrowest_well(initstate, 40, 5e-5, 1e-6, 2.0)
    assert element_scale([3.0], 2, 3).tolist() == [3.0] * 6 and element_scale([1, 2, 3], 1, 3).tolist() == [1, 2, 3]


def test_bad_strengths_are_refused_with_the_field_named():
    with pytest.raises(ParameterError, match="interface_strength.*one per interface"):
        FemParams(N=9, plates=3, interface_strength=(1.0, 2.0, 3.0)).check()
    with pytest.raises(ParameterError, match="interface_strength"):
        parse_params(FemParams, {"N": 9, "plates": 3, "interface_strength": [0.0]})


def _peaks(tmp_path, **extra):
    from stickslip.formats.fem_run import read_increments

    solver = registry.get("solver", "fem")
    params = parse_params(solver.params, {"N": 9, "plates": 2, "seed": 2, "k_drive": 0.081, "relaxation": "exact",
                                          "max_increments": 60, **extra})
    path = tmp_path / f"run-{len(extra)}.h5"
    solver.run(params, path, threads=1, inputs={})
    increments = read_increments(path)
    return increments[[name for name in increments if name.startswith("sigd")]].to_numpy(dtype=float)


def test_a_stack_whose_yield_strains_are_all_scaled_has_every_stress_scaled(tmp_path):
    plain = _peaks(tmp_path)
    strong = _peaks(tmp_path, interface_strength=[1.5])
    assert plain.shape == strong.shape and np.abs(plain).max() > 0
    assert np.allclose(strong, 1.5 * plain, rtol=2e-3, atol=2e-3 * np.abs(plain).max())
