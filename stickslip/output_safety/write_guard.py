"""The file object through which HDF5 writes a new file, so that a full disk is an error, never a crash.

HDF5 (2.0) does not survive a failed write while it closes a dataset or the file:
the process ends with a segmentation fault, after pages of tracebacks. Through a
:class:`WriteGuard` (h5py's ``fileobj`` driver) HDF5 never sees a failed write. The
first one (``ENOSPC``, ``EDQUOT``, ``EFBIG``, ...) is noted; it and every later write
are kept in memory instead (reads see them, so HDF5 can finish and close the file),
and the writer checks :attr:`WriteGuard.error` (:func:`stickslip.h5io.open_file` does,
on every flush and on closing). What is kept after a failure is
bounded (:data:`KEEP_LIMIT`); a write beyond it is passed to HDF5 as an error at once.
The file written is then incomplete: :func:`stickslip.output_safety.atomic.atomic_output` removes it.
"""

import os

__all__ = ["WriteGuard", "KEEP_LIMIT"]

#: Bytes kept in memory after a failed write, at most; a write beyond raises the failure.
KEEP_LIMIT = 64 * 2**20


class WriteGuard:
    """A binary file for h5py's ``fileobj`` driver that notes a failed write instead of passing it on.

    Parameters
    ----------
    path : str or pathlib.Path
        File to write; created, or emptied if it exists.
    """

    def __init__(self, path):
        self.name = str(path)
        self._fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o666)
        self._position = 0
        self._kept = []
        self._kept_bytes = 0
        self.error = None

    def __repr__(self):
        return self.name

    def seek(self, offset, whence=os.SEEK_SET):
        """Move to byte ``offset`` (from the start, the current position or the end)."""
        start = {os.SEEK_SET: 0, os.SEEK_CUR: self._position, os.SEEK_END: self._size()}[whence]
        self._position = start + offset
        return self._position

    def tell(self):
        """The current position [bytes]."""
        return self._position

    def _size(self):
        ends = [offset + len(data) for offset, data in self._kept]
        return max([os.fstat(self._fd).st_size] + ends)

    def write(self, data):
        """Write ``data`` at the current position; after a failure, keep it in memory."""
        data = memoryview(data).cast("B")
        if self.error is None:
            try:
                done = 0
                while done < len(data):
                    done += os.pwrite(self._fd, data[done:], self._position + done)
            except OSError as error:
                self.error = error
        if self.error is not None:
            if self._kept_bytes + len(data) > KEEP_LIMIT:
                raise self.error
            self._kept.append((self._position, bytes(data)))
            self._kept_bytes += len(data)
        self._position += len(data)
        return len(data)

    def readinto(self, buffer):
        """Fill ``buffer`` from the current position (what was kept in memory included); zeros past the end."""
        buffer = memoryview(buffer).cast("B")
        size = len(buffer)
        read = os.preadv(self._fd, [buffer], self._position)
        buffer[read:] = bytes(size - read)
        for offset, data in self._kept:
            first, last = max(offset, self._position), min(offset + len(data), self._position + size)
            if first < last:
                buffer[first - self._position:last - self._position] = data[first - offset:last - offset]
        self._position += size
        return size

    def read(self, size):
        """Read ``size`` bytes from the current position (see :meth:`readinto`)."""
        buffer = bytearray(size)
        self.readinto(buffer)
        return bytes(buffer)

    def truncate(self, size=None):
        """Set the file's length to ``size`` bytes (the current position if None), unless a write failed."""
        size = self._position if size is None else size
        if self.error is None:
            try:
                os.ftruncate(self._fd, size)
            except OSError as error:
                self.error = error
        return size

    def flush(self):
        """Nothing to do: every write goes to the operating system at once."""

    def close(self):
        """Close the file (``error`` tells whether a write failed: the file is then incomplete)."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
            self._kept.clear()
