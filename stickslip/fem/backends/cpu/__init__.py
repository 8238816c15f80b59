"""The numba CPU backends: ``structured`` (stencil plate kernels, the default) and ``assembled`` (CSR, the reference).

Modules: :mod:`.state` (the state arrays), :mod:`.backend` (:class:`.backend.CpuBackend`, what
both share), the kernels :mod:`.forces`, :mod:`.interface_elements`, :mod:`.dynamics`,
:mod:`.minimise`, the plate operators :mod:`.plates`, :mod:`.stencils` (the stencil plan),
:mod:`.structured` and :mod:`.assembled`.
"""

from .assembled import AssembledBackend
from .backend import CpuBackend
from .structured import StructuredBackend

__all__ = ["AssembledBackend", "CpuBackend", "StructuredBackend"]
