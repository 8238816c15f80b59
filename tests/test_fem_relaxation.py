"""The exact relaxation (``relaxation = exact``): equilibrium within fixed wells, direct linear response, runs."""

import math

import h5py
import numpy as np
import pandas as pd
import pytest

from stickslip import registry
from stickslip.fem.backends import make_backend
from stickslip.fem.constants import derived_constants
from stickslip.fem.linear_response import compute_linear_response
from stickslip.fem.parameters import FemParams
from stickslip.fem.protocol import AthermalProtocol
from stickslip.fem.simulation import Simulation
from stickslip.formats.fem_run import read_increments, read_run_attrs
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.plugin_params import parse_params

CASE = {"N": 9, "plates": 2, "seed": 0, "k_drive": 1e-3, "drive": "fixed-lever", "nchunk": 200}


def _simulation(N=9, plates=2, **values):
    return Simulation(FemParams(N=N, plates=plates, nchunk=60, **values),
                      build_stack_mesh(MeshParams(N=N, plates=plates)), make_backend())


@pytest.mark.parametrize("drive", ["fixed-lever", "free-lever"])
def test_direct_linear_response_is_an_equilibrium_and_the_limit_of_the_dynamic_one(drive):
    exact = _simulation(N=18, plates=3, drive=drive, relaxation="exact")
    response = exact.loading.response
    # equilibrium of the full nonlinear force (all wells elastic at this small strain): f = 0 on free DOFs
    exact.backend.set_state(response.delta_u, response.delta_target, response.delta_lever, 0.0)
    f, eps = exact.backend.read("f", "eps")
    free = ~exact.model.prescribed
    assert np.abs(f[free]).max() < 1e-12 * np.abs(f[~free]).max()
    np.testing.assert_allclose(eps, response.delta_eps, rtol=0, atol=1e-12 * np.abs(response.delta_eps).max())
    # the paper's dynamic minimisation converges to it (its residual tolerance 1e-5 leaves ~1e-5 relative)
    dynamic = _simulation(N=18, plates=3, drive=drive, relaxation="dynamic").loading.response
    scale = np.abs(response.delta_u).max()
    assert np.abs(dynamic.delta_u - response.delta_u).max() < 1e-3 * scale
    assert dynamic.delta_lever == pytest.approx(response.delta_lever, rel=1e-3)


def test_equilibrium_in_wells_is_where_the_dynamics_end():
    sim = _simulation(relaxation="dynamic", tol=1e-9)
    backend = sim.backend
    sim.loading.step(False)
    sim.loading.step(True)
    sim.relaxation.relax(backend)  # to residual 1e-9: far tighter than the protocol's 1e-5
    dynamic, wells = (array.copy() for array in backend.read("u", "idx"))
    exact = _simulation(relaxation="exact", tol=1e-9).relaxation  # the solve of the exact relaxation
    assert exact.solve_in_wells(backend)
    np.testing.assert_array_equal(backend.read("idx")[0], wells)
    assert backend.residual() < 1e-10
    assert np.abs(backend.read("u")[0] - dynamic).max() < 1e-6 * np.abs(dynamic).max()


def test_an_equilibrium_outside_the_current_wells_is_rejected_and_leaves_the_state_as_it_was():
    sim = _simulation(relaxation="exact")
    backend = sim.backend
    sim.loading.step(False)
    before = sim.stack.stored()
    backend.state.idx[0, :] += 3  # three wells up (the CPU state, changed behind the backend's back on purpose)
    backend.rest_in_wells()
    assert not backend.wells_hold()  # the plates cannot hold the block there
    kept = backend.checkpoint()
    assert not sim.relaxation.solve_in_wells(backend)
    for name, value in zip(kept._fields, kept):  # state untouched, bit for bit
        assert backend.read(name)[0].tobytes() == value.tobytes(), name
    sim.stack.restore(before)
    assert sim.relaxation.solve_in_wells(backend)  # at the brink of yielding, in its wells: accepted


def test_exact_relaxation_quenches_a_kick_in_far_fewer_steps():
    steps = {}
    for relaxation in ("dynamic", "exact"):
        sim = _simulation(relaxation=relaxation)
        backend = sim.backend
        sim.loading.step(False)
        wells = backend.read("idx")[0].copy()
        t0 = sim.stack.time
        assert sim.protocol.kick(5) == (True, False)
        steps[relaxation] = (sim.stack.time - t0) / sim.model.dt
        changed = backend.read("idx")[0] != wells
        assert changed.any()
        if relaxation == "exact":
            assert backend.residual() < 1e-10 and backend.wells_hold()
            np.testing.assert_array_equal(changed, reference)
        reference = changed
    assert steps["exact"] * 10 < steps["dynamic"]


def test_the_linear_response_leaves_the_stack_as_it_was():
    sim = _simulation(relaxation="exact")
    sim.loading.step(False)
    before = sim.backend.checkpoint()
    again = compute_linear_response(sim.stack, sim.model, sim.relaxation, sim.params, sim.mesh)
    for mine, theirs in zip(again, sim.loading.response):
        assert np.asarray(mine).tobytes() == np.asarray(theirs).tobytes()
    for name, value in zip(before._fields, before):
        assert sim.backend.read(name)[0].tobytes() == value.tobytes(), name


@pytest.mark.parametrize("N, dt_scale, steps", [(9, 1.0, 267), (162, 1.0, 4799), (162, 2.0, 2400), (1458, 1.0, 43185)])
def test_the_automatic_quiet_window_is_a_shear_wave_crossing_a_third_of_the_interface(N, dt_scale, steps):
    # L = N h (h = pi), c_s = sqrt(G / 2 rho) = 1/sqrt(2), dt = 0.05 dt_scale: L / (3 c_s dt) rounded up
    mesh = build_stack_mesh(MeshParams(N=N, plates=2))
    assert derived_constants(FemParams(N=N, dt_scale=dt_scale, relaxation="exact"), mesh)["quiet_steps"] == steps
    assert 0 <= steps - N * math.pi * math.sqrt(2.0) / 3.0 / (0.05 * dt_scale) < 1
    assert derived_constants(FemParams(N=N, quiet_steps=200, relaxation="exact"), mesh)["quiet_steps"] == 200


def _run(output, **values):
    plugin = registry.get("solver", "fem")
    params = parse_params(plugin.params, {**CASE, "relaxation": "exact", "max_increments": 120, **values})
    plugin.run(params, output, threads=1, inputs={})


def test_exact_runs_are_reproducible_resume_identically_and_record_the_relaxation(tmp_path, monkeypatch):
    first, second = tmp_path / "a.h5", tmp_path / "b.h5"
    _run(first)
    _run(second)
    assert first.read_bytes() == second.read_bytes()
    attrs = read_run_attrs(first)
    assert attrs["params"]["relaxation"] == "exact" and attrs["params"]["quiet_steps"] == 0
    # interrupted in the middle of the 31st kick (as by Ctrl-C), then resumed
    partial = tmp_path / "partial.h5"
    kick = AthermalProtocol.kick
    calls = []

    def interrupted(self, margin):
        calls.append(1)
        if len(calls) == 31:
            raise KeyboardInterrupt
        return kick(self, margin)

    monkeypatch.setattr(AthermalProtocol, "kick", interrupted)
    with pytest.raises(KeyboardInterrupt):
        _run(partial)
    monkeypatch.setattr(AthermalProtocol, "kick", kick)
    assert len(read_increments(partial)) == 62  # increment 0, 30 load steps and kicks, the 31st load step
    _run(partial)
    pd.testing.assert_frame_equal(read_increments(partial), read_increments(first))
    with h5py.File(partial) as a, h5py.File(first) as b:
        np.testing.assert_array_equal(a["state/u"][...], b["state/u"][...])
