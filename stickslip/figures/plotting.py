"""Plot helpers shared by every figure: the bins (one place: :func:`range_edges`,
:func:`linear_edges`, :func:`log_edges`), probability densities, the style of ``n`` and ``a``,
values against ``n`` (lines only between neighbouring ``n``), legends beside the axes, and panel
letters.
"""

import numpy as np

from .style import N_MARKERS, interface_color, n_color

__all__ = ["density", "plot_density", "range_edges", "linear_edges", "log_edges", "n_style",
           "individual_style", "a_style", "hollow", "plot_against_n", "legend_outside", "label_panels"]


def range_edges(values, bins):
    """``bins`` equal bins spanning the finite ``values`` (a unit-wide bin around a single value).

    Parameters
    ----------
    values : array_like
        Shape [k]; NaN entries are ignored.
    bins : int

    Returns
    -------
    numpy.ndarray
        Edges, shape [bins + 1], in units of ``values``.
    """
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    low, high = (values.min(), values.max()) if values.size else (0.0, 1.0)
    if high == low:
        low, high = low - 0.5, high + 0.5
    return np.linspace(low, high, bins + 1)


def linear_edges(values, bins=25):
    """``bins`` equal bins from 0 to the 99.5th percentile of the finite ``values``."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    top = np.percentile(values, 99.5) if values.size else 1.0
    return np.linspace(0.0, top * 1.02 if top > 0 else 1.0, bins + 1)


def log_edges(values, per_decade=8):
    """Logarithmic bins (``per_decade`` per factor 10) that cover the positive finite ``values``."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values) & (values > 0)]
    if not values.size:
        return np.logspace(0, 1, per_decade + 1)
    low = np.floor(np.log10(values.min()) * per_decade)
    high = np.ceil(np.log10(values.max()) * per_decade)
    return 10.0 ** (np.arange(low, max(high, low + 1) + 1) / per_decade)


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


def hollow(style, size=4.0):
    """``style`` (of :func:`a_style` or :func:`n_style`) with open markers of ``size`` [pt]: markers of
    different shapes and sizes stay distinguishable where they overlap."""
    return {**style, "markerfacecolor": "none", "markeredgecolor": style["color"], "markersize": size,
            "markeredgewidth": 0.8}


def plot_against_n(ax, n, values, errors=None, **style):
    """Values measured at integer ``n``: markers at every point (with error bars if ``errors``), lines
    only between neighbouring ``n`` (``n`` and ``n + 1`` both measured), so that no line crosses an
    ``n`` that was not measured.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    n, values : array_like
        Shape [k], ``n`` increasing (integers, or integers plus a common offset).
    errors : array_like, optional
        Half-lengths of the error bars, shape [k].
    **style
        Colour, marker, label (:func:`a_style`); the label goes to the markers only.

    Returns
    -------
    matplotlib.container.ErrorbarContainer or matplotlib.lines.Line2D
        The markers.
    """
    n, values = np.asarray(n, dtype=float), np.asarray(values, dtype=float)
    line_style = {key: value for key, value in style.items() if key in ("color", "linewidth", "linestyle")}
    breaks = np.flatnonzero(np.diff(n) != 1.0) + 1
    for part in np.split(np.arange(n.size), breaks):
        if part.size > 1:
            ax.plot(n[part], values[part], marker="none", **{"linewidth": 1.0, **line_style})
    if errors is None:
        return ax.plot(n, values, linestyle="none", **style)[0]
    return ax.errorbar(n, values, yerr=errors, linestyle="none", capsize=2, **style)


def legend_outside(ax, **options):
    """The legend of ``ax`` beside it, to the right (off the data), without a frame."""
    return ax.legend(**{"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "borderaxespad": 0.0, "frameon": False,
                        "fontsize": 6.5, "title_fontsize": 6.5, **options})


def label_panels(axes, letters="abcdefghijklmnopqrstuvwxyz"):
    """Write (a), (b), ... (or the given ``letters``) above the top-left corner of each axis."""
    for letter, ax in zip(letters, np.ravel(axes)):
        ax.set_title(f"({letter})", loc="left", fontweight="bold", fontsize=9)
