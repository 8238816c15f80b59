"""HDF5 reading and writing: reproducible bytes, checksummed datasets, tables, and the errors of input files.

Bit-identical outputs for the same inputs need two things from HDF5: no
modification times in object headers (``track_times=False``) and a fixed
file-format version (``libver``). :func:`open_file` and :func:`write_dataset`
set both; every writer of the package goes through them.

Files that a long run appends to (:mod:`stickslip.fem.run`) are written in
HDF5's single-writer/multiple-reader (SWMR) mode, so that a killed writer leaves a
readable file: :func:`open_file` reads such a file (running, or left "open for
write" by a killed process) through SWMR, :func:`copy_file` rewrites it into a
fresh file whose bytes depend only on its contents, and
:func:`stickslip.output_safety.lock.writer_lock` keeps a second process from writing the same file.

Tables (event lists, per-increment observables) are stored as a group with one
1-D dataset per column and the column order in the attribute ``columns``;
:func:`write_table` and :func:`read_table` convert to and from
:class:`pandas.DataFrame`.

What keeps outputs safe (atomic renames, locks, free space, the write guard through which
:func:`open_file` writes a new file) is :mod:`stickslip.output_safety`.
"""

import json
import time
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from .output_safety.errors import OutputError
from .output_safety.write_guard import WriteGuard

__all__ = ["open_file", "write_dataset", "read_array", "read_datasets", "write_table", "read_table", "write_attrs", "copy_file",
           "FileFormatError", "UnreadableFileError", "CorruptFileError"]

LIBVER = ("v110", "v110")

#: What HDF5 says about a file whose writer is running or was killed without closing it.
_OPEN_FOR_WRITE = "file is already open for write"

#: dtype kinds that take the fletcher32 checksum: booleans, integers, floats, complex, fixed-length bytes.
_CHECKSUMMED_KINDS = "biufcS"

#: Reads of a dataset of a file being written (SWMR) before a failed checksum counts as damage.
_SWMR_READ_ATTEMPTS = 4

#: Bytes per block in which :func:`copy_file` copies a dataset (bounded memory).
_COPY_BLOCK_BYTES = 64 * 2**20


class FileFormatError(ValueError):
    """An input file is missing, unreadable or lacks what the reader needs; the message says which."""


class UnreadableFileError(FileFormatError):
    """A file exists but HDF5 cannot open it (not HDF5, truncated, or damaged)."""


class CorruptFileError(FileFormatError):
    """Stored data fails its checksum or cannot be decompressed: the file is damaged."""


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
    file and renames it, :func:`~stickslip.output_safety.atomic.atomic_output`, or
    appends under :func:`~stickslip.output_safety.lock.writer_lock`). A file whose
    writer is running, or was killed, in SWMR mode is opened as an SWMR reader: it
    shows what the writer had flushed.

    A new file (``"w"``) is written through a
    :class:`~stickslip.output_safety.write_guard.WriteGuard`, so that a failed write
    (full disk) raises :class:`~stickslip.output_safety.errors.OutputError` from
    :meth:`~h5py.File.flush` or :meth:`~h5py.File.close`, where HDF5 itself would
    crash; the file is then incomplete. An existing file (``"r+"``) is opened
    directly: the guard's file driver would not mark the file as open for writing
    in the way SWMR readers need (HDF5 sets that flag with its file lock only);
    its writer checks the free space itself
    (:func:`~stickslip.output_safety.space.check_free_space`).

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
    """An HDF5 file written through a :class:`~stickslip.output_safety.write_guard.WriteGuard`: a failed write
    (full disk) raises :class:`~stickslip.output_safety.errors.OutputError` from :meth:`flush` and :meth:`close`."""

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


def read_datasets(path):
    """Every dataset of an HDF5 file, read whole (a comparison of two files' numbers, not a reader of a format).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    dict[str, numpy.ndarray or scalar]
        Each dataset's data by its path in the file (e.g. ``"state/u"``).
    """
    found = {}

    def keep(name, item):  # returns None: visititems stops at the first other value
        if isinstance(item, h5py.Dataset):
            found[name] = item[()]

    with h5py.File(path, "r") as file:
        file.visititems(keep)
    return found


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


