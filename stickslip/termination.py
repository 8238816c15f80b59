"""SIGTERM ends a process as Ctrl-C does: a ``KeyboardInterrupt`` that closes open files on its way out.

A cluster ends a job at its wall time, ``scancel`` and Snakemake end jobs with
SIGTERM, whose default action kills the process at once. Raised as an exception
instead, it unwinds the ``with`` blocks, so files are closed (and temporary
files removed) exactly as after Ctrl-C. An interrupt that arrives while compiled
(numba) code calls back into Python comes out wrapped in a ``SystemError``;
:func:`interruption` finds it.
"""

import signal
from contextlib import contextmanager

__all__ = ["sigterm_as_interrupt", "raise_interrupt_on_sigterm", "Terminated", "interruption", "exit_status"]


class Terminated(KeyboardInterrupt):
    """A termination signal, raised where the program was (``signum``: the signal's number)."""

    def __init__(self, signum):
        super().__init__(f"terminated by {signal.Signals(signum).name}")
        self.signum = signum


def _interrupt(signum, frame):
    raise Terminated(signum)


def interruption(error):
    """The ``KeyboardInterrupt`` that ``error`` is, or was caused by; None if there is none."""
    while error is not None:
        if isinstance(error, KeyboardInterrupt):
            return error
        error = error.__cause__ or error.__context__
    return None


def exit_status(interrupt):
    """The shell's exit status of a process ended by ``interrupt``: 128 + signal number (130: SIGINT)."""
    return 128 + getattr(interrupt, "signum", signal.SIGINT)


def raise_interrupt_on_sigterm():
    """From now on SIGTERM raises :class:`Terminated` (a ``KeyboardInterrupt``) in the main thread.

    Returns
    -------
    The previous SIGTERM handler.
    """
    return signal.signal(signal.SIGTERM, _interrupt)


@contextmanager
def sigterm_as_interrupt():
    """Within the block, SIGTERM raises ``KeyboardInterrupt`` (main thread only); the old handler comes back after."""
    previous = raise_interrupt_on_sigterm()
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
