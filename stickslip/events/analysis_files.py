"""Reading analysis files of fem runs back (event tables, front tables) and grouping runs for figures.

Figures group runs by what the files say about themselves (``regime``, ``n_interfaces``,
``N``, ``seed``), never by file names.
"""

import dataclasses
import json
from collections import defaultdict

import numpy as np
import pandas as pd

from .. import h5io
from ..formats.analysis_file import open_analysis_file
from ..h5io import FileFormatError

__all__ = ["AnalysisFile", "read_analysis_file", "group_runs", "pooled"]


@dataclasses.dataclass(frozen=True)
class AnalysisFile:
    """The tables and attributes of one analysis output file.

    Attributes
    ----------
    path : str
    attrs : dict[str, object]
        Root attributes (JSON text decoded, numpy scalars as Python scalars).
    tables : dict[str, pandas.DataFrame]
    """

    path: str
    attrs: dict
    tables: dict

    @property
    def n(self):
        """Number of interfaces (int)."""
        return int(self.attrs["n_interfaces"])

    @property
    def regime(self):
        """Driving regime, "stiff" or "compliant" (str)."""
        return str(self.attrs["regime"])


def _python_value(value):
    if isinstance(value, bytes):
        value = value.decode()
    if isinstance(value, str):
        try:
            decoded = json.loads(value)
        except ValueError:
            return value
        return decoded if isinstance(decoded, (dict, list)) else value
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_analysis_file(path, fmt, tables):
    """Read the named tables and the root attributes of an analysis file of a fem run.

    Parameters
    ----------
    path : str or pathlib.Path
    fmt : str
        The file's format (``"event-table"``, ``"front-table"``); its version is checked.
    tables : Iterable[str]
        Names of the tables to read (e.g. ``("increments", "slips")``).

    Returns
    -------
    AnalysisFile

    Raises
    ------
    FileFormatError
        If the file is not of format ``fmt`` in its current version, or a table or the attributes
        ``n_interfaces``/``regime``/``phi`` are missing.
    """
    with open_analysis_file(path, fmt) as file:
        attrs = {key: _python_value(value) for key, value in file.attrs.items()}
        for key in ("n_interfaces", "regime", "phi"):
            if key not in attrs:
                raise FileFormatError(f"{path}: attribute '{key}' missing (not an analysis file of a fem run?)")
        data = {name: h5io.read_table(file, name) for name in tables}
    return AnalysisFile(path=str(path), attrs=attrs, tables=data)


def group_runs(files, keys=("regime", "n_interfaces")):
    """Group analysis files by attribute values, in a reproducible order.

    Parameters
    ----------
    files : Iterable[AnalysisFile]
    keys : tuple[str, ...]
        Attribute names.

    Returns
    -------
    dict[tuple, list[AnalysisFile]]
        Keys sorted; within a group, files sorted by (N, seed, path).
    """
    groups = defaultdict(list)
    for item in files:
        groups[tuple(item.attrs[k] for k in keys)].append(item)
    order = lambda f: (f.attrs.get("N", 0), f.attrs.get("seed", 0), f.path)  # noqa: E731
    return {key: sorted(groups[key], key=order) for key in sorted(groups)}


def pooled(files, table):
    """Concatenate one table over several files.

    Parameters
    ----------
    files : Iterable[AnalysisFile]
    table : str

    Returns
    -------
    pandas.DataFrame
        Empty (no columns) if ``files`` is empty.
    """
    parts = [f.tables[table] for f in files]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()
