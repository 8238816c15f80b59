"""The error of an output that cannot be written."""

import os

__all__ = ["OutputError"]


class OutputError(OSError):
    """An output file cannot be written (full disk, no permission, read-only file system); the message says which.

    Parameters
    ----------
    path : str or pathlib.Path
        The output file.
    code : int
        The ``errno`` of the failure.
    reason : str, optional
        The message after ``<path>: ``; default ``cannot write it (<strerror of code>)``.
    """

    def __init__(self, path, code, reason=None):
        super().__init__(f"{path}: {reason or f'cannot write it ({os.strerror(code)})'}")
        self.errno = code
