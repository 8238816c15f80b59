"""What a ``fem`` run needs in memory at least, refused before the run starts where the machine has less.

The parameters that set the size of a run (``N``, ``plates``, the wells held per block, ``window`` or ``nchunk``,
and the minimisation's ``niter_tol``) are bounded by the memory of the machine rather than by a physical limit:
:func:`check_run_memory` estimates what the run's largest arrays take (a lower bound: what the run certainly
allocates) and refuses a run that needs more than a process of this machine can have, with the estimate, as a
writer refuses a disk without room (:func:`stickslip.output_safety.space.check_free_space`).
"""

from ..machine_memory import process_memory, size_text
from ..plugin_params import ParameterError

__all__ = ["run_memory", "check_run_memory", "NODES_PER_BLOCK", "NODE_BYTES"]

#: Nodes of the stack's mesh per block and interface, at least (the mesh has 11 N (plates - 1) nodes within 10 %
#: for N >= 54, :func:`stickslip.mesh.build_stack_mesh`).
NODES_PER_BLOCK = 10

#: Bytes of the state of one node, at least: coordinates, displacement, velocity, acceleration, forces, mass and
#: damping (2 dofs each, float64) and its share of the elements' connectivity and Gauss-point strains.
NODE_BYTES = 256


def run_memory(params):
    """The memory a run of ``params`` takes at least, by what takes it [B].

    Parameters
    ----------
    params : stickslip.fem.parameters.FemParams

    Returns
    -------
    dict[str, float]
        ``yield strains`` (the wells held per block: ``window`` + 1 with ``yield_strains`` 'extend', ``nchunk`` + 1
        with 'stop', float64), ``mesh and state`` (:data:`NODES_PER_BLOCK` nodes of :data:`NODE_BYTES` per block)
        and ``residual history`` (``niter_tol`` float64).
    """
    blocks = float(params.N) * (params.plates - 1)
    wells = params.window if params.yield_strains == "extend" else params.nchunk
    return {"yield strains": blocks * (wells + 1) * 8.0, "mesh and state": blocks * NODES_PER_BLOCK * NODE_BYTES,
            "residual history": params.niter_tol * 8.0}


def check_run_memory(params):
    """Raise ParameterError if a run of ``params`` needs more memory than a process of this machine can have.

    Raises
    ------
    stickslip.plugin_params.ParameterError
        Naming the parameters, the estimate (:func:`run_memory`) and the machine's memory
        (:func:`stickslip.machine_memory.process_memory`).
    """
    needed = run_memory(params)
    total, have = sum(needed.values()), process_memory()
    if total > have:
        largest = max(needed, key=needed.get)
        which = {"yield strains": "N, plates and " + ("window" if params.yield_strains == "extend" else "nchunk"),
                 "mesh and state": "N and plates", "residual history": "niter_tol"}[largest]
        raise ParameterError(f"parameters {which}: the run needs at least {size_text(total)} of memory ("
                             f"{largest}: {size_text(needed[largest])}), more than this machine gives a process "
                             f"({size_text(have)}); expected smaller values")
