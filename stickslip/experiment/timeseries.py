"""The ``timeseries`` format (experimental recordings): one HDF5 file per run, lab or virtual data.

Layout (``shared/design.md``, section "Experimental time-series format"):

===============  ==================  ==============================================
item             shape / type        meaning
===============  ==================  ==============================================
``/t_F``         float64 [n_F]       force sample times [s], strictly increasing
``/F``           float64 [n_F]       lever force [N]
``/t_x``         float64 [n_frames]  camera frame times [s], strictly increasing
``/x``           float64 [n_frames,  absolute horizontal slab positions [mm];
                 n_slabs]            column i-1 is slab i (1 = lowest)
attr ``n``       int                 driven slabs (springs attached), 1..n_slabs
attr ``n_slabs`` int                 slabs in the stack
attr ``protocol`` str                ``"stack"`` or ``"individual"``
attr ``a``       int                 slab driven alone (individual); stack: 0 or absent
attr ``normal_force`` float          N [N]
attr ``k_spring`` float              K [N/mm]
attr ``h``       float               slab thickness [mm]
attr ``H``       float               lever height [mm]
attr ``V``       float               lever-top speed actually imposed [mm/s]
attr ``format``  str                 ``"timeseries"``, with ``format_version``
===============  ==================  ==============================================

A dataset may carry its unit as the attribute ``unit`` (or ``units``); it must then be the one
above. A file written outside stickslip (a lab script following ``shared/design.md``) has no
``format`` attributes: it is read as version 1, checked by its content (every dataset and
attribute above, shapes, finite values, strictly increasing times), with a one-line note.

Protocols (paper, section "Experiments" and appendix "Individual sliding"):

- ``"stack"``: slabs 1..n carry a spring (n = 1..n_slabs), the slabs above ride
  on slab n; ``a = 0``.
- ``"individual"``: only slab ``a`` carries a spring, the slabs below it are
  clamped; hence ``n = 1``. The lever is driven at ``V = V_paper / a`` so that
  the spring of slab a moves at ``a h V / H = h V_paper / H``: ``V`` in the file
  is the speed of the lever top during that run.

Optional content: further attributes (a virtual run stores ``params`` as JSON
and ``seed``) and tables written with :func:`stickslip.h5io.write_table`; a
virtual run stores its ground truth as the tables ``truth`` (one row per slip)
and ``interfaces`` (one row per interface), see :mod:`stickslip.solvers.lever`.
"""

import dataclasses
import sys

import h5py
import numpy as np

from .. import formats, h5io
from ..output_safety.atomic import atomic_output

__all__ = ["FORMAT", "PROTOCOLS", "ExperimentRecord", "write_timeseries", "read_timeseries", "read_truth",
           "validate_record", "describe"]

#: The format name of these files (:mod:`stickslip.formats`).
FORMAT = "timeseries"

#: The known driving protocols.
PROTOCOLS = ("stack", "individual")

_DATASETS = ("t_F", "F", "t_x", "x")
#: The unit of every dataset.
_UNITS = {"t_F": "s", "F": "N", "t_x": "s", "x": "mm"}
#: Where the layout is described for other writers.
_LAYOUT = "docs/experimental-analysis.md, 'File layout'"
_INT_ATTRS = ("n", "n_slabs", "a")
_FLOAT_ATTRS = ("normal_force", "k_spring", "h", "H", "V")
# Lossless and deterministic; halves a 6000 s run (6.2 -> 2.9 MB) for ~0.1 s of writing.
_COMPRESSION = {"compression": "gzip", "compression_opts": 1, "shuffle": True}


@dataclasses.dataclass(frozen=True)
class ExperimentRecord:
    """One run of the lever experiment: force and slab-position time series.

    Attributes
    ----------
    t_F : numpy.ndarray
        float64 [n_F]: force sample times [s], strictly increasing.
    F : numpy.ndarray
        float64 [n_F]: lever force [N].
    t_x : numpy.ndarray
        float64 [n_frames]: camera frame times [s], strictly increasing.
    x : numpy.ndarray
        float64 [n_frames, n_slabs]: absolute horizontal slab positions [mm];
        column i-1 is slab i (1 = lowest).
    n : int
        Number of driven slabs (springs attached), 1..n_slabs (1 for "individual").
    n_slabs : int
        Slabs in the stack (5 in the paper).
    protocol : str
        ``"stack"`` (slabs 1..n driven) or ``"individual"`` (only slab ``a``
        driven, slabs below clamped).
    a : int
        Slab driven alone in the individual protocol; 0 for "stack".
    normal_force : float
        N [N].
    k_spring : float
        K [N/mm].
    h : float
        Slab thickness [mm].
    H : float
        Lever height [mm].
    V : float
        Lever-top speed imposed during the run [mm/s] (``V_paper / a`` for
        the individual protocol).
    """

    t_F: np.ndarray
    F: np.ndarray
    t_x: np.ndarray
    x: np.ndarray
    n: int
    n_slabs: int
    protocol: str
    a: int
    normal_force: float
    k_spring: float
    h: float
    H: float
    V: float

    @property
    def R(self):
        """Relative positions R_i = x_i - x_{i-1} (x_0 = 0, the fixed base) [mm].

        Returns
        -------
        numpy.ndarray
            float64 [n_frames, n_slabs]; column i-1 is interface i (under slab i).
        """
        return np.diff(self.x, axis=1, prepend=0.0)


def _fail(source, item, expected):
    raise h5io.FileFormatError(f"{source}: '{item}' {expected}")


def _shown(value):
    """An attribute's value on one line: a numpy scalar as the number it holds (``39.6``, not ``np.float64(39.6)``)."""
    value = value.item() if isinstance(value, np.generic) else value
    return " ".join(repr(value).split())[:80]


def _check_times(source, name, times):
    if times.ndim != 1 or times.size < 2:
        _fail(source, name, f"must be a 1-D array of at least 2 times, got shape {times.shape}")
    if not np.all(np.isfinite(times)):
        _fail(source, name, "must be finite (found NaN or inf)")
    steps = np.diff(times)
    if np.any(steps <= 0):
        index = int(np.argmax(steps <= 0))
        _fail(source, name, f"must be strictly increasing; sample {index + 1} ({times[index + 1]:.10g} s) "
                            f"does not follow sample {index} ({times[index]:.10g} s)")


def validate_record(record, source="record"):
    """Check that a record is consistent; raise naming the first offending item.

    Parameters
    ----------
    record : ExperimentRecord
    source : str, optional
        Name of the file or object, used in the message.

    Raises
    ------
    stickslip.h5io.FileFormatError
        If a time axis is not strictly increasing or not finite, a signal is not
        finite or has a shape inconsistent with its time axis and ``n_slabs``, the
        protocol is unknown, or ``n``, ``a`` or a physical constant is out of range.
    """
    if record.protocol not in PROTOCOLS:
        _fail(source, "protocol", f"must be one of {', '.join(PROTOCOLS)}, got {record.protocol!r}")
    if record.n_slabs < 1:
        _fail(source, "n_slabs", f"must be >= 1, got {record.n_slabs}")
    if not 1 <= record.n <= record.n_slabs:
        _fail(source, "n", f"must be in 1..n_slabs={record.n_slabs}, got {record.n}")
    if record.protocol == "stack" and record.a != 0:
        _fail(source, "a", f"must be 0 for the stack protocol, got {record.a}")
    if record.protocol == "individual":
        if not 1 <= record.a <= record.n_slabs:
            _fail(source, "a", f"must be in 1..n_slabs={record.n_slabs} for the individual protocol, "
                               f"got {record.a}")
        if record.n != 1:
            _fail(source, "n", f"must be 1 for the individual protocol (one spring), got {record.n}")
    for name in _FLOAT_ATTRS:
        value = getattr(record, name)
        if not (np.isfinite(value) and value > 0):
            _fail(source, name, f"must be a finite number > 0, got {float(value):g}")
    _check_times(source, "t_F", record.t_F)
    _check_times(source, "t_x", record.t_x)
    if record.F.shape != record.t_F.shape:
        _fail(source, "F", f"must have the shape of t_F {record.t_F.shape}, got {record.F.shape}")
    if record.x.shape != (record.t_x.size, record.n_slabs):
        _fail(source, "x", f"must have shape (n_frames, n_slabs) = {(record.t_x.size, record.n_slabs)}, "
                           f"got {record.x.shape}")
    for name in ("F", "x"):
        if not np.all(np.isfinite(getattr(record, name))):
            _fail(source, name, "must be finite (found NaN or inf)")


def write_timeseries(path, record, *, attrs=None, tables=None):
    """Write a record to an HDF5 file (atomically; equal inputs give equal bytes; gzip-compressed).

    Parameters
    ----------
    path : str or pathlib.Path
        Output file; replaced only once the new file is complete.
    record : ExperimentRecord
        Validated with :func:`validate_record` before anything is written.
    attrs : Mapping[str, object], optional
        Extra root attributes (e.g. ``params`` as a dict, stored as JSON, and ``seed``);
        they must not reuse the names of the format's attributes.
    tables : Mapping[str, pandas.DataFrame], optional
        Extra tables by name (e.g. ``"truth"``), see :func:`stickslip.h5io.write_table`.

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the record is inconsistent.
    ValueError
        If an extra attribute or table would overwrite an item of the format.
    """
    validate_record(record, source=str(path))
    reserved = set(_DATASETS) | set(_INT_ATTRS) | set(_FLOAT_ATTRS) | {"protocol", "format", "format_version"}
    clashes = sorted(reserved & (set(attrs or {}) | set(tables or {})))
    if clashes:
        raise ValueError(f"extra attributes/tables must not reuse the format's names: {', '.join(clashes)}")
    with atomic_output(path) as tmp, h5io.open_file(tmp, "w") as f:
        formats.stamp(f, FORMAT)
        for name in _DATASETS:
            h5io.write_dataset(f, name, np.asarray(getattr(record, name), dtype=np.float64), **_COMPRESSION)
        for name in _INT_ATTRS:
            f.attrs[name] = int(getattr(record, name))
        for name in _FLOAT_ATTRS:
            f.attrs[name] = float(getattr(record, name))
        f.attrs["protocol"] = record.protocol
        h5io.write_attrs(f, attrs or {})
        for name, table in (tables or {}).items():
            h5io.write_table(f, name, table)


def read_timeseries(path):
    """Read and validate a time-series file.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    ExperimentRecord

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the file is missing or unreadable, a required dataset or attribute is
        absent or of the wrong kind, a dataset states another unit, or the content
        fails :func:`validate_record`; the message names the file and the item. (``a``
        is required for the individual protocol only; a stack recording without it
        reads as ``a = 0``.) A file without ``format`` attributes (a lab recording) is
        read as version 1 when its content passes, with a note on stderr.
    """
    with h5io.open_file(path) as f:
        stamped = formats.check(f, FORMAT)
        try:
            record = _read_record(f, str(path))
        except h5io.FileFormatError as error:
            if stamped:
                raise
            raise h5io.FileFormatError(f"{error} (a file without a 'format' attribute is read as a lab recording "
                                       f"in the documented layout: {_LAYOUT})") from None
    if not stamped:
        print(f"stickslip: note: {path}: no 'format' attribute; read as a lab recording in the documented layout "
              f"({FORMAT} version 1), checked by its content", file=sys.stderr)
    return record


def _read_record(f, source):
    """The record of an open time-series file, checked (see :func:`read_timeseries`)."""
    values = {}
    for name in _DATASETS:
        if name not in f:
            _fail(source, name, "is missing (required dataset)")
        if not isinstance(f[name], h5py.Dataset):
            _fail(source, name, "must be a dataset, got a group")
        units = [h5io.attribute(f[name], key, "str", required=False) for key in ("unit", "units")]
        unit = units[0] if units[0] is not None else units[1]
        if unit is not None and unit != _UNITS[name]:
            _fail(source, name, f"is in [{unit}]; the format stores it in [{_UNITS[name]}] (convert it, or "
                                f"import the lab's CSV with `stickslip import-csv`, which converts units)")
        if f[name].dtype.kind not in "fiu":
            _fail(source, name, f"must be numeric, got dtype {f[name].dtype}")
        data = h5io.read_array(f[name])
        values[name] = np.asarray(data, dtype=np.float64)
    for name in ("protocol",) + _INT_ATTRS + _FLOAT_ATTRS:
        if name not in f.attrs and name != "a":
            _fail(source, name, "is missing (required attribute)")
    values["protocol"] = h5io.attribute(f, "protocol", "str")
    if "a" not in f.attrs and values["protocol"] == "individual":
        _fail(source, "a", "is missing (required attribute of the individual protocol: the driven slab)")
    for name in _INT_ATTRS:
        value = f.attrs.get(name, 0)  # only a of a stack recording may be absent: 0
        if not (np.issubdtype(type(value), np.integer) or (isinstance(value, float) and value.is_integer())):
            _fail(source, name, f"must be an integer, got {_shown(value)}")
        values[name] = int(value)
    for name in _FLOAT_ATTRS:
        value = f.attrs[name]
        if not np.issubdtype(type(value), np.number) or np.ndim(value) != 0:
            _fail(source, name, f"must be a number, got {_shown(value)}")
        values[name] = float(value)
    record = ExperimentRecord(**values)
    validate_record(record, source=source)
    return record


def read_truth(path, table="truth"):
    """Read a ground-truth table of a virtual run.

    Parameters
    ----------
    path : str or pathlib.Path
    table : {"truth", "interfaces"}, optional
        ``"truth"``: one row per slip the virtual experiment made; ``"interfaces"``:
        one row per interface (its friction parameters and slip/creep totals).
        Columns are documented in :mod:`stickslip.solvers.lever`.

    Returns
    -------
    pandas.DataFrame or None
        None if the file has no such table (lab data).

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the file is missing or unreadable.
    """
    with h5io.open_file(path) as f:
        if table not in f:
            return None
        return h5io.read_table(f, table)


def describe(path):
    """The results database's simulation columns of a ``timeseries`` file (:func:`stickslip.formats.describe`).

    Returns
    -------
    dict[str, object]
        ``protocol``, ``n`` (driven slabs), ``driven_slab`` (the attribute ``a``: the slab driven alone, 0 for
        the stack) and ``seed`` (None for lab data, which has no seed attribute).
    """
    with h5io.open_file(path) as f:
        formats.check(f, FORMAT)
        return {"protocol": h5io.attribute(f, "protocol", "str"), "n": h5io.attribute(f, "n", "int"),
                "driven_slab": h5io.attribute(f, "a", "int", 0, required=False),
                "seed": h5io.attribute(f, "seed", "int", required=False)}
