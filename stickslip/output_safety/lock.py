"""One writer per file: an exclusive lock that a killed process releases."""

import fcntl
from contextlib import contextmanager
from pathlib import Path

from ..h5io import FileFormatError

__all__ = ["writer_lock"]


@contextmanager
def writer_lock(path):
    """Hold an exclusive lock on writing ``path`` (released when the process ends, even if killed).

    The lock is the hidden file ``.<name>.lock`` beside ``path``, removed on exit.

    Parameters
    ----------
    path : str or pathlib.Path

    Raises
    ------
    FileFormatError
        If another process holds the lock.
    """
    path = Path(path)
    lock = path.parent / f".{path.name}.lock"
    with open(lock, "a") as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FileFormatError(f"{path}: another process is writing it (lock {lock})") from None
        try:
            yield
        finally:
            lock.unlink(missing_ok=True)
