"""HDF5 helpers shared by every module that writes files: reproducible bytes and tables.

Bit-identical outputs for the same inputs need two things from HDF5: no
modification times in object headers (``track_times=False``) and a fixed
file-format version (``libver``). :func:`open_file` and :func:`write_dataset`
set both; every writer of the package goes through them.

Tables (event lists, per-increment observables) are stored as a group with one
1-D dataset per column and the column order in the attribute ``columns``;
:func:`write_table` and :func:`read_table` convert to and from
:class:`pandas.DataFrame`.
"""

import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

__all__ = ["open_file", "write_dataset", "write_table", "read_table", "write_attrs", "atomic_output",
           "FileFormatError"]

LIBVER = ("v110", "v110")


class FileFormatError(ValueError):
    """An input file is missing, unreadable or lacks what the reader needs; the message says which."""


def open_file(path, mode="r"):
    """Open an HDF5 file with the package's reproducible settings.

    Parameters
    ----------
    path : str or pathlib.Path
    mode : {"r", "r+", "w", "a", "x"}

    Returns
    -------
    h5py.File

    Raises
    ------
    FileFormatError
        If a file to read does not exist or is not a readable HDF5 file.
    """
    path = Path(path)
    if mode in ("r", "r+"):
        if not path.is_file():
            raise FileFormatError(f"{path}: no such file")
        try:
            return h5py.File(path, mode)
        except OSError as error:
            raise FileFormatError(f"{path}: not a readable HDF5 file ({error})") from error
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


def read_table(group, name):
    """Read a table written by :func:`write_table`.

    Parameters
    ----------
    group : h5py.Group
    name : str

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
        values = sub[column][...]
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
