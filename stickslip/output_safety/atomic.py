"""Atomic outputs: a file appears complete under its name, or not at all.

:func:`atomic_output` writes under a temporary name beside the output and renames it into place on
success; an interrupted or failing writer leaves the previous file (or none), and temporaries left by
killed processes are removed by the next writer. :func:`check_output` fails at once, before a long
computation, if the output cannot be written.
"""

import errno
import fcntl
import os
import re
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .errors import OutputError

__all__ = ["atomic_output", "check_output"]

#: errno values that mean "the output cannot be written", reported as :class:`OutputError`.
_WRITE_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOENT,
                 errno.ENOTDIR, errno.EISDIR)


@contextmanager
def atomic_output(path):
    """Write a file under a temporary name and rename it into place on success.

    An interrupted or failing writer leaves the previous file (or none) intact, and
    no temporary file. The temporary file ``.<name>.<random>.tmp`` is locked
    (``flock``) while it is written; temporaries of ``path`` that no live process
    holds (left by a process that was killed) are removed first.

    Parameters
    ----------
    path : str or pathlib.Path
        Final path.

    Yields
    ------
    pathlib.Path
        Temporary path in the same directory, to write to.

    Raises
    ------
    OutputError
        If the file cannot be written (full disk, no permission, read-only file
        system, ``path`` a directory); the message names ``path`` and the cause.
    """
    path = Path(path)
    with _output_errors(path):
        _make_directory(path)
        _remove_stale_temporaries(path)
        fd, tmp = _locked_temporary(path)
    umask = os.umask(0)
    os.umask(umask)
    try:
        with _output_errors(path):
            yield tmp
            if tmp.exists():  # mkstemp makes it private; the result gets the usual permissions
                os.chmod(tmp, 0o666 & ~umask)
            os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
        os.close(fd)


def check_output(path):
    """Raise now if ``path`` cannot be written, before a long computation would find it out.

    Makes the missing directories and a temporary file beside ``path`` (removed again).

    Parameters
    ----------
    path : str or pathlib.Path

    Raises
    ------
    OutputError
        If ``path`` is a directory, or its directory cannot be made or written to.
    """
    path = Path(path)
    with _output_errors(path):
        _make_directory(path)
        fd, tmp = _locked_temporary(path)
        tmp.unlink()
        os.close(fd)


def _make_directory(path):
    """Make the directory of the output file ``path`` (IsADirectoryError if ``path`` is one)."""
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:  # a file where a directory should be
        raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR)) from None


@contextmanager
def _output_errors(path):
    """Turn an OSError of writing into :class:`OutputError` naming ``path``."""
    try:
        yield
    except OSError as error:
        if error.errno not in _WRITE_ERRNOS:
            raise
        raise OutputError(path, error.errno) from error


def _temporary_name(path):
    """Pattern of the names :func:`tempfile.mkstemp` gives the temporaries of ``path``."""
    return re.compile(rf"\.{re.escape(path.name)}\.[a-z0-9_]{{8}}\.tmp")


def _locked_temporary(path):
    """Create a temporary file beside ``path`` and lock it; return (descriptor, path).

    The lock is taken after the file appears, so :func:`_remove_stale_temporaries`
    of another process may lock and remove it in between; it is then made again.
    """
    while True:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        fcntl.flock(fd, fcntl.LOCK_EX)
        if _same_file(fd, tmp):
            return fd, Path(tmp)
        os.close(fd)


def _same_file(fd, path):
    """Whether ``path`` is (still) the file open as ``fd``."""
    try:
        return os.path.samestat(os.fstat(fd), os.stat(path))
    except FileNotFoundError:
        return False


def _remove_stale_temporaries(path):
    """Remove the temporaries of :func:`atomic_output` for ``path`` that no process holds.

    Parameters
    ----------
    path : pathlib.Path
        Final path; its directory is searched for ``.<name>.<random>.tmp``.

    Returns
    -------
    list of pathlib.Path
        The files removed.
    """
    pattern = _temporary_name(path)
    removed = []
    for candidate in sorted(path.parent.iterdir()):
        if not pattern.fullmatch(candidate.name):
            continue
        try:
            fd = os.open(candidate, os.O_RDONLY)
        except FileNotFoundError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            if _same_file(fd, candidate):
                candidate.unlink()
                removed.append(candidate)
        except BlockingIOError:
            pass
        finally:
            os.close(fd)
    return removed
