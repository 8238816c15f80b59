"""A thermally activated hop: one block carried over its barrier, a perturbation of the stack.

The barrier of a block (:mod:`.barriers`) is the energy to shear it over the edge of its well with
its surroundings held fixed. The hop does that (:class:`ShearHop`): the block's shear mode (its
upper nodes moved by ``+s/2`` in x, its lower nodes by ``-s/2``; a uniform simple shear
``eps_xy = s / (2 h)`` of the block) is applied with the smallest ``|s|`` that carries every one
of its four Gauss points a strain ``deps / 2`` past the edge (the athermal kick's overshoot). The
thermal protocol then relaxes the stack as after a kick
(:meth:`..protocol.EventLoop.perturb_and_relax`: the relaxation of the run, an avalanche may
follow), and rolls back to the state before the hop if every well index came back (the block fell back
into its well: the true barrier of the move is higher than the constant-load one). The amplitude is found on
the host from the block's strain at the event (one read of the interface strains; its wells are those the draw
saw, :class:`..host_copies.HostCopies`); whether the shear carried the block over is counted where the state is.
"""

import math

import numpy as np

from ...numba_options import njit
from ..errors import SolverError
from ..quad4 import element_strain
from .barriers import FORWARD

__all__ = ["shear_modes", "hop_step", "ShearHop"]


def shear_modes(mesh):
    """The shear mode of every interface block: ``+1/2`` on the x DOFs of its upper nodes, ``-1/2`` on its lower ones.

    Parameters
    ----------
    mesh : stickslip.mesh.LayeredMesh

    Returns
    -------
    numpy.ndarray
        float64 [ni, 8], element DOF order (node-major, x then y), rows in ``interface_elements`` order.
    """
    elements = np.asarray(mesh.interface_elements, dtype=np.int64).ravel()
    y = np.asarray(mesh.coor, dtype=np.float64)[np.asarray(mesh.conn, dtype=np.int64)[elements], 1]  # [ni, 4]
    modes = np.zeros((elements.size, 8))
    modes[:, 0::2] = np.where(y > y.mean(axis=1, keepdims=True), 0.5, -0.5)
    return modes


@njit
def hop_step(dNdx, mode, eps, epsy, idx, direction, overshoot):
    """Amplitude ``s`` of the shear mode that carries all four Gauss points of one block over an edge.

    Parameters
    ----------
    dNdx : numpy.ndarray
        [4, 4, 2] the block's shape-function gradients.
    mode : numpy.ndarray
        [8] its shear mode (:func:`shear_modes`).
    eps : numpy.ndarray
        [4, 3] its strain now.
    epsy : numpy.ndarray
        [ny] its yield strains.
    idx : numpy.ndarray
        int64 [4] the wells of its Gauss points.
    direction : int
        :data:`.barriers.FORWARD` (over ``hi``) or backward (over ``lo``).
    overshoot : float
        Strain beyond the edge that every Gauss point reaches (the kick's ``deps / 2``).

    Returns
    -------
    float
        ``s`` [length]; NaN if the mode cannot carry every Gauss point over (the block's shear
        does not move all of them towards the edge).
    """
    d = np.empty((4, 3))
    element_strain(dNdx, mode, d)
    slope = 0.0
    for q in range(4):
        slope += 0.5 * (eps[q, 0] - eps[q, 1]) * 0.5 * (d[q, 0] - d[q, 1]) + eps[q, 2] * d[q, 2]
    sigma = 1.0 if slope >= 0.0 else -1.0  # the sign of s that raises the block's eps_eq
    step = 0.0
    for q in range(4):
        if direction == FORWARD:
            target = epsy[idx[q] + 1] + overshoot
        else:
            target = epsy[idx[q]] - overshoot
        et = 0.5 * (eps[q, 0] - eps[q, 1])
        gt = eps[q, 2]
        ed = 0.5 * (d[q, 0] - d[q, 1])
        gd = d[q, 2]
        a = ed * ed + gd * gd
        b = 2.0 * (et * ed + gt * gd)
        c = et * et + gt * gt - target * target
        disc = b * b - 4.0 * a * c
        if a == 0.0 or disc < 0.0:
            return math.nan
        # forward: the root on the side that raises eps_eq; backward: the nearer root on the other side
        s = (-b + sigma * math.sqrt(disc)) / (2.0 * a)
        if (direction == FORWARD) != (s * sigma > 0.0):
            return math.nan
        if abs(s) > abs(step):
            step = s
    return step


class ShearHop:
    """The hop of one block over an edge of its well, by its shear mode: a perturbation of the stack.

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
        At rest.
    model : stickslip.fem.model.Model
        The stack's model (its interface elements).
    modes : numpy.ndarray
        [ni, 8] :func:`shear_modes`.
    block : int
        Interface element.
    direction : int
        :data:`.barriers.FORWARD` or backward.
    overshoot : float
        Strain beyond the edge that every Gauss point of the block reaches (the kick's ``deps / 2``).
    start : stickslip.fem.stack.Checkpoint
        A checkpoint of the stack as it is (whenever :meth:`apply` is called, the stack is at it).

    Attributes
    ----------
    amplitude : float
        ``s`` of the shear mode from the state at ``start`` [length] (:func:`hop_step`; NaN: impossible).
    """

    def __init__(self, stack, model, modes, block, direction, overshoot, start):
        self.stack = stack
        self.model = model
        self.mode = modes[block]
        self.block = block
        self.start = start
        eps, idx = stack.read("eps", "idx")
        self.amplitude = hop_step(model.iface_dNdx[block], self.mode, eps[block], stack.yield_strains[block],
                                  idx[block], direction, overshoot)

    def apply(self):
        """Shear the block over its edge.

        Raises
        ------
        SolverError
            If the shear did not move every Gauss point of the block to another well (a bug, not physics).
        """
        b = self.block
        self.stack.add_u(self.model.iface_dofs[b], self.amplitude * self.mode)
        if self.stack.changed_since(self.start, elements=np.array([b])) != 4:
            raise SolverError(f"hop of block {b}: the kick of {self.amplitude:.6e} did not carry all its Gauss points "
                              "over the edge")
