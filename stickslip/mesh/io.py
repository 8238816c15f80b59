"""Layered meshes in HDF5: into a group of any file, or as a file of their own.

Layout of a mesh group: datasets ``coor`` [nnode, 2], ``conn`` [nelem, 4],
``dofs`` [nnode, 2], ``iip`` [niip], ``elem_layer`` [nelem], ``layer_y``
[nlayer, 2], ``interface_elements`` [n_interfaces, N]; attributes ``N``,
``plates``, ``h`` (the :class:`MeshParams`) and ``mesh_format``.
"""

from pathlib import Path

import h5py
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

_DATASETS = ("coor", "conn", "dofs", "iip", "elem_layer", "layer_y", "interface_elements")


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
        If a dataset or attribute is missing, the format version is not :data:`MESH_FORMAT`, or the arrays are not
        the mesh of the stored ``N``, ``plates`` and ``h`` (:func:`~stickslip.mesh.layered.build_stack_mesh` of them,
        exactly: a mesh is determined by its parameters, so a damaged one is refused before it is used; their
        declared shapes are checked before a number is read); the message names file, group and item.
    """
    where = f"{group.file.filename}:{group.name}"
    missing = [name for name in _DATASETS if not isinstance(group.get(name), h5py.Dataset)]
    missing += [name for name in ("N", "plates", "h", "mesh_format") if name not in group.attrs]
    if missing:
        raise FileFormatError(f"{where}: not a stickslip mesh, missing {', '.join(missing)}")
    if attribute(group, "mesh_format", "int") != MESH_FORMAT:
        raise FileFormatError(f"{where}: mesh_format {group.attrs['mesh_format']} is not the supported "
                              f"{MESH_FORMAT}; rebuild the mesh")
    params = read_mesh_params(group)
    _check_shapes(where, {name: group[name].shape for name in _DATASETS}, params)
    arrays = {name: read_array(group[name]) for name in _DATASETS}
    expected = build_stack_mesh(params)
    for name in _DATASETS:
        if not np.array_equal(arrays[name], getattr(expected, name)):
            raise FileFormatError(f"{where}/{name}: not the mesh of N = {params.N}, plates = {params.plates}, h = "
                                  f"{params.h:g} (mesh format {MESH_FORMAT}) that the file names: the file is damaged")
    return expected


#: Elements of the stack's mesh per block and plate, at most (11 per block and interface for N >= 54).
_ELEMENTS_PER_BLOCK = 20


def _check_shapes(where, shapes, params):
    """Raise FileFormatError unless the declared shapes of the mesh arrays fit each other and the mesh's N and
    plates (before any is read, and before the mesh of N and plates is built to compare them with)."""
    nnode, nelem = (shapes[name][0] if shapes[name] else 0 for name in ("coor", "conn"))
    expected = {"coor": (nnode, 2), "conn": (nelem, 4), "dofs": (nnode, 2), "elem_layer": (nelem,),
                "iip": shapes["iip"] if len(shapes["iip"]) == 1 and shapes["iip"][0] <= 2 * nnode else (2 * nnode,),
                "layer_y": (2 * params.plates - 1, 2), "interface_elements": (params.plates - 1, params.N)}
    wrong = [name for name, shape in expected.items() if shapes[name] != shape]
    if not params.N * (params.plates - 1) <= nelem <= _ELEMENTS_PER_BLOCK * params.N * params.plates:
        wrong.append("conn")
    if wrong:
        raise FileFormatError(f"{where}/{wrong[0]}: shape {shapes[wrong[0]]} does not fit a mesh of N = {params.N}, "
                              f"plates = {params.plates} with the other arrays' shapes: the file is damaged")


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
