"""A model's mesh on the device: the layout of :mod:`.layout`, copied once and shared by batches."""

import numpy as np
from numba import cuda

from .layout import build_layout

__all__ = ["DeviceMesh"]

#: The model's fields that batches sharing a device mesh must have equal (the operators, the drive).
_SHARED_FIELDS = ("ndof", "k_ptr", "k_col", "k_val", "mass_inv", "damping", "prescribed", "multiplicity",
                  "iface_dofs", "iface_dNdx", "iface_dV", "layer_ptr", "layer_xdofs", "layer_w", "layer_volume",
                  "drive_active", "free_lever", "lever_ratio", "dt")


class DeviceMesh:
    """The layout of a model on its mesh, on the device (``layout``: a :class:`.layout.Layout` of device arrays).

    Parameters
    ----------
    model : stickslip.fem.model.Model
    mesh : stickslip.mesh.LayeredMesh
        The mesh the model was built from (its node lines give the stencils).
    place : callable, optional
        Puts a host array where the kernels read it (default ``numba.cuda.to_device``; a host copy for
        compiling without a device, :mod:`.compile`).
    """

    def __init__(self, model, mesh, place=cuda.to_device):
        self.place = place
        self.host = build_layout(model, mesh)
        self.layout = self.host._replace(**{name: place(np.ascontiguousarray(value))
                                            for name, value in self.host._asdict().items()
                                            if isinstance(value, np.ndarray)})
        self.model = model
        self.dt = float(model.dt)
        self.free_lever = bool(model.free_lever)

    def serves(self, model):
        """True if ``model`` has this mesh, these operators, this time step and this drive."""
        return all(np.array_equal(getattr(model, name), getattr(self.model, name)) for name in _SHARED_FIELDS)
