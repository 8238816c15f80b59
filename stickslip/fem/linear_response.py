"""The linear response of a stack: its elastic equilibrium under a unit drive, scaled to the narrowest well.

Along it the interface strain changes linearly, which the event-driven steps use
(:mod:`.loading`). It is the equilibrium of the stack with every interface block elastic
(:class:`.laws.Elastic`), in a model and state of its own (:meth:`.stack.Stack.backend_for`):
fixed lever, targets ``2 eps0 H_l`` (affine simple shear ``gamma = eps0``); free lever, lever
drive target ``eps0``. Then scaled so that the largest interface equivalent strain is 0.1 of the
narrowest well of the first ``nchunk`` (:func:`.event_driven.autoscale`).
"""

from collections import namedtuple

import numpy as np

from .backends.base import unbounded_wells
from .event_driven import autoscale
from .laws import Elastic
from .yield_strains import element_scale, interface_initstate, narrowest_well

__all__ = ["LinearResponse", "compute_linear_response"]

LinearResponse = namedtuple("LinearResponse", [
    "delta_u",       # float64 [ndof]: displacement [length]
    "delta_eps",     # float64 [ni, 4, 3]: interface strain (xx, yy, xy)
    "delta_target",  # float64 [nlayer]: layer drive targets [length]
    "delta_lever",   # float: free lever's drive target [length] (0 for a fixed lever)
])


def compute_linear_response(stack, model, relaxation, params, mesh):
    """The scaled linear response of a stack (module docstring); the stack's own state is not changed.

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
    model : stickslip.fem.model.Model
        The stack's model.
    relaxation : stickslip.fem.relaxation.DynamicRelaxation
        ``dynamic``: minimised from rest by damped dynamics (the paper's protocol); ``exact``: one
        direct solve with the run's factorisation (the model is linear).
    params : FemParams
    mesh : stickslip.mesh.LayeredMesh

    Returns
    -------
    LinearResponse
    """
    backend = stack.backend_for(model._replace(law=Elastic(params.K, params.G)),
                                unbounded_wells(model.iface_dofs.shape[0]))
    unit_target = 2.0 * params.eps0 * np.asarray(mesh.layer_mid_height, dtype=np.float64)
    backend.set_state(np.zeros(model.ndof), unit_target, params.eps0, 0.0)
    relaxation.equilibrate_linear(backend)
    u, eps = backend.read("u", "eps")
    scale = autoscale(narrowest_well(interface_initstate(params.seed, mesh.N, mesh.n_interfaces), params.nchunk,
                                     params.eps0, params.eps_offset, params.weibull_k,
                                     element_scale(params.interface_strength, mesh.N, mesh.n_interfaces)), eps)
    lever = scale * params.eps0 if model.free_lever else 0.0
    return LinearResponse(scale * u, scale * eps, scale * unit_target, float(lever))
