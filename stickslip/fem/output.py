"""The simulation file: layout, appending increments, reading results, time-resolved reruns.

One HDF5 file per run (written with :mod:`stickslip.h5io`, so equal runs give equal bytes):

``/`` attributes
    ``solver`` ("fem"), ``version`` (package), ``params`` (JSON of all :class:`FemParams`),
    the main parameters again as typed attributes (``N``, ``plates``, ``n_interfaces``,
    ``k_drive``, ``drive``, ``seed``, ``nchunk``), normalisation (``eps0``, ``sig0``,
    ``gamma0`` [deg], ``c_s``, ``h``, ``dt``, ``alpha``, ``H``), ``nstored`` (complete
    increments) and ``completed`` (bool) with ``stop_reason`` ("margin" or "max_increments").
``/mesh``
    The layered mesh (:func:`stickslip.mesh.save_mesh`).
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
import pandas as pd

from .. import __version__
from ..h5io import FileFormatError, atomic_output, copy_file, open_file, read_table, write_attrs, write_dataset
from ..mesh import load_mesh, save_mesh
from ..params import parse_params, params_to_dict
from .stiffness import driving_regime, stiffness_ratio
from .observables import observable_columns
from .parameters import FemParams

__all__ = ["create_file", "append_increment", "rewrite", "read_increments", "read_run_attrs", "read_params", "RunFile",
           "rerun_with_failures"]

_STATE = ("u", "target", "lever_target", "t")


def create_file(file, system, observer):
    """Write the header of a new simulation file (no increment yet).

    Parameters
    ----------
    file : h5py.File
        Open for writing, empty.
    system : System
        With its linear response set.
    observer : Observer
    """
    p = system.params
    c = system.constants
    phi = stiffness_ratio(p.k_drive, p.N, p.G)
    write_attrs(file, {
        "solver": "fem", "version": __version__, "params": params_to_dict(p),
        "N": p.N, "plates": p.plates, "n_interfaces": p.plates - 1, "k_drive": p.k_drive, "drive": p.drive,
        "seed": p.seed, "nchunk": p.nchunk, "eps0": p.eps0, "sig0": c["sig0"], "gamma0": observer.gamma0,
        "c_s": c["c_s"], "h": c["h"], "dt": c["dt"], "alpha": c["alpha"], "H": c["H"],
        "nstored": 0, "completed": False, "stop_reason": "", "phi": phi, "regime": driving_regime(phi),
    })
    save_mesh(system.mesh, file.create_group("mesh"))
    event = file.create_group("event")
    write_dataset(event, "delta_u", system.delta_u)
    write_dataset(event, "delta_eps", system.delta_eps)
    write_dataset(event, "delta_target", system.delta_target)
    write_dataset(event, "delta_lever", np.array([system.delta_lever]))
    state = file.create_group("state")
    ndof, nlayer = system.model.ndof, system.model.layer_volume.size
    write_dataset(state, "u", np.zeros((0, ndof)), maxshape=(None, ndof), chunks=(1, ndof))
    write_dataset(state, "target", np.zeros((0, nlayer)), maxshape=(None, nlayer), chunks=(64, nlayer))
    for name in ("lever_target", "t"):
        write_dataset(state, name, np.zeros(0), maxshape=(None,), chunks=(1024,))
    table = file.create_group("increments")
    columns = ["increment", "kick", "yield_element"] + observable_columns(observer.nlayer, observer.n_interfaces,
                                                                          system.model.free_lever)
    dtypes = {"increment": np.int64, "kick": bool, "yield_element": bool}
    for name in columns:
        dtype = dtypes.get(name, np.int64 if name[:2] in ("S_", "A_") else np.float64)
        write_dataset(table, name, np.zeros(0, dtype=dtype), maxshape=(None,), chunks=(1024,))
    table.attrs["columns"] = json.dumps(columns)


def _append(dataset, value):
    n = dataset.shape[0]
    dataset.resize(n + 1, axis=0)
    dataset[n] = value


def append_increment(file, system, row):
    """Append one increment (state and observables) and commit it.

    The rows are flushed first, then ``nstored`` is raised and flushed: a process
    killed at any moment leaves at most rows beyond ``nstored``, which readers and
    :func:`rewrite` ignore.

    Parameters
    ----------
    file : h5py.File
    system : System
    row : dict
        ``increment``, ``kick``, ``yield_element`` and the observables.
    """
    u, target, lever_target, t = system.snapshot()
    for name, value in zip(_STATE, (u, target, lever_target, t)):
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
        If the file is not a ``fem`` simulation file.
    """
    if file.attrs.get("solver") != "fem" or "params" not in file.attrs:
        raise FileFormatError(f"{file.filename}: not a fem simulation file (attribute 'solver' != 'fem')")
    return parse_params(FemParams, json.loads(file.attrs["params"]), owner="solver 'fem'")


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
        s = self.file["state"]
        return s["u"][increment], s["target"][increment], float(s["lever_target"][increment]), float(s["t"][increment])

    def linear_response(self):
        """(delta_u, delta_eps, delta_target, delta_lever) as stored."""
        e = self.file["event"]
        return e["delta_u"][...], e["delta_eps"][...], e["delta_target"][...], float(e["delta_lever"][0])


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


def rerun_with_failures(path, increment):
    """Redo the kick and minimisation of one increment, recording every block failure.

    The state of ``increment - 1`` is restored, the stored kick is redone (with the
    whole-element fallback if the increment used it) and the minimisation records
    every change of the well index of Gauss point 0 of the interface blocks (the
    kick's own change at ``t = 0`` included). The result must reproduce the stored
    increment exactly (asserted).

    Parameters
    ----------
    path : str or pathlib.Path
    increment : int
        A stored kick increment (>= 2).

    Returns
    -------
    pandas.DataFrame
        Columns ``a`` (interface, 1 = lowest), ``block`` (0 ... N-1), ``t`` (time since the
        kick [FE time units]), ``direction`` (+1 / -1); one row per well hop, in time order.

    Raises
    ------
    FileFormatError
        If the increment is not a stored kick.
    """
    from .system import System

    with open_file(path) as file:
        run = RunFile(file)
        table = read_table(file, "increments", rows=run.nstored)
        if not 1 <= increment < run.nstored or not bool(table["kick"][increment]):
            raise FileFormatError(f"{path}: increment {increment} is not a stored kick increment")
        yield_element = bool(table["yield_element"][increment])
        before = run.state(increment - 1)
        after = run.state(increment)
        response = run.linear_response()
        system = System(run.params, run.mesh)
    system.set_linear_response(*response)
    system.restore(*before)
    t0 = before[3]
    N = run.mesh.N
    niter, events = system.kick_and_minimise(yield_element, run.params.margin, record=True)
    if niter == 0 or not np.array_equal(system.state.u, after[0]) or system.state.t[0] != after[3]:
        raise AssertionError(f"{path}: rerunning increment {increment} did not reproduce the stored state")
    element = events[:, 0].astype(np.int64)
    return pd.DataFrame({"a": element // N + 1, "block": element % N, "t": events[:, 1] - t0,
                         "direction": events[:, 2].astype(np.int64)})
