"""The ``fem-run`` format: layout, writing a run increment by increment, reading it back.

The writer works on arrays and tables (no solver object), so any solver that produces
this format writes it through here. One HDF5 file per run (written with
:mod:`stickslip.h5io`, so equal runs give equal bytes):

``/`` attributes
    ``format`` ("fem-run"), ``format_version``, ``solver`` and ``solver_version`` (the
    plugin that wrote it), ``version`` (package), ``params`` (JSON of all :class:`FemParams`),
    the main parameters again as typed attributes (``N``, ``plates``, ``n_interfaces``,
    ``k_drive``, ``drive``, ``seed``, ``nchunk``), normalisation (``eps0``, ``sig0``,
    ``gamma0`` [deg], ``c_s``, ``h``, ``dt``, ``alpha``, ``H``), the rigidity ratio ``phi``
    and the driving ``regime`` ("stiff" or "compliant", :mod:`.stiffness`), ``nstored``
    (complete increments) and ``completed`` (bool) with ``stop_reason`` ("margin" or
    "max_increments").
``/mesh``
    The layered mesh (:func:`stickslip.mesh.save_mesh`); with it the run's own interface
    <-> layer map (``interface_elements``, ``elem_layer``; :func:`stickslip.mesh.interface_layer`).
``/event``
    Scaled linear response: ``delta_u`` [ndof], ``delta_eps`` [ni, 4, 3],
    ``delta_target`` [nlayer], ``delta_lever`` [1].
``/state``
    One row per increment, enough to restore it: ``u`` [ninc, ndof], ``target``
    [ninc, nlayer], ``lever_target`` [ninc], ``t`` [ninc].
``/increments``
    The observables table (one 1-D dataset per column, attribute ``columns``,
    readable by :func:`stickslip.h5io.read_table`): ``increment``, ``kick``,
    ``yield_element`` and :func:`.observables.observable_columns`.
"""

import json

import numpy as np

from .. import __version__, formats
from ..h5io import (FileFormatError, atomic_output, copy_file, open_file, read_array, read_table, write_attrs,
                    write_dataset)
from ..mesh import load_mesh, save_mesh
from ..params import parse_params
from .parameters import FemParams

__all__ = ["FORMAT", "create_file", "append_increment", "rewrite", "read_increments", "read_run_attrs", "read_params",
           "RunFile", "describe"]

#: The format name of these files (:mod:`stickslip.formats`).
FORMAT = "fem-run"

_STATE = ("u", "target", "lever_target", "t")


def create_file(file, header, mesh, linear_response, columns, dtypes=None):
    """Write the header of a new ``fem-run`` file (no increment yet).

    Parameters
    ----------
    file : h5py.File
        Open for writing, empty.
    header : Mapping[str, object]
        Root attributes: ``solver``, ``solver_version``, ``params`` (dict of :class:`FemParams`),
        the typed parameters, normalisation, ``phi`` and ``regime`` of the module docstring.
    mesh : stickslip.mesh.LayeredMesh
    linear_response : tuple
        ``(delta_u [ndof], delta_eps [ni, 4, 3], delta_target [nlayer], delta_lever)``.
    columns : Sequence[str]
        Columns of the observables table after ``increment``, ``kick``, ``yield_element``.
    dtypes : Mapping[str, numpy.dtype], optional
        Types of columns that are neither float64 nor the well counts ``S_*``, ``A_*`` (int64).
    """
    formats.stamp(file, FORMAT)
    write_attrs(file, {**header, "version": __version__, "nstored": 0, "completed": False, "stop_reason": ""})
    save_mesh(mesh, file.create_group("mesh"))
    delta_u, delta_eps, delta_target, delta_lever = linear_response
    event = file.create_group("event")
    write_dataset(event, "delta_u", delta_u)
    write_dataset(event, "delta_eps", delta_eps)
    write_dataset(event, "delta_target", delta_target)
    write_dataset(event, "delta_lever", np.array([delta_lever]))
    state = file.create_group("state")
    ndof, nlayer = np.size(delta_u), np.size(delta_target)
    write_dataset(state, "u", np.zeros((0, ndof)), maxshape=(None, ndof), chunks=(1, ndof))
    write_dataset(state, "target", np.zeros((0, nlayer)), maxshape=(None, nlayer), chunks=(64, nlayer))
    for name in ("lever_target", "t"):
        write_dataset(state, name, np.zeros(0), maxshape=(None,), chunks=(1024,))
    table = file.create_group("increments")
    columns = ["increment", "kick", "yield_element"] + list(columns)
    dtypes = {"increment": np.int64, "kick": bool, "yield_element": bool, **(dtypes or {})}
    for name in columns:
        dtype = dtypes.get(name, np.int64 if name[:2] in ("S_", "A_") else np.float64)
        write_dataset(table, name, np.zeros(0, dtype=dtype), maxshape=(None,), chunks=(1024,))
    table.attrs["columns"] = json.dumps(columns)


def _append(dataset, value):
    n = dataset.shape[0]
    dataset.resize(n + 1, axis=0)
    dataset[n] = value


def append_increment(file, state, row):
    """Append one increment (state and observables) and commit it.

    The rows are flushed first, then ``nstored`` is raised and flushed: a process
    killed at any moment leaves at most rows beyond ``nstored``, which readers and
    :func:`rewrite` ignore.

    Parameters
    ----------
    file : h5py.File
    state : tuple
        ``(u [ndof], target [nlayer], lever_target, t)``: what restores the increment.
    row : dict
        ``increment``, ``kick``, ``yield_element`` and the observables.
    """
    for name, value in zip(_STATE, state):
        _append(file["state"][name], value)
    table = file["increments"]
    for name in json.loads(table.attrs["columns"]):
        _append(table[name], row[name])
    file.flush()
    file.attrs["nstored"] = int(file["state/t"].shape[0])
    file.flush()


def rewrite(path, **attrs):
    """Rewrite a simulation file from its complete increments, atomically.

    Rows beyond ``nstored`` (an increment being written when the writer was
    killed) are dropped, and the file is written afresh with
    :func:`stickslip.h5io.copy_file`, so its bytes depend only on the stored
    increments, not on how often the run was interrupted. A file left "open for
    write" by a killed process comes back writable.

    Parameters
    ----------
    path : str or pathlib.Path
        A simulation file (not open elsewhere).
    **attrs
        Root attributes to set in the copy (e.g. ``completed``, ``stop_reason``).
    """
    with open_file(path) as source, atomic_output(path) as tmp:
        with open_file(tmp, "w") as target:
            copy_file(source, target, rows=int(source.attrs["nstored"]))
            write_attrs(target, attrs)


def read_params(file):
    """The :class:`FemParams` of an open simulation file.

    Raises
    ------
    FileFormatError
        If the file is not a ``fem-run`` file of the current version.
    """
    formats.check(file, FORMAT)
    return parse_params(FemParams, json.loads(file.attrs["params"]), owner=f"{file.filename}: params")


class RunFile:
    """Read access to the stored states of a simulation file.

    Parameters
    ----------
    file : h5py.File
        Open simulation file.
    """

    def __init__(self, file):
        self.file = file
        self.params = read_params(file)
        self.mesh = load_mesh(file["mesh"])
        self.nstored = int(file.attrs["nstored"])

    def state(self, increment):
        """(u, target, lever_target, t) of a stored increment."""
        if not 0 <= increment < self.nstored:
            raise FileFormatError(f"{self.file.filename}: increment {increment} is not stored "
                                  f"(0 ... {self.nstored - 1})")
        u, target, lever_target, t = (read_array(self.file["state"][name], increment) for name in _STATE)
        return u, target, float(lever_target), float(t)

    def increment_bytes(self):
        """Bytes that appending one increment may allocate at most: one new chunk of every growing dataset [B]."""
        datasets = [self.file["state"][name] for name in _STATE]
        datasets += [self.file["increments"][name] for name in json.loads(self.file["increments"].attrs["columns"])]
        return sum(int(np.prod(d.chunks)) * d.dtype.itemsize for d in datasets)

    def linear_response(self):
        """(delta_u, delta_eps, delta_target, delta_lever) as stored."""
        e = self.file["event"]
        delta_u, delta_eps, delta_target, delta_lever = (
            read_array(e[name]) for name in ("delta_u", "delta_eps", "delta_target", "delta_lever"))
        return delta_u, delta_eps, delta_target, float(delta_lever[0])


def read_increments(path):
    """Per-increment observables of a simulation file.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    pandas.DataFrame
        One row per stored increment; columns ``increment``, ``kick``, ``yield_element``, ``t``,
        ``gamma``, ``epsd``, ``sigd``, ``epsd_<l>``, ``sigd_<l>``, ``ubar_<l>``, ``fxdrive_<l>``,
        ``S_a<a>``, ``A_a<a>``; free lever also ``lever_target``, ``lever_position``
        (see :mod:`.observables`).
    """
    with open_file(path) as file:
        read_params(file)
        return read_table(file, "increments", rows=int(file.attrs["nstored"]))


def read_run_attrs(path):
    """Parameters, normalisation and status of a simulation file.

    Returns
    -------
    dict
        ``N``, ``plates``, ``n_interfaces``, ``k_drive``, ``drive``, ``seed``, ``nchunk``,
        ``completed``, ``stop_reason``, ``nstored``, ``eps0``, ``sig0``, ``gamma0``, ``c_s``,
        ``h``, ``dt``, ``alpha``, ``H``, ``version``, ``params`` (dict).
    """
    with open_file(path) as file:
        read_params(file)
        out = {}
        for key, value in file.attrs.items():
            out[key] = value.item() if isinstance(value, np.generic) else value
        out["params"] = json.loads(out["params"])
        out["completed"] = bool(out["completed"])
        return out


def describe(path):
    """The results database's simulation columns of a ``fem-run`` file (:func:`stickslip.formats.describe`).

    Returns
    -------
    dict[str, object]
        ``n`` (interfaces), ``plates``, ``blocks`` (N), ``k_drive``, ``phi`` and ``regime``
        (the file's own attributes, :mod:`.stiffness`), ``seed``, ``temperature`` (0: athermal), and
        for a thermal run ``attempt_rate`` and ``drive_rate`` (None for an athermal one).
    """
    attrs = read_run_attrs(path)
    thermal = attrs.get("protocol") == "thermal"
    return {"n": int(attrs["n_interfaces"]), "plates": int(attrs["plates"]), "blocks": int(attrs["N"]),
            "k_drive": float(attrs["k_drive"]), "phi": float(attrs["phi"]), "regime": str(attrs["regime"]),
            "seed": int(attrs["seed"]), "temperature": float(attrs["temperature"]) if thermal else 0.0,
            "attempt_rate": float(attrs["attempt_rate"]) if thermal else None,
            "drive_rate": float(attrs["drive_rate"]) if thermal else None}
