"""Panels of the periodicity and synchronisation measures (:mod:`stickslip.events.periodicity`),
shared by fig2 (against n) and figS-phi-sweep (against Phi): per-run values averaged over the
runs (seeds) of each point, error bars one standard error over the runs.
"""

import numpy as np
import pandas as pd

from ..events.periodicity import MEASURES, TABLE, seed_summary

__all__ = ["MEASURE_LABEL", "MEASURE_MARKER", "periodicity_rows", "periodicity_summary", "plot_measure"]

#: Axis / legend label of each measure.
MEASURE_LABEL = {
    "interval_cv": r"CV of $\Delta\gamma$ between slips",
    "drop_cv": r"CV of $\Delta\Sigma$",
    "multi_fraction": r"$\rho(s > 1)$",
    "spanning_fraction": r"$\rho(s = n)$ (all interfaces)",
    "alternation_cv": "CV of singles between multis",
    "runs_z": "runs test z (single/multi order)",
}

#: Marker of each measure where several share a panel.
MEASURE_MARKER = {"interval_cv": "o", "drop_cv": "s", "multi_fraction": "D", "spanning_fraction": "^",
                  "alternation_cv": "v", "runs_z": "P"}


def periodicity_rows(files, keys):
    """One row per run: the ``keys`` (functions of the file) and its ``periodicity`` table.

    Parameters
    ----------
    files : Iterable[stickslip.events.analysis_files.AnalysisFile]
        ``numerical-events`` files read with the table ``periodicity``.
    keys : Mapping[str, Callable[[AnalysisFile], object]]
        Column name -> value of a file (e.g. ``{"n": lambda f: f.n}``).

    Returns
    -------
    pandas.DataFrame
    """
    rows = [{**{name: key(item) for name, key in keys.items()}, **item.tables[TABLE].iloc[0].to_dict()}
            for item in files]
    return pd.DataFrame(rows)


def periodicity_summary(files, keys):
    """:func:`stickslip.events.periodicity.seed_summary` of :func:`periodicity_rows` grouped by ``keys``."""
    rows = periodicity_rows(files, keys)
    return seed_summary(rows, list(keys)) if len(rows) else pd.DataFrame()


def plot_measure(ax, rows, x, measure, **style):
    """Draw one measure of a :func:`periodicity_summary` against column ``x`` with its seed error bars.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    rows : pandas.DataFrame
        Rows of one series (e.g. one regime or one n), sorted by ``x``.
    x : str
    measure : str
        One of :data:`stickslip.events.periodicity.MEASURES`.
    **style
        Forwarded to :meth:`matplotlib.axes.Axes.errorbar`.
    """
    if measure not in MEASURES:
        raise ValueError(f"unknown periodicity measure {measure!r}")
    y = rows[measure].to_numpy(dtype=float)
    error = rows[f"{measure}_error"].to_numpy(dtype=float)
    ax.errorbar(rows[x].to_numpy(dtype=float), y, yerr=np.where(np.isfinite(error), error, 0.0), capsize=2,
                markersize=4, **style)
