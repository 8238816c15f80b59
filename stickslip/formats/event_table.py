"""The ``event-table`` format: slip events, one row per (event, slipping interface).

A file of this format (written by :func:`stickslip.formats.analysis_file.write_analysis_file`)
holds the table ``slip_events`` with the columns of :data:`COLUMNS`, normalised so that
the results database ingests it as it is, followed by any further numeric or boolean
columns of the analysis (the database keeps them as JSON in ``extra``); the analysis may
add tables of its own beside it. Numerical (``numerical-events``) and experimental
(``experiment-events``) analyses both produce it.

An optional one-row table ``periodicity`` (:data:`PERIODICITY_COLUMNS`) holds the periodicity
and synchronisation measures of the run's slip events (:mod:`stickslip.events.periodicity`);
the database keeps it in its table ``run_periodicity``.

Version 2: the package's vocabulary (:mod:`stickslip.vocabulary`): a numerical analysis writes its drops in
``dmu_sig0`` [sig0] and its clock in ``t`` [time], leaving ``dmu`` [1] and ``time`` [s] to the lab's; the
periodicity counts are ``n_slips``, ``n_multi``, ``n_spanning``.
"""

import numpy as np
import pandas as pd

from ..h5io import FileFormatError, read_table
from ..vocabulary import QUANTITIES
from .analysis_file import open_analysis_file

__all__ = ["FORMAT", "TABLE", "COLUMNS", "REQUIRED", "PERIODICITY_TABLE", "PERIODICITY_COLUMNS", "slip_events_table",
           "read_slip_events", "read_periodicity"]

FORMAT = "event-table"

#: Name of the normalised table.
TABLE = "slip_events"

#: Columns: name -> (dtype, meaning), in order (:data:`stickslip.vocabulary.QUANTITIES`, units there). Optional
#: columns may be left out; an analysis without a quantity leaves its column out (the database stores NULL).
#: The lab's drop and clock (``dmu`` [1], ``time`` [s]) and the model's (``dmu_sig0`` [sig0], ``t`` [time])
#: are separate columns.
COLUMNS = {name: (QUANTITIES[name].dtype, QUANTITIES[name].doc)
           for name in ("event", "interface", "multi", "slip", "dmu", "dmu_sig0", "time", "t", "increment")}

#: Columns every table has.
REQUIRED = ("event", "interface", "multi")

#: Name of the optional one-row table of the run's periodicity measures.
PERIODICITY_TABLE = "periodicity"

#: Its columns: name -> (dtype, meaning); every one is present (NaN where undefined).
PERIODICITY_COLUMNS = {name: (QUANTITIES[name].dtype, QUANTITIES[name].doc)
                       for name in ("n_slips", "n_multi", "n_spanning", "interval_cv", "drop_cv", "multi_fraction",
                                    "spanning_fraction", "alternation_cv", "runs_z")}


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


def read_periodicity(path):
    """Read the optional ``periodicity`` table of an ``event-table`` file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    pandas.DataFrame or None
        One row, columns :data:`PERIODICITY_COLUMNS`; None if the file has no such table.

    Raises
    ------
    FileFormatError
        If the file is not an ``event-table`` file of the current version, or the table lacks a column.
    """
    with open_analysis_file(path, FORMAT) as file:
        if PERIODICITY_TABLE not in file:
            return None
        table = read_table(file, PERIODICITY_TABLE)
    missing = [c for c in PERIODICITY_COLUMNS if c not in table.columns]
    if missing:
        raise FileFormatError(f"{path}: table '{PERIODICITY_TABLE}' lacks column(s) {', '.join(missing)}")
    return table[list(PERIODICITY_COLUMNS)].astype({c: dtype for c, (dtype, _) in PERIODICITY_COLUMNS.items()})
