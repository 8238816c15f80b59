"""Free space for a writer that appends to a file in place."""

import errno
import shutil
from pathlib import Path

from .errors import OutputError

__all__ = ["check_free_space"]


def check_free_space(path, nbytes, margin=0):
    """Raise OutputError (ENOSPC) unless the file system of ``path`` has ``nbytes`` free.

    For a writer that appends to an existing file in place, where a write that fails
    for lack of space would crash HDF5: checked before each append, with a margin,
    it ends the writer cleanly instead. (Space taken by another process between the
    check and the write, and quotas, which the check does not see, are not covered.)

    Parameters
    ----------
    path : str or pathlib.Path
        The file appended to.
    nbytes : int
        Bytes needed [B].
    margin : int, optional
        Bytes of ``nbytes`` that are a safety margin, not data [B]: the message then says that the
        disk is not full but kept from filling.

    Raises
    ------
    OutputError
        If less is free (for unprivileged users); the message gives what is free and what is needed.
    """
    free = shutil.disk_usage(Path(path).parent).free
    if free < nbytes:
        kept = f", {_mib(margin)} of it a safety margin kept free: HDF5 crashes on a full disk" if margin else ""
        raise OutputError(path, errno.ENOSPC, f"cannot write it: {_mib(free)} free, the next write needs "
                                              f"{_mib(nbytes)}{kept}; free some space and rerun")


def _mib(nbytes):
    return f"{nbytes / 2**20:.2f} MiB"
