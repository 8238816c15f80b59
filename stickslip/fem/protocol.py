"""The protocol of a run: one event-driven loop whose named hooks decide which perturbation comes next.

A protocol drives a stack (:class:`.stack.Stack`) one stored increment at a time for the increment
loop of :mod:`.run`; increments alternate, a load then an event, as in the paper, and the protocol knows which
comes next (:meth:`EventLoop.step`). :class:`EventLoop`
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
    displacement, drive and time (:attr:`.formats.fem_run.StoredState.further`, e.g. the junctions);
``initial_row()``
    its columns for increment 0;
``step(margin, increment)``
    the loop: the next increment (number ``increment``), a load or an event, whichever is next, its
    columns with ``kick`` (True: the event) and ``yield_element``;
``stored(row)``
    is told the row just appended (e.g. to start a hold after a slip).

Going back (a relaxation redone with more wells held, the whole-element fallback of a kick, a hop that fell back)
returns to a checkpoint (:meth:`.stack.Stack.checkpoint`), kept where the state is: a device backend's state does
not come to the host for it.

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
    table : Mapping[str, numpy.ndarray], optional
        The stored increment table's columns (a resumed run: its last ``kick`` tells what comes next); None: the
        stack is at rest after an event (increment 0, a stored event, a hold's start), a load comes next.

    Attributes
    ----------
    pending : object or None
        The event a load increment ended at, what :meth:`perform` is given next (None: none, or the athermal
        protocol's, whose event is always the kick).
    event_next : bool
        Whether the next increment is an event (else a load).
    """

    columns = {}
    header = {}
    state_fields = {}

    def __init__(self, stack, loading, relaxation, table=None):
        self.stack = stack
        self.loading = loading
        self.relaxation = relaxation
        self.pending = None
        self.event_next = table is not None and not bool(np.asarray(table["kick"])[-1])

    @staticmethod
    def initial_row():
        """No columns of its own."""
        return {}

    def step(self, margin, increment):
        """The next increment, number ``increment``: :meth:`next_event` (a load), or :meth:`perform` the pending event
        and :meth:`after_event` (an event), whichever is next; its columns with ``kick`` (True: the event), None if
        the run must stop at the margin."""
        event, self.event_next = self.event_next, not self.event_next
        if event:
            pending, self.pending = self.pending, None
            row = self.perform(pending, margin)
            if row is not None:
                self.after_event(margin, increment)
        else:
            row = self.next_event(margin, increment)
        return None if row is None else {"kick": event, **row}

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

    def perturb_and_relax(self, perturbation, margin, record=False, before=None, ahead=True):
        """Perturb the stack and relax it; with ``extend``, redone until the held wells suffice.

        The stack relaxes (:meth:`.stack.Stack.relax`: with ``extend`` and ``ahead`` the wells are then held ahead).
        With ``yield_strains = extend``, a relaxation that comes within ``margin`` wells of the end
        of the held wells is discarded: the stack rolls back to its checkpoint before the perturbation, the windows
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
        before : stickslip.fem.stack.Checkpoint, optional
            A checkpoint of the stack as it is (default: one is made).
        ahead : bool, optional
            False: the windows are not moved after the relaxation (:meth:`.stack.Stack.relax`).

        Returns
        -------
        niter : int
            Time steps made (0: stopped by the margin, ``stop`` only).
        events : numpy.ndarray
            [nevent, 3] (element, time, direction) when ``record``.
        """
        stack = self.stack
        before = stack.checkpoint() if before is None else before
        start, t0 = (stack.well_index()[:, 0], stack.time) if record else (None, None)
        while True:
            perturbation.apply()
            kicked = stack.well_index()[:, 0] - start if record else None
            niter, events = stack.relax(self.relaxation, margin, record, ahead)
            if niter or not stack.extend:
                break
            stack.rollback(before)
            stack.widen_wells()
        if record:
            rows = [(e, t0, np.sign(kicked[e])) for e in np.flatnonzero(kicked) for _ in range(abs(kicked[e]))]
            events = np.concatenate([np.asarray(rows, dtype=np.float64).reshape(-1, 3), events])
        return niter, events

    def kick(self, margin):
        """Kick and relax (an event increment), with the whole-element fallback.

        :meth:`perturb_and_relax` with the kick along the linear response; if the relaxation ends
        with no well index changed (the kicked point fell back), the stack rolls back to the state before the kick
        and the kick is redone so that all Gauss points of one element yield (``yield_element``).

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
        before = stack.checkpoint()
        niter, _ = self.perturb_and_relax(KickAlongResponse(self.loading, False), margin, before=before)
        fallback = niter != 0 and not stack.changed_since(before)
        if fallback:
            stack.rollback(before)
            niter, _ = self.perturb_and_relax(KickAlongResponse(self.loading, True), margin, before=before)
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
