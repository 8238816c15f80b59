"""The ``front-table`` format: block failures and rupture fronts of re-run slip events.

A file of this format (written by :func:`stickslip.formats.analysis_file.write_analysis_file`,
the ``front-dynamics`` analysis, :mod:`stickslip.events.fronts`) holds two tables with the
columns and dtypes below, and the attributes of the run it re-ran (``N``, ``n_interfaces``,
``phi``, ``regime``, ``seed``, ...) plus ``interface_spacing`` [FE length]:

``failures``
    one row per block failure (a well hop of an interface block) of every re-run event:
    ``increment`` (the stored kick increment), ``a`` (interface, 1 = lowest), ``block``
    (0 ... N-1), ``t`` (time since the kick [FE time]), ``direction`` (+1 forward, -1 backward);
``fronts``
    one row per re-run event: ``increment``, ``s`` (slipping interfaces), ``a_first``,
    ``a_second`` (0 if fewer than two slip), ``nucleation`` (block of the first failure),
    ``meeting`` (block both branches of the front reach last), ``c_f`` (front speed of the first
    slipping interface [c_s]: the mean of the branches whose fit is meaningful, NaN if none),
    ``fit`` ("ok" or the reasons), per branch ``right`` / ``left``: ``c_f_<b>`` [c_s],
    ``t0_<b>`` [FE time], ``points_<b>``, ``r2_<b>``, ``quality_<b>`` (text); ``t_first`` (first
    failure [FE time]), ``tau`` (delay between the first failures of the first two slipping
    interfaces [H / c_s]). See :func:`stickslip.events.fronts.analyse_event`.

Version 2 (issue 23): the per-branch columns, ``meeting`` and ``fit`` replace ``fit_t0`` and ``fit_points``.
"""

from ..h5io import FileFormatError, read_table
from .analysis_file import open_analysis_file

__all__ = ["FORMAT", "FAILURE_DTYPES", "FRONT_DTYPES", "TABLES", "read_front_tables"]

FORMAT = "front-table"

#: Columns of the table "failures" (one row per block failure) and their dtypes.
FAILURE_DTYPES = {"increment": "int64", "a": "int64", "block": "int64", "t": "float64", "direction": "int64"}

#: Columns of the table "fronts" (one row per re-run event) and their dtypes.
FRONT_DTYPES = {"increment": "int64", "s": "int64", "a_first": "int64", "a_second": "int64", "nucleation": "int64",
                "meeting": "int64", "c_f": "float64", "fit": "object",
                **{f"{column}_{side}": dtype for side in ("right", "left")
                   for column, dtype in (("c_f", "float64"), ("t0", "float64"), ("points", "int64"),
                                         ("r2", "float64"), ("quality", "object"))},
                "t_first": "float64", "tau": "float64"}

#: The tables of a file and their columns.
TABLES = {"failures": FAILURE_DTYPES, "fronts": FRONT_DTYPES}


def read_front_tables(path):
    """Read the tables ``failures`` and ``fronts`` of a ``front-table`` file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    dict[str, pandas.DataFrame]
        ``failures`` and ``fronts``, with the columns of :data:`TABLES` in their dtypes.

    Raises
    ------
    FileFormatError
        If the file is not a ``front-table`` file of the current version, or a table lacks a column.
    """
    with open_analysis_file(path, FORMAT) as file:
        tables = {name: read_table(file, name) for name in TABLES}
    for name, dtypes in TABLES.items():
        missing = [c for c in dtypes if c not in tables[name].columns]
        if missing:
            raise FileFormatError(f"{path}: table {name!r} lacks column(s) {', '.join(missing)}")
        tables[name] = tables[name][list(dtypes)].astype(dtypes)
    return tables
