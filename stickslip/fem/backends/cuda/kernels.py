"""The device kernels of the ``cuda`` backend, compiled per law class.

:func:`kernels_for` builds them from the plain work items (:mod:`.items`), the synchronisation
(:mod:`.sync`), the tile work (:mod:`.tiles`) and the minimisation kernel (:mod:`.minimise`). Every kernel
takes named records (:mod:`.records`): ``launch`` (which realisations, how), ``mesh`` (the layout of
:mod:`.layout` on the device), ``state`` and ``control``. Besides ``minimise``, the kernels here act on
the listed realisations with one block per (realisation, tile), or one per realisation; none waits for
another block (a kernel's end is the barrier between two of them):

- ``prime``: before a minimisation, every tile's predicted displacement ``u_1`` (buffer 1) and its
  layers' averages (the partials of parity 0) — the state a launch of ``minimise`` starts from;
- ``layer_sums``, ``evaluate``: a force evaluation of the state as it is (the layers' averages first,
  then every tile's elements and nodes and its residual terms, partials of parity 1);
- ``residual_rows``: the residual's terms of the state as it is (partials of parity 1);
- ``residual``: one block per realisation sums the partials of parity 1 into its relative residual;
- ``wells_hold``, ``load``, ``add_u``, ``shift_wells``, ``zero_motion``: small element- or DOF-wise updates.
"""

import functools
from types import SimpleNamespace

import numpy as np
from numba import config, cuda, float64, int32, int64

from ...laws import LAWS
from . import items as items_module, minimise as minimise_module, resident as resident_module, sync as sync_module
from . import tiles as tiles_module
from .layout import LEAVES, MAX_LAYERS, MAX_TILE, MAX_TILE_ELEMENTS, MAX_TILE_TRIPLETS
from .minimise import ROWS
from .tiles import LAYER_ROW

__all__ = ["kernels_for", "KERNELS", "MAX_REGISTERS", "MINIMISERS"]

#: Every kernel of :func:`kernels_for`: the two minimisation kernels (:mod:`.minimise`, the default, and
#: :mod:`.resident`), then the small ones.
KERNELS = ("minimise", "resident", "prime", "layer_sums", "evaluate", "residual_rows", "residual", "wells_hold", "load",
           "add_u", "shift_wells", "zero_motion")

#: Registers per thread of the minimisation kernels at most (two blocks of 128 threads and more fit an SM).
MAX_REGISTERS = 128

#: The minimisation kernels by the name a backend chooses them with (``CudaBackend(kernel=...)``).
MINIMISERS = {"tiles": "minimise", "resident": "resident"}

if not hasattr(np, "row_stack"):
    # numba-cuda 0.30.4 overloads np.row_stack when its numpy support loads (at the first compilation); NumPy 2.5
    # removed that alias of np.vstack, and the compilation then fails (seen on the GPU machine's numpy 2.5.2)
    np.row_stack = np.vstack


def _device(function):
    return cuda.jit(device=True, inline="always")(function)


def _placed(launch, ntile):
    """(realisation, tile) of the calling block in a launch of one block per (listed realisation, tile)."""
    return launch.members[cuda.blockIdx.x // ntile], cuda.blockIdx.x % ntile


def _small_kernels(device, items, sync, tiles, drive):
    """The kernels besides ``minimise`` (module docstring), as plain functions."""
    placed, equivalent, well, tile_sums = device(_placed), items.equivalent, items.well, sync.tile_sums
    load_stencils, elements, publish = tiles.load_stencils, tiles.elements, tiles.publish
    state_rows, force_nodes = tiles.state_rows, tiles.force_nodes

    def prime(launch, mesh, state):
        m, k = placed(launch, mesh.ntile)
        rows = cuda.shared.array((ROWS, MAX_TILE), float64)
        nrows = LAYER_ROW + mesh.nlayer
        t, bd = cuda.threadIdx.x, cuda.blockDim.x
        state_rows(mesh, k, m, state.u[m, 0], state.u[m, 1], state, launch.dt, True, rows, nrows, t, bd)
        publish(rows, nrows, mesh.tile, state.partials[m, 0, k], t, bd)
        for j in range(t, 3, bd):
            state.flags[m, 0, k, j] = 0

    def layer_sums(launch, mesh, state):
        m, k = placed(launch, mesh.ntile)
        rows = cuda.shared.array((ROWS, MAX_TILE), float64)
        nrows = LAYER_ROW + mesh.nlayer
        t, bd = cuda.threadIdx.x, cuda.blockDim.x
        state_rows(mesh, k, m, state.u[m, 0], state.u[m, 0], state, launch.dt, False, rows, nrows, t, bd)
        publish(rows, nrows, mesh.tile, state.partials[m, 0, k], t, bd)

    def evaluate(law, launch, mesh, state):
        m, k = placed(launch, mesh.ntile)
        rows = cuda.shared.array((ROWS, MAX_TILE), float64)
        leaves = cuda.shared.array((ROWS, LEAVES), float64)
        coef = cuda.shared.array((MAX_TILE_TRIPLETS, 12), float64)
        target = cuda.shared.array((MAX_TILE_TRIPLETS, 3, 4), int32)
        fe = cuda.shared.array((MAX_TILE_ELEMENTS, 8), float64)
        drive_out = cuda.shared.array((4, MAX_LAYERS), float64)
        flags = cuda.shared.array(3, int64)
        ue = cuda.local.array(8, float64)
        strain = cuda.local.array((4, 3), float64)
        t, bd = cuda.threadIdx.x, cuda.blockDim.x
        tile_sums(state.partials[m, 0], mesh.ntile, LAYER_ROW, mesh.nlayer, leaves, t, bd)
        drive(launch, mesh, state, m, leaves, drive_out)
        load_stencils(mesh, k, coef, target, t, bd)
        elements(law, mesh, k, state.u[m, 0], state, m, fe, flags, launch.update_wells, state.ny[m] + 1, False,
                 True, t, bd, ue, strain)
        force_nodes(mesh, k, m, state.u[m, 0], state, coef, target, fe, drive_out[1], rows, t, bd)
        publish(rows, LAYER_ROW, mesh.tile, state.partials[m, 1, k], t, bd)
        if k == 0 and t == 0:
            for layer in range(mesh.nlayer):
                state.ubar[m, layer] = drive_out[0, layer]
                state.target[m, layer] = drive_out[2, layer]
            state.lever[m, 1] = drive_out[3, 0]

    def residual_rows(launch, mesh, state):
        m, k = placed(launch, mesh.ntile)
        rows = cuda.shared.array((ROWS, MAX_TILE), float64)
        t, bd = cuda.threadIdx.x, cuda.blockDim.x
        state_rows(mesh, k, m, state.u[m, 0], state.u[m, 0], state, launch.dt, False, rows, LAYER_ROW, t, bd)
        publish(rows, LAYER_ROW, mesh.tile, state.partials[m, 1, k], t, bd)

    def residual(launch, mesh, state):
        m = launch.members[cuda.blockIdx.x]
        leaves = cuda.shared.array((ROWS, LEAVES), float64)
        tile_sums(state.partials[m, 1], mesh.ntile, 0, LAYER_ROW, leaves, cuda.threadIdx.x, cuda.blockDim.x)
        if cuda.threadIdx.x == 0:
            res, ext = leaves[0, 0], leaves[1, 0]
            state.scalar[m] = (res / ext) ** 0.5 if ext > 0.0 else res ** 0.5

    def wells_hold(launch, mesh, state):
        """``state.flag[m]`` = 0 if some Gauss point of realisation ``m`` lies outside its held well."""
        m = launch.members[cuda.blockIdx.x]
        for item in range(cuda.threadIdx.x, mesh.ni * 4, cuda.blockDim.x):
            e, q = item // 4, item % 4
            i = state.idx[m, e, q]
            x = equivalent(state.eps[m, e, q, 0], state.eps[m, e, q, 1], state.eps[m, e, q, 2])
            if well(state.epsy[m, e, :state.ny[m]], x, i) != i:
                state.flag[m] = 0

    def load(launch, mesh, state, step):
        """Move every listed realisation by ``step`` times its load direction."""
        m = launch.members[cuda.blockIdx.x]
        for d in range(cuda.threadIdx.x, mesh.ndof, cuda.blockDim.x):
            state.u[m, 0, d] += step * state.delta_u[m, d]
        for layer in range(cuda.threadIdx.x, mesh.nlayer, cuda.blockDim.x):
            state.target[m, layer] += step * state.delta_target[m, layer]
        if cuda.threadIdx.x == 0:
            state.lever[m, 0] += step * state.delta_lever[m]

    def add_u(m, dofs, delta, state):
        """``u[m, dofs] += delta`` (distinct DOFs)."""
        i = cuda.grid(1)
        if i < dofs.size:
            state.u[m, 0, dofs[i]] += delta[i]

    def shift_wells(m, shift, state):
        """Renumber the held wells of realisation ``m``: ``idx[m, e] -= shift[e]``."""
        e = cuda.grid(1)
        if e < shift.size:
            for q in range(4):
                state.idx[m, e, q] -= shift[e]

    def zero_motion(m, state):
        """Stop realisation ``m``: ``v = a = 0``."""
        d = cuda.grid(1)
        if d < state.v.shape[1]:
            state.v[m, d] = 0.0
            state.a[m, d] = 0.0

    return dict(prime=prime, layer_sums=layer_sums, evaluate=evaluate, residual_rows=residual_rows, residual=residual,
                wells_hold=wells_hold, load=load, add_u=add_u, shift_wells=shift_wells, zero_motion=zero_motion)


def python_kernels(law_class, device=_device):
    """Every kernel for laws of class ``law_class`` as a plain function (for :func:`numba.cuda.jit` or
    :func:`numba.cuda.compile`), by name (:data:`KERNELS`)."""
    items = items_module.build(device, law_class)
    sync = sync_module.build(device)
    tiles = tiles_module.build(device, items, sync)
    step = minimise_module.build(device, items, sync, tiles)
    return {"minimise": step.minimise, "resident": resident_module.build(device, items, sync, tiles, step),
            **_small_kernels(device, items, sync, tiles, step.drive)}


@functools.lru_cache(maxsize=None)
def kernels_for(law_name):
    """The kernels for laws named ``law_name`` (compiled on first launch; cached per law).

    Returns
    -------
    types.SimpleNamespace
        One :func:`numba.cuda.jit` kernel per name of :data:`KERNELS`; the minimisation kernels with at most
        :data:`MAX_REGISTERS` registers per thread.
    """
    python = python_kernels(LAWS[law_name])
    capped = {} if config.ENABLE_CUDASIM else {"max_registers": MAX_REGISTERS}  # the simulator has no registers
    compiled = {name: cuda.jit(function, **(capped if name in MINIMISERS.values() else {}))
                for name, function in python.items()}
    return SimpleNamespace(**compiled)
