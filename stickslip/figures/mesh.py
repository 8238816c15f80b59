"""SI figure "Finite element mesh of the numerical model" (n = 4 interfaces by default).

Left: the whole mesh, elements filled by layer (bottom plate grey, slab i in the
colour of interface i, interfaces dark), fixed bottom nodes marked, and a
schematic lever with one spring per driven plate at its mid-height. Right: a
zoom on the lowest interface that shows the fine rows and the first
refinement rows.
"""

import dataclasses

import numpy as np
from matplotlib.collections import PolyCollection

from ..h5io import FileFormatError, open_file
from ..mesh import interface_layer, read_mesh, read_mesh_params
from ..plugin_params import param
from ..registry import register
from .style import interface_color, plt, save_figure

__all__ = ["MeshFigureParams", "layer_colors", "plot_mesh", "select_mesh", "figure_mesh"]


def layer_colors(mesh):
    """Default fill colour of every layer, as in the paper's figures.

    The bottom plate (fixed, not driven) is grey, plate ``i >= 1`` has the colour
    of slab ``i`` (:func:`.style.interface_color`), interfaces
    are dark.

    Parameters
    ----------
    mesh : LayeredMesh

    Returns
    -------
    list
        nlayer matplotlib colours.
    """
    interfaces = {interface_layer(a) for a in range(1, mesh.n_interfaces + 1)}
    colors = []
    for layer in range(mesh.nlayer):
        if layer in interfaces:
            colors.append("0.15")
        elif layer == 0:
            colors.append("0.7")
        else:
            colors.append(interface_color(layer // 2))
    return colors


def plot_mesh(mesh, ax, *, colors=None, edge_width=0.2, edge_color="k", mark_fixed=True):
    """Draw every element of a mesh, filled by layer.

    Parameters
    ----------
    mesh : LayeredMesh
    ax : matplotlib.axes.Axes
    colors : Sequence, optional
        One fill colour per layer (nlayer); default :func:`layer_colors`.
    edge_width : float, optional
        Element edge line width [pt]; 0 draws no edges.
    edge_color : optional
        Element edge colour.
    mark_fixed : bool, optional
        Mark the bottom-edge nodes (both displacement components prescribed).

    Returns
    -------
    matplotlib.collections.PolyCollection
        The elements, in element order.
    """
    colors = layer_colors(mesh) if colors is None else list(colors)
    if len(colors) != mesh.nlayer:
        raise ValueError(f"colors: expected one colour per layer ({mesh.nlayer}), got {len(colors)}")
    fills = [colors[layer] for layer in mesh.elem_layer]
    elements = PolyCollection(mesh.coor[mesh.conn], facecolors=fills, edgecolors=edge_color,
                              linewidths=edge_width)
    ax.add_collection(elements)
    if mark_fixed:
        bottom = np.flatnonzero(mesh.coor[:, 1] == 0.0)
        ax.plot(mesh.coor[bottom, 0], mesh.coor[bottom, 1], ls="none", marker="^", ms=3, color="k",
                clip_on=False, label="fixed nodes")
    ax.set_xlim(0.0, mesh.length)
    ax.set_ylim(0.0, mesh.height)
    ax.set_aspect("equal")
    return elements


@dataclasses.dataclass(frozen=True)
class MeshFigureParams:
    """Which mesh to draw.

    Attributes
    ----------
    plates : int
        Plates of the mesh drawn (``plates - 1`` interfaces; the paper shows n = 4).
    N : int
        Blocks per interface of the mesh drawn; 0 takes the largest available.
    zoom_width : int
        Width of the zoom on the lowest interface, in blocks (no zoom if N is not larger).
    """

    plates: int = param(5, "plates of the mesh drawn (plates - 1 interfaces)", minimum=2, maximum=6)
    N: int = param(0, "blocks per interface of the mesh drawn (0: the largest available)", minimum=0)
    zoom_width: int = param(60, "width of the zoom on the lowest interface, in blocks (no zoom if N <= this)", minimum=1)


def select_mesh(paths, params):
    """Return the path of the mesh to draw among the study's mesh files.

    Parameters
    ----------
    paths : Sequence[str or pathlib.Path]
        Mesh files (see :func:`stickslip.mesh.write_mesh`).
    params : MeshFigureParams

    Returns
    -------
    str or pathlib.Path
        The mesh with ``params.plates`` plates and ``params.N`` blocks (or the
        largest N when ``params.N == 0``).

    Raises
    ------
    FileFormatError
        If no mesh matches; the message lists what is available.
    """
    available = []
    for path in paths:
        with open_file(path) as file:
            mesh_params = read_mesh_params(file)
        available.append((mesh_params.plates, mesh_params.N, str(path), path))
    candidates = sorted(entry for entry in available
                        if entry[0] == params.plates and params.N in (0, entry[1]))
    if not candidates:
        have = ", ".join(f"plates={p} N={n}" for p, n, _, _ in sorted(available)) or "none"
        wanted = f"plates={params.plates}" + (f" N={params.N}" if params.N else "")
        raise FileFormatError(f"figure 'figS-mesh': no mesh with {wanted} among its inputs (available: {have}); "
                              f"add such a mesh to the study or set the figure's 'plates'/'N'")
    return candidates[-1][3]


def _spring(x0, x1, y, coils=6, amplitude=1.0):
    """Zigzag polyline (x [k], y [k]) of a spring from (x0, y) to (x1, y)."""
    x = np.linspace(x0, x1, 2 * coils + 3)
    offsets = np.zeros_like(x)
    offsets[1:-1] = amplitude * np.where(np.arange(1, len(x) - 1) % 2 == 0, 1.0, -1.0)
    offsets[1] = offsets[-2] = 0.0
    return x, y + offsets


def _draw_lever(ax, mesh):
    """Schematic lever hinged at y = 0 right of the mesh, with a spring to every driven plate."""
    L, H = mesh.length, mesh.height
    pivot = L + 0.3 * L
    tilt = 0.06 * L / H  # schematic rotation of the lever (the imposed shear)
    ax.plot([pivot, pivot + tilt * H], [0.0, H], color="k", lw=2.0, solid_capstyle="round", clip_on=False)
    ax.plot([pivot], [0.0], marker="o", color="k", ms=5, clip_on=False)
    for plate in range(1, mesh.plates):
        y = mesh.layer_mid_height[2 * plate]
        x, yy = _spring(L, pivot + tilt * y, y, amplitude=0.012 * H)
        ax.plot(x, yy, color="k", lw=0.8, clip_on=False)
    ax.text(pivot + tilt * H, H, r" $\gamma$", va="bottom", ha="left")


def figure_mesh(mesh, zoom_width=60):
    """Draw the mesh figure.

    Parameters
    ----------
    mesh : LayeredMesh
    zoom_width : int, optional
        Width of the zoom panel in blocks; no zoom panel when the mesh is not wider.

    Returns
    -------
    matplotlib.figure.Figure
    """
    with_zoom = mesh.N > zoom_width
    fig, axes = plt.subplots(1, 2 if with_zoom else 1, figsize=(7.0 if with_zoom else 4.2, 4.2),
                             width_ratios=(1.35, 1.0) if with_zoom else None, squeeze=False)
    full = axes[0, 0]
    plot_mesh(mesh, full, edge_width=0.08 if mesh.N > 200 else 0.3)
    _draw_lever(full, mesh)
    full.set_xlim(0.0, 1.45 * mesh.length)
    full.set_axis_off()
    full.set_title(f"N = {mesh.N}, {mesh.n_interfaces} interfaces, {mesh.nelem} elements", fontsize=9)
    if with_zoom:
        _draw_zoom(axes[0, 1], full, mesh, zoom_width * mesh.h)
    fig.tight_layout()
    return fig


def _draw_zoom(zoom, full, mesh, width):
    """Zoom panel of ``width`` x ``width`` on the lowest interface, its frame drawn on ``full``."""
    centre = mesh.layer_mid_height[1]
    bottom, top = max(centre - 0.5 * width, 0.0), min(centre + 0.5 * width, mesh.height)
    plot_mesh(mesh, zoom, edge_width=0.3, mark_fixed=False)
    zoom.set_xlim(0.0, width)
    zoom.set_ylim(bottom, top)
    zoom.set_xticks([])
    zoom.set_yticks([])
    zoom.set_title("zoom on interface 1", fontsize=9)
    full.add_patch(plt.Rectangle((0.0, bottom), width, top - bottom, fill=False, edgecolor="r", lw=0.8))


@register("figure", "figS-mesh", "1", MeshFigureParams, inputs=("format:mesh",))
def run(params, inputs, output):
    """SI figure: the finite-element mesh of the numerical model, coloured per layer."""
    mesh = read_mesh(select_mesh(inputs.get("format:mesh", []), params))
    save_figure(figure_mesh(mesh, params.zoom_width), output)
