"""The kernels' arguments as named records: what a launch is, the batch's state, its minimisations' control.

Every kernel takes a few of these records (and the law) instead of long positional lists: numba
passes a named tuple of arrays and scalars to a kernel as its fields, and the kernels read
``state.u``, ``control.tol``. The same records are built from host arrays to compile the kernels
without a device (:mod:`.compile`).
"""

from collections import namedtuple

__all__ = ["Launch", "State", "Control", "STATE_FIELDS", "CHECKPOINT_FIELDS"]

#: One launch: the realisations (``members`` int64 [count], their slots), the blocks of each (``groups``), at most
#: ``nsteps`` time steps, the barrier's ``deadline`` [clock cycles], the time step ``dt``, whether the drive is a free
#: lever, and whether a force evaluation moves Gauss points to the well of their strain (``update_wells``).
Launch = namedtuple("Launch", ["members", "groups", "nsteps", "deadline", "dt", "free_lever", "update_wells"])

#: The state of a batch of ``B`` realisations (device arrays): ``u`` float64 [B, 2, ndof] (two buffers: the state
#: in buffer 0 between minimisations, the step's parity during one), ``v``, ``a``, ``f`` [B, ndof], ``idx`` int64
#: [B, ni, 4], ``eps``, ``sig`` [B, ni, 4, 3], ``target``, ``ubar`` [B, nlayer], ``lever`` [B, 2], ``clock`` [B],
#: the held yield strains ``epsy`` [B, ni, width] and their count ``ny`` int64 [B], ``k_drive`` [B], the load
#: direction (``delta_u`` [B, ndof], ``delta_target`` [B, nlayer], ``delta_lever`` [B]), the tiles' sums
#: ``partials`` [B, 2, ntile, 2 + nlayer] and flags ``flags`` int64 [B, 2, ntile, 3] (by the parity of a step),
#: ``previous`` int64 [B, ni] (the recorded well of Gauss point 0), and a result per realisation (``scalar``
#: float64 [B], ``flag`` int64 [B]).
State = namedtuple("State", ["u", "v", "a", "f", "idx", "eps", "sig", "target", "ubar", "lever", "clock", "epsy",
                             "ny", "k_drive", "delta_u", "delta_target", "delta_lever", "partials", "flags",
                             "previous", "scalar", "flag"])

#: The minimisations of a batch (device arrays, one entry per realisation): the criteria (``tol`` float64,
#: ``niter_tol``, ``max_iter``, ``margin``, ``quiet``, ``record`` int64), and what persists between launches:
#: ``done`` (time steps made), ``judged`` (1: step ``done`` was judged), ``status``, ``needed`` (event rows a
#: step needs when the buffer was full), ``runs`` int64 [B, 4] (consecutive steps below ``tol``, below
#: ``tol^2``, non-increasing, without a well change), ``last`` float64 (the last residual), ``nevent``,
#: ``events`` float64 [B, capacity, 3], and the barrier's ``counter`` int32.
Control = namedtuple("Control", ["tol", "niter_tol", "max_iter", "margin", "quiet", "record", "done", "judged",
                                 "status", "needed", "runs", "last", "nevent", "events", "counter"])

#: The fields of :class:`State` that :meth:`..base.Backend.read` names (``t`` is ``clock``).
STATE_FIELDS = {"u": "u", "v": "v", "a": "a", "f": "f", "idx": "idx", "eps": "eps", "sig": "sig",
                "target": "target", "ubar": "ubar", "lever": "lever", "t": "clock"}

#: What a checkpoint copies.
CHECKPOINT_FIELDS = ("u", "v", "a", "f", "idx", "eps", "sig", "target", "ubar", "lever", "clock")
