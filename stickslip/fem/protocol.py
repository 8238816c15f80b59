"""The protocol of a run: what sequence of loads, kicks and relaxations makes its increments.

A protocol drives a stack (:class:`.stack.Stack`) one stored increment at a time for the increment
loop of :mod:`.run`. Its interface:

``columns``
    dict name -> numpy dtype of the columns it adds to the increment table;
``header``
    dict of the root attributes it adds to the run file;
``state_fields``
    dict name -> (shape, dtype) of further state it stores per increment beside the stack's
    displacement, drive and clock (the fifth item of :meth:`.stack.Stack.stored`, e.g. the junctions);
``initial_row()``
    its columns for increment 0;
``step(event, margin, increment)``
    makes the next increment (number ``increment``), a load (``event`` False) or an event (True), and returns its
    columns with ``yield_element``, or None if the run must stop at the margin;
``stored(row)``
    is told the row just appended (e.g. to start a hold after a slip).

:class:`AthermalProtocol` is the paper's event-driven quasistatic protocol; its
:meth:`AthermalProtocol.perturb_and_relax` serves any perturbation (its own kick, a thermal hop);
:class:`.thermal.ThermalProtocol` (``temperature > 0``) overrides the steps and keeps the rest.
"""

import numpy as np

from .loading import KickAlongResponse

__all__ = ["AthermalProtocol"]


class AthermalProtocol:
    """The paper's protocol: elastic load steps to the brink of yielding alternate with kicks and relaxations.

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
    loading : stickslip.fem.loading.Loading
        Steps along the stack's linear response.
    relaxation : stickslip.fem.relaxation.DynamicRelaxation
        How a kicked stack comes to rest.
    """

    columns = {}
    header = {}
    state_fields = {}

    def __init__(self, stack, loading, relaxation):
        self.stack = stack
        self.loading = loading
        self.relaxation = relaxation

    @staticmethod
    def initial_row():
        """No columns of its own."""
        return {}

    def step(self, event, margin, increment):
        """Load to the brink (:meth:`.loading.Loading.step`) or kick and relax (:meth:`kick`)."""
        if event:
            converged, yield_element = self.kick(margin)
            return {"yield_element": yield_element} if converged else None
        self.loading.step(False)
        if not self.stack.extend and not self.stack.within_margin(margin):
            return None
        return {"yield_element": False}

    def stored(self, row):
        """Nothing to remember."""

    def perturb_and_relax(self, perturbation, margin, record=False):
        """Perturb the stack and relax it; with ``extend``, redone until the held wells suffice.

        The stack relaxes (:meth:`.stack.Stack.relax`: with ``extend`` the wells are then held ahead).
        With ``yield_strains = extend``, a relaxation that comes within ``margin`` wells of the end
        of the held wells is discarded: the state before the perturbation is restored, the windows
        are widened (doubled) and the perturbation redone, which gives the state a longer sequence
        held from the start would give.

        Parameters
        ----------
        perturbation
            An object whose ``apply()`` changes the state (the kick along the linear response,
            :class:`.loading.KickAlongResponse`; a thermally activated hop, :class:`.thermal.hop.ShearHop`);
            applied again after every restore.
        margin : int
            See :meth:`.relaxation.DynamicRelaxation.relax`.
        record : bool, optional
            Record the well changes of Gauss point 0, the perturbation's own included (at its time).

        Returns
        -------
        niter : int
            Time steps made (0: stopped by the margin, ``stop`` only).
        events : numpy.ndarray
            [nevent, 3] (element, time, direction) when ``record``.
        """
        stack = self.stack
        before = stack.stored()
        while True:
            token = stack.watch()
            perturbation.apply()
            kicked = stack.well_changes(token)[:, 0]
            niter, events = stack.relax(self.relaxation, margin, record)
            if niter or not stack.extend:
                break
            stack.restore(*before)
            stack.widen_wells()
        if record:
            rows = [(e, before[3], np.sign(kicked[e])) for e in np.flatnonzero(kicked) for _ in range(abs(kicked[e]))]
            events = np.concatenate([np.asarray(rows, dtype=np.float64).reshape(-1, 3), events])
        return niter, events

    def kick(self, margin):
        """Kick and relax (an event increment), with the whole-element fallback.

        :meth:`perturb_and_relax` with the kick along the linear response; if the relaxation ends
        with no well index changed (the kicked point fell back), the state before the kick is
        restored and the kick redone so that all Gauss points of one element yield
        (``yield_element``).

        Parameters
        ----------
        margin : int
            Stop when a Gauss point comes within this many wells of the end of its sequence.

        Returns
        -------
        converged : bool
            False if stopped by the margin (``yield_strains = stop`` only).
        yield_element : bool
            Whether the whole-element kick was needed.
        """
        stack = self.stack
        before = stack.stored()
        token = stack.watch()
        niter, _ = self.perturb_and_relax(KickAlongResponse(self.loading, False), margin)
        fallback = niter != 0 and not stack.moved(token)
        if fallback:
            stack.restore(*before)
            niter, _ = self.perturb_and_relax(KickAlongResponse(self.loading, True), margin)
        return niter != 0, fallback
