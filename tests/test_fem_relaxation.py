"""The exact relaxation (``relaxation = exact``): equilibrium within fixed wells, direct linear response, runs."""

import math

import h5py
import numpy as np
import pandas as pd
import pytest

from stickslip import registry
from stickslip.fem.backends import make_backend
from stickslip.fem.dynamics import residual
from stickslip.fem.forces import wells_hold
from stickslip.fem.parameters import FemParams
from stickslip.fem.system import System, derived_constants
from stickslip.formats.fem_run import read_increments, read_run_attrs
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.params import parse_params

CASE = {"N": 9, "plates": 2, "seed": 0, "k_drive": 1e-3, "drive": "fixed-lever", "nchunk": 200}


def _system(N=9, plates=2, **values):
    return System(FemParams(N=N, plates=plates, nchunk=60, **values), build_stack_mesh(MeshParams(N=N, plates=plates)),
                  make_backend())


@pytest.mark.parametrize("drive", ["fixed-lever", "free-lever"])
def test_direct_linear_response_is_an_equilibrium_and_the_limit_of_the_dynamic_one(drive):
    exact = _system(N=18, plates=3, drive=drive, relaxation="exact")
    exact.compute_linear_response()
    # equilibrium of the full nonlinear force (all wells elastic at this small strain): f = 0 on free DOFs
    state = exact.state
    state.u[:] = exact.delta_u
    state.target[:] = exact.delta_target
    state.lever[0] = exact.delta_lever
    exact.backend.force(exact.model, state)
    free = ~exact.model.prescribed
    assert np.abs(state.f[free]).max() < 1e-12 * np.abs(state.f[~free]).max()
    np.testing.assert_allclose(state.eps, exact.delta_eps, rtol=0, atol=1e-12 * np.abs(exact.delta_eps).max())
    # the paper's dynamic minimisation converges to it (its residual tolerance 1e-5 leaves ~1e-5 relative)
    dynamic = _system(N=18, plates=3, drive=drive, relaxation="dynamic")
    dynamic.compute_linear_response()
    scale = np.abs(exact.delta_u).max()
    assert np.abs(dynamic.delta_u - exact.delta_u).max() < 1e-3 * scale
    assert dynamic.delta_lever == pytest.approx(exact.delta_lever, rel=1e-3)


def test_equilibrium_in_wells_is_where_the_dynamics_end():
    system = _system(relaxation="dynamic", tol=1e-9)
    system.compute_linear_response()
    system.event_step(False)
    system.event_step(True)
    system.minimise()  # to residual 1e-9: far tighter than the protocol's 1e-5
    dynamic = system.state.u.copy()
    wells = system.state.idx.copy()
    assert system.relax_in_wells()
    np.testing.assert_array_equal(system.state.idx, wells)
    assert residual(system.model, system.state) < 1e-10
    assert np.abs(system.state.u - dynamic).max() < 1e-6 * np.abs(dynamic).max()


def test_an_equilibrium_outside_the_current_wells_is_rejected():
    system = _system(relaxation="exact")
    system.compute_linear_response()
    system.event_step(False)
    before = system.snapshot()
    system.state.idx[0, :] += 3  # three wells up: the plates cannot hold the block there
    assert not wells_hold(system.model, system.state)
    assert not system.relax_in_wells()
    np.testing.assert_array_equal(system.state.u, before[0])  # state untouched
    system.restore(*before)
    assert system.relax_in_wells()  # at the brink of yielding, in its wells: accepted


def test_exact_relaxation_quenches_a_kick_in_far_fewer_steps():
    steps = {}
    for relaxation in ("dynamic", "exact"):
        system = _system(relaxation=relaxation)
        system.compute_linear_response()
        system.event_step(False)
        wells = system.state.idx.copy()
        t0 = system.state.t[0]
        assert system.kick(5) == (True, False)
        steps[relaxation] = (system.state.t[0] - t0) / system.model.dt
        changed = system.state.idx != wells
        assert changed.any()
        if relaxation == "exact":
            assert residual(system.model, system.state) < 1e-10 and wells_hold(system.model, system.state)
            np.testing.assert_array_equal(changed, reference)
        reference = changed
    assert steps["exact"] * 10 < steps["dynamic"]


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
    kick = System.kick
    calls = []

    def interrupted(self, margin):
        calls.append(1)
        if len(calls) == 31:
            raise KeyboardInterrupt
        return kick(self, margin)

    monkeypatch.setattr(System, "kick", interrupted)
    with pytest.raises(KeyboardInterrupt):
        _run(partial)
    monkeypatch.setattr(System, "kick", kick)
    assert len(read_increments(partial)) == 62  # increment 0, 30 load steps and kicks, the 31st load step
    _run(partial)
    pd.testing.assert_frame_equal(read_increments(partial), read_increments(first))
    with h5py.File(partial) as a, h5py.File(first) as b:
        np.testing.assert_array_equal(a["state/u"][...], b["state/u"][...])
