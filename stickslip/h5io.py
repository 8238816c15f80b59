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

import fcntl
import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

__all__ = ["open_file", "write_dataset", "write_table", "read_table", "write_attrs", "atomic_output",
           "copy_file", "writer_lock", "FileFormatError", "UnreadableFileError"]

LIBVER = ("v110", "v110")

#: What HDF5 says about a file whose writer is running or was killed without closing it.
_OPEN_FOR_WRITE = "file is already open for write"

#: Bytes per block in which :func:`copy_file` copies a dataset (bounded memory).
_COPY_BLOCK_BYTES = 64 * 2**20


class FileFormatError(ValueError):
    """An input file is missing, unreadable or lacks what the reader needs; the message says which."""


class UnreadableFileError(FileFormatError):
    """A file exists but HDF5 cannot open it (not HDF5, truncated, or damaged)."""


def open_file(path, mode="r"):
    """Open an HDF5 file with the package's reproducible settings.

    Parameters
    ----------
    path : str or pathlib.Path
    mode : {"r", "r+", "w", "a", "x"}

    Returns
    -------
    h5py.File

    Reading (``"r"``) takes no HDF5 file lock, so that a reader never stops a writer
    from opening the file (every writer of the package either writes a temporary
    file and renames it, :func:`atomic_output`, or appends under
    :func:`writer_lock`). A file whose writer is running, or was killed, in SWMR
    mode is opened as an SWMR reader: it shows what the writer had flushed.

    Raises
    ------
    FileFormatError
        If a file to read does not exist.
    UnreadableFileError
        If it is not a readable HDF5 file.
    """
    path = Path(path)
    if mode in ("r", "r+"):
        if not path.is_file():
            raise FileFormatError(f"{path}: no such file")
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
    return h5py.File(path, mode, libver=LIBVER, track_order=False)


def write_dataset(group, name, data, **kwargs):
    """Create a dataset without modification times (so equal data gives equal bytes).

    Parameters
    ----------
    group : h5py.Group
    name : str
    data : array_like
    **kwargs
        Forwarded to :meth:`h5py.Group.create_dataset` (e.g. ``maxshape``, ``chunks``).

    Returns
    -------
    h5py.Dataset
    """
    return group.create_dataset(name, data=data, track_times=False, **kwargs)


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
        values = sub[column][:rows]
        if values.dtype.kind in "OS":
            values = np.asarray([v.decode() if isinstance(v, bytes) else v for v in values], dtype=object)
        data[column] = values
    return pd.DataFrame(data, columns=columns)


@contextmanager
def atomic_output(path):
    """Write a file under a temporary name and rename it into place on success.

    An interrupted writer leaves the previous file (or none) intact.

    Parameters
    ----------
    path : str or pathlib.Path
        Final path.

    Yields
    ------
    pathlib.Path
        Temporary path in the same directory, to write to.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    tmp = Path(tmp)
    umask = os.umask(0)
    os.umask(umask)
    try:
        yield tmp
        if tmp.exists():  # mkstemp makes it private; the result gets the usual permissions
            os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


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
                out[()] = obj[()]
            elif shape[0]:
                chunk = obj.chunks[0] if obj.chunks else 1
                row_bytes = max(1, obj.dtype.itemsize * int(np.prod(shape[1:])))
                step = max(1, _COPY_BLOCK_BYTES // row_bytes // chunk) * chunk
                for start in range(0, shape[0], step):
                    out[start:start + step] = obj[start:min(start + step, shape[0])]
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
