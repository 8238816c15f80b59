"""HDF5 helpers shared by every module that writes files: reproducible bytes and tables.

Bit-identical outputs for the same inputs need two things from HDF5: no
modification times in object headers (``track_times=False``) and a fixed
file-format version (``libver``). :func:`open_file` and :func:`write_dataset`
set both; every writer of the package goes through them.

Files that a long run appends to (:mod:`stickslip.fem.run`) are written in
HDF5's single-writer/multiple-reader (SWMR) mode, so that a killed writer leaves a
readable file: :func:`open_file` reads such a file (running, or left "open for
write" by a killed process) through SWMR, :func:`copy_file` rewrites it into a
fresh file whose bytes depend only on its contents, and :func:`writer_lock` keeps
a second process from writing the same file.

Tables (event lists, per-increment observables) are stored as a group with one
1-D dataset per column and the column order in the attribute ``columns``;
:func:`write_table` and :func:`read_table` convert to and from
:class:`pandas.DataFrame`.
"""

import errno
import fcntl
import json
import os
import re
import shutil
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from .write_guard import WriteGuard

__all__ = ["open_file", "write_dataset", "read_array", "write_table", "read_table", "write_attrs", "atomic_output",
           "copy_file", "writer_lock", "FileFormatError", "UnreadableFileError", "CorruptFileError", "OutputError",
           "check_output", "check_free_space"]

LIBVER = ("v110", "v110")

#: What HDF5 says about a file whose writer is running or was killed without closing it.
_OPEN_FOR_WRITE = "file is already open for write"

#: dtype kinds that take the fletcher32 checksum: booleans, integers, floats, complex, fixed-length bytes.
_CHECKSUMMED_KINDS = "biufcS"

#: Reads of a dataset of a file being written (SWMR) before a failed checksum counts as damage.
_SWMR_READ_ATTEMPTS = 4

#: errno values that mean "the output cannot be written", reported as :class:`OutputError`.
_WRITE_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOENT,
                 errno.ENOTDIR, errno.EISDIR)

#: Bytes per block in which :func:`copy_file` copies a dataset (bounded memory).
_COPY_BLOCK_BYTES = 64 * 2**20


class FileFormatError(ValueError):
    """An input file is missing, unreadable or lacks what the reader needs; the message says which."""


class UnreadableFileError(FileFormatError):
    """A file exists but HDF5 cannot open it (not HDF5, truncated, or damaged)."""


class CorruptFileError(FileFormatError):
    """Stored data fails its checksum or cannot be decompressed: the file is damaged."""


class OutputError(OSError):
    """An output file cannot be written (full disk, no permission, read-only file system); the message says which.

    Parameters
    ----------
    path : str or pathlib.Path
        The output file.
    code : int
        The ``errno`` of the failure.
    """

    def __init__(self, path, code):
        super().__init__(f"{path}: cannot write it ({os.strerror(code)})")
        self.errno = code


def open_file(path, mode="r"):
    """Open an HDF5 file with the package's reproducible settings.

    Parameters
    ----------
    path : str or pathlib.Path
    mode : {"r", "r+", "w"}
        Read; read and write an existing file; create (or empty) a file.

    Returns
    -------
    h5py.File

    Reading (``"r"``) takes no HDF5 file lock, so that a reader never stops a writer
    from opening the file (every writer of the package either writes a temporary
    file and renames it, :func:`atomic_output`, or appends under
    :func:`writer_lock`). A file whose writer is running, or was killed, in SWMR
    mode is opened as an SWMR reader: it shows what the writer had flushed.

    A new file (``"w"``) is written through a :class:`~stickslip.write_guard.WriteGuard`,
    so that a failed write (full disk) raises :class:`OutputError` from
    :meth:`~h5py.File.flush` or :meth:`~h5py.File.close`, where HDF5 itself would
    crash; the file is then incomplete. An existing file (``"r+"``) is opened
    directly: the guard's file driver would not mark the file as open for writing
    in the way SWMR readers need (HDF5 sets that flag with its file lock only);
    its writer checks the free space itself (:func:`check_free_space`).

    Raises
    ------
    FileFormatError
        If a file to read does not exist.
    UnreadableFileError
        If it is not a readable HDF5 file.
    """
    path = Path(path)
    if mode not in ("r", "r+", "w"):
        raise ValueError(f"mode must be 'r', 'r+' or 'w', not {mode!r}")
    if mode in ("r", "r+") and not path.is_file():
        raise FileFormatError(f"{path}: no such file")
    if mode == "w":
        return _GuardedFile(WriteGuard(path))
    reading = {"locking": False} if mode == "r" else {"libver": LIBVER}
    try:
        return h5py.File(path, mode, **reading)
    except OSError as error:
        if mode == "r" and _OPEN_FOR_WRITE in str(error):
            try:
                return h5py.File(path, "r", swmr=True, **reading)
            except OSError:
                pass
        raise UnreadableFileError(f"{path}: not a readable HDF5 file ({error})") from error


class _GuardedFile(h5py.File):
    """An HDF5 file written through a :class:`~stickslip.write_guard.WriteGuard`: a failed write
    (full disk) raises :class:`OutputError` from :meth:`flush` and :meth:`close`."""

    def __init__(self, guard):
        try:
            super().__init__(guard, "w", libver=LIBVER, track_order=False)
        except BaseException:
            guard.close()
            raise
        self._guard = guard

    def flush(self):
        """Write what HDF5 holds to the file; raise OutputError if a write failed."""
        super().flush()
        self._check()

    def close(self):
        """Close the file; raise OutputError if a write failed."""
        super().close()
        try:
            self._guard.close()
        finally:
            self._check()

    def _check(self):
        if self._guard.error is not None:
            raise OutputError(self._guard.name, self._guard.error.errno) from self._guard.error


def write_dataset(group, name, data, **kwargs):
    """Create a dataset without modification times (so equal data gives equal bytes), with checksums.

    Arrays of numbers, booleans and fixed-length bytes get HDF5's ``fletcher32``
    checksum on every chunk (they are chunked for it): a damaged chunk then fails to
    read (:func:`read_array`) instead of giving wrong numbers. Scalars and strings
    cannot carry the filter.

    Parameters
    ----------
    group : h5py.Group
    name : str
    data : array_like or None
    **kwargs
        Forwarded to :meth:`h5py.Group.create_dataset` (e.g. ``maxshape``, ``chunks``,
        ``shape`` and ``dtype`` with ``data=None``, ``fletcher32=False``).

    Returns
    -------
    h5py.Dataset
    """
    if "fletcher32" not in kwargs:
        shape = kwargs.get("shape", np.shape(data))
        dtype = np.dtype(kwargs.get("dtype") or np.asarray(data).dtype)
        kwargs["fletcher32"] = len(shape) > 0 and dtype.kind in _CHECKSUMMED_KINDS
    return group.create_dataset(name, data=data, track_times=False, **kwargs)


def read_array(dataset, selection=()):
    """Read ``dataset[selection]``, refusing damaged data.

    Parameters
    ----------
    dataset : h5py.Dataset
    selection : slice, tuple or int, optional
        Default: everything.

    Returns
    -------
    numpy.ndarray or scalar

    Raises
    ------
    CorruptFileError
        If HDF5 cannot read the data: a checksum (:func:`write_dataset`) or the
        decompression of a chunk failed. The message names the file and dataset.
        In a file being written (SWMR), where a chunk may be read while its writer
        rewrites it, the read is tried :data:`_SWMR_READ_ATTEMPTS` times first.
    """
    attempts = _SWMR_READ_ATTEMPTS if dataset.file.swmr_mode else 1
    for attempt in range(1, attempts + 1):
        try:
            return dataset[selection]
        except OSError as error:
            failure = error
            if attempt < attempts:  # a running writer may be rewriting the chunk: read it again
                time.sleep(0.1)
                dataset.refresh()
    raise CorruptFileError(f"{dataset.file.filename}: dataset {dataset.name} is damaged and cannot be read "
                           f"({failure}); remake the file (rerun the job that wrote it)") from None


def write_attrs(obj, attrs):
    """Write attributes; dicts and lists are stored as JSON text, None as "null".

    Parameters
    ----------
    obj : h5py.Group or h5py.Dataset
    attrs : Mapping[str, object]
    """
    for key, value in attrs.items():
        if isinstance(value, (dict, list, tuple)) or value is None:
            value = json.dumps(value, sort_keys=True)
        obj.attrs[key] = value


def write_table(group, name, table, attrs=None):
    """Store a DataFrame as a group of column datasets.

    Parameters
    ----------
    group : h5py.Group
        Parent group (or file).
    name : str
        Name of the table group; an existing one is replaced.
    table : pandas.DataFrame
        Columns of numbers, booleans or strings.
    attrs : Mapping[str, object], optional
        Attributes of the table group (see :func:`write_attrs`).
    """
    if name in group:
        del group[name]
    sub = group.create_group(name, track_order=False)
    for column in table.columns:
        values = table[column].to_numpy()
        if values.dtype == object or pd.api.types.is_string_dtype(table[column].dtype):
            values = np.asarray([str(v) for v in values], dtype=h5py.string_dtype())
        write_dataset(sub, str(column), values)
    sub.attrs["columns"] = json.dumps([str(c) for c in table.columns])
    write_attrs(sub, attrs or {})


def read_table(group, name, rows=None):
    """Read a table written by :func:`write_table`.

    Parameters
    ----------
    group : h5py.Group
    name : str
    rows : int, optional
        Read only the first ``rows`` rows (of a table being appended to, whose
        columns may have different lengths while a row is written).

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    FileFormatError
        If the table is missing or malformed.
    """
    if name not in group or "columns" not in group[name].attrs:
        raise FileFormatError(f"{group.file.filename}: no table '{name}' in {group.name}")
    sub = group[name]
    columns = json.loads(sub.attrs["columns"])
    data = {}
    for column in columns:
        values = read_array(sub[column], slice(None, rows))
        if values.dtype.kind in "OS":
            values = np.asarray([v.decode() if isinstance(v, bytes) else v for v in values], dtype=object)
        data[column] = values
    return pd.DataFrame(data, columns=columns)


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


def copy_file(source, target, rows):
    """Copy every group, dataset and attribute of ``source`` into the empty file ``target``.

    The copy is written in one pass, in name order, so its bytes depend only on
    the contents of ``source`` (not on how that file grew, was interrupted or
    resumed). Datasets keep their type, chunks, maximum shape and filters.

    Parameters
    ----------
    source, target : h5py.File
        Open for reading; open for writing (empty, made by :func:`open_file`).
    rows : int
        Growable datasets (unlimited first dimension) keep their first ``rows`` rows.
    """
    def copy_attrs(src, dst):
        for name in sorted(src.attrs):
            dst.attrs.create(name, src.attrs[name], dtype=src.attrs.get_id(name).dtype)

    def copy_group(src, dst):
        copy_attrs(src, dst)
        for name in sorted(src):
            obj = src[name]
            if isinstance(obj, h5py.Group):
                copy_group(obj, dst.create_group(name, track_order=False))
                continue
            growable = obj.maxshape and obj.maxshape[0] is None
            shape = (min(rows, obj.shape[0]),) + obj.shape[1:] if growable else obj.shape
            out = write_dataset(dst, name, None, shape=shape, dtype=obj.dtype, chunks=obj.chunks,
                                maxshape=obj.maxshape, fletcher32=obj.fletcher32, compression=obj.compression,
                                compression_opts=obj.compression_opts)
            if not shape:
                out[()] = read_array(obj)
            elif shape[0]:
                chunk = obj.chunks[0] if obj.chunks else 1
                row_bytes = max(1, obj.dtype.itemsize * int(np.prod(shape[1:])))
                step = max(1, _COPY_BLOCK_BYTES // row_bytes // chunk) * chunk
                for start in range(0, shape[0], step):
                    out[start:start + step] = read_array(obj, slice(start, min(start + step, shape[0])))
            copy_attrs(obj, out)

    copy_group(source, target)


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
