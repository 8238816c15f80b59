"""The ``event-table`` format: slip events, one row per (event, slipping interface).

A file of this format (written by :func:`stickslip.formats.analysis_file.write_analysis_file`)
holds the table ``slip_events`` with the columns of :data:`COLUMNS`, normalised so that
the results database ingests it as it is, followed by any further numeric or boolean
columns of the analysis (the database keeps them as JSON in ``extra``); the analysis may
add tables of its own beside it. Numerical (``numerical-events``) and experimental
(``experiment-events``) analyses both produce it.
"""

import numpy as np
import pandas as pd

from ..h5io import FileFormatError, read_table
from .analysis_file import open_analysis_file

__all__ = ["FORMAT", "TABLE", "COLUMNS", "REQUIRED", "slip_events_table", "read_slip_events"]

FORMAT = "event-table"

#: Name of the normalised table.
TABLE = "slip_events"

#: Columns: name -> (dtype, meaning). Optional columns may be left out; an analysis
#: without a quantity leaves its column out (the database stores NULL).
COLUMNS = {
    "event": ("int64", "event index within the run, from 0"),
    "interface": ("int64", "interface (slab) a that slipped, 1 = lowest"),
    "multi": ("bool", "more than one interface slipped in the event"),
    "slip": ("float64", "slip of the interface [mm] (experimental)"),
    "dmu": ("float64", "drop of friction coefficient [-] (experimental) or interface stress [sig0] (numerical)"),
    "time": ("float64", "time of the slip [s] (experimental)"),
    "increment": ("int64", "increment of the event (numerical)"),
}

#: Columns every table has.
REQUIRED = ("event", "interface", "multi")


def slip_events_table(table, source="slip table"):
    """Check and normalise a slip-event table: :data:`COLUMNS` first, in order and with their dtypes.

    Parameters
    ----------
    table : pandas.DataFrame
        All columns of :data:`REQUIRED`, optional ones of :data:`COLUMNS`, then any further
        numeric or boolean columns (kept as they are, after the standard ones).
    source : str
        For messages.

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    FileFormatError
        If a required column is missing or a further column is not numeric or boolean.
    """
    missing = [c for c in REQUIRED if c not in table.columns]
    if missing:
        raise FileFormatError(f"{source}: slip-event table lacks column(s) {', '.join(missing)}")
    further = [c for c in table.columns if c not in COLUMNS]
    textual = [c for c in further if np.asarray(table[c]).dtype.kind not in "biuf"]
    if textual:
        raise FileFormatError(f"{source}: slip-event column(s) {', '.join(textual)} must be numbers or booleans")
    columns = [c for c in COLUMNS if c in table.columns]
    data = {c: np.asarray(table[c]).astype(COLUMNS[c][0]) for c in columns}
    data.update({c: np.asarray(table[c]) for c in further})
    return pd.DataFrame(data, columns=columns + further)


def read_slip_events(path):
    """Read the ``slip_events`` table of an ``event-table`` file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    pandas.DataFrame
        Columns among :data:`COLUMNS`.

    Raises
    ------
    FileFormatError
        If the file is not an ``event-table`` file of the current version, or the table is malformed.
    """
    with open_analysis_file(path, FORMAT) as file:
        table = read_table(file, TABLE)
    return slip_events_table(table, source=str(path))
