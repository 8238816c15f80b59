"""Errors of the public API that say what went wrong, in the standard library's words.

Each is also a :class:`stickslip.h5io.FileFormatError` (a ``ValueError``), as the API raised before, so
that code catching those keeps working, and the command line prints it as one line.
"""

from .h5io import FileFormatError

__all__ = ["StudyNotFoundError", "RunNotFoundError", "IncrementError", "SolverError"]


class StudyNotFoundError(FileFormatError, FileNotFoundError):
    """A study has neither results nor a config where it was looked for (the message says where)."""


class RunNotFoundError(FileFormatError, LookupError):
    """A study's database holds no simulation of that run id."""


class IncrementError(FileFormatError, IndexError):
    """An increment that a run file does not store (the message gives the stored range)."""


class SolverError(RuntimeError):
    """A solver cannot go on with the run its parameters describe (no convergence, no yielding step found, an
    integration that failed); the message says why, in one line. The command line prints it as a user's error
    (exit status 2): the parameters asked for a run the method cannot make."""
