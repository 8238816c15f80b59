"""What the experimental figures share: reading ``experiment-events`` files, finding the
time series a table came from, probability densities, and the style of ``n`` and ``a``.

Every figure receives lists of paths and groups runs by the attributes stored in the files:
``n`` (driven slabs), ``protocol`` ("stack" or "individual") and ``a`` (slab driven alone).
"""

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd

from .. import h5io
from ..experiment.timeseries import read_timeseries
from .style import N_MARKERS, interface_color, n_color

__all__ = ["EVENTS", "LEVER", "load_slips", "load_interfaces", "example_run", "excerpt", "density", "plot_density",
           "n_style", "individual_style", "a_style", "label_panels"]

#: Input categories of the experimental figures.
EVENTS = "analysis:experiment-events"
LEVER = "solver:lever"

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
        with h5io.open_file(path) as f:
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


def _sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def example_run(slips, lever_paths, *, n, protocol="stack"):
    """The first run (sorted by seed, then path) with ``n`` and ``protocol``: its time series and slips.

    Parameters
    ----------
    slips : pandas.DataFrame
        :func:`load_slips` of the ``experiment-events`` files.
    lever_paths : list of str or pathlib.Path
        Time-series files; a table is matched to its time series by the SHA-256 of the analysed
        file (attribute ``input_sha256`` of the table's file).
    n : int
    protocol : str

    Returns
    -------
    record : stickslip.experiment.timeseries.ExperimentRecord
    slips : pandas.DataFrame

    Raises
    ------
    stickslip.h5io.FileFormatError
        If no such run, or no time series matching its table, is given.
    """
    runs = slips[(slips["n"] == n) & (slips["protocol"] == protocol)]
    if runs.empty:
        raise h5io.FileFormatError(f"no {EVENTS} file with n = {n} and protocol '{protocol}' among the inputs")
    order = runs.sort_values([c for c in ("seed", "file") if c in runs.columns])
    chosen = order["file"].iloc[0]
    with h5io.open_file(chosen) as f:
        digest = f.attrs["input_sha256"]
    for path in lever_paths:
        with h5io.open_file(path) as f:
            same = int(f.attrs.get("n", -1)) == n and f.attrs.get("protocol", "") == protocol
        if same and _sha256(path) == digest:
            return read_timeseries(path), runs[runs["file"] == chosen]
    raise h5io.FileFormatError(f"{chosen}: none of the {LEVER} inputs is the time series it was made from")


def excerpt(record, t_from, duration):
    """Time range ``(t_0, t_1)`` [s] of length ``duration`` from ``t_from``, moved back to end with the
    record if it is shorter."""
    end = min(t_from + duration, record.t_x[-1])
    return (max(record.t_x[0], end - duration), end)


def density(values, edges):
    """Probability density of ``values`` on the bins ``edges``.

    Parameters
    ----------
    values : array_like
        NaN entries are ignored.
    edges : numpy.ndarray, shape (m + 1,)

    Returns
    -------
    centres : numpy.ndarray, shape (m,)
        Bin centres (geometric centres if the edges are logarithmic, i.e. all > 0 and of constant
        ratio).
    pdf : numpy.ndarray, shape (m,)
        ``count / (total * width)``, NaN where the bin is empty (so that lines skip it).
    """
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    counts, _ = np.histogram(values, edges)
    widths = np.diff(edges)
    with np.errstate(invalid="ignore", divide="ignore"):
        pdf = counts / (max(values.size, 1) * widths)
    ratio = edges[1:] / edges[:-1] if np.all(edges > 0) else None
    logarithmic = ratio is not None and np.allclose(ratio, ratio[0])
    centres = np.sqrt(edges[1:] * edges[:-1]) if logarithmic else 0.5 * (edges[1:] + edges[:-1])
    return centres, np.where(counts > 0, pdf, np.nan)


def plot_density(ax, values, edges, *, logarithmic=False, **style):
    """Draw ``P(values)`` on ``ax`` as a line with markers.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    values : array_like
    edges : numpy.ndarray
        Bin edges, in units of ``values``.
    logarithmic : bool
        Draw the density of ``log10(values)`` (per decade) at the bin centres, for an axis in
        logarithmic scale; ``edges`` must then be positive.
    **style
        Forwarded to :meth:`matplotlib.axes.Axes.plot`.

    Returns
    -------
    matplotlib.lines.Line2D or None
        None if there is no finite value.
    """
    values = np.asarray(values, dtype=float)
    if not np.isfinite(values).any():
        return None
    if logarithmic:
        with np.errstate(divide="ignore", invalid="ignore"):
            centres, pdf = density(np.log10(values), np.log10(edges))
        centres = 10.0 ** centres
    else:
        centres, pdf = density(values, edges)
    return ax.plot(centres, pdf, markersize=3.5, linewidth=1.0, **style)[0]


def n_style(n):
    """Colour, marker and label of a stack of ``n`` driven slabs."""
    return {"color": n_color(n), "marker": N_MARKERS[(int(n) - 1) % len(N_MARKERS)], "label": f"$n = {int(n)}$"}


def individual_style():
    """Style of an interface driven alone (the paper's black ``n = 1`` reference)."""
    return {"color": "black", "marker": "o", "label": "$n = 1$ (individual)"}


def a_style(a):
    """Colour, marker and label of interface ``a``."""
    return {"color": interface_color(a), "marker": N_MARKERS[(int(a) - 1) % len(N_MARKERS)], "label": f"$a = {int(a)}$"}


def label_panels(axes):
    """Write (a), (b), ... above the top-left corner of each axis."""
    for letter, ax in zip("abcdefghijklmnopqrstuvwxyz", np.ravel(axes)):
        ax.set_title(f"({letter})", loc="left", fontsize=9)
