"""What the experimental figures share: reading ``experiment-events`` files, the time series
a table came from (its lineage), and the time excerpts of panels.

Every figure receives the ``experiment-events`` outputs as artifacts, each with the time series
it analysed as ``parent`` (:class:`stickslip.lineage.Artifact`), and groups runs by the
attributes stored in the files: ``n`` (driven slabs), ``protocol`` ("stack" or "individual")
and ``a`` (slab driven alone).
"""

import pandas as pd

from .. import h5io
from ..experiment.timeseries import read_timeseries
from ..formats import event_table
from ..formats.analysis_file import open_analysis_file

__all__ = ["EVENTS", "load_slips", "load_interfaces", "example_run", "excerpt"]

#: Input category of the experimental figures.
EVENTS = "analysis:experiment-events"

_RUN_ATTRS = ("n", "protocol", "a", "seed", "normal_force", "k_spring", "h", "H", "V")


def _run_attrs(f, path):
    attrs = {}
    for name in ("n", "protocol", "a"):
        if name not in f.attrs:
            raise h5io.FileFormatError(f"{path}: attribute '{name}' is missing (not an experiment-events file?)")
    for name in _RUN_ATTRS:
        if name in f.attrs:
            value = f.attrs[name]
            attrs[name] = value.decode() if isinstance(value, bytes) else value
    attrs["n"], attrs["a"] = int(attrs["n"]), int(attrs["a"])
    attrs["protocol"] = str(attrs["protocol"])
    attrs["file"] = str(path)
    return attrs


def _load(paths, table):
    frames = []
    for path in sorted(map(str, paths)):
        with open_analysis_file(path, event_table.FORMAT) as f:
            attrs = _run_attrs(f, path)
            data = h5io.read_table(f, table)
        data = data.drop(columns=[c for c in ("n", "protocol") if c in data.columns])
        frames.append(data.assign(**{("a_driven" if k == "a" else k): v for k, v in attrs.items()}))
    if not frames:
        raise h5io.FileFormatError(f"no {EVENTS} files given")
    return pd.concat(frames, ignore_index=True)


def load_slips(paths):
    """All slips of several ``experiment-events`` files in one table.

    Parameters
    ----------
    paths : list of str or pathlib.Path

    Returns
    -------
    pandas.DataFrame
        The ``slips`` table of every file (see :func:`stickslip.experiment.analysis.analyse_record`)
        plus the run's ``n``, ``protocol``, ``a_driven`` (attribute ``a``), ``seed`` (if stored),
        apparatus constants ``normal_force`` [N], ``k_spring`` [N/mm], ``h``, ``H`` [mm], ``V``
        [mm/s], and ``file``.
    """
    return _load(paths, "slips")


def load_interfaces(paths):
    """All ``interfaces`` tables (``a``, ``R_tot``, ``dR_sum``, ``R_slow``, ...) with the run attributes."""
    return _load(paths, "interfaces")


def example_run(slips, events, *, n, protocol="stack"):
    """The first run (sorted by seed, then path) with ``n`` and ``protocol``: its time series and slips.

    Parameters
    ----------
    slips : pandas.DataFrame
        :func:`load_slips` of the ``experiment-events`` files.
    events : list of stickslip.lineage.Artifact
        The ``experiment-events`` outputs, each with its time series as ``parent``.
    n : int
    protocol : str

    Returns
    -------
    record : stickslip.experiment.timeseries.ExperimentRecord
    slips : pandas.DataFrame

    Raises
    ------
    stickslip.h5io.FileFormatError
        If no such run is given, or its events file comes without its time series.
    """
    runs = slips[(slips["n"] == n) & (slips["protocol"] == protocol)]
    if runs.empty:
        raise h5io.FileFormatError(f"no {EVENTS} file with n = {n} and protocol '{protocol}' among the inputs")
    order = runs.sort_values([c for c in ("seed", "file") if c in runs.columns])
    chosen = order["file"].iloc[0]
    artifact = next(item for item in events if str(item) == chosen)
    if artifact.parent is None:
        raise h5io.FileFormatError(f"{chosen}: given without the time series it was made from (its lineage)")
    return read_timeseries(artifact.parent), runs[runs["file"] == chosen]


def excerpt(record, t_from, duration):
    """Time range ``(t_0, t_1)`` [s] of length ``duration`` from ``t_from``, moved back to end with the
    record if it is shorter."""
    end = min(t_from + duration, record.t_x[-1])
    return (max(record.t_x[0], end - duration), end)
