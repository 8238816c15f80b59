"""Solver ``fem``: the paper's finite-element model (shared/reference-model.md), one run per file.

Parameters: :class:`stickslip.fem.parameters.FemParams` (every field documented
with its unit; ``stickslip plugins --params`` lists them). The mesh is read from
``inputs["mesh"]`` (a file of :func:`stickslip.mesh.write_mesh`) when given, else
built from ``N`` and ``plates``. The output file (format ``fem-run``, :mod:`stickslip.formats.fem_run`)
is appended after every increment; an existing incomplete file with the same
parameters is resumed, a completed one is left as it is. Runs with ``backend = cuda`` share a GPU in
batches (:data:`GPU_BATCHING`, the solver's ``device_batch``). A run chooses its interface law and its
backend by name (:data:`CHOICES`): its code hash covers those two and no other
(:func:`stickslip.provenance.code.plugin_code_hash`).
"""

from .. import registry
from ..fem.backends import BACKENDS, make_backend
from ..fem.laws import INTERFACE_LAWS
from ..fem.memory import check_run_memory
from ..fem.parameters import FemParams
from ..fem.replay import EventReplay
from ..fem.run import simulate_to_file
from ..h5io import FileFormatError
from ..mesh import MeshParams, build_stack_mesh, read_mesh

__all__ = ["FemParams", "run", "stack_mesh", "can_run", "VERSION", "GPU_BATCHING", "GPU_BACKEND", "CHOICES"]

#: Algorithm version (part of every run id); bump when results change.
VERSION = "4"  # 4: exact relaxation by QDLDL and fixed-order loops (host-independent bits); 3: stencil passes three entries at a time (round-off); 2: structured plate kernel, relaxation, dt_scale


def stack_mesh(params, inputs):
    """The mesh of a run: the ``mesh`` input if given (checked against ``N`` and ``plates``), else built.

    Parameters
    ----------
    params : FemParams
    inputs : Mapping[str, os.PathLike] or None
        The solver's inputs by format; ``"mesh"``, if present, is a mesh file.

    Returns
    -------
    stickslip.mesh.LayeredMesh

    Raises
    ------
    FileFormatError
        If the mesh file's ``N`` or ``plates`` differ from the parameters.
    """
    path = (inputs or {}).get("mesh")
    if path is None:
        return build_stack_mesh(MeshParams(N=params.N, plates=params.plates))
    mesh = read_mesh(path)
    if (mesh.N, mesh.plates) != (params.N, params.plates):
        raise FileFormatError(f"{path}: mesh has N = {mesh.N}, plates = {mesh.plates}; the run needs "
                              f"N = {params.N}, plates = {params.plates}")
    return mesh


def can_run(params):
    """Raise :class:`stickslip.plugin_params.ParameterError` if this machine cannot run ``params.backend`` (e.g. no GPU)
    or has less memory than the run needs (:func:`stickslip.fem.memory.check_run_memory`)."""
    check_run_memory(params)
    make_backend(params.backend)


#: The backend of the runs on a GPU (they share it in batches, :data:`GPU_BATCHING`).
GPU_BACKEND = "cuda"


def on_gpu(params):
    """Whether a run of ``params`` (a defaults-filled dict) runs on a GPU: ``backend = cuda``."""
    return params.get("backend") == GPU_BACKEND


def run_on_gpu(runs):
    """Run a GPU batch: its runs together on the device (the ``cuda`` backend's ``run_ensemble``)."""
    return BACKENDS[GPU_BACKEND].run_ensemble(runs)


#: Runs on a GPU in batches: what one batch shares (the device mesh, its operators, the law, the time step, the
#: drive); they may differ in every other parameter (seed, drive stiffness, protocol, temperature, ...).
GPU_BATCHING = registry.DeviceBatching(
    on_device=on_gpu,
    shared=("N", "plates", "K", "G", "rho", "dt_scale", "drive", "lever_height", "interface_law", "law_params"),
    run=run_on_gpu)

#: What a run chooses by name: its interface law and its backend.
CHOICES = (registry.Choice("interface_law", INTERFACE_LAWS), registry.Choice("backend", BACKENDS))


@registry.register("solver", "fem", VERSION, FemParams, consumes=("mesh",), produces="fem-run", replay=EventReplay,
                   preflight=can_run, device_batch=GPU_BATCHING, choices=CHOICES)
def run(params, output, *, threads=1, inputs=None, backend=None):
    """Finite-element model of the stack: event-driven quasistatic drive, inertial dynamics.

    ``backend``: a backend object of ``params.backend`` to run on (a GPU batch's,
    :func:`stickslip.workflow_api.run_simulation_batch`); default: a new one.
    """
    simulate_to_file(params, output, stack_mesh(params, inputs), backend or make_backend(params.backend, threads),
                   producer=("fem", VERSION))
