"""What a ``fem`` run needs in memory, refused before the run starts where the machine has less.

The parameters that set the size of a run (``N``, ``plates``, the wells held per block, ``window`` or ``nchunk``,
and the minimisation's ``niter_tol``) are bounded by the memory of the machine rather than by a physical limit:
:func:`check_run_memory` estimates the run's peak resident memory and refuses a run that needs more than a process
of this machine can have, with the estimate, as a writer refuses a disk without room
(:func:`stickslip.output_safety.space.check_free_space`).

The peak of a run is when its model is assembled (:func:`stickslip.fem.model.build_model`): the yield strains are
held, and the plates' stiffness is assembled from the element arrays (:func:`stickslip.fem.assembly.assemble_csr`);
what the run holds afterwards (the model, the backend's state, the observables) is less than those temporaries.
The estimate counts those arrays from the code, plus what the process holds already (the interpreter, numpy, numba)
and what loading the compiled kernels adds (measured, :data:`KERNEL_BYTES`); it is a lower bound, 6-14 % under the
peak measured at N = 9 to 1458 on three machines (docs/fem.md).
"""

from ..machine_memory import process_memory, resident_memory, size_text
from ..plugin_params import ParameterError

__all__ = ["run_memory", "check_run_memory", "ELEMENTS_PER_BLOCK", "MESH_BYTES", "ELEMENT_ARRAY_BYTES",
           "ASSEMBLY_ENTRY_BYTES", "ENTRIES_PER_ELEMENT", "KERNEL_BYTES"]

#: Bytes the run's process takes beyond what it holds at the preflight and the arrays counted here, at least: the
#: numba kernels loaded from the cache (their machine code and LLVM's state), the HDF5 writer, the scratch of the
#: first increment. Measured, not counted: peak less the other terms was 168-173 MB at N = 486 (plates 3) and
#: N = 1458 (plates 2) on one 2-core VM, 144-152 MB at N = 9 to 486 on a 2-core AMD EPYC and 150 MB at N = 486
#: (plates 3) on the CI machine (``benchmarks/fem_memory.py``, docs/fem.md): it differs with the machine (the code
#: compiled for its CPU), so the bound keeps some 15 % under the least of those.
KERNEL_BYTES = 120e6

#: Elements (and nodes) of the stack's mesh per block and interface, at least: 11 N (plates - 1) less one row
#: (10.8 at N = 486, 10.95 at N = 1458, :func:`stickslip.mesh.build_stack_mesh`).
ELEMENTS_PER_BLOCK = 10.75

#: Bytes the mesh holds per element and node: ``coor`` (2 float64) and ``dofs`` (2 int64) of a node, ``conn``
#: (4 int64) and ``elem_layer`` (int64) of an element (:class:`stickslip.mesh.LayeredMesh`).
MESH_BYTES = 16 + 16 + 32 + 8

#: Bytes per element of the arrays alive while the stiffness is assembled (:func:`stickslip.fem.model.build_model`):
#: ``Ke`` (float64 [8, 8]), ``dNdx`` (float64 [4, 4, 2]), ``dV`` (float64 [4]), ``xe`` (float64 [4, 2]),
#: ``edofs`` (int64 [8]) and ``conn`` (int64 [4]).
ELEMENT_ARRAY_BYTES = 512 + 256 + 32 + 64 + 64 + 32

#: Entries of an element's stiffness in the assembly (8 x 8).
ENTRIES_PER_ELEMENT = 64

#: Bytes per entry alive at once at the peak of :func:`stickslip.fem.assembly.assemble_csr`: ``rows``, ``cols``,
#: ``key``, its sorted copy, ``order`` and the sorted values (int64 or float64 each), and the stable sort's merge
#: buffer (half an int64).
ASSEMBLY_ENTRY_BYTES = 6 * 8 + 4


def run_memory(params):
    """The peak memory of a run of ``params``, by what takes it [B].

    Parameters
    ----------
    params : stickslip.fem.parameters.FemParams

    Returns
    -------
    dict[str, float]
        ``process`` (what this process holds now, :func:`stickslip.machine_memory.resident_memory`), ``kernels``
        (:data:`KERNEL_BYTES`),
        ``yield strains`` (the wells held per block: ``window`` + 1 with ``yield_strains`` 'extend', ``nchunk`` + 1
        with 'stop', float64), ``mesh`` (:data:`MESH_BYTES` per element), ``stiffness assembly``
        (:data:`ELEMENT_ARRAY_BYTES` and :data:`ENTRIES_PER_ELEMENT` entries of :data:`ASSEMBLY_ENTRY_BYTES` per
        element) and ``residual history`` (``niter_tol`` float64); :data:`ELEMENTS_PER_BLOCK` elements per block.
    """
    blocks = float(params.N) * (params.plates - 1)
    elements = blocks * ELEMENTS_PER_BLOCK
    wells = params.window if params.yield_strains == "extend" else params.nchunk
    return {"process": float(resident_memory()), "kernels": KERNEL_BYTES, "yield strains": blocks * (wells + 1) * 8.0,
            "mesh": elements * MESH_BYTES,
            "stiffness assembly": elements * (ELEMENT_ARRAY_BYTES + ENTRIES_PER_ELEMENT * ASSEMBLY_ENTRY_BYTES),
            "residual history": params.niter_tol * 8.0}


#: The parameters that set each term of :func:`run_memory` (the refusal names those of the largest).
_SET_BY = {"mesh": "N and plates", "stiffness assembly": "N and plates", "residual history": "niter_tol"}


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
        largest = max((term for term in needed if term not in ("process", "kernels")), key=needed.get)
        which = _SET_BY.get(largest, "N, plates and " + ("window" if params.yield_strains == "extend" else "nchunk"))
        raise ParameterError(f"parameters {which}: the run needs at least {size_text(total)} of memory ("
                             f"{largest}: {size_text(needed[largest])}), more than this machine gives a process "
                             f"({size_text(have)}); expected smaller values")
