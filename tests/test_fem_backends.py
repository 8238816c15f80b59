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
from stickslip.fem.parameters import FemParams
from stickslip.fem.system import System
from stickslip.mesh import MeshParams, build_stack_mesh
from stickslip.params import params_to_dict, parse_params


@pytest.mark.slow
@pytest.mark.parametrize("relaxation", ["dynamic", "exact"])
def test_both_backends_run_the_same_events(relaxation):
    params = FemParams(N=18, plates=3, seed=1, nchunk=200, yield_strains="stop", relaxation=relaxation)
    mesh = build_stack_mesh(MeshParams(N=18, plates=3))
    systems = {name: System(params, mesh, make_backend(name)) for name in ("structured", "assembled")}
    reference, other = systems["structured"], systems["assembled"]
    reference.compute_linear_response()
    other.set_linear_response(reference.delta_u, reference.delta_eps, reference.delta_target, reference.delta_lever)
    slips = 0
    for event in range(12):
        other.restore(*reference.snapshot())  # the same state before every event
        before = reference.state.idx.copy()
        for system in (reference, other):
            system.event_step(False)
            assert system.kick(params.margin)[0]
        np.testing.assert_array_equal(other.state.idx, reference.state.idx, err_msg=f"event {event}")
        slips += int(np.count_nonzero(reference.state.idx != before))
        scale = np.abs(reference.state.u).max()
        tolerance = 1e-10 if relaxation == "exact" else 1e-6  # exact: solved equilibria; dynamic: tol 1e-5
        assert np.abs(other.state.u - reference.state.u).max() < tolerance * scale, f"event {event}"
        assert other.state.u.tobytes() != reference.state.u.tobytes() or event == 0  # other round-off, indeed
    assert slips > 12  # the events moved wells


def test_the_backend_is_a_parameter_that_makes_its_own_run_id_and_the_default_leaves_ids_alone():
    plugin = registry.get("solver", "fem")
    default = parse_params(plugin.params, {"N": 9, "max_increments": 10})
    assert default.backend == "structured" and "backend" not in params_to_dict(default)  # not keyed
    assembled = parse_params(plugin.params, {"N": 9, "max_increments": 10, "backend": "assembled"})
    assert registry.run_id(plugin, assembled) != registry.run_id(plugin, default)
    assert set(BACKENDS) == {"structured", "assembled"}
    with pytest.raises(ValueError, match="backend 'assembled' given for a run whose parameter 'backend' is"):
        from stickslip.fem.run import run_simulation
        run_simulation(default, "unused.h5", build_stack_mesh(MeshParams(N=9)), make_backend("assembled"),
                       producer=("fem", "x"))
