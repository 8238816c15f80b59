"""Drawing a layered mesh: elements filled by layer, fixed bottom nodes marked."""

import numpy as np

__all__ = ["layer_colors", "plot_mesh"]


def layer_colors(mesh):
    """Default fill colour of every layer, as in the paper's figures.

    The bottom plate (fixed, not driven) is grey, plate ``i >= 1`` has the colour
    of slab ``i`` (:func:`stickslip.figures.style.interface_color`), interfaces
    are dark.

    Parameters
    ----------
    mesh : LayeredMesh

    Returns
    -------
    list
        nlayer matplotlib colours.
    """
    from ..figures.style import interface_color

    colors = []
    for layer in range(mesh.nlayer):
        if layer % 2 == 1:
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
    from matplotlib.collections import PolyCollection

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
