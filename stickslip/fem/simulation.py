"""One run's objects, composed from its parameters: the stack, its relaxation, the loading and the protocol.

Each object has one job and is passed to those that use it (:mod:`.stack`, :mod:`.relaxation`,
:mod:`.loading`, :mod:`.protocol`, :mod:`.thermal`); :class:`Simulation` only builds them in order,
for the increment loop (:mod:`.run`), the event replay (:mod:`.replay`), tests and benchmarks.
"""

from .constants import derived_constants
from .linear_response import LinearResponse, compute_linear_response
from .loading import Loading
from .protocol import AthermalProtocol
from .relaxation import make_relaxation
from .stack import Stack, stack_model
from .thermal import thermal_protocol

__all__ = ["Simulation", "make_protocol"]


def make_protocol(simulation, table=None):
    """The protocol of a simulation's parameters: athermal, or thermal for ``temperature > 0`` (with junction aging
    if ``junction_strengthening > 0``).

    Parameters
    ----------
    simulation : Simulation
    table : Mapping[str, numpy.ndarray], optional
        The stored increment table's columns (a resumed run; None for a new one).
    """
    s = simulation
    if s.params.temperature > 0.0:
        return thermal_protocol(s.stack, s.model, s.loading, s.relaxation, s.params, s.mesh, s.constants, table)
    return AthermalProtocol(s.stack, s.loading, s.relaxation, table)


class Simulation:
    """The composed objects of one run, the stack at rest at the origin.

    Parameters
    ----------
    params : FemParams
    mesh : stickslip.mesh.LayeredMesh
    backend : stickslip.fem.backends.base.Backend
        Not yet prepared (:func:`.backends.make_backend`); must be the one ``params.backend`` names
        for results under the run's id.
    response : LinearResponse or tuple, optional
        A stored linear response; None: computed (:func:`.linear_response.compute_linear_response`).
    table : Mapping[str, numpy.ndarray], optional
        The stored increment table of a resumed run (for the protocol).

    Attributes
    ----------
    params, mesh
    constants : dict
        :func:`.constants.derived_constants`.
    model : stickslip.fem.model.Model
        The stack's model (its yield strains those at the origin; :attr:`.stack.Stack.yield_strains` the held ones).
    backend : stickslip.fem.backends.base.Backend
        The prepared backend, for backend-level tests and benchmarks only: the package reads and changes the state
        through ``stack``.
    stack : stickslip.fem.stack.Stack
    relaxation : stickslip.fem.relaxation.DynamicRelaxation
    loading : stickslip.fem.loading.Loading
    protocol : stickslip.fem.protocol.EventLoop
        :class:`.protocol.AthermalProtocol` or a thermal protocol (:func:`.thermal.thermal_protocol`).
    """

    def __init__(self, params, mesh, backend, response=None, table=None):
        self.params = params
        self.mesh = mesh
        self.constants = derived_constants(params, mesh)
        self.model, wells = stack_model(params, mesh, self.constants)
        self.backend = backend.prepare(self.model, mesh, wells.epsy)
        self.stack = Stack(self.backend, wells, params.yield_strains == "extend")
        self.relaxation = make_relaxation(params, self.constants, self.model)
        if response is None:
            response = compute_linear_response(self.stack, self.model, self.relaxation, params, mesh)
        self.loading = Loading(self.stack, self.model, LinearResponse(*response), self.constants["deps"])
        self.protocol = make_protocol(self, table)
