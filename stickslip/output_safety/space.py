"""Free space for a writer that appends to a file in place."""

import errno
import shutil
from pathlib import Path

from .errors import OutputError

__all__ = ["check_free_space"]


def check_free_space(path, nbytes):
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

    Raises
    ------
    OutputError
        If less is free (for unprivileged users).
    """
    if shutil.disk_usage(Path(path).parent).free < nbytes:
        raise OutputError(path, errno.ENOSPC)
