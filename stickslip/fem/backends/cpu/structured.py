"""Backend ``structured`` (the default): the plates' product by periodic stencils over node lines.

The plan and kernels of the stencil product are in :mod:`.stencils`; this module makes
them a plate operator of a CPU backend, serial or in parallel blocks (the same bits).
"""

from collections import namedtuple

import numpy as np
from numba import prange

from ....numba_options import njit
from .plates import register_plate_operator
from .stencils import apply_groups, build_stencils, gather_views, plan_blocks, plan_product, plate_product
from ..base import register_backend
from .backend import CpuBackend

__all__ = ["StructuredBackend", "StencilPlates"]


@njit(parallel=True)
def _product_parallel(view_blocks, group_blocks, views, groups, triplet_ptr, triplet_view, triplet_coef, empty, work,
                      u, f):
    # plain arrays: numba loses writes to named-tuple fields inside prange
    for b in prange(view_blocks.size - 1):
        gather_views(views, view_blocks[b], view_blocks[b + 1], u, work[0], work[1])
    for b in prange(group_blocks.size - 1):
        apply_groups(groups, triplet_ptr, triplet_view, triplet_coef, group_blocks[b], group_blocks[b + 1],
                     work[0], work[1], work[2], work[3], f)
    for i in empty:
        f[i] = 0.0


@njit(inline="always")
def _product(plates, nblock, u, f):
    p = plates
    if nblock > 1:
        _product_parallel(p.view_blocks, p.group_blocks, p.views, p.groups, p.triplet_ptr, p.triplet_view,
                          p.triplet_coef, p.empty, p.work, u, f)
    else:
        plate_product(p.views, p.groups, p.triplet_ptr, p.triplet_view, p.triplet_coef, p.empty, p.work, u, f)


@register_plate_operator
class StencilPlates(namedtuple("StencilPlates", [
        "views", "groups", "triplet_ptr", "triplet_view", "triplet_coef",  # :class:`.stencils.PlatePlan` arrays
        "empty",         # int64 [nempty]: DOFs with an empty plate row
        "work",          # float64 [4, nwork]: scratch (views x, y; rows x, y)
        "view_blocks",   # int64 [nblock + 1]: view ranges of the parallel blocks (balanced)
        "group_blocks",  # int64 [nblock + 1]: group ranges of the parallel blocks (balanced)
])):
    """The stencil plan of the plates' stiffness (:func:`.stencils.plan_product`)."""

    __slots__ = ()
    product = staticmethod(_product)


@register_backend
class StructuredBackend(CpuBackend):
    """Numba CPU kernels with the plates' stencil product (6x the CSR product at N = 1458)."""

    name = "structured"
    summary = "numba CPU kernels, plates by periodic stencils over node lines (default)"

    def plate_operator(self, model, mesh, nblock):
        plan = plan_product(build_stencils(mesh, model.k_ptr, model.k_col, model.k_val), model.ndof)
        view_blocks, group_blocks = plan_blocks(plan, nblock)
        return StencilPlates(views=plan.views, groups=plan.groups, triplet_ptr=plan.triplet_ptr,
                             triplet_view=plan.triplet_view, triplet_coef=plan.triplet_coef, empty=plan.empty_dofs,
                             work=np.zeros((4, max(plan.view_size, plan.output_size))), view_blocks=view_blocks,
                             group_blocks=group_blocks)
