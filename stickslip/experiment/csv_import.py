"""Import lab exports (two CSV files) into the experimental time-series format.

CSV layout (comma-separated, one header line, lines starting with ``#`` are comments)::

    # force.csv                      # positions.csv
    t [s],F [N]                      t [s],x1 [mm],x2 [mm],x3 [mm],x4 [mm],x5 [mm]
    0.00,2.803                       0.0,-3.21,-6.42,-9.63,-9.63,-9.63
    0.02,2.805                       0.2,-3.21,-6.42,-9.63,-9.63,-9.63

- force file: exactly the columns ``t`` and ``F``;
- positions file: exactly ``t``, ``x1`` ... ``x<n_slabs>`` (``x1`` the lowest slab), absolute
  horizontal positions of the slabs;
- every header names its unit in brackets. Accepted units, converted to the format's units:
  time ``s``, ``ms``; force ``N``, ``mN``, ``kN``; length ``mm``, ``um`` (or ``µm``), ``m``.
  A file whose headers carry no unit can be read by declaring the units
  (``time_unit``, ``force_unit``, ``position_unit``); a declared unit that contradicts a
  header is an error.

Errors (:class:`stickslip.h5io.FileFormatError`) name the file, the column and, for bad
values, the line: missing or unexpected columns, missing or unknown units, non-numeric or
NaN/inf values, times that do not strictly increase, fewer than two rows.
"""

import re
from pathlib import Path

import numpy as np
import pandas as pd

from ..h5io import FileFormatError
from ..hashing import sha256_file
from ..output_safety.overwrite import claimed_output
from .timeseries import FORMAT, ExperimentRecord, validate_record, write_timeseries

__all__ = ["UNITS", "import_csv", "read_csv_columns"]

#: Accepted units per quantity, with the factor to the format's unit (s, N, mm).
UNITS = {
    "time": {"s": 1.0, "ms": 1e-3},
    "force": {"N": 1.0, "mN": 1e-3, "kN": 1e3},
    "length": {"mm": 1.0, "um": 1e-3, "µm": 1e-3, "m": 1e3},
}

#: The unit of each quantity in the format.
_FORMAT_UNITS = {quantity: next(unit for unit, factor in units.items() if factor == 1.0) for quantity, units in
                 UNITS.items()}

_HEADER = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\[\s*([^\]]*?)\s*\])?\s*$")


def _refuse_semicolons(path):
    """Raise FileFormatError with a hint if the header line is separated by ';' (a European spreadsheet's CSV)."""
    with open(path, encoding="utf-8", errors="replace") as handle:
        header = next((line.strip() for line in handle if line.strip() and not line.startswith("#")), "")
    if ";" in header and "," not in header:
        raise FileFormatError(f"{path}: one column whose header {header!r} holds ';': the file seems separated by "
                              f"';' (a European export); expected ',' between columns (save it as CSV with ',' as "
                              f"separator and '.' as decimal point)")


#: Names a message lists at most (a header of 100 000 columns is one short line, not one of 800 kB).
_LISTED = 8


def _listed(names):
    """Names comma-separated, at most :data:`_LISTED` of them and how many more, each cut to 40 characters."""
    shown = [_cut(name, 40) for name in names[:_LISTED]]
    more = f" and {len(names) - _LISTED} more" if len(names) > _LISTED else ""
    return ", ".join(shown) + more


def _cut(text, length):
    """``text`` cut to ``length`` characters (with ``...``)."""
    text = str(text)
    return text if len(text) <= length else text[:length - 3] + "..."


def _parse_header(path, header):
    """Map each column name to its unit ('' when the header has none)."""
    columns = {}
    for position, text in enumerate(header, start=1):
        match = _HEADER.match(str(text))
        if match is None:
            raise FileFormatError(f"{path}: header column {position} {_cut(text, 80)!r} is not of the form "
                                  "'name [unit]'")
        name, unit = match.group(1), match.group(2) or ""
        if name in columns:
            raise FileFormatError(f"{path}: column '{name}' appears twice in the header")
        columns[name] = unit
    return columns


def _factor(path, column, unit, quantity, declared):
    units = UNITS[quantity]
    accepted = ", ".join(units)
    if declared is not None and declared not in units:
        raise FileFormatError(f"{path}: declared {quantity} unit {declared!r} is not known; expected one of {accepted}")
    if unit and declared is not None and unit != declared:
        raise FileFormatError(f"{path}: column '{column}' is in [{unit}] but the declared {quantity} unit is "
                              f"{declared!r}")
    unit = unit or declared
    if not unit:
        raise FileFormatError(f"{path}: column '{column}' has no unit; write it in the header as "
                              f"'{column} [{next(iter(units))}]' or declare the {quantity} unit")
    if unit not in units:
        raise FileFormatError(f"{path}: column '{column}' has unit [{unit}], which is not a {quantity} unit; "
                              f"expected one of {accepted}")
    return units[unit]


def read_csv_columns(path, quantities, units):
    """Read a CSV file with exactly the given columns, converted to the format's units.

    Parameters
    ----------
    path : str or pathlib.Path
    quantities : Mapping[str, str]
        Column name to quantity (``"time"``, ``"force"`` or ``"length"``), in the expected order;
        the first column is the time axis, which must increase strictly.
    units : Mapping[str, str or None]
        Declared unit per quantity, for headers without one (None: the header must name it).

    Returns
    -------
    dict[str, numpy.ndarray]
        float64 [n_rows] per column, in s, N or mm.

    Raises
    ------
    stickslip.h5io.FileFormatError
        See the module docstring.
    """
    path = Path(path)
    if not path.is_file():
        raise FileFormatError(f"{path}: no such file")
    _refuse_semicolons(path)
    try:
        table = pd.read_csv(path, comment="#", header=None, dtype=str, skipinitialspace=True,
                            keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as error:
        raise FileFormatError(f"{path}: not a readable CSV file ({error})") from error
    header = _parse_header(path, table.iloc[0])
    table = table.iloc[1:].reset_index(drop=True)
    missing = [name for name in quantities if name not in header]
    if missing:
        raise FileFormatError(f"{path}: missing column{'s' if len(missing) > 1 else ''} {_listed(missing)}; "
                              f"expected exactly {_listed(list(quantities))}")
    unexpected = [name for name in header if name not in quantities]
    if unexpected:
        raise FileFormatError(f"{path}: unexpected column{'s' if len(unexpected) > 1 else ''} "
                              f"{_listed(unexpected)}; expected exactly {_listed(list(quantities))}")
    if len(table) < 2:
        raise FileFormatError(f"{path}: expected at least 2 data rows, got {len(table)}")
    lines = _data_line_numbers(path, len(table))
    values = {}
    text = {name: table[position].str.strip() for position, name in enumerate(header)}
    for name, unit in header.items():
        factor = _factor(path, name, unit, quantities[name], units.get(quantities[name]))
        column = pd.to_numeric(text[name], errors="coerce").to_numpy(dtype=float)
        bad = ~np.isfinite(column)
        if np.any(bad):
            row = int(np.argmax(bad))
            raise FileFormatError(f"{path}: line {lines[row]}, column '{name}': expected a finite number, "
                                  f"got {_cut(text[name].iloc[row], 40)!r}")
        with np.errstate(over="ignore"):
            values[name] = column * factor
        beyond = ~np.isfinite(values[name])
        if np.any(beyond):
            row = int(np.argmax(beyond))
            raise FileFormatError(f"{path}: line {lines[row]}, column '{name}': {_cut(text[name].iloc[row], 40)} "
                                  f"times {factor:g} (to {_FORMAT_UNITS[quantities[name]]}) is beyond the range of a "
                                  "double")
    time_name = next(iter(quantities))
    steps = np.diff(values[time_name])
    if np.any(steps <= 0):
        row = int(np.argmax(steps <= 0)) + 1
        raise FileFormatError(f"{path}: line {lines[row]}, column '{time_name}': time must increase strictly, "
                              f"got {_cut(text[time_name].iloc[row], 40)!r} after "
                              f"{_cut(text[time_name].iloc[row - 1], 40)!r}")
    return {name: values[name] for name in quantities}


def _data_line_numbers(path, n_rows):
    """1-based line numbers of the data rows (after the header, skipping comments and blank lines)."""
    numbers = []
    with open(path, encoding="utf-8", errors="replace") as stream:
        for number, line in enumerate(stream, start=1):
            if line.strip() and not line.lstrip().startswith("#"):
                numbers.append(number)
    return numbers[1:n_rows + 1]


def import_csv(force_csv, positions_csv, output, *, n, n_slabs=5, protocol="stack", a=0, normal_force=49.0,
               k_spring=55.0, h=10.0, H=100.0, V=0.01, time_unit=None, force_unit=None, position_unit=None,
               overwrite=False):
    """Convert a lab export (force CSV + positions CSV) into a time-series HDF5 file.

    Parameters
    ----------
    force_csv, positions_csv : str or pathlib.Path
        The two CSV files (layout in the module docstring).
    output : str or pathlib.Path
        HDF5 file to write (atomically). An existing one is replaced only if it is an import of
        the same two files with the same apparatus, or with ``overwrite``
        (:func:`stickslip.output_safety.overwrite.claimed_output`).
    n : int
        Driven slabs (1 for the individual protocol).
    n_slabs : int, optional
        Slabs in the stack; the positions file has columns x1..x<n_slabs>.
    protocol : {"stack", "individual"}, optional
    a : int, optional
        Slab driven alone (individual protocol); 0 for stack.
    normal_force, k_spring, h, H, V : float, optional
        N [N], K [N/mm], h [mm], H [mm], lever-top speed imposed during the run [mm/s]
        (defaults: the paper's apparatus).
    time_unit, force_unit, position_unit : str, optional
        Units of columns whose header names none (see :data:`UNITS`).
    overwrite : bool, optional
        Replace an existing ``output`` that holds something else.

    Returns
    -------
    ExperimentRecord
        What was written.

    Raises
    ------
    stickslip.h5io.FileFormatError
        For a bad CSV file (naming file, column and line) or inconsistent metadata.
    stickslip.output_safety.overwrite.OutputExistsError
        If ``output`` holds something else and ``overwrite`` is false.
    """
    units = {"time": time_unit, "force": force_unit, "length": position_unit}
    force = read_csv_columns(force_csv, {"t": "time", "F": "force"}, units)
    position_columns = {"t": "time", **{f"x{i}": "length" for i in range(1, n_slabs + 1)}}
    positions = read_csv_columns(positions_csv, position_columns, units)
    x = np.column_stack([positions[f"x{i}"] for i in range(1, n_slabs + 1)])
    record = ExperimentRecord(t_F=force["t"], F=force["F"], t_x=positions["t"], x=x, n=n, n_slabs=n_slabs,
                              protocol=protocol, a=a, normal_force=normal_force, k_spring=k_spring, h=h, H=H, V=V)
    validate_record(record, source=f"import of {force_csv} and {positions_csv}")  # before naming the output
    source = {"force_csv": {"name": Path(force_csv).name, "sha256": sha256_file(force_csv)},
              "positions_csv": {"name": Path(positions_csv).name, "sha256": sha256_file(positions_csv)}}
    apparatus = {name: getattr(record, name) for name in ("n", "n_slabs", "protocol", "a", "normal_force", "k_spring",
                                                           "h", "H", "V")}
    with claimed_output(output, {"format": FORMAT, "imported_from": source, **apparatus}, overwrite=overwrite):
        write_timeseries(output, record, attrs={"imported_from": source})
    return record
