"""The ``fem-run`` format: layout, writing a run increment by increment, reading it back.

The format belongs to no solver: its writer works on arrays, tables and a header
mapping, and its readers return arrays, tables and plain values, so any producer
(the ``fem`` solver, another solver, another backend) writes a file that every
consumer reads. The producer's parameters are stored as opaque JSON (``params``):
the format never interprets them; what the analyses need is a typed header field
(:data:`HEADER`). One HDF5 file per run (written with :mod:`stickslip.h5io`, so
equal runs give equal bytes):

``/`` attributes
    ``format`` ("fem-run"), ``format_version``, the producer's header: every field
    of :data:`HEADER` (``solver``, ``solver_version``,
    ``params``, ``N``, ``plates``, ``n_interfaces``, ``k_drive``, ``seed``, the
    normalisation ``eps0``, ``sig0``, ``gamma0`` [deg], ``c_s``, ``h``, ``dt``, the
    rigidity ratio ``phi`` and the driving ``regime``) and any further attributes of
    the producer (``fem``: ``drive``, ``nchunk``, ``alpha``, ``H``; a thermal ``fem`` run also
    ``protocol`` = "thermal", ``temperature``, ``attempt_rate``, ``drive_rate``, ``hold_times``,
    ``hold_delay``, ``energy_unit``: docs/fem.md, "Finite temperature"); then ``version``
    (package), ``arithmetic`` (what decides the bits of the numbers: a JSON list of segments, each
    :func:`stickslip.arithmetic.decisive`, for a ``cuda`` run with its GPU, driver, numba-cuda and
    whether numba's CUDA simulator ran it (:func:`stickslip.fem.backends.gpu_arithmetic`), and the
    ``from_increment`` it holds from; one segment unless
    a resume was told to continue under another, :func:`check_arithmetic`), ``nstored`` (complete
    increments) and ``completed`` (bool) with ``stop_reason`` ("margin" or "max_increments").
    Format version 2 added ``arithmetic``.
``/mesh``
    The layered mesh (:func:`stickslip.mesh.save_mesh`); with it the run's own interface
    <-> layer map (``interface_elements``, ``elem_layer``; :func:`stickslip.mesh.interface_layer`).
``/event``
    Scaled linear response: ``delta_u`` [ndof], ``delta_eps`` [ni, 4, 3],
    ``delta_target`` [nlayer], ``delta_lever`` [1].
``/state``
    One row per increment, enough to restore it (:class:`StoredState`): ``u`` [ninc, ndof], ``target``
    [ninc, nlayer], ``lever_target`` [ninc], ``t`` [ninc]; and any further state the producer
    declares (``create_file``'s ``state_fields``, e.g. ``fem`` with junction aging:
    ``junction_depth``, ``junction_well`` [ninc, ni]), which files without it lack.
``/increments``
    The observables table (one 1-D dataset per column, attribute ``columns``,
    readable by :func:`stickslip.h5io.read_table`): ``increment``, ``kick``,
    ``yield_element`` and the producer's observables (``fem``:
    :func:`stickslip.fem.observables.observable_columns`; a thermal run adds ``hop_block``,
    ``hop_direction``, ``failed_hops`` (integers) and ``held``); columns ``S_*`` and ``A_*``
    are integers, the others floats unless the producer types them (``create_file``'s ``dtypes``).

``phi`` and ``regime`` are the producer's (``fem``: :mod:`stickslip.fem.stiffness`);
consumers read them from here and never recompute them.
"""

import json
import numbers
from types import MappingProxyType
from typing import Mapping, NamedTuple

import h5py
import numpy as np

from .. import __version__, formats
from ..arithmetic import check_resume, decisive
from ..h5io import (CorruptFileError, FileFormatError, attribute, copy_file, open_file, read_array, read_table,
                    write_attrs, write_dataset)
from ..mesh import load_mesh, save_mesh
from ..output_safety.atomic import atomic_output
from ..stored_rows import first_unstored_row

__all__ = ["FORMAT", "HEADER", "REGIMES", "StoredState", "create_file", "append_increment", "rewrite", "read_params",
           "read_increments", "read_run_attrs", "stored_increments", "RunFile", "describe", "check_arithmetic"]

#: The format name of these files (:mod:`stickslip.formats`).
FORMAT = "fem-run"

#: Driving regimes a file may state.
REGIMES = ("stiff", "compliant")

#: Typed root attributes every file holds: name -> (kind, meaning). Kinds: ``int``, ``float``,
#: ``str``, ``json`` (a mapping, stored as JSON text).
HEADER = {
    "solver": ("str", "the producing solver plugin"),
    "solver_version": ("str", "its algorithm version"),
    "params": ("json", "the producer's parameters, opaque to the format"),
    "N": ("int", "blocks per interface"),
    "plates": ("int", "elastic plates"),
    "n_interfaces": ("int", "interfaces, plates - 1"),
    "k_drive": ("float", "drive spring stiffness per unit volume [G/h^2]"),
    "seed": ("int", "realisation id"),
    "eps0": ("float", "strain unit of the observables"),
    "sig0": ("float", "stress unit of the observables"),
    "gamma0": ("float", "unit of the lever rotation gamma [deg]"),
    "c_s": ("float", "shear-wave speed [FE length / FE time]"),
    "h": ("float", "block size [FE length]"),
    "dt": ("float", "time step [FE time]"),
    "phi": ("float", "rigidity ratio Phi = K / K_s of the drive"),
    "regime": ("str", "driving regime, one of REGIMES"),
}

_KINDS = {"int": (numbers.Integral,), "float": (numbers.Real,), "str": (str,), "json": (dict,)}



class StoredState(NamedTuple):
    """One stored increment's state: what restores it (``/state``), the record that writers, readers and producers share.

    Attributes
    ----------
    u : numpy.ndarray
        float64 [ndof] displacement [length].
    target : numpy.ndarray
        float64 [nlayer] drive targets of the layers [length].
    lever_target : float
        The free lever's drive target [length] (0 for a fixed lever).
    t : float
        Time [time].
    further : Mapping[str, numpy.ndarray]
        The producer's further state (``create_file``'s ``state_fields``) by dataset name; empty without it.
    """

    u: object
    target: object
    lever_target: float
    t: float
    further: Mapping = MappingProxyType({})


#: The datasets of every file's stored state, by :class:`StoredState` field.
_STATE = ("u", "target", "lever_target", "t")

#: The first columns of every file's ``/increments`` table (the producer's columns follow).
_FIRST_COLUMNS = ["increment", "kick", "yield_element"]


def _check_header(header):
    """Raise ValueError naming every field of :data:`HEADER` that ``header`` lacks or mistypes."""
    missing = [name for name in HEADER if name not in header]
    if missing:
        raise ValueError(f"fem-run header lacks {', '.join(missing)}")
    wrong = [f"{name} ({HEADER[name][0]}, got {type(header[name]).__name__})" for name in HEADER
             if not isinstance(header[name], _KINDS[HEADER[name][0]]) or isinstance(header[name], bool)]
    if wrong:
        raise ValueError(f"fem-run header: wrong type of {', '.join(wrong)}")
    if header["regime"] not in REGIMES:
        raise ValueError(f"fem-run header: regime must be one of {', '.join(REGIMES)}, got {header['regime']!r}")


def create_file(file, header, mesh, linear_response, columns, dtypes=None, state_fields=None, arithmetic=None):
    """Write the header of a new ``fem-run`` file (no increment yet).

    Parameters
    ----------
    file : h5py.File
        Open for writing, empty.
    header : Mapping[str, object]
        Root attributes: every field of :data:`HEADER` (``params`` a JSON-able mapping) and any
        further attributes of the producer, written in the mapping's order.
    mesh : stickslip.mesh.LayeredMesh
    linear_response : tuple
        ``(delta_u [ndof], delta_eps [ni, 4, 3], delta_target [nlayer], delta_lever)``.
    columns : Sequence[str]
        Columns of the observables table after ``increment``, ``kick``, ``yield_element``.
    dtypes : Mapping[str, numpy.dtype], optional
        Types of columns that are neither float64 nor the well counts ``S_*``, ``A_*`` (int64).
    state_fields : Mapping[str, tuple], optional
        Further state stored per increment: name -> ``(shape, dtype)`` of one increment's value
        (datasets ``/state/<name>``; :func:`append_increment` takes their values as :attr:`StoredState.further`).
    arithmetic : Mapping[str, object], optional
        What decides the bits beside :func:`stickslip.arithmetic.decisive` (a device backend's GPU,
        :func:`stickslip.fem.backends.backend_arithmetic`), recorded with it in ``arithmetic``.

    Raises
    ------
    ValueError
        If a field of :data:`HEADER` is missing or of another kind.
    """
    _check_header(header)
    formats.stamp(file, FORMAT)
    arithmetic = json.dumps([{"from_increment": 0, **decisive(), **(arithmetic or {})}], sort_keys=True)
    write_attrs(file, {**header, "version": __version__, "arithmetic": arithmetic, "nstored": 0, "completed": False,
                       "stop_reason": ""})
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
    for name, (shape, dtype) in (state_fields or {}).items():
        shape = tuple(shape)
        write_dataset(state, name, np.zeros((0, *shape), dtype=dtype), maxshape=(None, *shape), chunks=(1, *shape))
    table = file.create_group("increments")
    columns = _FIRST_COLUMNS + list(columns)
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
    state : StoredState
        What restores the increment (its ``further`` the values of ``create_file``'s ``state_fields``).
    row : dict
        ``increment``, ``kick``, ``yield_element`` and the observables.
    """
    for name in _STATE:
        _append(file["state"][name], getattr(state, name))
    for name, value in state.further.items():
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
        RunFile(source)  # header, mesh, the arrays' shapes and the stored rows checked before a byte is copied
        with open_file(tmp, "w") as target:
            copy_file(source, target, rows=stored_increments(source))
            write_attrs(target, attrs)


def check_arithmetic(path, arithmetic=None):
    """Before a resume: the attributes that record this process's arithmetic, if it is not the stored one.

    Parameters
    ----------
    path : str or pathlib.Path
        An incomplete simulation file.
    arithmetic : Mapping[str, object], optional
        As :func:`create_file`'s: compared too.

    Returns
    -------
    dict
        ``{}`` if the arithmetic is the stored one, else ``{"arithmetic": ...}`` with a segment
        appended (to pass to :func:`rewrite`).

    Raises
    ------
    stickslip.arithmetic.ArithmeticMismatchError
        If it differs and continuing anyway was not asked for (:func:`stickslip.arithmetic.check_resume`).
    """
    with open_file(path) as file:
        _check(file)
        stored, nstored = file.attrs.get("arithmetic", ""), stored_increments(file)
    text = check_resume(path, stored, nstored, extra=arithmetic)
    return {} if text is None else {"arithmetic": text}


def _check(file):
    """Raise unless ``file`` is a ``fem-run`` file of the current version with every :data:`HEADER` field, each of its
    kind, and a count of stored increments."""
    formats.check(file, FORMAT)
    missing = [name for name in HEADER if name not in file.attrs]
    if missing:
        raise FileFormatError(f"{file.filename}: fem-run header lacks {', '.join(missing)}")
    for name, (kind, _) in HEADER.items():
        value = attribute(file, name, kind)
        if kind == "json" and not isinstance(value, dict):
            raise FileFormatError(f"{file.filename}: attribute '{name}' is not a JSON object")
    regime = attribute(file, "regime", "str")
    if regime not in REGIMES:
        raise FileFormatError(f"{file.filename}: attribute 'regime' is {regime!r}, expected one of {', '.join(REGIMES)}")
    stored_increments(file)
    attribute(file, "completed", "bool")


def stored_increments(file):
    """The number of complete increments an open ``fem-run`` file says it stores (``nstored``), checked against its
    datasets.

    Every growable dataset of ``/state`` and ``/increments`` must hold ``nstored`` rows, and the file must store
    the last of them (its chunk was written, :mod:`stickslip.stored_rows`): a file resized and told a larger
    ``nstored`` is refused here, before any row is read, in a few lookups of each chunk index (a chunk missing
    before the last is refused where the rows are read, :func:`stickslip.h5io.read_array`).

    Raises
    ------
    FileFormatError
        If ``nstored`` is not an integer >= 0, or more than the file's rows (``/state/t``).
    stickslip.h5io.CorruptFileError
        If a growable dataset holds fewer rows or the file does not store its row ``nstored - 1``.
    """
    nstored = attribute(file, "nstored", "int")
    times = file.get("state/t")
    if not isinstance(times, h5py.Dataset) or times.ndim != 1:
        raise FileFormatError(f"{file.filename}: /state/t is not a 1-D dataset (the time of every stored increment)")
    if not 0 <= nstored <= times.shape[0]:
        raise FileFormatError(f"{file.filename}: attribute 'nstored' is {nstored}, expected 0 ... the "
                              f"{times.shape[0]} rows of /state/t")
    growable = _growable(file) if nstored else []
    if any(dataset.shape[0] < nstored or first_unstored_row(dataset, nstored - 1, nstored) is not None
           for dataset in growable):
        stored = {dataset.name: min(dataset.shape[0], first_unstored_row(dataset, 0, nstored) or nstored)
                  for dataset in growable}
        name = min(stored, key=stored.get)
        raise CorruptFileError(f"{file.filename}: attribute 'nstored' is {nstored}, but {name} stores {stored[name]} "
                               f"rows at most (declared: {file[name].shape[0]}): the file is damaged or not what it "
                               "claims; remake it (rerun the job that wrote it)")
    return nstored


def _growable(file):
    """The datasets of ``/state`` and ``/increments`` with an unlimited first axis (one row per increment)."""
    groups = [file.get(name) for name in ("state", "increments")]
    return [item for group in groups if isinstance(group, h5py.Group) for item in group.values()
            if isinstance(item, h5py.Dataset) and item.maxshape and item.maxshape[0] is None]


def read_params(file):
    """The producer's parameters stored in an open ``fem-run`` file, as they were written.

    The format does not interpret them: the producer parses them (``fem``:
    :func:`stickslip.fem.parameters.stored_params`).

    Parameters
    ----------
    file : h5py.File

    Returns
    -------
    dict

    Raises
    ------
    FileFormatError
        If the file is not a ``fem-run`` file of the current version.
    """
    _check(file)
    return attribute(file, "params", "json")


class RunFile:
    """Read access to the stored states of a simulation file.

    Parameters
    ----------
    file : h5py.File
        Open ``fem-run`` file.

    Attributes
    ----------
    params : dict
        The producer's parameters (:func:`read_params`).
    mesh : stickslip.mesh.LayeredMesh
    nstored : int
        Complete increments.

    Raises
    ------
    FileFormatError
        If the file is not a ``fem-run`` file of the current version.
    """

    def __init__(self, file):
        self.file = file
        self.params = read_params(file)
        self.mesh = load_mesh(file["mesh"])
        self.nstored = stored_increments(file)
        if not self.nstored:
            raise CorruptFileError(f"{file.filename}: attribute 'nstored' is 0, but a fem run stores its increment 0 "
                                   "when its file is created: the file is damaged; remake it (rerun the job that "
                                   "wrote it)")
        self._check_shapes()
        self._check_columns()

    def _check_shapes(self):
        """Raise FileFormatError unless the linear response and the state have the shapes of the mesh (module
        docstring), before any of them is used."""
        ndof, nlayer = self.mesh.ndof, self.mesh.nlayer
        expected = {"event/delta_u": (ndof,), "event/delta_eps": (self.mesh.N * self.mesh.n_interfaces, 4, 3),
                    "event/delta_target": (nlayer,), "event/delta_lever": (1,), "state/u": (ndof,),
                    "state/target": (nlayer,), "state/lever_target": (), "state/t": ()}
        for name, shape in expected.items():
            dataset = self.file.get(name)
            per_row = name.startswith("state/")
            found = dataset.shape if isinstance(dataset, h5py.Dataset) else None
            found = (found[1:] if found else None) if per_row else found
            if found != shape:
                what = f"of shape {dataset.shape}" if isinstance(dataset, h5py.Dataset) else "missing"
                raise FileFormatError(f"{self.file.filename}: /{name} is {what}, expected "
                                      f"{'rows of ' if per_row else ''}{shape} (the stored mesh's): the file is "
                                      "damaged")

    def _check_columns(self):
        """Raise CorruptFileError unless the attribute ``columns`` of ``/increments`` names its datasets, the
        format's first (:func:`create_file`)."""
        table = self.file["increments"]
        columns = attribute(table, "columns", "json")
        if not (isinstance(columns, list) and columns[:len(_FIRST_COLUMNS)] == _FIRST_COLUMNS
                and sorted(columns) == sorted(table)):
            raise CorruptFileError(f"{self.file.filename}: attribute 'columns' of /increments is {str(columns)[:80]}, "
                                   f"expected the names of its {len(table)} datasets, {', '.join(_FIRST_COLUMNS)} "
                                   "first: the file is damaged; remake it (rerun the job that wrote it)")

    def state(self, increment):
        """The :class:`StoredState` of a stored increment (its ``further`` empty in a file without further state)."""
        if not 0 <= increment < self.nstored:
            raise FileFormatError(f"{self.file.filename}: increment {increment} is not stored "
                                  f"(0 ... {self.nstored - 1})")
        u, target, lever_target, t = (read_array(self.file["state"][name], increment) for name in _STATE)
        further = {name: read_array(self.file["state"][name], increment) for name in self._further()}
        return StoredState(u, target, float(lever_target), float(t), further)

    def _further(self):
        return [name for name in sorted(self.file["state"]) if name not in _STATE]

    def increments(self):
        """The observables table of the stored increments (pandas.DataFrame, :func:`read_increments`)."""
        return read_table(self.file, "increments", rows=self.nstored)

    def increment_bytes(self):
        """Bytes that appending one increment may allocate at most: one new chunk of every growing dataset [B]."""
        datasets = [self.file["state"][name] for name in (*_STATE, *self._further())]
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
    path : str or os.PathLike

    Returns
    -------
    pandas.DataFrame
        One row per stored increment; columns ``increment``, ``kick``, ``yield_element`` and
        the producer's observables (``fem``: ``t``, ``gamma``, ``epsd``, ``sigd``, ``epsd_<l>``,
        ``sigd_<l>``, ``ubar_<l>``, ``fxdrive_<l>``, ``S_a<a>``, ``A_a<a>``; free lever also
        ``lever_target``, ``lever_position``; :mod:`stickslip.fem.observables`).

    Raises
    ------
    FileFormatError
        If the file is not a ``fem-run`` file of the current version.
    """
    with open_file(path) as file:
        _check(file)
        return read_table(file, "increments", rows=stored_increments(file))


def read_run_attrs(path):
    """Header and status of a simulation file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    dict
        Every root attribute as a Python value: the fields of :data:`HEADER` (``params`` decoded
        to a dict), the producer's further attributes, ``version``, ``nstored``, ``completed``
        (bool), ``stop_reason``, ``format``, ``format_version``.

    Raises
    ------
    FileFormatError
        If the file is not a ``fem-run`` file of the current version.
    """
    with open_file(path) as file:
        _check(file)
        out = {}
        for key, value in file.attrs.items():
            out[key] = value.item() if isinstance(value, np.generic) else value
        out.update({name: attribute(file, name, kind) for name, (kind, _) in HEADER.items()})
        out["nstored"], out["completed"] = stored_increments(file), attribute(file, "completed", "bool")
        return out


def describe(path):
    """The results database's simulation columns of a ``fem-run`` file (:func:`stickslip.formats.describe`).

    Returns
    -------
    dict[str, object]
        ``n`` (interfaces), ``plates``, ``blocks`` (N), ``k_drive``, ``phi``, ``regime``, ``seed``:
        the file's own header; ``temperature`` (a thermal producer's attribute; 0 for a file without it,
        the athermal protocol), for a thermal run ``attempt_rate`` and ``drive_rate`` (None otherwise) and
        ``junction_strengthening`` (0 without junction aging), and with aging ``junction_glass_temperature``
        and ``junction_attempt_rate`` (None otherwise).
    """
    attrs = read_run_attrs(path)
    with open_file(path) as file:
        thermal = attribute(file, "protocol", "str", "", required=False) == "thermal"
        aging = "junction_strengthening" in attrs

        def number(name, used):
            return attribute(file, name, "float") if used else None

        return {"n": attrs["n_interfaces"], "plates": attrs["plates"], "blocks": attrs["N"],
                "k_drive": attrs["k_drive"], "phi": attrs["phi"], "regime": attrs["regime"], "seed": attrs["seed"],
                "temperature": number("temperature", thermal) or 0.0,
                "attempt_rate": number("attempt_rate", thermal), "drive_rate": number("drive_rate", thermal),
                "junction_strengthening": number("junction_strengthening", aging) if aging else 0.0 if thermal
                else None,
                **{name: number(name, aging) for name in ("junction_glass_temperature", "junction_attempt_rate")}}
