"""The rigidity ratio Phi = K / K_s of a stack: drive springs against the shear rigidity of a plate.

The paper defines ``Phi = K / K_s`` with ``K`` the rigidity of a drive spring and
``K_s = A G / h`` the shear rigidity of a slab (``A`` the interface area, ``h`` the slab
height, ``G`` its shear modulus, which is ``mu = G_fe / 2`` in the FE units where the
solver's ``G`` is ``2 mu``). For its model it states ``A = n_x l0``, ``K_s = 4 G``,
``K = 1e-3`` and ``1e-6``, ``G = 1/2``: ``Phi = k_drive / (4 mu) = 5e-4`` and ``5e-7``
("Phi ~ 1e-3 / 1e-6"), taking the solver's ``k_drive`` (a stiffness per unit volume)
for ``K`` and its plates' height ``h = N l0 / 4`` (the mesh's target ``M = N / 4``
blocks, :func:`stickslip.mesh.rows.plate_target_height`).

That reading holds at the paper's N = 1458 only. The spring on a plate of height
``h_p`` and length ``L`` has rigidity ``k_drive L h_p`` (force per displacement, unit
thickness) and the plate shears with ``mu L / h_p``: the dimensionless ratio is
``k_drive h_p^2 / mu``, which grows as ``h_p^2`` at fixed ``k_drive``. This module
carries the paper's Phi to other N with that law::

    Phi = k_drive / (4 mu) * (M / M_paper)^2,   M = max(3, N // 4),  M_paper = 364 (N = 1458)

so runs at different N with equal Phi drive their plates alike, and at N = 1458 Phi
is the paper's number. The consistent ratio is ``k_drive h_p^2 / mu =
Phi * 4 (M_paper h)^2`` (``h = pi``): 5.2e6 Phi.
"""

import math

from ..mesh.rows import plate_target_height

__all__ = ["PAPER_N", "PAPER_PHI", "PHI_STIFF", "stiffness_ratio", "driving_regime", "at_paper_phi"]

#: Blocks per interface of the paper's simulations (2 x 3^6).
PAPER_N = 1458

#: Phi of the paper's two runs (k_drive = 1e-3 and 1e-6 at N = 1458): "Phi ~ 1e-3 / 1e-6".
PAPER_PHI = {"stiff": 5e-4, "compliant": 5e-7}

#: Phi separating "stiff" from "compliant" driving: the geometric mean of the paper's two
#: runs (5e-4 and 5e-7 at N = 1458).
PHI_STIFF = math.sqrt(5e-4 * 5e-7)


def stiffness_ratio(k_drive, N, G=1.0):
    """The rigidity ratio ``Phi = k_drive / (4 mu) (M / M_paper)^2`` of a run (module doc).

    Parameters
    ----------
    k_drive : float
        Drive spring stiffness per unit volume [G / h^2, FE units].
    N : int
        Blocks per interface.
    G : float, optional
        The solver's shear-like modulus ``G = 2 mu`` [stress].

    Returns
    -------
    float
        Phi [1]; 5.0e-4 for the paper's stiff run (k_drive = 1e-3, N = 1458, G = 1).
    """
    scale = plate_target_height(int(N)) / plate_target_height(PAPER_N)
    return float(k_drive) / (4.0 * (float(G) / 2.0)) * scale**2


def driving_regime(phi):
    """``"stiff"`` if ``phi >= PHI_STIFF`` (1.6e-5), else ``"compliant"``."""
    return "stiff" if phi >= PHI_STIFF else "compliant"


def at_paper_phi(phi):
    """Whether ``phi`` is one of the paper's two values, within a factor sqrt(10) (half a decade)."""
    return any(abs(math.log10(phi / value)) <= 0.5 for value in PAPER_PHI.values())
