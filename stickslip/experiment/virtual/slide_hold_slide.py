"""Slide-hold-slide on one rate-and-state interface: how much a hold heals it, the twin's true aging rate.

The lab measures aging by slide-hold-slide: slide at a steady speed, stop the drive for a hold ``T``, slide again;
the peak friction on the restart rises by the aging rate ``B`` per e-fold of ``T``. :func:`hold_healing` does that on
interface 1 of a law (slab 1 driven alone, everything above riding on it) with a stiff spring (``stiffness`` times
the critical one), so that the interface slides steadily before the hold and the peak is the interface's, not a
stick-slip cycle's. Under the aging law the peak rises by ``b`` per e-fold; under the slip law only by the creep in
the hold (:mod:`.rate_state`).
"""

import numpy as np

from .apparatus import Apparatus
from .slab_dynamics import SlabDynamics

__all__ = ["hold_healing"]


def hold_healing(law, *, holds=(10.0, 100.0, 1000.0), stiffness=100.0, V=0.1, normal_force=49.0, h=10.0, H=100.0,
                 slide=20.0, slab_mass=0.143, load_mass=5.0):
    """The peak friction after holds of interface 1 of ``law``, and its rise per e-fold of the hold.

    Parameters
    ----------
    law : RateStateLaw
        One value per slab; interface 1's are used.
    holds : Sequence[float]
        Hold times [s], at least two.
    stiffness : float
        The spring's stiffness over the interface's critical stiffness ``N (b - a) / D_c`` (> 1: steady sliding).
    V : float
        The lever's speed (the apparatus's ``V``) [mm/s]; the spring moves at ``h V / H``.
    normal_force, h, H : float
        The apparatus's normal force [N], slab height and lever height [mm].
    slide : float
        Sliding before each hold and after it [s].
    slab_mass, load_mass : float
        [kg].

    Returns
    -------
    dict
        ``holds`` (shape (k,)), ``peaks`` (the largest friction coefficient after each hold, shape (k,)),
        ``states`` (``psi`` at the end of each hold minus before it, shape (k,)), ``rate`` (the least-squares slope
        of the peaks against ``ln(hold)``: the healing per e-fold).
    """
    k_spring = stiffness * float(law.critical_stiffness(normal_force)[0])
    apparatus = Apparatus.from_protocol("individual", n=1, a=1, n_slabs=len(law.a), k_spring=k_spring,
                                        normal_force=normal_force, h=h, H=H, V=V, gamma_start=0.0)
    dynamics = SlabDynamics(apparatus, law, slab_mass, load_mass)
    spring_speed = h * apparatus.shear_rate
    _, y0 = dynamics.initial_state(spring_speed, law.D_c[0] / spring_speed, 0.0)
    _, y, _ = dynamics.integrate(y0, slide, apparatus.shear_rate)
    sliding = y[-1]
    peaks, states = [], []
    for hold in holds:
        _, held, _ = dynamics.integrate(sliding, hold, 0.0)
        _, again, _ = dynamics.integrate(held[-1], slide, apparatus.shear_rate)
        peaks.append(again[:, 1].max())
        states.append(held[-1, 2] - sliding[2])
    holds, peaks = np.asarray(holds, dtype=float), np.asarray(peaks)
    logs = np.log(holds) - np.log(holds).mean()
    return {"holds": holds, "peaks": peaks, "states": np.asarray(states),
            "rate": float(np.sum(logs * (peaks - peaks.mean())) / np.sum(logs**2))}
