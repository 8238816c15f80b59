"""Verification of the interface laws (stickslip.fem.laws): energy, stress, continuity, barriers, runs."""

import os
import subprocess
import sys
from collections import namedtuple

import numpy as np
import pytest

from stickslip.fem.backends import make_backend
from stickslip.fem.laws import (INTERFACE_LAWS, LAWS, Cusp, Elastic, Smooth, backward_barrier, deviatoric_factor,
                                energy_density, forward_barrier, register_law, well_energy, well_stress)
from stickslip.fem.materials import elastic_stress
from stickslip.fem.materials import equivalent_strain
from stickslip.fem.parameters import FemParams
from stickslip.fem.simulation import Simulation
from stickslip.mesh import MeshParams, build_stack_mesh

LO, HI = 2.0e-4, 3.1e-4  # a well [strain]: centre 2.55e-4, half-width 5.5e-5


@pytest.mark.parametrize("name", sorted(LAWS))
def test_the_stress_is_the_derivative_of_the_energy(name):
    law = LAWS[name](4.5, 1.0)
    rng = np.random.default_rng(1)
    h = 1e-9
    scale = law.K * 1e-3 + law.G * HI  # the stresses' size [stress]
    for _ in range(200):
        # strains whose equivalent strain lies in the well, at any angle and volumetric part
        eq = rng.uniform(LO + 2 * h, HI - 2 * h)
        angle, m = rng.uniform(0, 2 * np.pi), rng.uniform(-1e-3, 1e-3)
        strain = np.array([m + eq * np.cos(angle), m - eq * np.cos(angle), eq * np.sin(angle)])
        assert equivalent_strain(*strain) == pytest.approx(eq, rel=1e-12)
        sig = well_stress(law, *strain, LO, HI)
        for c, weight in ((0, 1.0), (1, 1.0), (2, 0.5)):  # sigma_xy = dU / d(2 eps_xy): the tensor has xy and yx
            up, down = strain.copy(), strain.copy()
            up[c] += h
            down[c] -= h
            derivative = (energy_density(law, *up, LO, HI) - energy_density(law, *down, LO, HI)) / (2 * h)
            assert sig[c] == pytest.approx(weight * derivative, rel=1e-6, abs=1e-9 * scale)


def test_the_wells_join_continuously_the_cusp_with_a_kink_the_smooth_law_smoothly():
    # two neighbouring wells (LO, HI] and (HI, HI + 0.3e-4]: energy continuous at HI for both laws; the
    # slope W' jumps by 2 G (Delta_1 + Delta_2) for the cusp and is 0 on both sides for the smooth law
    nxt = HI + 0.3e-4
    for law in (Cusp(4.5, 1.0), Smooth(4.5, 1.0)):
        assert well_energy(law, HI, LO, HI) == pytest.approx(well_energy(law, HI, HI, nxt), abs=1e-22)
        assert well_energy(law, HI, LO, HI) == pytest.approx(0.0, abs=1e-22)
    slope = {type(law).name: (2 * HI * deviatoric_factor(law, HI, LO, HI), 2 * HI * deviatoric_factor(law, HI, HI, nxt))
             for law in (Cusp(4.5, 1.0), Smooth(4.5, 1.0))}
    assert slope["cusp"][0] - slope["cusp"][1] == pytest.approx(2.0 * (0.5 * (HI - LO) + 0.5 * (nxt - HI)), rel=1e-12)
    assert slope["smooth"][0] == pytest.approx(0.0, abs=1e-18) and slope["smooth"][1] == pytest.approx(0.0, abs=1e-18)
    # the bottom of a well has the same curvature 2 G for both (the smooth law is the cusp near the bottom)
    centre, d = 0.5 * (LO + HI), 1e-7
    for law in (Cusp(4.5, 1.0), Smooth(4.5, 1.0)):
        curvature = (well_energy(law, centre + d, LO, HI) - 2 * well_energy(law, centre, LO, HI)
                     + well_energy(law, centre - d, LO, HI)) / d**2
        assert curvature == pytest.approx(2.0, rel=1e-4)


def _barrier_by_search(law, eq):
    """max over y in [eq, HI] of W(y) - W(eq) - W'(eq) (y - eq): a dense grid, then a golden-section refinement."""
    slope = 2 * eq * deviatoric_factor(law, eq, LO, HI)
    y = np.linspace(eq, HI, 20001)
    tilted = np.array([well_energy(law, v, LO, HI) for v in y]) - slope * (y - eq)
    k = int(np.argmax(tilted))
    a, b = y[max(k - 1, 0)], y[min(k + 1, y.size - 1)]

    def f(v):
        return well_energy(law, v, LO, HI) - slope * (v - eq)

    for _ in range(100):
        c, d = b - (b - a) / 1.618033988749895, a + (b - a) / 1.618033988749895
        a, b = (a, d) if f(c) > f(d) else (c, b)
    return max(f(0.5 * (a + b)), tilted.max()) - well_energy(law, eq, LO, HI)


@pytest.mark.parametrize("name", sorted(INTERFACE_LAWS))
def test_the_barrier_formula_is_the_maximum_of_the_tilted_well(name):
    law = LAWS[name](4.5, 1.0)
    scale = law.G * (0.5 * (HI - LO)) ** 2
    for eq in np.linspace(LO + 1e-7, HI - 1e-7, 41):
        assert forward_barrier(law, eq, LO, HI) == pytest.approx(_barrier_by_search(law, eq), rel=1e-6,
                                                                 abs=1e-9 * scale)


def test_the_backward_barrier_is_the_mirrored_forward_one_for_symmetric_wells():
    # the cusp's barrier over its back edge at constant load: G (eq - lo)^2 (module doc of laws.cusp)
    law = Cusp(4.5, 1.0)
    for eq in np.linspace(LO + 1e-7, HI - 1e-7, 9):
        assert backward_barrier(law, eq, LO, HI) == pytest.approx(law.G * (eq - LO) ** 2, rel=1e-12)
    for eq in np.linspace(LO + 1e-7, HI - 1e-7, 9):
        assert backward_barrier(Smooth(4.5, 1.0), eq, LO, HI) == forward_barrier(Smooth(4.5, 1.0), LO + HI - eq, LO, HI)


def test_the_elastic_law_is_the_plates_elasticity_whatever_the_wells_and_never_yields():
    law = Elastic(4.5, 1.0)
    assert "elastic" in LAWS and "elastic" not in INTERFACE_LAWS  # not a choice of interface_law
    rng = np.random.default_rng(2)
    for lo, hi in ((LO, HI), (-np.inf, np.inf), (0.0, 1e-9)):
        strain = rng.uniform(-1e-3, 1e-3, 3)
        assert well_stress(law, *strain, lo, hi) == pytest.approx(elastic_stress(*strain, 4.5, 1.0), rel=1e-14)
    assert forward_barrier(law, 1e-4, LO, HI) == backward_barrier(law, 1e-4, LO, HI) == np.inf


def test_the_barrier_vanishes_as_the_square_for_the_cusp_and_the_three_halves_power_for_the_smooth_law():
    # load sigma = W'(eq); threshold sigma_c: the cusp's at the yield strain (2 G Delta), the smooth law's at
    # the inflection (2 G Delta / pi); barrier ~ (sigma_c - sigma)^alpha
    half, centre = 0.5 * (HI - LO), 0.5 * (LO + HI)
    exponents = {}
    for law, threshold in ((Cusp(4.5, 1.0), HI), (Smooth(4.5, 1.0), centre + 0.5 * half)):
        critical = 2 * threshold * deviatoric_factor(law, threshold, LO, HI)
        distance = np.geomspace(1e-4, 1e-2, 8) * half
        load = np.array([2 * e * deviatoric_factor(law, e, LO, HI) for e in threshold - distance])
        barrier = np.array([forward_barrier(law, e, LO, HI) for e in threshold - distance])
        exponents[type(law).name] = np.polyfit(np.log(critical - load), np.log(barrier), 1)[0]
        assert forward_barrier(law, threshold, LO, HI) == pytest.approx(0.0, abs=1e-30)
    assert exponents["cusp"] == pytest.approx(2.0, abs=1e-3)
    assert exponents["smooth"] == pytest.approx(1.5, abs=1e-2)
    # beyond the inflection a smooth well holds nothing at constant load
    assert forward_barrier(Smooth(4.5, 1.0), centre + 0.7 * half, LO, HI) == 0.0


def _smooth_simulation(relaxation, **values):
    params = FemParams(N=9, plates=2, nchunk=200, yield_strains="stop", interface_law="smooth",
                       relaxation=relaxation, **values)
    return Simulation(params, build_stack_mesh(MeshParams(N=9, plates=2)), make_backend())


@pytest.mark.slow
def test_the_event_driven_protocol_and_both_relaxations_run_with_the_smooth_law():
    dynamic, exact = _smooth_simulation("dynamic", tol=1e-9), _smooth_simulation("exact")
    assert dynamic.model.law == Smooth(4.5, 1.0)
    for event in range(8):
        wells = []
        for sim in (dynamic, exact):
            sim.loading.step(False)
            before = sim.stack.well_index()
            assert sim.protocol.kick(5) == (True, False)
            assert np.any(sim.stack.well_index() != before)
            wells.append(sim.stack.well_index())
        # the same event with both relaxations: the same wells, the same state up to the tolerance (the drive's
        # soft mode amplifies a residual tol into ~1e-4 of the displacement, docs/fem.md)
        np.testing.assert_array_equal(wells[0], wells[1], err_msg=f"event {event}")
        # the exact relaxation ends at rest in the current wells, with a residual below tol (tol^2, or tol
        # where the iterations stall, as for the cusp)
        backend = exact.backend
        assert backend.residual() < exact.params.tol
        assert backend.wells_hold()
        u, v = backend.read("u", "v")
        assert v.max() == v.min() == 0.0
        scale = np.abs(u).max()
        assert np.abs(dynamic.backend.read("u")[0] - u).max() < 1e-3 * scale
        dynamic.stack.restore(exact.stack.stored())  # continue both from the same state


def test_registering_refuses_a_law_parameter_without_a_default():
    class Unfinished(namedtuple("Unfinished", ("K", "G", "c"))):
        name = "test-unfinished"

    with pytest.raises(ValueError, match=r"law 'test-unfinished': parameter\(s\) c without a default"):
        register_law(Unfinished)
    assert "test-unfinished" not in LAWS


OTHER_PACKAGE = {
    "other_laws.py": "from stickslip.fem.laws import Cusp, register_law\n\n\n@register_law\nclass OtherCusp(Cusp):\n"
                     "    __slots__ = ()\n    name = 'other-cusp'\n",
    "other_backends.py": "from stickslip.fem.backends import register_backend\nfrom stickslip.fem.backends.cpu import "
                         "StructuredBackend\n\n\n@register_backend\nclass Other(StructuredBackend):\n"
                         "    name = 'other'\n",
}


def _distribution(folder, entry_points, modules):
    """A folder holding ``modules`` and an installed distribution whose entry points are ``entry_points``."""
    folder.mkdir()
    for name, text in modules.items():
        (folder / name).write_text(text)
    info = folder / "other-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: other\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(entry_points)
    return folder


def test_laws_and_backends_of_another_package_are_found_through_their_entry_points(tmp_path):
    site = _distribution(tmp_path / "site", "[stickslip.fem.laws]\nother = other_laws\n\n"
                         "[stickslip.fem.backends]\nother = other_backends\n", OTHER_PACKAGE)
    script = ("from stickslip.fem.parameters import FemParams; from stickslip.plugin_params import parse_params; "
              "from stickslip import registry; from stickslip.provenance.code import plugin_code_hash, module_sources; "
              "fem = registry.get('solver', 'fem'); "
              "params = parse_params(FemParams, {'interface_law': 'other-cusp', 'backend': 'other'}); "
              "print([choice.module(params) for choice in fem.choices], len(plugin_code_hash(fem, params)))")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), *sys.path[1:]])}
    done = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["['other_laws',", "'other_backends']", "16"]
    broken = _distribution(tmp_path / "broken", "[stickslip.fem.laws]\nbroken = broken_law\n",
                           {"broken_law.py": "raise ImportError('a missing dependency')\n"})
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(broken), *sys.path[1:]])}
    done = subprocess.run([sys.executable, "-c", "import stickslip.fem.laws"], cwd=tmp_path, env=env,
                          capture_output=True, text=True)
    assert done.returncode != 0
    assert ("entry point 'broken' in group 'stickslip.fem.laws' failed to load: a missing dependency"
            in done.stderr.splitlines()[-1])
