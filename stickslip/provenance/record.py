"""Provenance records: one JSON file beside every output of the workflow.

A record says what made a file and how: the plugin and its version, the code
hash, the package version and git commit, every parameter, the seed, the
library versions, the host and its arithmetic (CPU, BLAS kernel, numba target:
:mod:`stickslip.arithmetic`), the start and end time, the wall time, the peak
memory, and the inputs and outputs with their sha256. It is written under a
temporary name and renamed into place, so a reader never sees half a record.

The record of ``results/default/sim/lever/0123456789abcdef.h5`` is
``results/default/sim/lever/0123456789abcdef.provenance.json`` (:func:`record_path`).
"""

import datetime
import json
import platform
import resource
import socket
import subprocess
import sys
import time
from contextlib import contextmanager
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from .. import __version__
from ..arithmetic import decisive, host
from ..h5io import FileFormatError
from ..hashing import sha256_file
from ..lineage import Artifact
from ..output_safety.atomic import atomic_output

__all__ = ["SCHEMA_VERSION", "REQUIRED_FIELDS", "record_path", "file_entry", "check_recorded_sha256", "git_state",
           "library_versions", "peak_memory_mib", "write_record", "read_record", "recording"]

#: Version of the record layout; bump when fields change meaning. 2: file entries carry lineage
#: (``format``; inputs also ``run_id``, ``plugin`` and ``parent`` of the job that made them).
SCHEMA_VERSION = 2

#: Fields every record has (values may be null where not applicable, e.g. ``seed``).
REQUIRED_FIELDS = ("schema_version", "run_id", "kind", "plugin", "plugin_version", "code_hash",
                   "package_version", "git_commit", "git_dirty", "params", "seed", "threads",
                   "versions", "host", "start", "end", "wall_time_s", "peak_memory_mib", "inputs", "outputs")

LIBRARIES = ("numpy", "scipy", "numba", "llvmlite", "qdldl", "threadpoolctl", "h5py", "pandas", "matplotlib",
             "sqlalchemy", "snakemake")


def record_path(output):
    """Return the record path of an output file: same stem, suffix ``.provenance.json``.

    Parameters
    ----------
    output : str or pathlib.Path

    Returns
    -------
    pathlib.Path
    """
    return Path(output).with_suffix(".provenance.json")


def file_entry(role, path, **lineage):
    """Describe one input or output file.

    Parameters
    ----------
    role : str
        What the file is to the job (``"output"``, ``"mesh"``, ``"simulation"``,
        ``"analysis:experiment-events"``, ...).
    path : str or os.PathLike
        A :class:`stickslip.lineage.Artifact` adds its lineage: ``run_id``, ``plugin``,
        ``format`` and ``parent`` (the parent's run id).
    **lineage
        Further fields, e.g. ``format`` of an output.

    Returns
    -------
    dict
        ``{"role", "path", "sha256", "bytes"}`` and the lineage fields.

    Raises
    ------
    FileFormatError
        If the file does not exist.
    """
    if isinstance(path, Artifact):
        lineage = {"run_id": path.run_id, "plugin": path.plugin, "format": path.format,
                   **({} if path.parent is None else {"parent": path.parent.run_id}), **lineage}
    path = Path(path)
    if not path.is_file():
        raise FileFormatError(f"{path}: no such file (expected as {role})")
    return {"role": role, "path": path.as_posix(), "sha256": sha256_file(path), "bytes": path.stat().st_size,
            **lineage}


def git_state(directory=None):
    """Return the git commit and dirty flag of the repository holding the package.

    Parameters
    ----------
    directory : str or pathlib.Path, optional
        Where to ask git; default: the package's source directory.

    Returns
    -------
    tuple[str | None, bool | None]
        Commit hash and whether tracked files differ from it; ``(None, None)`` if
        the package is not in a git working tree (e.g. installed from a wheel).
    """
    directory = Path(directory or Path(__file__).resolve().parent.parent)

    def git(*args):
        return subprocess.run(["git", "-C", str(directory), *args], capture_output=True, text=True,
                              check=True, timeout=30).stdout.strip()

    try:
        commit = git("rev-parse", "HEAD")
        dirty = bool(git("status", "--porcelain", "--untracked-files=no"))
    except (OSError, subprocess.SubprocessError):
        return None, None
    return commit, dirty


def library_versions():
    """Return the versions of Python and of the libraries that shape results.

    Returns
    -------
    dict[str, str | None]
        ``python``, ``platform`` and each of :data:`LIBRARIES` (None if not installed).
    """
    versions = {"python": platform.python_version(), "platform": platform.platform()}
    for name in LIBRARIES:
        try:
            versions[name] = version(name)
        except PackageNotFoundError:
            versions[name] = None
    return versions


def _now():
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="milliseconds")


def peak_memory_mib():
    """Return the peak resident memory of this process so far [MiB] (Linux ``ru_maxrss``)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024.0 * 1024.0) if sys.platform == "darwin" else peak / 1024.0


def write_record(path, record):
    """Write a record as JSON, atomically (temporary file, then rename).

    Parameters
    ----------
    path : str or pathlib.Path
    record : dict
    """
    with atomic_output(path) as tmp:
        tmp.write_text(json.dumps(record, indent=1, sort_keys=True) + "\n", encoding="utf-8")


def read_record(path):
    """Read and check a record.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    dict

    Raises
    ------
    FileFormatError
        If the file is missing, not JSON, or lacks a field of :data:`REQUIRED_FIELDS`.
    """
    path = Path(path)
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FileFormatError(f"{path}: no such provenance record") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise FileFormatError(f"{path}: not a valid provenance record (bad JSON: {error})") from None
    if not isinstance(record, dict):
        raise FileFormatError(f"{path}: not a valid provenance record (expected a JSON object)")
    missing = [field for field in REQUIRED_FIELDS if field not in record]
    if missing:
        raise FileFormatError(f"{path}: provenance record lacks {', '.join(missing)}")
    if record["schema_version"] != SCHEMA_VERSION:
        raise FileFormatError(f"{path}: provenance schema_version {record['schema_version']!r}, "
                              f"expected {SCHEMA_VERSION}")
    return record


def _job_record(*, run_id, kind, plugin, plugin_version, code_hash, params, threads=1, inputs=()):
    """The part of a record known before the job runs (inputs are hashed now)."""
    commit, dirty = git_state()
    return {
        "schema_version": SCHEMA_VERSION, "run_id": run_id, "kind": kind, "plugin": plugin,
        "plugin_version": plugin_version, "code_hash": code_hash, "package_version": __version__,
        "git_commit": commit, "git_dirty": dirty, "params": params, "seed": params.get("seed"),
        "threads": threads, "versions": library_versions(), "host": socket.gethostname(),
        "arithmetic": {"decisive": decisive(), "host": host()},
        "inputs": [_input_entry(role, path) for role, path in inputs],
    }


def _input_entry(role, path):
    """:func:`file_entry` of an input, checked against the record of the job that wrote it."""
    entry = file_entry(role, path)
    check_recorded_sha256(path, entry["sha256"])
    return entry


def check_recorded_sha256(path, sha256):
    """Raise if the provenance record beside ``path`` states another sha256 for it.

    Parameters
    ----------
    path : str or pathlib.Path
        A file some job wrote (its record: :func:`record_path`); files without a
        record (lab data, files made by hand) are not checked.
    sha256 : str
        The file's sha256 now.

    Raises
    ------
    FileFormatError
        If the record lists the file with another sha256: it was damaged or changed
        after the job wrote it.
    """
    path = Path(path)
    record = record_path(path)
    if not record.is_file():
        return
    for entry in read_record(record)["outputs"]:
        if Path(entry["path"]).name == path.name and entry["sha256"] != sha256:
            raise FileFormatError(
                f"{path}: sha256 {sha256[:16]}... differs from {entry['sha256'][:16]}... recorded in {record} "
                f"when it was written; the file was damaged or changed since: delete it and rerun the job that makes it")


@contextmanager
def recording(record_file, outputs, **identity):
    """Time a job and write its provenance record when it succeeds.

    Parameters
    ----------
    record_file : str or pathlib.Path
        Where the record goes (see :func:`record_path`).
    outputs : Sequence[tuple]
        ``(role, path)`` or ``(role, path, format)`` of each file the job writes; hashed
        after the job.
    **identity
        ``run_id``, ``kind``, ``plugin``, ``plugin_version``, ``code_hash``,
        ``params`` (dict), and optionally ``threads`` (int) and ``inputs``
        (sequence of ``(role, path)``; a :class:`stickslip.lineage.Artifact` as path
        records its lineage).

    Yields
    ------
    dict
        The record; the job may add fields before the block ends.

    Notes
    -----
    Nothing is written if the block raises, so a failed job leaves no record.
    Inputs are hashed before the job starts (a missing input fails early); the
    outputs' directories are created.
    """
    record = _job_record(**identity)
    for _, path, *_ in outputs:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
    start_clock, start = time.perf_counter(), _now()
    yield record
    wall = time.perf_counter() - start_clock
    record.update({
        "start": start, "end": _now(), "wall_time_s": round(wall, 6),
        "peak_memory_mib": round(peak_memory_mib(), 3),
        "outputs": [file_entry(role, path, **({"format": rest[0]} if rest else {})) for role, path, *rest in outputs],
    })
    write_record(record_file, record)
