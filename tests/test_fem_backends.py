"""The execution backends (stickslip.fem.backends) compute the same events.

The ``assembled`` backend (the plates' CSR product) sums the plate rows in another order than
the default ``structured`` one (stencils): the same physics with other round-off. From the same
state, the same kick and relaxation give the same wells (the events are the same) and states
equal to round-off amplified by the dynamics; a run with it has its own run id.
"""

import numpy as np
import pytest

from stickslip import registry
from stickslip.fem.backends import BACKENDS, make_backend
from stickslip.fem.backends.cpu import StructuredBackend
from stickslip.fem.parameters import FemParams
from stickslip.fem.run import simulate_to_file
from stickslip.fem.simulation import Simulation
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.plugin_params import params_to_dict, parse_params


@pytest.mark.slow
@pytest.mark.parametrize("relaxation", ["dynamic", "exact"])
def test_both_backends_run_the_same_events(relaxation):
    params = FemParams(N=18, plates=3, seed=1, nchunk=200, yield_strains="stop", relaxation=relaxation)
    mesh = build_stack_mesh(MeshParams(N=18, plates=3))
    reference = Simulation(params, mesh, make_backend("structured"))
    other = Simulation(params, mesh, make_backend("assembled"), response=reference.loading.response)
    slips = 0
    for event in range(12):
        other.stack.restore(reference.stack.stored())  # the same state before every event
        before = reference.stack.well_index()
        for sim in (reference, other):
            sim.loading.step(False)
            assert sim.protocol.kick(params.margin)[0]
        wells, u = reference.stack.well_index(), reference.backend.read("u")[0]
        np.testing.assert_array_equal(other.stack.well_index(), wells, err_msg=f"event {event}")
        slips += int(np.count_nonzero(wells != before))
        scale = np.abs(u).max()
        tolerance = 1e-10 if relaxation == "exact" else 1e-6  # exact: solved equilibria; dynamic: tol 1e-5
        other_u = other.backend.read("u")[0]
        assert np.abs(other_u - u).max() < tolerance * scale, f"event {event}"
        assert other_u.tobytes() != u.tobytes() or event == 0  # other round-off, indeed
    assert slips > 12  # the events moved wells


def test_the_backend_is_a_parameter_that_makes_its_own_run_id_and_the_default_leaves_ids_alone():
    plugin = registry.get("solver", "fem")
    default = parse_params(plugin.params, {"N": 9, "max_increments": 10})
    assert default.backend == "structured" and "backend" not in params_to_dict(default)  # not keyed
    assembled = parse_params(plugin.params, {"N": 9, "max_increments": 10, "backend": "assembled"})
    assert registry.run_id(plugin, assembled) != registry.run_id(plugin, default)
    assert set(BACKENDS) == {"structured", "assembled", "cuda"}
    with pytest.raises(ValueError, match="backend 'assembled' given for a run whose parameter 'backend' is"):
        simulate_to_file(default, "unused.h5", build_stack_mesh(MeshParams(N=9)), make_backend("assembled"),
                       producer=("fem", "x"))


class _ShortLoads(StructuredBackend):
    """The default backend whose loads fall short by 1e-4 of the step: another backend's round-off, much exaggerated."""

    name = "short-loads"

    def load(self, step):
        super().load(step * (1.0 - 1e-4))


def test_a_kick_that_a_backend_s_round_off_leaves_short_of_its_yield_strain_is_completed():
    # the step to the brink is found with the CPU's arithmetic; a GPU's fused multiply-adds can leave the kicked
    # point a rounding error short of its yield strain: the kick goes on from there (found on the H100)
    params = FemParams(N=9, plates=2, seed=1, nchunk=60)
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    exact = Simulation(params, mesh, make_backend())
    short = Simulation(params, mesh, _ShortLoads(), response=exact.loading.response)
    for sim in (exact, short):
        sim.loading.step(False)
    before = short.stack.well_index()
    step = short.loading.step(True)
    assert np.any(short.stack.well_index() != before)
    assert step > exact.loading.step_size(True)  # a second, small kick followed the first
