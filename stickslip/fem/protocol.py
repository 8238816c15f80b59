"""The protocol of a run: one event-driven loop whose named hooks decide which perturbation comes next.

A protocol drives a stack (:class:`.stack.Stack`) one stored increment at a time for the increment
loop of :mod:`.run`; increments alternate, a load then an event, as in the paper. :class:`EventLoop`
is that loop, once for every protocol; a protocol overrides its hooks, not the loop (as FrictionQPotFEM's
thermal class does):

``next_event(margin, increment)``
    brings the stack to the next event (a load increment) and remembers it as ``pending``; returns the
    increment's columns, or None if the run must stop at the margin;
``perform(pending, margin)``
    performs that event (the event increment): a perturbation, then the relaxation
    (:meth:`EventLoop.perturb_and_relax`); returns the increment's columns, or None at the margin;
``after_event(margin, increment)``
    what follows every event (junction aging renews the junctions).

Its other interface, for the increment loop:

``columns``
    dict name -> numpy dtype of the columns it adds to the increment table;
``header``
    dict of the root attributes it adds to the run file;
``state_fields``
    dict name -> (shape, dtype) of further state it stores per increment beside the stack's
    displacement, drive and time (the fifth item of :meth:`.stack.Stack.stored`, e.g. the junctions);
``initial_row()``
    its columns for increment 0;
``step(event, margin, increment)``
    the loop: the next increment (number ``increment``), a load (``event`` False) or an event (True), its
    columns with ``yield_element``;
``stored(row)``
    is told the row just appended (e.g. to start a hold after a slip).

:class:`AthermalProtocol` is the paper's: the athermal threshold is the only source of events and the event
is the kick. :class:`.thermal.ThermalProtocol` (``temperature > 0``) draws its events from composed event
sources (:mod:`.thermal.sources`) and keeps the physical time (:mod:`.clock`).
"""

import numpy as np

from .loading import KickAlongResponse

__all__ = ["EventLoop", "AthermalProtocol"]


class EventLoop:
    """The event-driven loop of every protocol (module docstring): a load to the next event, then that event.

    Parameters
    ----------
    stack : stickslip.fem.stack.Stack
    loading : stickslip.fem.loading.Loading
        Steps along the stack's linear response.
    relaxation : stickslip.fem.relaxation.DynamicRelaxation or stickslip.fem.relaxation.ExactRelaxation
        How a perturbed stack comes to rest.

    Attributes
    ----------
    pending : object or None
        The event a load increment ended at, what :meth:`perform` is given next (None: none, or the athermal
        protocol's, whose event is always the kick).
    """

    columns = {}
    header = {}
    state_fields = {}

    def __init__(self, stack, loading, relaxation):
        self.stack = stack
        self.loading = loading
        self.relaxation = relaxation
        self.pending = None

    @staticmethod
    def initial_row():
        """No columns of its own."""
        return {}

    def step(self, event, margin, increment):
        """The next increment: :meth:`next_event` (a load), or :meth:`perform` the pending event and
        :meth:`after_event` (an event)."""
        if not event:
            return self.next_event(margin, increment)
        pending, self.pending = self.pending, None
        row = self.perform(pending, margin)
        if row is not None:
            self.after_event(margin, increment)
        return row

    def next_event(self, margin, increment):
        """Hook: bring the stack to the next event, set :attr:`pending`; the load increment's columns (None: stop)."""
        raise NotImplementedError

    def perform(self, pending, margin):
        """Hook: perform the event ``pending``; the event increment's columns (None: stopped by the margin)."""
        raise NotImplementedError

    def after_event(self, margin, increment):
        """Hook: what follows every event (nothing here)."""

    def stored(self, row):
        """Told the row just appended (nothing to remember here)."""

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


class AthermalProtocol(EventLoop):
    """The paper's protocol: elastic load steps to the brink of yielding (the athermal threshold) alternate with
    kicks and relaxations. Parameters as :class:`EventLoop`."""

    def next_event(self, margin, increment):
        """Load to the brink of yielding (:meth:`.loading.Loading.step`); None if a Gauss point is within ``margin``."""
        self.loading.step(False)
        if not self.stack.extend and not self.stack.within_margin(margin):
            return None
        return {"yield_element": False}

    def perform(self, pending, margin):
        """Kick and relax (:meth:`EventLoop.kick`); ``pending`` is None (the event is always the kick)."""
        converged, yield_element = self.kick(margin)
        return {"yield_element": yield_element} if converged else None
