"""One rule for every command that writes a file: an existing output that holds another run is refused.

A writer names the run it is about to write by its *identity*: values its file stores as root
attributes (a solver's ``format``, ``solver``, ``solver_version`` and ``params``; a CSV import's
``imported_from`` and apparatus; a mesh's ``mesh_id``), or, for a workflow job, the run id in the
provenance record beside the file. An existing output with the same identity is the same run: the
writer may resume it, leave it or write the same result again. Anything else (another run, a file of
another kind, a file that is not HDF5) is refused before any work, with one line that names the file
and what differs (:func:`refuse_other_run`), unless the user asked to overwrite it
(``--overwrite``, :func:`claimed_output`). Files whose content is their identity (CSV tables) are
replaced only by the same bytes (:func:`write_text_output`).

Nothing is lost on the way: a replaced file is kept aside until the new one is complete, and an HDF5
file too damaged to open (a truncated copy) is moved aside, never deleted (:func:`set_aside`).
"""

import errno
import filecmp
import glob
import json
import os
import re
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..h5io import FileFormatError, open_file
from .atomic import atomic_output
from .errors import OutputError
from .lock import writer_lock

__all__ = ["OutputExistsError", "refuse_other_run", "claimed_output", "write_text_output", "set_aside",
           "OVERWRITE_HINT"]

#: What a command-line user can do about a refused output.
OVERWRITE_HINT = "pass --overwrite to replace it, or choose another output"

#: The first bytes of every HDF5 file (at offset 0 for the files written here).
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"

#: Root attributes that describe a file in a message (besides those of the identity).
_DESCRIBING = ("format", "solver", "solver_version", "analysis")

#: How a message calls an item of the identity.
_NAMES = {"params": "parameters"}


_MISSING = object()


class OutputExistsError(OutputError):
    """An output exists and holds another run; the message names the file, what differs and what to do.

    Parameters
    ----------
    path : str or pathlib.Path
    difference : str
        What the file holds, against the run about to be written.
    hint : str
        What the user can do.
    """

    def __init__(self, path, difference, hint):
        super().__init__(path, errno.EEXIST, f"{difference}; {hint}")
        self.difference = difference


def set_aside(path, reason):
    """Rename ``path`` to a free name ``<name>.<reason>[-<k>]`` beside it and return that name.

    Parameters
    ----------
    path : pathlib.Path
    reason : str
        E.g. ``"unreadable"``, ``"replaced"``.

    Returns
    -------
    pathlib.Path
    """
    aside = path.with_name(f"{path.name}.{reason}")
    k = 1
    while aside.exists():
        k += 1
        aside = path.with_name(f"{path.name}.{reason}-{k}")
    os.replace(path, aside)
    return aside


def _damaged_hdf5(path):
    """Whether ``path`` starts like an HDF5 file but HDF5 cannot open it (truncated, damaged)."""
    with open(path, "rb") as handle:
        if handle.read(len(_HDF5_SIGNATURE)) != _HDF5_SIGNATURE:
            return False
    try:
        open_file(path).close()
    except FileFormatError:
        return True
    return False


def root_attributes(path, names):
    """The root attributes ``names`` of the HDF5 file ``path`` that it has (JSON text decoded).

    Raises
    ------
    stickslip.h5io.FileFormatError
        If ``path`` is not a readable HDF5 file.
    """
    with open_file(path) as file:
        return {name: _plain(file.attrs[name]) for name in names if name in file.attrs}


def _plain(value):
    """An attribute as a Python value: text decoded, JSON objects and arrays parsed, numpy scalars and arrays
    unwrapped (a damaged file's array compares as a list, not elementwise)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, bytes):
        value = value.decode("utf-8", "surrogateescape")
    if isinstance(value, str) and value[:1] in "{[":
        try:
            return json.loads(value)
        except ValueError:
            return value
    return value.item() if isinstance(value, np.generic) else value


def _normal(value):
    """A value as stored and read back (tuples as lists, numbers as Python numbers)."""
    return json.loads(json.dumps(value)) if isinstance(value, (dict, list, tuple)) else _plain(value)


def _show(value):
    return "(none)" if value is _MISSING else json.dumps(value) if isinstance(value, (dict, list)) else repr(value)


def _description(stored):
    """``a <format> file of solver <name> <version>`` (what is known of it)."""
    fmt = stored.get("format")
    what = f"a {fmt} file" if fmt else "an HDF5 file without a 'format' attribute"
    if "solver" in stored:
        what += f" of solver {stored['solver']} {stored.get('solver_version', '')}".rstrip()
    if "analysis" in stored:
        what += f" of analysis {stored['analysis']}"
    return what


def changed_values(stored, wanted):
    """Every entry of two mappings that differs, as ``name = stored (this run: wanted)``, comma-separated.

    Parameters
    ----------
    stored, wanted : Mapping[str, object]
        E.g. a file's parameters and this run's (an entry absent from one shows as "(none)").

    Returns
    -------
    str
    """
    changed = [name for name in {**stored, **wanted} if stored.get(name, _MISSING) != wanted.get(name, _MISSING)]
    return ", ".join(f"{name} = {_show(stored.get(name, _MISSING))} (this run: {_show(wanted.get(name, _MISSING))})"
                     for name in changed)


def _difference(stored, identity, describe):
    """What ``stored`` holds against ``identity``, or None if it is the same run."""
    for key, expected in identity.items():
        expected, value = _normal(expected), stored.get(key, _MISSING)
        if value == expected:
            continue
        what = describe(stored)
        if isinstance(expected, dict) and isinstance(value, dict):
            return f"holds {what} with other {_NAMES.get(key, key)}: {changed_values(value, expected)}"
        if key in _DESCRIBING:
            return f"holds {what} (this run: {key} {_show(expected)})"
        return f"holds {what} with {key} = {_show(value)} (this run: {_show(expected)})"
    return None


def refuse_other_run(path, identity, *, hint=OVERWRITE_HINT, read=None, describe=_description, damage=None):
    """Raise :class:`OutputExistsError` if ``path`` exists and holds another run than ``identity``.

    Parameters
    ----------
    path : str or pathlib.Path
        The output.
    identity : Mapping[str, object]
        What the file of this run stores, by name (see the module docstring).
    hint : str, optional
        The end of the message: what the user can do.
    read : callable, optional
        ``read(path, names) -> dict``: the stored values of an existing output (those it has);
        default :func:`root_attributes`. May raise ``FileFormatError``: the file is then not
        this run.
    describe : callable, optional
        ``describe(stored) -> str``: what the stored values say the file is.
    damage : callable, optional
        ``damage(stored) -> str or None``: why stored values that differ from ``identity`` cannot be those
        of any run of this writer (a damaged file: a parameter no run has), or None; the message then says
        the file is damaged, not another run.

    Returns
    -------
    bool
        Whether ``path`` exists (and holds this run).

    Raises
    ------
    OutputExistsError
        If ``path`` exists and is not this run; the message names the file and the first
        difference.
    """
    path = Path(path)
    if not path.exists():
        return False
    if path.is_dir():
        raise OutputError(path, errno.EISDIR)
    try:
        stored = (read or root_attributes)(path, tuple(dict.fromkeys([*identity, *_DESCRIBING])))
    except FileFormatError:
        raise OutputExistsError(path, "exists and is not a file this command can recognise as its own run (not "
                                      "a readable HDF5 file)", hint) from None
    difference = _difference(stored, identity, describe)
    if difference is not None:
        why = damage(stored) if damage is not None else None
        raise OutputExistsError(path, f"holds {describe(stored)} that is damaged: {why}" if why else difference, hint)
    return True


@contextmanager
def claimed_output(path, identity, *, overwrite=False, hint=OVERWRITE_HINT, damage=None):
    """The one rule of the command line: write ``path`` in the block only if it is absent, this run, or ``overwrite``.

    Before the block: an absent output or one that holds this run (:func:`refuse_other_run`) is
    left to the writer (to write, resume or leave); an HDF5 file too damaged to open is moved
    aside to ``<name>.unreadable`` (with a message); another run is refused, unless ``overwrite``:
    it is then moved aside to ``<name>.replaced`` until the block ends (never while another process
    writes it: that is refused first). If the block fails before it has written ``path``, the
    replaced file is moved back; if it fails after, the replaced file stays aside (the message says
    where); if it succeeds, the replaced file is deleted, and so is one left aside by an earlier
    ``--overwrite`` whose new run was interrupted and has now been completed (with a message).

    Parameters
    ----------
    path : str or pathlib.Path
    identity : Mapping[str, object]
        Root attributes of the file this run writes (see the module docstring).
    overwrite : bool, optional
        Replace another run (``--overwrite``).
    hint : str, optional
        The end of the refusal's message: how to overwrite (default: the command line's ``--overwrite``).
    damage : callable, optional
        Why a differing output is damaged rather than another run (:func:`refuse_other_run`).

    Raises
    ------
    OutputExistsError
        If ``path`` holds another run and ``overwrite`` is false.
    """
    path = Path(path)
    if path.is_file() and _damaged_hdf5(path):
        aside = set_aside(path, "unreadable")
        print(f"stickslip: {path}: not a readable HDF5 file; moved it to {aside}, starting the run over",
              file=sys.stderr)
    try:
        refuse_other_run(path, identity, hint=hint, damage=damage)
    except OutputExistsError as error:
        if not overwrite:
            raise
        with writer_lock(path):  # another process writing it: refused before anything is moved
            replaced = set_aside(path, "replaced")
        print(f"stickslip: {path}: {error.difference}; --overwrite: moved it to {replaced} until the new output "
              f"is complete", file=sys.stderr)
    else:
        replaced = None
    try:
        yield
    except BaseException:
        if replaced is not None:
            if path.exists():
                print(f"stickslip: the file replaced by {path} stays at {replaced}", file=sys.stderr)
            else:
                os.replace(replaced, path)
        raise
    if replaced is not None:
        replaced.unlink()
    for earlier in _replaced_earlier(path):
        earlier.unlink()
        print(f"stickslip: {path} is complete: removed {earlier}, the run it replaced (an earlier --overwrite)",
              file=sys.stderr)


def _replaced_earlier(path):
    """Files that an earlier ``--overwrite`` of ``path`` set aside (``<name>.replaced[-<k>]``)."""
    pattern = re.compile(re.escape(path.name) + r"\.replaced(-\d+)?")
    return sorted(p for p in path.parent.glob(glob.escape(path.name) + ".replaced*") if pattern.fullmatch(p.name))


def write_text_output(path, text, *, overwrite=False):
    """Write a text output (a CSV table) atomically; an existing file with other content only if ``overwrite``.

    Parameters
    ----------
    path : str or pathlib.Path
    text : str or Iterable[str]
        The whole content (UTF-8), or its pieces in order (written as they come: the text is never held whole).
    overwrite : bool, optional

    Returns
    -------
    bool
        Whether ``path`` held other content that was replaced.

    Raises
    ------
    OutputExistsError
        If ``path`` exists with other content and ``overwrite`` is false (the new text is then discarded).
    """
    path = Path(path)
    with atomic_output(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as stream:
            for piece in [text] if isinstance(text, str) else text:
                stream.write(piece)
        replaced = path.exists() and (path.is_dir() or not filecmp.cmp(tmp, path, shallow=False))
        if replaced and not overwrite and not path.is_dir():
            raise OutputExistsError(path, "exists with other content", OVERWRITE_HINT)
    return replaced
