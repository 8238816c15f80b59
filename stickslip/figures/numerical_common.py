"""Helpers shared by the figures of the numerical study (fig2, figS-dgamma, figS-sequences,
figS-event-maps, figS-tau): reading their inputs, line styles per driving regime, densities.
"""

import numpy as np

from ..events.results import read_analysis_file
from ..h5io import FileFormatError
from .style import N_MARKERS, n_color

__all__ = ["REGIME_LINESTYLE", "REGIME_LABEL", "read_inputs", "density", "plot_density", "n_style", "panel_label"]

#: The paper's convention: stiff driving dashed, compliant solid.
REGIME_LINESTYLE = {"stiff": "--", "compliant": "-"}

REGIME_LABEL = {"stiff": "stiff driving", "compliant": "compliant driving"}


def read_inputs(inputs, category, tables, figure):
    """Read every analysis file of one input category.

    Parameters
    ----------
    inputs : Mapping[str, Sequence[str or pathlib.Path]]
        The figure's inputs, by category.
    category : str
        E.g. ``"analysis:numerical-events"``.
    tables : tuple[str, ...]
        Tables to read from each file.
    figure : str
        Figure name, for error messages.

    Returns
    -------
    list[stickslip.events.results.AnalysisFile]

    Raises
    ------
    FileFormatError
        If the category has no file.
    """
    paths = list(inputs.get(category, []))
    if not paths:
        raise FileFormatError(f"figure '{figure}': no input file of category '{category}'")
    return [read_analysis_file(path, tables) for path in paths]


def density(values, bins):
    """Probability density of ``values`` on ``bins`` equal bins spanning their range.

    Parameters
    ----------
    values : array_like
        Shape [k]; NaN are dropped.
    bins : int

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray]
        Bin centres [bins] and density [bins] (integrates to 1); empty arrays without data.
    """
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return np.zeros(0), np.zeros(0)
    low, high = values.min(), values.max()
    if high == low:
        low, high = low - 0.5, high + 0.5
    counts, edges = np.histogram(values, bins=bins, range=(low, high), density=True)
    return 0.5 * (edges[1:] + edges[:-1]), counts


def n_style(n):
    """Colour and marker of a stack of ``n`` interfaces (dict for ``Axes.plot``)."""
    return {"color": n_color(n), "marker": N_MARKERS[(int(n) - 1) % len(N_MARKERS)]}


def plot_density(ax, values, bins, **style):
    """Plot the density of ``values`` (see :func:`density`) as a line with markers, if there are any."""
    x, p = density(values, bins)
    if x.size:
        ax.plot(x, p, markersize=3, **style)


def panel_label(ax, letter):
    """Write ``(letter)`` above the top-left corner of ``ax``."""
    ax.set_title(f"({letter})", loc="left", fontweight="bold", fontsize=9)
