"""The state arrays of a CPU backend, as one named tuple that the numba kernels take whole."""

from collections import namedtuple

import numpy as np

__all__ = ["State", "new_state"]

State = namedtuple("State", [
    "u", "v", "a",    # float64 [ndof]: displacement [length], velocity, acceleration
    "f",              # float64 [ndof]: internal force (material + drive, no damping) [force]
    "idx",            # int64 [ni, 4]: current well per interface Gauss point
    "eps", "sig",     # float64 [ni, 4, 3]: interface strain (xx, yy, xy) and stress
    "target",         # float64 [nlayer]: drive target of ubar_x per layer [length]
    "ubar",           # float64 [nlayer]: volume-averaged x-displacement per layer [length]
    "lever",          # float64 [2]: (drive target x_target, lever position x_lever) at height H [length]
    "t",              # float64 [1]: time [time]
    "epsy",           # float64 [ni, ny]: the held yield strains [strain] (replaced, never changed in place)
])


def new_state(model, epsy):
    """A state at rest holding the yield strains ``epsy`` [ni, ny]: zero displacement, velocity, targets and time
    (forces not yet evaluated).

    Parameters
    ----------
    model : stickslip.fem.model.Model
    epsy : numpy.ndarray
        float64 [ni, ny], kept (not copied).

    Returns
    -------
    State
    """
    ni = model.iface_dofs.shape[0]
    nlayer = model.layer_volume.size
    return State(u=np.zeros(model.ndof), v=np.zeros(model.ndof), a=np.zeros(model.ndof), f=np.zeros(model.ndof),
                 idx=np.zeros((ni, 4), dtype=np.int64), eps=np.zeros((ni, 4, 3)), sig=np.zeros((ni, 4, 3)),
                 target=np.zeros(nlayer), ubar=np.zeros(nlayer), lever=np.zeros(2), t=np.zeros(1), epsy=epsy)

