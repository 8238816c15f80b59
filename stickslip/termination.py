"""Ctrl-C and SIGTERM end a process at any moment, as a ``KeyboardInterrupt`` that closes open files on its way out.

A cluster ends a job at its wall time, ``scancel`` and Snakemake end jobs with
SIGTERM, whose default action kills the process at once. Raised as an exception
instead, it unwinds the ``with`` blocks, so files are closed (and temporary
files removed) exactly as after Ctrl-C. An interrupt that arrives while compiled
(numba) code calls back into Python comes out wrapped in a ``SystemError``;
:func:`interruption` finds it.

Python raises the exception of a signal where the main thread is. If that is a
finaliser (a ``__del__`` method, a ``weakref`` callback), the exception cannot
propagate: Python prints "Exception ignored in ..." and goes on, and the signal is
lost. While numba compiles, llvmlite's finalisers run all the time, so Ctrl-C
during a job's compilation (10-60 s per job on a cold cache) was often swallowed
and the job ran on to its end. Within :func:`interrupts_raised` a signal that finds
the main thread in a finaliser is delivered again as soon as the finaliser has
returned (:data:`REDELIVERY_DELAY`), and an interrupt that a finaliser swallowed
anyway is delivered again too (``sys.unraisablehook``).
"""

import _thread
import signal
import sys
import threading
import time
import weakref
from contextlib import contextmanager

__all__ = ["interrupts_raised", "raise_interrupt_on_sigterm", "Terminated", "interruption", "exit_status",
           "REDELIVERY_DELAY"]

#: Seconds after which a signal that found the main thread in a finaliser is delivered again.
REDELIVERY_DELAY = 0.01

#: Signals that :func:`interrupts_raised` turns into exceptions.
_SIGNALS = (signal.SIGINT, signal.SIGTERM)


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


def _in_finaliser(frame):
    """Whether ``frame`` runs inside a finaliser, where a raised exception would be printed and ignored."""
    while frame is not None:
        code = frame.f_code
        if code.co_name == "__del__" or code.co_filename == weakref.__file__ or code is _HOOK_CODE:
            return True
        frame = frame.f_back
    return False


def _deliver_later(signum):
    """Make ``signum`` arrive again in the main thread after :data:`REDELIVERY_DELAY` seconds."""
    def deliver():
        time.sleep(REDELIVERY_DELAY)
        _thread.interrupt_main(signum)

    threading.Thread(target=deliver, name=f"redeliver-{signal.Signals(signum).name}", daemon=True).start()


def _raise(signum, frame):
    """The handler of SIGINT and SIGTERM within :func:`interrupts_raised`."""
    if _in_finaliser(frame):
        _deliver_later(signum)
        return
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signum)


def _unraisable_hook(previous):
    """A ``sys.unraisablehook`` that delivers a swallowed interrupt again and passes anything else to ``previous``."""
    def hook(unraisable):
        interrupt = unraisable.exc_value
        if isinstance(interrupt, KeyboardInterrupt):
            _deliver_later(getattr(interrupt, "signum", signal.SIGINT))
        else:
            previous(unraisable)

    return hook


#: The code of every hook of :func:`_unraisable_hook` (a signal that finds it running waits for it to return).
_HOOK_CODE = _unraisable_hook(None).__code__


@contextmanager
def interrupts_raised():
    """Within the block, SIGINT and SIGTERM raise a ``KeyboardInterrupt`` in the main thread, whenever they come.

    SIGINT raises a plain ``KeyboardInterrupt``, SIGTERM a :class:`Terminated`. A signal
    that arrives while a finaliser runs is raised once it has returned. The previous
    handlers come back after the block. Main thread only.
    """
    previous = {signum: signal.signal(signum, _raise) for signum in _SIGNALS}
    previous_hook, sys.unraisablehook = sys.unraisablehook, _unraisable_hook(sys.unraisablehook)
    try:
        yield
    finally:
        sys.unraisablehook = previous_hook
        for signum, handler in previous.items():
            signal.signal(signum, handler)
