"""The layered mesh of the paper's numerical model: elastic plates and one-block-thick interfaces.

Layer order, bottom to top: bottom plate, interface, [plate, interface] x
(plates - 2), top plate. Layer ``l = 2 i`` is plate ``i`` (0 = bottom), layer
``l = 2 a - 1`` is interface ``a`` (1 = lowest). Plates are cut from GooseFEM's
FineLayer(N, M, h) with ``M = max(3, int(N / 4))`` (see :mod:`.rows`), so they
are fine (h) where they touch an interface and coarse inside.

The mesh is periodic in x: a node on the right edge carries the DOFs of the
node on the left edge at the same height. The bottom edge is fixed (both
components), the top edge is fixed in y only.
"""

import dataclasses
import math

import numpy as np

from ..plugin_params import param
from .stacking import stack_rows
from .rows import (bottom_plate_rows, interface_rows, middle_plate_rows, plate_target_height,
                   top_plate_rows)

__all__ = ["MeshParams", "LayeredMesh", "build_stack_mesh", "interface_layer"]


def interface_layer(a):
    """The layer of interface ``a``: ``2a - 1`` (the one place this convention is written).

    Layers are numbered from the bottom: plate ``i`` is layer ``2i``, interface ``a``
    (1 = lowest) the block layer between plates ``a - 1`` and ``a``.

    Parameters
    ----------
    a : int
        Interface, 1 ... n.

    Returns
    -------
    int
    """
    return 2 * int(a) - 1


@dataclasses.dataclass(frozen=True)
class MeshParams:
    """Parameters of the layered mesh.

    Attributes
    ----------
    N : int
        Blocks per interface (finest elements along x). ``N = 2 * 3**k`` allows
        full coarsening inside the plates; any ``N >= 2`` gives a valid mesh.
    plates : int
        Number of elastic plates (``plates - 1`` interfaces).
    h : float
        Edge of a block (finest element), the length unit l0 of the model.
    """

    N: int = param(1458, "blocks per interface (finest elements along x)", minimum=2)
    plates: int = param(2, "number of elastic plates (plates - 1 frictional interfaces)", minimum=2, maximum=6)
    h: float = param(math.pi, "edge of a block (finest element), the length unit l0", unit="length",
                     exclusive_minimum=0.0)


def _frozen(array, dtype):
    array = np.ascontiguousarray(array, dtype=dtype)
    array.setflags(write=False)
    return array


@dataclasses.dataclass(frozen=True, eq=False)
class LayeredMesh:
    """A layered, x-periodic Quad4 mesh (arrays are read-only).

    Attributes
    ----------
    coor : numpy.ndarray
        float64 [nnode, 2] node positions (x, y); x in [0, N h], y from 0 at the bottom.
    conn : numpy.ndarray
        int64 [nelem, 4] element nodes, counter-clockwise from the bottom-left (GooseFEM order).
    dofs : numpy.ndarray
        int64 [nnode, 2] DOF numbers 0 ... ndof - 1; right-edge nodes carry the DOFs of the
        left-edge node at the same y.
    iip : numpy.ndarray
        int64 [niip] sorted prescribed DOFs: both components of the bottom-edge nodes, the
        y-component of the top-edge nodes.
    elem_layer : numpy.ndarray
        int64 [nelem] layer of every element (``2 i``: plate i, ``2 a - 1``: interface a).
    layer_y : numpy.ndarray
        float64 [nlayer, 2] bottom and top y of every layer.
    interface_elements : numpy.ndarray
        int64 [n_interfaces, N] element of block b (left to right) of interface a (row a - 1).
    N : int
        Blocks per interface.
    plates : int
        Number of plates.
    h : float
        Block edge.
    """

    coor: np.ndarray
    conn: np.ndarray
    dofs: np.ndarray
    iip: np.ndarray
    elem_layer: np.ndarray
    layer_y: np.ndarray
    interface_elements: np.ndarray
    N: int
    plates: int
    h: float

    def __post_init__(self):
        for name, dtype in (("coor", np.float64), ("conn", np.int64), ("dofs", np.int64), ("iip", np.int64),
                            ("elem_layer", np.int64), ("layer_y", np.float64),
                            ("interface_elements", np.int64)):
            object.__setattr__(self, name, _frozen(getattr(self, name), dtype))

    @property
    def nnode(self):
        """Number of nodes."""
        return self.coor.shape[0]

    @property
    def nelem(self):
        """Number of elements."""
        return self.conn.shape[0]

    @property
    def ndof(self):
        """Number of independent DOFs (periodic images counted once)."""
        return int(self.dofs.max()) + 1

    @property
    def nlayer(self):
        """Number of layers, ``2 plates - 1``."""
        return 2 * self.plates - 1

    @property
    def n_interfaces(self):
        """Number of interfaces, ``plates - 1``."""
        return self.plates - 1

    @property
    def length(self):
        """Periodic length ``L = N h``."""
        return self.N * self.h

    @property
    def height(self):
        """Total height of the stack."""
        return float(self.layer_y[-1, 1])

    @property
    def layer_mid_height(self):
        """float64 [nlayer] mid-height ``H_l = (y_bottom + y_top) / 2`` of every layer."""
        return self.layer_y.mean(axis=1)

    @property
    def layer_is_plastic(self):
        """bool [nlayer]: True for the interfaces (odd layers)."""
        return np.arange(self.nlayer) % 2 == 1

    def layer_elements(self, layer):
        """int64 [nelem_layer] elements of layer ``layer``, in increasing order."""
        self._check_layer(layer)
        return np.flatnonzero(self.elem_layer == layer)

    def layer_nodes(self, layer):
        """int64 [nnode_layer] sorted nodes of the elements of layer ``layer`` (shared faces included)."""
        return np.unique(self.conn[self.layer_elements(layer)])

    def _check_layer(self, layer):
        if not 0 <= layer < self.nlayer:
            raise IndexError(f"layer {layer} out of range: the mesh has layers 0 ... {self.nlayer - 1}")


def _stack_layout(params):
    """Rows of every layer, bottom to top (list of lists of Row)."""
    M = plate_target_height(params.N)
    interface = interface_rows()
    layers = [bottom_plate_rows(params.N, M), interface]
    for _ in range(params.plates - 2):
        layers += [middle_plate_rows(params.N, M), interface]
    layers.append(top_plate_rows(params.N, M))
    return layers


def _periodic_dofs(grid, N):
    """DOFs [nnode, 2] with every right-edge node mapped onto the left-edge node at the same y.

    ``grid`` is sorted by (y, x), so the left partner of a right-edge node is found
    by its key; independent nodes are numbered in node order.
    """
    keys = grid[:, 1] * (N + 1) + grid[:, 0]
    independent = grid[:, 0] < N
    rank = np.cumsum(independent) - 1
    master = np.arange(len(grid))
    right = np.flatnonzero(~independent)
    master[right] = np.searchsorted(keys, grid[right, 1] * (N + 1))
    node_dof = rank[master]
    return np.stack([2 * node_dof, 2 * node_dof + 1], axis=1)


def build_stack_mesh(params):
    """Build the layered mesh of the paper's model.

    Parameters
    ----------
    params : MeshParams

    Returns
    -------
    LayeredMesh

    Notes
    -----
    Geometry (every node position and element) is that of the paper's code:
    GooseFEM FineLayer halves and Regular rows stitched with GooseFEM Vstack. Node
    numbering is row by row (bottom to top, left to right); elements are numbered
    row by row, blocks left to right. Cost: O(nelem log nelem), about 0.03 s for
    N = 1458 and 6 plates.
    """
    N = params.N
    layers = _stack_layout(params)
    rows = [row for layer in layers for row in layer]
    layer_of_row = np.repeat(np.arange(len(layers)), [len(layer) for layer in layers])
    grid, conn, row_of_element = stack_rows(rows, N)
    elem_layer = layer_of_row[row_of_element]

    tops = np.cumsum([sum(row.height for row in layer) for layer in layers])
    bottoms = np.concatenate([[0], tops[:-1]])
    layer_y = np.stack([bottoms, tops], axis=1) * params.h

    dofs = _periodic_dofs(grid, N)
    bottom_nodes = np.flatnonzero(grid[:, 1] == 0)
    top_nodes = np.flatnonzero(grid[:, 1] == tops[-1])
    iip = np.unique(np.concatenate([dofs[bottom_nodes].ravel(), dofs[top_nodes, 1]]))

    interface_elements = np.stack([np.flatnonzero(elem_layer == interface_layer(a)) for a in range(1, params.plates)])
    return LayeredMesh(coor=grid * params.h, conn=conn, dofs=dofs, iip=iip, elem_layer=elem_layer,
                       layer_y=layer_y, interface_elements=interface_elements.reshape(params.plates - 1, N),
                       N=N, plates=params.plates, h=params.h)
