"""The artifact formats: every file that passes between stages, with its name and version.

A stage's output is its contract. Each format has one module that reads and writes it
(working on arrays and tables) and a version stored in every file as the root attributes
``format`` and ``format_version`` (:func:`stamp`); readers refuse another version
(:func:`check`). Plugins declare the formats they consume and produce
(:mod:`stickslip.registry`), and the study wires an analysis to every simulation whose
solver produces the format it consumes, whatever the solver's name.

Built-in formats (``docs/developing.md`` draws the data flow):

=============  =======================================  ========================================
format         reader/writer                            producers -> consumers
=============  =======================================  ========================================
mesh           :mod:`stickslip.mesh.io`                 mesh stage -> ``fem`` (solver input), figS-mesh
fem-run        :mod:`stickslip.formats.fem_run`         ``fem`` -> numerical-events, front-dynamics, thermal-events
timeseries     :mod:`stickslip.experiment.timeseries`   ``lever``, lab CSV import -> experiment-events
event-table    :mod:`stickslip.formats.event_table`     numerical-, experiment-, thermal-events -> figures, database
front-table    :mod:`stickslip.formats.front_table`     front-dynamics -> figS-event-maps, figS-tau
=============  =======================================  ========================================

A simulation format says what kind of data it holds (``source``: "numerical" or
"experimental") and may describe a file by the typed columns of the results database
(``describe``); the database ingests formats, never file names.

A format whose files are also written outside stickslip (lab recordings, ``timeseries``) names
the version that a file without ``format`` and ``format_version`` is read as (``unstamped``);
its reader then validates the file by its content. A file that states another format is
refused as any other.

A third-party package adds a format with :func:`register_format` in the module its entry
point imports.
"""

import dataclasses
import importlib
import re

from ..h5io import FileFormatError, attribute
from ..plugin_params import ParameterError, parse_params

__all__ = ["Format", "FormatError", "register_format", "get_format", "available_formats", "stamp", "check",
           "describe", "stored_run_params"]

_NAME = re.compile(r"^[a-z][a-z0-9-]*$")


class FormatError(LookupError):
    """A format is malformed, registered twice with another definition, or unknown."""


@dataclasses.dataclass(frozen=True)
class Format:
    """One artifact format.

    Attributes
    ----------
    name : str
        Lowercase letters, digits and ``-`` (e.g. ``fem-run``).
    version : int
        Layout version, stored in every file; bump it when the layout changes meaning.
    module : str
        Dotted module holding the format's reader and writer.
    summary : str
        One line: what a file of this format holds.
    source : {"numerical", "experimental", None}
        For simulation formats: the kind of data (a column of the database).
    describe : str or None
        ``"module:function"``: ``function(path) -> dict`` of the database's simulation
        columns (``protocol``, ``n``, ``driven_slab``, ``plates``, ``blocks``, ``k_drive``,
        ``phi``, ``regime``, ``seed``, ``temperature``, ``attempt_rate``, ``drive_rate``, ``junction_strengthening``,
        ``junction_glass_temperature``, ``junction_attempt_rate``) read from one file.
    unstamped : int or None
        The version a file without ``format`` attributes is read as (its layout is
        documented for other writers, e.g. lab scripts; the reader validates the
        content); None: such a file is refused.
    """

    name: str
    version: int
    module: str
    summary: str
    source: str | None = None
    describe: str | None = None
    unstamped: int | None = None


_formats = {}


def register_format(fmt):
    """Register a format (idempotent for an identical definition).

    Parameters
    ----------
    fmt : Format

    Returns
    -------
    Format

    Raises
    ------
    FormatError
        If the name is malformed or taken by another definition.
    """
    if not _NAME.match(fmt.name):
        raise FormatError(f"format name {fmt.name!r} must match {_NAME.pattern}")
    if fmt.source not in (None, "numerical", "experimental"):
        raise FormatError(f"format {fmt.name!r}: source must be 'numerical', 'experimental' or None")
    existing = _formats.get(fmt.name)
    if existing is not None and existing != fmt:
        raise FormatError(f"format {fmt.name!r} is already registered by {existing.module}")
    _formats[fmt.name] = fmt
    return fmt


def get_format(name):
    """Return a registered format.

    Raises
    ------
    FormatError
        If there is none; the message lists the known formats.
    """
    try:
        return _formats[name]
    except KeyError:
        raise FormatError(f"unknown format {name!r}; known: {', '.join(sorted(_formats))}") from None


def available_formats():
    """Return the registered formats by name (sorted)."""
    return dict(sorted(_formats.items()))


def stamp(file, name):
    """Write the root attributes ``format`` and ``format_version`` of a new file.

    Parameters
    ----------
    file : h5py.File
    name : str
        A registered format.
    """
    fmt = get_format(name)
    file.attrs["format"] = fmt.name
    file.attrs["format_version"] = fmt.version


def check(file, name):
    """Raise unless an open file is of format ``name`` in its current version.

    Parameters
    ----------
    file : h5py.File
    name : str

    Returns
    -------
    bool
        True if the file states its format; False if it states none and the format
        reads such files (``Format.unstamped``, the current version): the caller must
        then validate the content, and may say so.

    Raises
    ------
    FileFormatError
        Naming the file, the format found and the one expected.
    """
    fmt = get_format(name)
    found = attribute(file, "format", "str", required=False)
    if found is None and "format_version" not in file.attrs and fmt.unstamped == fmt.version:
        return False
    if found is None:
        raise FileFormatError(f"{file.filename}: no 'format' attribute (expected a {name} file, version "
                              f"{fmt.version}; written by an older stickslip? rerun the job that made it)")
    version = attribute(file, "format_version", "int", -1, required=False)
    if found != name or version != fmt.version:
        raise FileFormatError(f"{file.filename}: a {found} file version {version}, expected {name} version "
                              f"{fmt.version}")
    return True


def stored_run_params(params_class, stored, path, solver):
    """The parameters a solver's output file stores, validated: parameters that no run has are a damaged file.

    Parameters
    ----------
    params_class : type
        The solver's parameter dataclass (:mod:`stickslip.plugin_params`).
    stored : Mapping[str, object]
        The file's attribute ``params``, decoded.
    path : str or pathlib.Path
        The file, for the message.
    solver : str
        The solver's name, for the message.

    Returns
    -------
    object
        An instance of ``params_class``.

    Raises
    ------
    FileFormatError
        Naming the file as damaged, with the parameter that no run has (a flipped bit in the stored text reads
        otherwise as the user's wrong parameter).
    """
    try:
        return parse_params(params_class, stored, owner=f"{path}: params")
    except ParameterError as error:
        raise FileFormatError(f"{path}: attribute 'params' holds parameters no {solver} run has ({error}): the file "
                              "is damaged or not what it claims; remake it (rerun the job that wrote it)") from None


def describe(name, path):
    """Return the database's simulation columns of a file of format ``name`` (empty if none).

    Parameters
    ----------
    name : str
    path : str or pathlib.Path

    Returns
    -------
    dict[str, object]
    """
    fmt = get_format(name)
    if fmt.describe is None:
        return {}
    module, _, function = fmt.describe.partition(":")
    return getattr(importlib.import_module(module), function)(path)


for _builtin in (
        Format("mesh", 1, "stickslip.mesh.io", "a layered Quad4 mesh (coordinates, connectivity, layers)"),
        Format("fem-run", 2, "stickslip.formats.fem_run", "a quasistatic finite-element run: header, mesh, linear "
               "response, one state and one row of observables per increment", source="numerical",
               describe="stickslip.formats.fem_run:describe"),
        Format("timeseries", 1, "stickslip.experiment.timeseries", "an experimental recording: lever force F(t), "
               "slab positions x(t), apparatus attributes", source="experimental",
               describe="stickslip.experiment.timeseries:describe", unstamped=1),
        Format("event-table", 2, "stickslip.formats.event_table", "slip events: one row per (event, slipping "
               "interface) in the table 'slip_events', plus the analysis's own tables"),
        Format("front-table", 2, "stickslip.formats.front_table", "re-run events: block failures and rupture fronts"),
):
    register_format(_builtin)
