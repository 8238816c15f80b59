"""Constants of a run that follow from its parameters and its mesh."""

import math

import numpy as np

__all__ = ["derived_constants"]


def derived_constants(params, mesh):
    """Constants that follow from the parameters and the mesh.

    Parameters
    ----------
    params : FemParams
    mesh : stickslip.mesh.LayeredMesh

    Returns
    -------
    dict
        ``h`` (block size), ``L`` (periodic length), ``c`` = sqrt(G / rho), ``c_s`` = sqrt(G / 2 / rho)
        (shear-wave speed), ``alpha`` = sqrt(2) (2 pi / L) c rho (critical damping of
        the shear wave of wavelength L), ``dt`` = ``dt_scale`` h / (2 pi c) / 10, ``sig0`` = 2 G eps0,
        ``deps`` (kick, strain), ``H`` (free-lever drive height), ``quiet_steps`` (the
        exact relaxation's quiet window in time steps: ``params.quiet_steps``, or if that
        is 0 the shear-wave transit time over a third of the interface, ``L / (3 c_s)``,
        rounded up to whole steps).
    """
    h = float(mesh.h)
    L = mesh.N * h
    c = math.sqrt(params.G / params.rho)
    c_s = math.sqrt(params.G / 2.0 / params.rho)
    dt = params.dt_scale * (1.0 / (c * 2.0 * math.pi / h)) / 10.0
    heights = np.asarray(mesh.layer_mid_height, dtype=np.float64)
    return {
        "h": h, "L": L, "c": c, "c_s": c_s,
        "alpha": math.sqrt(2.0) * (2.0 * math.pi / L) * c * params.rho,
        "dt": dt,
        "quiet_steps": params.quiet_steps or math.ceil(L / (3.0 * c_s) / dt),
        "sig0": 2.0 * params.G * params.eps0,
        "deps": params.deps * params.eps0,
        "H": params.lever_height * float(heights[1] - heights[0]),
    }
