"""Layered Quad4 meshes of the paper's numerical model (FineLayer coarsening, stacking, periodicity, HDF5).

Drawing a mesh is a figure's business: :func:`stickslip.figures.mesh.plot_mesh`.
"""

from .io import MESH_FORMAT, load_mesh, mesh_id, read_mesh, read_mesh_params, save_mesh, write_mesh
from .layered import LayeredMesh, MeshParams, build_stack_mesh, interface_layer

__all__ = ["MeshParams", "LayeredMesh", "build_stack_mesh", "save_mesh", "load_mesh", "read_mesh_params",
           "write_mesh", "read_mesh", "mesh_id", "MESH_FORMAT", "interface_layer"]
