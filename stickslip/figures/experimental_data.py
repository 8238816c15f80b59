"""What the experimental figures share: reading ``experiment-events`` files, the time series
a table came from (its lineage), the runs that panels show, and the time excerpts of panels.

Every figure receives the ``experiment-events`` outputs as artifacts, each with the time series
it analysed as ``parent`` (:class:`stickslip.lineage.Artifact`), and groups runs by the
attributes stored in the files: ``n`` (driven slabs), ``protocol`` ("stack" or "individual"),
``a`` (slab driven alone) and ``slab_order`` (the physical slab at each position; written by
``rate-state-lever``, absent in other files: in order). Runs with the slabs shuffled (the paper's
control) are left out of every table unless asked for: only figS-slow-slip shows them.
"""

import json

import numpy as np
import pandas as pd

from .. import h5io
from ..experiment.timeseries import read_timeseries
from ..formats import event_table
from ..formats.analysis_file import open_analysis_file

__all__ = ["EVENTS", "load_slips", "load_interfaces", "example_run", "median_run", "excerpt"]

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
    order = f.attrs.get("slab_order")
    order = json.loads(order) if order is not None else list(range(1, int(f.attrs.get("n_slabs", 5)) + 1))
    attrs["slab_order"] = ",".join(map(str, order))
    attrs["shuffled"] = order != sorted(order)
    attrs["file"] = str(path)
    return attrs


def _load(paths, table, shuffled):
    frames = []
    for path in sorted(map(str, paths)):
        with open_analysis_file(path, event_table.FORMAT) as f:
            attrs = _run_attrs(f, path)
            if attrs["shuffled"] and not shuffled:
                continue
            data = h5io.read_table(f, table)
        data = data.drop(columns=[c for c in ("n", "protocol") if c in data.columns])
        frames.append(data.assign(**{("driven_slab" if k == "a" else k): v for k, v in attrs.items()}))
    if not frames:
        raise h5io.FileFormatError(f"no {EVENTS} files given" if not paths else f"only shuffled runs among the "
                                   f"{len(paths)} {EVENTS} files given")
    return pd.concat(frames, ignore_index=True)


def load_slips(paths, *, shuffled=False):
    """All slips of several ``experiment-events`` files in one table.

    Parameters
    ----------
    paths : list of str or pathlib.Path

    Returns
    -------
    pandas.DataFrame
        The ``slips`` table of every file (see :func:`stickslip.experiment.analysis.analyse_record`)
        plus the run's ``n``, ``protocol``, ``driven_slab`` (attribute ``a``), ``seed`` (if stored),
        apparatus constants ``normal_force`` [N], ``k_spring`` [N/mm], ``h``, ``H`` [mm], ``V``
        [mm/s], ``slab_order`` (text, e.g. "4,3,2,1,5"), ``shuffled`` and ``file``.
    shuffled : bool
        Include the runs with the slabs shuffled (default: leave them out).
    """
    return _load(paths, "slips", shuffled)


def load_interfaces(paths, *, shuffled=False):
    """All ``interfaces`` tables (``a``, ``R_tot``, ``dR_sum``, ``R_slow``, ...) with the run attributes
    (shuffled runs only if ``shuffled``)."""
    return _load(paths, "interfaces", shuffled)


def _record_of(events, file):
    """The time series that the ``experiment-events`` output ``file`` (one of ``events``) analysed."""
    artifact = next(item for item in events if str(item) == file)
    if artifact.parent is None:
        raise h5io.FileFormatError(f"{file}: given without the time series it was made from (its lineage)")
    return read_timeseries(artifact.parent)


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
    return _record_of(events, chosen), runs[runs["file"] == chosen]


def median_run(interfaces, events, *, n, a):
    """The stack run with ``n`` driven slabs whose slow-slip fraction ``R_slow`` of interface ``a`` is
    the median of those runs (the lower of the two middle ones for an even number): a typical run.

    Parameters
    ----------
    interfaces : pandas.DataFrame
        :func:`load_interfaces` of the ``experiment-events`` files.
    events : list of stickslip.lineage.Artifact
        The ``experiment-events`` outputs, each with its time series as ``parent``.
    n, a : int

    Returns
    -------
    record : stickslip.experiment.timeseries.ExperimentRecord
    file : str
        Its ``experiment-events`` file.
    R_slow : float
        Its ``R_slow`` of ``a``.
    rank : tuple of int
        ``(rank, count)``: its place (1-based) among the runs sorted by ``R_slow`` of ``a``.
    """
    runs = interfaces[(interfaces["protocol"] == "stack") & (interfaces["n"] == n) & (interfaces["interface"] == a)]
    runs = runs[np.isfinite(runs["R_slow"].to_numpy(dtype=float))]
    if runs.empty:
        raise h5io.FileFormatError(f"no {EVENTS} file with n = {n} and a slow-slip fraction of a = {a}")
    ordered = runs.sort_values(["R_slow", "file"], kind="stable")
    middle = (len(ordered) - 1) // 2
    chosen = ordered.iloc[middle]
    return _record_of(events, chosen["file"]), chosen["file"], float(chosen["R_slow"]), (middle + 1, len(ordered))


def excerpt(record, t_from, duration):
    """Time range ``(t_0, t_1)`` [s] of length ``duration`` from ``t_from``, moved back to end with the
    record if it is shorter."""
    end = min(t_from + duration, record.t_x[-1])
    return (max(record.t_x[0], end - duration), end)
