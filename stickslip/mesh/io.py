"""Layered meshes in HDF5: into a group of any file, or as a file of their own.

Layout of a mesh group: datasets ``coor`` [nnode, 2], ``conn`` [nelem, 4],
``dofs`` [nnode, 2], ``iip`` [niip], ``elem_layer`` [nelem], ``layer_y``
[nlayer, 2], ``interface_elements`` [n_interfaces, N]; attributes ``N``,
``plates``, ``h`` (the :class:`MeshParams`) and ``mesh_format``.
"""

from pathlib import Path

import numpy as np

from .. import formats
from ..h5io import FileFormatError, attribute, open_file, read_array, write_attrs, write_dataset
from ..hashing import short_hash
from ..output_safety.atomic import atomic_output
from ..plugin_params import ParameterError, params_to_dict, parse_params
from .layered import LayeredMesh, MeshParams, build_stack_mesh

__all__ = ["MESH_FORMAT", "mesh_id", "save_mesh", "load_mesh", "read_mesh_params", "write_mesh", "read_mesh"]

#: Version of the mesh geometry and file layout (format ``mesh``); part of every mesh id.
MESH_FORMAT = formats.get_format("mesh").version

_DATASETS = {"coor": 2, "conn": 2, "dofs": 2, "iip": 1, "elem_layer": 1, "layer_y": 2, "interface_elements": 2}


def mesh_id(params):
    """Short stable id of a mesh: a hash of its parameters and :data:`MESH_FORMAT`.

    Parameters
    ----------
    params : MeshParams

    Returns
    -------
    str
        16 hexadecimal characters (file name ``results/{study}/mesh/{mesh_id}.h5``).
    """
    return short_hash({"mesh_format": MESH_FORMAT, "params": params_to_dict(params)})


def save_mesh(mesh, group):
    """Write a mesh into an open HDF5 group (e.g. ``/mesh`` of a simulation file).

    Parameters
    ----------
    mesh : LayeredMesh
    group : h5py.Group
        Must not yet hold the mesh datasets.
    """
    for name in _DATASETS:
        write_dataset(group, name, getattr(mesh, name))
    write_attrs(group, {"N": mesh.N, "plates": mesh.plates, "h": mesh.h, "mesh_format": MESH_FORMAT})


def load_mesh(group):
    """Read a mesh written by :func:`save_mesh`.

    Parameters
    ----------
    group : h5py.Group

    Returns
    -------
    LayeredMesh

    Raises
    ------
    FileFormatError
        If a dataset or attribute is missing, has the wrong rank or a shape or numbers that do not fit the rest of
        the mesh, or the format version is not :data:`MESH_FORMAT`; the message names file, group and item.
    """
    where = f"{group.file.filename}:{group.name}"
    missing = [name for name in _DATASETS if name not in group]
    missing += [name for name in ("N", "plates", "h", "mesh_format") if name not in group.attrs]
    if missing:
        raise FileFormatError(f"{where}: not a stickslip mesh, missing {', '.join(missing)}")
    if attribute(group, "mesh_format", "int") != MESH_FORMAT:
        raise FileFormatError(f"{where}: mesh_format {group.attrs['mesh_format']} is not the supported "
                              f"{MESH_FORMAT}; rebuild the mesh")
    params = read_mesh_params(group)
    arrays = {name: read_array(group[name]) for name in _DATASETS}
    for name, rank in _DATASETS.items():
        if arrays[name].ndim != rank:
            raise FileFormatError(f"{where}/{name}: expected {rank} dimensions, got shape {arrays[name].shape}")
    _check_consistent(where, arrays, params)
    return LayeredMesh(**arrays, N=params.N, plates=params.plates, h=params.h)


def _check_consistent(where, arrays, params):
    """Raise FileFormatError unless the mesh arrays fit each other and the mesh's N and plates: every shape, and
    every node, element, layer and DOF number within its range (a damaged file is refused before it is used)."""
    nnode, nelem, nlayer = len(arrays["coor"]), len(arrays["conn"]), 2 * params.plates - 1
    expected = {"coor": (nnode, 2), "conn": (nelem, 4), "dofs": (nnode, 2), "elem_layer": (nelem,),
                "layer_y": (nlayer, 2), "interface_elements": (params.plates - 1, params.N)}
    for name, shape in expected.items():
        if arrays[name].shape != shape:
            raise FileFormatError(f"{where}/{name}: shape {arrays[name].shape}, expected {shape} (the mesh's other "
                                  f"arrays, N = {params.N}, plates = {params.plates}): the file is damaged")
    ndof = 2 * nnode
    for name, top in (("conn", nnode), ("dofs", ndof), ("iip", ndof), ("elem_layer", nlayer),
                      ("interface_elements", nelem)):
        values = arrays[name]
        if values.size and (not np.issubdtype(values.dtype, np.integer) or values.min() < 0 or values.max() >= top):
            raise FileFormatError(f"{where}/{name}: values outside 0 ... {top - 1} (numbers of the mesh's "
                                  "nodes, elements, layers or DOFs): the file is damaged")
    if not all(np.all(np.isfinite(arrays[name])) for name in ("coor", "layer_y")):
        raise FileFormatError(f"{where}: coordinates that are not finite numbers: the file is damaged")


def read_mesh_params(group):
    """Return the :class:`MeshParams` stored with a mesh group (cheap: attributes only).

    Raises
    ------
    FileFormatError
        If an attribute is missing or invalid.
    """
    where = f"{group.file.filename}:{group.name}"
    try:
        return parse_params(MeshParams, {name: group.attrs[name] for name in ("N", "plates", "h")})
    except KeyError as error:
        raise FileFormatError(f"{where}: not a stickslip mesh, missing attribute {error}") from None
    except ParameterError as error:
        raise FileFormatError(f"{where}: invalid mesh attributes: {error}") from None


def write_mesh(params, output):
    """Build the mesh of ``params`` and write it as one HDF5 file (atomically).

    Parameters
    ----------
    params : MeshParams
    output : str or pathlib.Path
        The mesh is in the root group (format ``mesh``); attribute ``mesh_id`` holds :func:`mesh_id`.
    """
    mesh = build_stack_mesh(params)
    with atomic_output(Path(output)) as tmp:
        with open_file(tmp, "w") as file:
            formats.stamp(file, "mesh")
            save_mesh(mesh, file)
            write_attrs(file, {"mesh_id": mesh_id(params)})


def read_mesh(path):
    """Read a mesh file written by :func:`write_mesh`.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    LayeredMesh

    Raises
    ------
    FileFormatError
        If the file is not a ``mesh`` file of the current version.
    """
    with open_file(path) as file:
        formats.check(file, "mesh")
        return load_mesh(file)
