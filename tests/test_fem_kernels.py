"""Verification of the fem kernels: random numbers, elements, elasticity, dynamics, event-driven steps."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from stickslip.fem.backends import make_backend
from stickslip.fem.backends.cpu.forces import compute_force
from stickslip.fem.backends.cpu.state import new_state
from stickslip.fem.event_driven import step_size
from stickslip.fem.laws import INTERFACE_LAWS, Cusp, well_index, well_stress
from stickslip.fem.linear_response import compute_linear_response
from stickslip.fem.materials import equivalent_strain
from stickslip.fem.model import build_model
from stickslip.fem.observables import Observer
from stickslip.fem.parameters import FemParams
from stickslip.fem.quad4 import element_strain
from stickslip.fem.random import pcg32_uint32, pcg32_uniform
from stickslip.fem.simulation import Simulation
from stickslip.fem.yield_strains import interface_initstate, yield_strains
from stickslip.formats.fem_run import StoredState
from stickslip.mesh import MeshParams, build_stack_mesh


def test_pcg32_reproduces_the_published_reference_outputs():
    # O'Neill's pcg32-demo, pcg32_srandom_r(&rng, 42u, 54u): first six outputs
    out = pcg32_uint32(np.array([42], dtype=np.uint64), np.array([54], dtype=np.uint64), 6)[0]
    assert [int(x) for x in out] == [0xA15C02B7, 0x7B47F409, 0xBA1D3330, 0x83D2F293, 0xBFA4784B, 0xCBED606E]
    assert pcg32_uniform([42], 54, 1)[0, 0] == 0xA15C02B7 / 2.0**32


def test_yield_strains_statistics_and_seeding():
    initstate = interface_initstate(seed=1, N=9, n_interfaces=2)
    assert initstate[0] == 9 * 99 and initstate[-1] == 9 * 99 + 17
    epsy = yield_strains(interface_initstate(0, 2000, 1), nchunk=200, eps0=5e-5, eps_offset=1e-6, k=2.0)
    assert epsy.shape == (2000, 201)
    np.testing.assert_array_equal(epsy[:, 0], -epsy[:, 1])  # symmetric first well
    widths = np.diff(epsy[:, 1:], axis=1)
    assert widths.min() >= 1e-6
    # mean width 2 eps0 Gamma(3/2) + offset, std 2 eps0 sqrt(1 - pi / 4) (Weibull k = 2)
    assert widths.mean() == pytest.approx(2 * 5e-5 * math.gamma(1.5) + 1e-6, rel=5e-3)
    assert widths.std() == pytest.approx(2 * 5e-5 * math.sqrt(1 - math.pi / 4), rel=5e-3)
    # same seed, same disorder on the first interface whatever the number of interfaces
    one = yield_strains(interface_initstate(3, 9, 1), 50, 5e-5, 1e-6, 2.0)
    two = yield_strains(interface_initstate(3, 9, 2), 50, 5e-5, 1e-6, 2.0)
    np.testing.assert_array_equal(one, two[:9])


@pytest.fixture(scope="module")
def sim():
    """A 3-plate stack with coarsening rows (N = 18), at rest at the origin."""
    mesh = build_stack_mesh(MeshParams(N=18, plates=3))
    return Simulation(FemParams(N=18, plates=3, nchunk=50), mesh, make_backend())


def _drive_at_rest(sim, u):
    """Set displacement ``u`` with the drive springs at rest (targets at the layer averages)."""
    sim.stack.restore(StoredState(u, np.zeros(sim.mesh.nlayer), 0.0, 0.0))
    sim.stack.restore(StoredState(u, sim.backend.read("ubar")[0].copy(), 0.0, 0.0))
    return sim.backend.read("f")[0]


def test_homogeneous_simple_shear_gives_the_shear_modulus(sim):
    gamma = 1e-6
    mesh, model = sim.mesh, sim.model
    y = mesh.coor[:, 1]
    u = np.zeros(model.ndof)
    u[mesh.dofs[:, 0]] = 2.0 * gamma * y
    f = _drive_at_rest(sim, u)
    # patch test: a homogeneous stress is in equilibrium at every interior node, transition rows included
    top = mesh.coor[:, 1] == mesh.coor[:, 1].max()
    interior = np.ones(model.ndof, dtype=bool)
    interior[mesh.dofs[top].ravel()] = False
    interior[model.prescribed] = False
    assert np.abs(f[interior]).max() < 1e-12 * np.abs(f).max()
    # energy G eps_eq^2 V, eps_eq = gamma
    volume = model.layer_volume.sum()
    assert 0.5 * u @ f == pytest.approx(sim.params.G * gamma**2 * volume, rel=1e-10)
    observer = Observer(sim)
    row = observer.observe(observer.well_index())
    for layer in range(mesh.nlayer):  # sigma_eq = 2 G gamma, eps_eq = gamma, in units 2 G eps0 and eps0
        assert row[f"sigd_{layer}"] == pytest.approx(gamma / sim.params.eps0, rel=1e-10)
        assert row[f"epsd_{layer}"] == pytest.approx(gamma / sim.params.eps0, rel=1e-10)
        assert row[f"ubar_{layer}"] == pytest.approx(2 * gamma * mesh.layer_mid_height[layer], rel=1e-10)


def test_uniaxial_strain_gives_bulk_and_shear_energy(sim):
    eps = 1e-6
    u = np.zeros(sim.model.ndof)
    u[sim.mesh.dofs[:, 1]] = eps * sim.mesh.coor[:, 1]
    f = _drive_at_rest(sim, u)
    # eps_m = eps / 2, eps_eq = eps / 2: U = (K + G) eps^2 / 4
    expected = (sim.params.K + sim.params.G) * eps**2 / 4 * sim.model.layer_volume.sum()
    assert 0.5 * u @ f == pytest.approx(expected, rel=1e-10)


def _undamped_energy_error(sim, dt, nsteps):
    model = sim.model._replace(damping=np.zeros(sim.model.ndof), dt=dt,
                                     drive_active=np.zeros_like(sim.model.drive_active))
    backend = sim.backend.for_model(model, sim.stack.yield_strains)
    x, y = sim.mesh.coor[:, 0], sim.mesh.coor[:, 1]
    L, H = sim.mesh.N * sim.mesh.h, y.max()
    u = np.zeros(model.ndof)
    u[sim.mesh.dofs[:, 0]] = 1e-6 * np.sin(2 * np.pi * x / L) * np.sin(np.pi * y / H)
    backend.set_state(u, np.zeros(sim.mesh.nlayer), 0.0, 0.0)
    mass = np.where(model.mass_inv > 0, 1.0 / np.where(model.mass_inv > 0, model.mass_inv, 1.0), 0.0)
    energies = []
    for _ in range(nsteps):
        backend.advance(1)
        u, v, f = backend.read("u", "v", "f")
        energies.append(0.5 * mass @ v**2 + 0.5 * u @ f)
    energies = np.array(energies)
    return np.abs(energies - energies[0]).max() / energies[0]


def test_undamped_dynamics_conserves_energy_to_second_order(sim):
    dt = sim.model.dt
    coarse = _undamped_energy_error(sim, dt, 1000)
    fine = _undamped_energy_error(sim, dt / 2, 2000)
    assert coarse < 1e-3
    assert 3.0 < coarse / fine < 5.0  # O(dt^2)


def _column_mesh(nx, ny, h):
    """A periodic column of square elements, one elastic layer, no interface."""
    x, y = np.meshgrid(np.arange(nx + 1) * h, np.arange(ny + 1) * h)
    coor = np.column_stack([x.ravel(), y.ravel()])
    node = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    conn = np.column_stack([node[:-1, :-1].ravel(), node[:-1, 1:].ravel(), node[1:, 1:].ravel(),
                            node[1:, :-1].ravel()])
    base = node.copy()
    base[:, -1] = base[:, 0]
    _, inverse = np.unique(base.ravel(), return_inverse=True)
    dofs = np.column_stack([2 * inverse, 2 * inverse + 1])
    iip = np.unique(np.concatenate([dofs[node[0]].ravel(), dofs[node[-1], 1]]))
    return SimpleNamespace(coor=coor, conn=conn, dofs=dofs, iip=iip, elem_layer=np.zeros(len(conn), dtype=int),
                           nlayer=1, layer_is_plastic=np.array([False]), layer_mid_height=np.array([ny * h / 2]),
                           interface_elements=np.zeros((0, nx), dtype=int))


def test_shear_pulse_travels_at_the_shear_wave_speed():
    h, nx, ny = np.pi, 4, 400
    mesh = _column_mesh(nx, ny, h)
    model = build_model(mesh, law=Cusp(4.5, 1.0), rho=1.0, alpha=0.0, dt=0.05, k_drive=0.0,
                        drive_active=np.array([False]), free_lever=False, lever_height=1.0)
    backend = make_backend().prepare(model, mesh, np.zeros((0, 2)))  # no interface
    c_s = math.sqrt(1.0 / 2.0 / 1.0)
    y = mesh.coor[:, 1]
    y0, width = 100 * h, 12 * h
    profile = np.exp(-(((y - y0) / width) ** 2))
    u = np.zeros(model.ndof)
    u[mesh.dofs[:, 0]] = 1e-6 * profile
    backend.set_state(u, np.zeros(1), 0.0, 0.0)
    state = backend.state  # a CPU backend's own arrays: the initial velocity of the pulse u(y - c_s t)
    state.v[mesh.dofs[:, 0]] = 1e-6 * 2 * (y - y0) / width**2 * profile * c_s
    state.v[model.prescribed] = 0.0
    column = mesh.dofs[mesh.coor[:, 0] == 0, 0]
    ycol = y[mesh.coor[:, 0] == 0]

    def centre():
        w = backend.read("u")[0][column] ** 2
        return (w * ycol).sum() / w.sum()

    start = centre()
    nsteps = 4000
    backend.advance(nsteps)
    speed = (centre() - start) / (nsteps * model.dt)
    assert speed == pytest.approx(c_s, rel=0.01)


def test_linear_response_and_load_step_superpose(sim):
    stack, model, nlayer = sim.stack, sim.model, sim.mesh.nlayer
    backend = sim.backend
    r = compute_linear_response(stack, model, sim.relaxation, sim.params, sim.mesh)
    # the response is linear: forces scale with the displacement (interfaces in their first well)
    stack.restore(StoredState(3.0 * r.delta_u, 3.0 * r.delta_target, 0.0, 0.0))
    f3 = backend.read("f")[0].copy()
    stack.restore(StoredState(r.delta_u, r.delta_target, 0.0, 0.0))
    f = backend.read("f")[0]
    np.testing.assert_allclose(f3, 3.0 * f, rtol=0, atol=1e-12 * np.abs(f3).max())
    # and it is in equilibrium with its drive (minimised to the residual tolerance)
    free = ~model.prescribed
    assert np.linalg.norm(f[free]) < 1e-3 * np.linalg.norm(f[~free])
    # the load step superposes strain and stops just short of the first yield strain
    stack.restore(StoredState(np.zeros(model.ndof), np.zeros(nlayer), 0.0, 0.0))
    step = sim.loading.step(kick=False)
    u, eps, idx = backend.read("u", "eps", "idx")
    np.testing.assert_allclose(eps, step * r.delta_eps, rtol=0, atol=1e-12 * np.abs(eps).max())
    eq = np.hypot(0.5 * (eps[..., 0] - eps[..., 1]), eps[..., 2])
    ratio = eq / stack.yield_strains[:, 1][:, None]
    assert np.all(idx == 0)
    assert 1.0 - 2e-5 < ratio.max() < 1.0
    # a kick makes at least one Gauss point yield, and no more than a kick's worth of strain is added
    before = idx.copy()
    kick = step_size(stack.yield_strains, model.iface_dofs, model.iface_dNdx, u, r.delta_u, eps, r.delta_eps, before,
                     sim.constants["deps"], True, False)
    sim.loading.step(kick=True)
    assert np.any(backend.read("idx")[0] != before)
    assert kick * equivalent_strain(*r.delta_eps.reshape(-1, 3).max(axis=0)) < 10 * sim.constants["deps"]


@pytest.mark.parametrize("law", sorted(INTERFACE_LAWS))
@pytest.mark.parametrize("update_wells", [True, False])
def test_vectorised_interface_kernel_has_the_bits_of_the_scalar_law(update_wells, law):
    # every interface Gauss point: strain (element_strain), well (well_index) and the law's stress
    # (well_stress, its scalar reference) evaluated one by one must give the same bits as the
    # vectorised kernel, with displacements large enough that many points change well (the
    # recompute path)
    backend = Simulation(FemParams(N=9, plates=3, nchunk=50, interface_law=law),
                         build_stack_mesh(MeshParams(N=9, plates=3)), make_backend()).backend
    model, state = backend.model, new_state(backend.model, backend.state.epsy)
    assert model.law.name == law
    rng = np.random.default_rng(3)
    state.u[:] = 2e-3 * rng.standard_normal(model.ndof)
    state.idx[:] = rng.integers(0, 5, state.idx.shape)
    before = state.idx.copy()
    compute_force(model, backend.work, state, update_wells)
    fe = backend.work.iface.fe
    moved = 0
    for e in range(model.iface_dofs.shape[0]):
        eps = np.zeros((4, 3))
        element_strain(model.iface_dNdx[e], state.u[model.iface_dofs[e]], eps)
        force = np.zeros(8)
        for q in range(4):
            i = before[e, q]
            if update_wells:
                i = well_index(state.epsy[e], equivalent_strain(*eps[q]), i)
            moved += i != before[e, q]
            assert state.idx[e, q] == i
            sig = well_stress(model.law, *eps[q], state.epsy[e, i], state.epsy[e, i + 1])
            assert state.eps[e, q].tobytes() == eps[q].tobytes()
            assert state.sig[e, q].tobytes() == np.array(sig).tobytes()
            for m in range(4):
                gx, gy = model.iface_dNdx[e, q, m]
                force[2 * m] += model.iface_dV[e, q] * (gx * sig[0] + gy * sig[2])
                force[2 * m + 1] += model.iface_dV[e, q] * (gx * sig[2] + gy * sig[1])
        assert fe[e].tobytes() == force.tobytes()
    assert (moved > 10) == update_wells
