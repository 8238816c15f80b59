"""Shared figure style: one colour per interface (as in the paper), and saving.

Every figure module uses :func:`interface_color` for anything tied to interface
(or slab) ``a`` and :func:`save_figure` to write its PDF and the PNG beside it.
"""

from pathlib import Path

import matplotlib.pyplot as plt

__all__ = ["INTERFACE_COLORS", "interface_color", "n_color", "save_figure", "plt"]

#: Interface (slab) a = 1 ... 5, from the lowest: purple to orange, as the paper's colour code.
INTERFACE_COLORS = ("#5e3c99", "#2c7fb8", "#1b9e77", "#e6ab02", "#e66101")

#: Markers per number of driven interfaces n = 1 ... 5.
N_MARKERS = ("o", "s", "^", "D", "v")


def interface_color(a):
    """Colour of interface (or slab) ``a`` (1 = lowest); cycles beyond 5."""
    return INTERFACE_COLORS[(int(a) - 1) % len(INTERFACE_COLORS)]


def n_color(n, n_max=5):
    """Colour of a stack of ``n`` driven interfaces on a sequential scale (1 ... n_max)."""
    return plt.get_cmap("viridis")((int(n) - 1) / max(n_max - 1, 1))


def save_figure(fig, output):
    """Write ``fig`` to ``output`` (PDF) and to the PNG beside it, then close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    output : str or pathlib.Path
        Path ending in ``.pdf``.

    Returns
    -------
    tuple[pathlib.Path, pathlib.Path]
        The PDF and PNG paths.
    """
    output = Path(output)
    if output.suffix != ".pdf":
        raise ValueError(f"figure output must end in .pdf, got {output}")
    output.parent.mkdir(parents=True, exist_ok=True)
    png = output.with_suffix(".png")
    # Fixed metadata: the same figure gives the same PDF bytes.
    fig.savefig(output, metadata={"CreationDate": None, "ModDate": None, "Producer": "stickslip"})
    fig.savefig(png, dpi=150, metadata={"Software": "stickslip"})
    plt.close(fig)
    return output, png
