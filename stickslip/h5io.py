"""HDF5 reading and writing: reproducible bytes, checksummed datasets, tables, and the errors of input files.

Bit-identical outputs for the same inputs need two things from HDF5: no
modification times in object headers (``track_times=False``) and a fixed
file-format version (``libver``). :func:`open_file` and :func:`write_dataset`
set both; every writer of the package goes through them.

Files that a long run appends to (:mod:`stickslip.fem.run`) are written in
HDF5's single-writer/multiple-reader (SWMR) mode, so that a killed writer leaves a
readable file: :func:`open_file` reads such a file (running, or left "open for
write" by a killed process) through SWMR, :func:`copy_file` rewrites it into a
fresh file whose bytes depend only on its contents (keeping the committed rows of a
chunk whose in-place rewrite the kill tore, :mod:`stickslip.output_safety.torn_chunk`), and
:func:`stickslip.output_safety.lock.writer_lock` keeps a second process from writing the same file.

Tables (event lists, per-increment observables) are stored as a group with one
1-D dataset per column and the column order in the attribute ``columns``;
:func:`write_table` and :func:`read_table` convert to and from
:class:`pandas.DataFrame`.

What keeps outputs safe (atomic renames, locks, free space, the write guard through which
:func:`open_file` writes a new file) is :mod:`stickslip.output_safety`.

Files are not trusted: before a read allocates anything, :func:`read_array` checks the size the file
declares against what it stores (a dataset cannot hold more numbers than its chunks, compressed at most
:data:`MAX_EXPANSION` to one; rows in a chunk that was never written are not stored, :mod:`.stored_rows`)
and against a memory budget (:func:`read_budget`: half of what this process can still allocate, at most
``STICKSLIP_READ_LIMIT_MIB``; :func:`read_table` budgets a table whole), and reads large selections in blocks; a file
whose HDF5 metadata fail their checksums raises :class:`CorruptFileError` naming it wherever it is read
(:func:`open_file`). Each is one line naming the file and the dataset.
"""

import json
import math
import os
import time
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from .machine_memory import room_left, size_text
from .output_safety.errors import OutputError
from .output_safety.torn_chunk import committed_rows
from .output_safety.write_guard import WriteGuard
from .stored_rows import data_elsewhere, first_unstored_row

__all__ = ["open_file", "write_dataset", "read_array", "read_datasets", "write_table", "read_table", "write_attrs",
           "copy_file", "attribute", "read_budget", "check_budget", "FileFormatError", "UnreadableFileError",
           "CorruptFileError", "ReadBudgetError", "READ_LIMIT_VARIABLE", "MAX_EXPANSION"]

LIBVER = ("v110", "v110")

#: What HDF5 says about a file whose writer is running or was killed without closing it.
_OPEN_FOR_WRITE = "file is already open for write"

#: dtype kinds that take the fletcher32 checksum: booleans, integers, floats, complex, fixed-length bytes.
_CHECKSUMMED_KINDS = "biufcS"

#: Reads of a dataset of a file being written (SWMR) before a failed checksum counts as damage.
_SWMR_READ_ATTEMPTS = 4

#: Bytes per block in which :func:`copy_file` copies and :func:`read_array` reads a dataset (bounded memory).
_BLOCK_BYTES = 64 * 2**20

#: Environment variable: the most one read of a dataset may allocate [MiB] (below the default budget).
READ_LIMIT_VARIABLE = "STICKSLIP_READ_LIMIT_MIB"

#: The most a compressed dataset can expand on reading (deflate's limit is 1032 to 1; lzf's and szip's are lower).
MAX_EXPANSION = 1100

#: HDF5 filters that compress (their data may expand up to :data:`MAX_EXPANSION`: deflate, szip, n-bit,
#: scale-offset, lzf) and those that do not (shuffle, fletcher32); a dataset with another filter is not checked
#: against its storage.
_COMPRESSING = {h5py.h5z.FILTER_DEFLATE, h5py.h5z.FILTER_SZIP, h5py.h5z.FILTER_NBIT, h5py.h5z.FILTER_SCALEOFFSET,
                32000}
_KEEPING = {h5py.h5z.FILTER_SHUFFLE, h5py.h5z.FILTER_FLETCHER32}

#: Bytes counted per element of a variable-length dataset (a Python object and its text).
_OBJECT_BYTES = 64


class FileFormatError(ValueError):
    """An input file is missing, unreadable or lacks what the reader needs; the message says which."""


class UnreadableFileError(FileFormatError):
    """A file exists but HDF5 cannot open it (not HDF5, truncated, or damaged)."""


class CorruptFileError(FileFormatError):
    """Stored data fails its checksum or cannot be decompressed, or the file declares more than it stores: it is
    damaged."""


class ReadBudgetError(FileFormatError):
    """Reading a dataset would take more memory than the budget of one read (:func:`read_budget`)."""


def read_budget():
    """The most one read of a dataset may allocate [B]: half of what this process can still allocate.

    That is the least of the memory available (``MemAvailable``), the room left under the process's
    address-space and data limits (``ulimit -v``, ``ulimit -d``), and ``STICKSLIP_READ_LIMIT_MIB``
    (:data:`READ_LIMIT_VARIABLE`) if set; half of it, so that what the reader builds from the data (a
    table, a copy) fits too.

    Returns
    -------
    float
        [B]; ``inf`` where nothing limits it.
    """
    budget = 0.5 * room_left()
    capped = os.environ.get(READ_LIMIT_VARIABLE)
    if capped:
        try:
            budget = min(budget, float(capped) * 2**20)
        except ValueError:
            raise ReadBudgetError(f"{READ_LIMIT_VARIABLE}={capped!r}: expected a number of MiB") from None
    return budget


def _selected_shape(shape, selection):
    """The shape of ``dataset[selection]`` for a selection of integers and slices (else the whole shape)."""
    items = selection if isinstance(selection, tuple) else (selection,)
    if len(items) > len(shape) or any(not isinstance(item, (slice, int, np.integer)) for item in items):
        return tuple(shape)
    out = [len(range(*item.indices(n))) for item, n in zip(items, shape) if isinstance(item, slice)]
    return tuple(out) + tuple(shape[len(items):])


def _nbytes(dataset, shape):
    """Bytes that ``shape`` of ``dataset`` takes in memory (a variable-length element: :data:`_OBJECT_BYTES`)."""
    itemsize = _OBJECT_BYTES if dataset.dtype.kind == "O" else dataset.dtype.itemsize
    return float(np.prod(shape, dtype=float)) * itemsize


def _check_size(dataset, shape):
    """Raise unless reading ``shape`` of ``dataset`` is consistent with what the file stores and fits the budget."""
    nbytes = _nbytes(dataset, shape)
    if nbytes <= _BLOCK_BYTES:  # small: allocated at once whatever the file says
        return
    _check_storage(dataset, shape)
    check_budget(nbytes, f"{dataset.file.filename}: dataset {dataset.name}: reading {shape} {dataset.dtype}")


def _check_storage(dataset, shape):
    """Raise CorruptFileError if ``shape`` of ``dataset`` (more than 64 MiB) is more than its file's storage of it
    can hold: its bytes, compressed at most :data:`MAX_EXPANSION` to one, plus one chunk."""
    nbytes = _nbytes(dataset, shape)
    plist = dataset.id.get_create_plist()
    filters = {plist.get_filter(i)[0] for i in range(plist.get_nfilters())}
    if nbytes <= _BLOCK_BYTES or dataset.dtype.kind == "O" or not filters <= _COMPRESSING | _KEEPING:
        return
    stored = dataset.id.get_storage_size()
    expansion = MAX_EXPANSION if filters & _COMPRESSING else 1
    chunk = _nbytes(dataset, dataset.chunks) if dataset.chunks else 0.0
    if nbytes > stored * expansion + chunk:
        compressed = " compressed" if expansion > 1 else ""
        raise CorruptFileError(f"{dataset.file.filename}: dataset {dataset.name} declares {shape} {dataset.dtype} "
                               f"({size_text(nbytes)}) but stores {size_text(stored)}{compressed}: the file is "
                               "damaged or not what it claims; remake it (rerun the job that wrote it)")


def check_budget(nbytes, what):
    """Raise ReadBudgetError if ``nbytes`` are more than :func:`read_budget`; ``what`` starts the message.

    Parameters
    ----------
    nbytes : float
        [B] that a read would allocate.
    what : str
        What would be read, naming the file (e.g. ``"run.h5: table 'increments' of 41 rows"``).
    """
    budget = read_budget()
    if nbytes > budget:
        raise ReadBudgetError(f"{what} would take {size_text(nbytes)}, beyond the memory budget of one read "
                              f"({size_text(budget)}: half of what this process can still allocate, or "
                              f"{READ_LIMIT_VARIABLE})")


def _selected_rows(shape, selection):
    """The rows ``(start, stop)`` along the first axis that a selection of integers and slices touches (else all)."""
    items = selection if isinstance(selection, tuple) else (selection,)
    if not shape or not items or items[0] is Ellipsis:
        return 0, shape[0] if shape else 0
    first = items[0]
    if isinstance(first, (int, np.integer)):
        row = int(first) + (shape[0] if first < 0 else 0)
        return row, row + 1
    if isinstance(first, slice):
        picked = range(*first.indices(shape[0]))
        return (min(picked), max(picked) + 1) if picked else (0, 0)
    return 0, shape[0]


def _check_stored(dataset, start, stop):
    """Raise CorruptFileError unless the file stores rows ``start ... stop - 1`` of ``dataset`` itself
    (:mod:`stickslip.stored_rows`): never a fill value where a chunk was never written, never data of other files."""
    name = f"{dataset.file.filename}: dataset {dataset.name}"
    elsewhere = data_elsewhere(dataset)
    if elsewhere:
        raise CorruptFileError(f"{name} {elsewhere}, which this package never writes: the file is not what it "
                               "claims; remake it (rerun the job that wrote it)")
    row = first_unstored_row(dataset, start, stop)
    if row is not None:
        raise CorruptFileError(f"{name} declares {dataset.shape[0]} rows but stores none from row {row} on (a "
                               f"chunk never written reads as zeros): the file is damaged or not what it claims; "
                               f"remake it (rerun the job that wrote it)")


def _blocks(rows, row_bytes, chunk_rows):
    """Row ranges ``(start, stop)`` of at most :data:`_BLOCK_BYTES`, whole chunks each, covering ``rows`` rows."""
    step = max(1, _BLOCK_BYTES // max(1, row_bytes) // chunk_rows) * chunk_rows
    return [(start, min(start + step, rows)) for start in range(0, rows, step)]


class _CheckedFile(h5py.File):
    """An HDF5 file opened for reading whose failures inside a ``with`` block name it: metadata that fail their
    checksums or cannot be parsed (h5py's KeyError, RuntimeError, OSError, ...) become :class:`CorruptFileError`."""

    def __init__(self, path, *args, **kwargs):
        super().__init__(path, *args, **kwargs)
        self._path = Path(path)

    def __exit__(self, kind, error, trace):
        super().__exit__(kind, error, trace)
        if isinstance(error, _HDF5_FAILURES) and not isinstance(error, FileFormatError) and _raised_by_hdf5(trace):
            raise CorruptFileError(f"{self._path}: damaged or not a file of the expected layout: HDF5 cannot read "
                                   f"it ({type(error).__name__}: {str(error).strip(chr(39))}); remake it (rerun the "
                                   "job that wrote it)") from error


#: What h5py raises for metadata it cannot read (a failed checksum, a missing or malformed object).
_HDF5_FAILURES = (KeyError, RuntimeError, OSError, ValueError, TypeError)


def _raised_by_hdf5(trace):
    """Whether the innermost frame of a traceback is h5py's (its Python or its compiled modules)."""
    while trace.tb_next is not None:
        trace = trace.tb_next
    filename = trace.tb_frame.f_code.co_filename.replace(os.sep, "/")
    return "/h5py/" in filename or filename.startswith("h5py/")


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
    CorruptFileError
        From the end of a ``with`` block of a file opened to read (``"r"``) in which HDF5 failed to read
        it (damaged metadata, an object the layout needs that is not there).
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
        return _CheckedFile(path, "r", **reading) if mode == "r" else h5py.File(path, mode, **reading)
    except OSError as error:
        if mode == "r" and _OPEN_FOR_WRITE in str(error):
            try:
                return _CheckedFile(path, "r", swmr=True, **reading)
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
        decompression of a chunk failed; or the dataset declares more data than the
        file stores (more than its storage can hold, rows in chunks that were never written:
        :mod:`stickslip.stored_rows`) or keeps its data in other files. The message names the file and
        dataset.
        In a file being written (SWMR), where a chunk may be read while its writer
        rewrites it, the read is tried :data:`_SWMR_READ_ATTEMPTS` times first.
    ReadBudgetError
        If the selection would take more memory than :func:`read_budget`.

    Notes
    -----
    A selection of more than 64 MiB along the first axis is read in blocks of whole chunks into one
    array (no temporary of its size).
    """
    shape = _selected_shape(dataset.shape, selection)
    _check_size(dataset, shape)
    _check_stored(dataset, *_selected_rows(dataset.shape, selection))
    items = selection if isinstance(selection, tuple) else (selection,)
    whole_rows = items in ((), (slice(None),)) or (len(items) == 1 and isinstance(items[0], slice)
                                                    and items[0].step in (None, 1))
    if shape and whole_rows and dataset.dtype.kind != "O":
        first = items[0].indices(dataset.shape[0])[0] if items else 0
        return _read_rows(dataset, first, first + shape[0])
    return _read(dataset, selection)


def _read_rows(dataset, start, stop):
    """Rows ``start ... stop - 1`` of a dataset of fixed-size elements: more than 64 MiB in blocks of whole chunks
    into one array (no temporary of its size); raises CorruptFileError (:func:`read_array`, no checks of its own)."""
    shape = (stop - start,) + dataset.shape[1:]
    if _nbytes(dataset, shape) <= _BLOCK_BYTES:
        return _read(dataset, slice(start, stop))
    out = np.empty(shape, dtype=dataset.dtype)
    row_bytes = dataset.dtype.itemsize * int(np.prod(shape[1:], dtype=np.int64))
    for low, high in _blocks(shape[0], row_bytes, dataset.chunks[0] if dataset.chunks else 1):
        out[low:high] = _read(dataset, slice(start + low, start + high))
    return out


def _read(dataset, selection):
    """``dataset[selection]``, tried again in a file being written; raises CorruptFileError (:func:`read_array`)."""
    attempts = _SWMR_READ_ATTEMPTS if dataset.file.swmr_mode else 1
    for attempt in range(1, attempts + 1):
        try:
            return dataset[selection]
        except OSError as error:
            failure = str(error)  # not the exception: its traceback would keep the caller's datasets open
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


#: What :func:`attribute` accepts of each kind, for its messages.
_ATTRIBUTE_KINDS = {"int": "an integer", "float": "a finite number", "str": "text", "bool": "true or false",
                    "json": "JSON text"}


def attribute(obj, name, kind, default=None, *, required=True):
    """An attribute of the right kind, or a one-line FileFormatError naming the file, the object and the attribute.

    Parameters
    ----------
    obj : h5py.Group or h5py.Dataset
    name : str
    kind : {"int", "float", "str", "bool", "json"}
        ``int``: an integer (an integral float too); ``float``: a finite real number; ``str``: text (bytes
        decoded as UTF-8); ``bool``: a boolean (or 0 / 1); ``json``: JSON text, returned decoded.
    default : object, optional
        Returned if the attribute is absent and not ``required``.
    required : bool, optional

    Returns
    -------
    int, float, str, bool or the decoded JSON value

    Raises
    ------
    FileFormatError
        If the attribute is absent (and required) or not of that kind.
    """
    where = f"{obj.file.filename}: attribute '{name}'" + ("" if obj.name == "/" else f" of {obj.name}")
    if name not in obj.attrs:
        if required:
            raise FileFormatError(f"{where} is missing")
        return default
    value = obj.attrs[name]
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, bytes):
        try:
            value = value.decode("utf-8")
        except UnicodeDecodeError:
            raise FileFormatError(f"{where} is not UTF-8 text") from None
    found = value.item() if isinstance(value, np.generic) else value
    if kind == "str" and isinstance(found, str):
        return found
    if kind == "json" and isinstance(found, str):
        try:
            return json.loads(found)
        except ValueError as error:
            raise FileFormatError(f"{where} is not JSON ({error})") from None
    if kind == "bool" and (isinstance(found, bool) or (isinstance(found, int) and found in (0, 1))):
        return bool(found)
    if kind == "int" and not isinstance(found, bool):
        if isinstance(found, int) or (isinstance(found, float) and found.is_integer()):
            return int(found)
    if kind == "float" and isinstance(found, (int, float)) and not isinstance(found, bool) and math.isfinite(found):
        return float(found)
    shown = np.array2string(found, threshold=6) if isinstance(found, np.ndarray) else repr(found)
    shown = " ".join(shown.split())
    raise FileFormatError(f"{where} is {shown[:80]}, expected {_ATTRIBUTE_KINDS[kind]}")


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
        columns may have different lengths while a row is written): the committed
        rows, kept also from a chunk whose rewrite a killed writer tore (:func:`copy_file`).

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    FileFormatError
        If the table is missing or malformed: its ``columns`` attribute is not a JSON list of names, a
        column is not a 1-D dataset, or the columns have other lengths (fewer than ``rows``).
    CorruptFileError
        If a column's file does not store its rows (:func:`read_array`).
    ReadBudgetError
        If the table would take more memory than :func:`read_budget`; checked before any column is read.
    """
    where = f"{group.file.filename}: table '{name}'"
    if name not in group or not isinstance(group[name], h5py.Group) or "columns" not in group[name].attrs:
        raise FileFormatError(f"{group.file.filename}: no table '{name}' in {group.name}")
    sub = group[name]
    columns = attribute(sub, "columns", "json")
    if not isinstance(columns, list) or not all(isinstance(column, str) for column in columns):
        raise FileFormatError(f"{where}: attribute 'columns' is not a JSON list of column names")
    lengths = {}
    for column in columns:
        dataset = sub.get(column)
        if not isinstance(dataset, h5py.Dataset) or dataset.ndim != 1:
            found = "missing" if dataset is None else f"of shape {getattr(dataset, 'shape', 'a group')}"
            raise FileFormatError(f"{where}: column '{column}' is {found}, expected a 1-D dataset")
        lengths[column] = dataset.shape[0]
    expected = rows if rows is not None else max(lengths.values(), default=0)
    short = {column: n for column, n in lengths.items() if n < expected or (rows is None and n != expected)}
    if short:
        column, n = next(iter(short.items()))
        raise FileFormatError(f"{where}: column '{column}' has {n} rows, expected {expected}"
                              f"{' (the rows the file says it stores)' if rows is not None else ''}")
    check_budget(sum(_nbytes(sub[column], (expected,)) for column in columns), f"{where} of {expected} rows")
    data = {}
    for column in columns:
        growing = rows is not None and sub[column].maxshape[0] is None
        values = _read_committed(sub[column], 0, rows, rows) if growing else read_array(sub[column], slice(None, rows))
        if values.dtype.kind in "OS":
            values = np.asarray([v.decode("utf-8", "replace") if isinstance(v, bytes) else v for v in values],
                                dtype=object)
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
        Growable datasets (unlimited first dimension) keep their first ``rows`` rows: the rows its
        writer had committed. A chunk of theirs that a writer killed while appending row ``rows``
        tore is copied from its committed rows where its old checksum proves them
        (:func:`stickslip.output_safety.torn_chunk.committed_rows`); any other damage raises
        :class:`CorruptFileError`.
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
                _check_storage(obj, shape)
                _check_stored(obj, 0, shape[0])
                row_bytes = obj.dtype.itemsize * int(np.prod(shape[1:]))
                for start, stop in _blocks(shape[0], row_bytes, obj.chunks[0] if obj.chunks else 1):
                    out[start:stop] = _through_torn(obj, start, stop, rows) if growable else \
                        _read_rows(obj, start, stop)
            copy_attrs(obj, out)

    copy_group(source, target)


def _read_committed(dataset, start, stop, committed):
    """Rows ``start ... stop - 1`` (``stop <= committed``) of a growable dataset, through a chunk torn by a kill.

    The rows are checked against what the file stores and the memory budget before anything is read
    (:func:`read_array`'s checks), then read by :func:`_through_torn`.

    Raises
    ------
    CorruptFileError
        If the file does not store the rows, or a chunk cannot be read and is not a torn chunk whose
        committed rows its old checksum proves (:func:`stickslip.output_safety.torn_chunk.committed_rows`).
    ReadBudgetError
        If the rows would take more memory than :func:`read_budget`.
    """
    _check_size(dataset, (stop - start,) + dataset.shape[1:])
    _check_stored(dataset, start, stop)
    return _through_torn(dataset, start, stop, committed)


def _through_torn(dataset, start, stop, committed):
    """Rows ``start ... stop - 1`` of a growable dataset (checked), a chunk that fails to read replaced by its
    committed rows where its old checksum proves them, in the one array of the result."""
    try:
        return _read_rows(dataset, start, stop)
    except CorruptFileError as error:
        damage = str(error)  # not the exception: its traceback would keep the caller's datasets open
    size = dataset.chunks[0]
    out = np.empty((stop - start,) + dataset.shape[1:], dtype=dataset.dtype)
    for first in range(start - start % size, stop, size):
        low, high = max(first, start), min(first + size, stop)
        try:
            out[low - start:high - start] = _read(dataset, slice(low, high))
        except CorruptFileError:
            rows = committed_rows(dataset, first, committed)
            if rows is None:
                raise CorruptFileError(damage) from None
            out[low - start:high - start] = rows[low - first:high - first]
    return out
