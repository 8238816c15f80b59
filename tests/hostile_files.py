"""The fuzz harness of hostile files: small valid files of every kind the package reads, seeded mutations of them,
and a worker that reads each mutated file through the package's readers under a memory limit.

Used by tests/test_hostile_files.py (a short run in CI) and benchmarks/fuzz_files.py (the long run, 1 000
mutations, whose figures docs/benchmarks.md records).

**The valid files** (:func:`write_study`): a ``fem`` run (N = 9, two plates, the ``stop`` yield strains) killed
after :data:`PARTIAL` of its :data:`FULL` increments (what a resume continues), its ``numerical-events`` table, a
lab recording (``timeseries``), their provenance records and the study's SQLite database.

**The mutations** (:func:`mutate`, one per file, drawn from a seeded generator): an attribute set to a hostile value
or deleted (a lying attribute); every growable dataset and ``nstored`` resized to 10^6 ... 2^40 rows (a lying
file); one dataset resized, replaced by another shape or type, or deleted; a stored row's chunk left unwritten
(HDF5 reads it as zeros); a gzip bomb (2.5 * 10^8 zeros in 2 MB) in place of a dataset; a flipped byte in a data
chunk or an object header; the file cut short. A database gets a flipped byte, a zeroed page, a damaged header or
is cut short (:func:`mutate_database`).

**The readers** (the worker, :func:`main`, one process for many files, under ``RLIMIT_AS``: what its imports took
plus :data:`HEADROOM`): a ``fem`` file through :func:`stickslip.open_run` (increments and events),
``stickslip increments``, ``stickslip db rebuild`` of the study and the resume (``stickslip simulate`` with the
run's parameters); an event table through its readers and ``db rebuild``; a recording through ``open_run`` (its
analysis) and ``db rebuild``; a database through ``db runs``, ``db sql``, ``db ingest`` of every record into it and
``db rebuild``. Each read ends as

- ``read``: with a digest of what it returned (the tables' CSV text), to compare with the intact file's;
- ``refused``: one of the package's errors (a command's exit status 2), one line, naming the file;
- ``FAILED``: anything else: a traceback, a message of more lines or without the file's name, a MemoryError, more
  than :data:`CASE_SECONDS` (a hang).

:func:`judge` compares: every read of a file whose mutation left it well-formed in the sense of the readers (an
attribute set to another value of its kind: a file of other parameters; fewer rows committed) only has to end as
``read`` or ``refused``; every other read must give the intact file's digest. The direct reads of a damaged database
(``db runs``, ``db sql``, ``db ingest`` into it) are not compared: SQLite keeps no checksum of its rows, so a flipped
bit in a value reads as another value; ``db rebuild`` (which remakes the database from the records) must give the
intact one.
"""

import hashlib
import io
import json
import math
import os
import resource
import shutil
import signal
import subprocess
import sys
import time
import traceback
import zlib
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

#: The fem run of the valid study: small, with the paper's finite yield-strain sequences.
FEM_ARGS = ["--param", "N=9", "--param", "plates=2", "--param", "nchunk=200", "--param", "yield_strains=stop",
            "--param", "max_increments=30"]

#: Increments of the complete run, and those of the killed run that a resume continues.
FULL, PARTIAL = 31, 16

#: Address space the worker may take beyond what it has after its imports and a first read of the intact files [B].
HEADROOM = 3 * 2**29

#: Seconds one reader may take on one file before it counts as a hang.
CASE_SECONDS = 60

#: Rows of a gzip bomb (2 GB of float64 zeros in about 2 MB).
BOMB_ROWS = 250_000_000

#: Kinds of files, with the name of the file of each kind in the study.
FILES = {"fem": "run.h5", "events": "events.h5", "timeseries": "series.h5", "database": "stickslip.sqlite"}


# ------------------------------------------------------------------------------------------------ the valid study

def write_timeseries(path, frames=2000):
    """A small valid ``timeseries`` file (gzip-compressed datasets), a stack of 3 slabs driven at 2."""
    from stickslip.experiment.timeseries import ExperimentRecord
    from stickslip.experiment.timeseries import write_timeseries as write

    t = np.linspace(0.0, 200.0, frames)
    x = np.cumsum(np.where(np.arange(frames)[:, None] % 250 == 0, 0.05, 0.0) * np.ones((1, 3)), axis=0)
    record = ExperimentRecord(t_F=t, F=1.0 + 0.1 * np.sin(t), t_x=t, x=x + np.arange(3) * 10.0, n=2, n_slabs=3,
                              protocol="stack", a=0, normal_force=10.0, k_spring=1.0, h=5.0, H=100.0, V=0.01)
    write(path, record)
    return path


def write_study(directory):
    """The valid files (module docstring) and their provenance records in ``directory``; returns it.

    The fem run is made by the solver (``stickslip simulate``), then cut back to :data:`PARTIAL` committed
    increments, as a run killed there leaves it (:func:`stickslip.formats.fem_run.rewrite`).
    """
    from stickslip import registry
    from stickslip.cli import main as cli
    from stickslip.formats.fem_run import rewrite
    from stickslip.lineage import Artifact
    from stickslip.provenance.ingest import find_records, ingest
    from stickslip.provenance.record import recording

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    fem, events, series = (directory / FILES[kind] for kind in ("fem", "events", "timeseries"))
    identity = {"plugin_version": "4", "code_hash": "0" * 16, "params": {}}
    with recording(directory / "run.provenance.json", [("output", fem, "fem-run")], run_id="a" * 16, kind="solver",
                   plugin="fem", **identity):
        with redirect_stderr(io.StringIO()):
            assert cli(["simulate", "--solver", "fem", *FEM_ARGS, "-o", str(fem)]) == 0
        with h5py.File(fem, "r+") as file:
            assert file.attrs["nstored"] == FULL
            file.attrs["nstored"] = PARTIAL
        rewrite(fem, completed=False, stop_reason="")
    analysis = registry.get("analysis", "numerical-events")
    simulation = Artifact(fem, "a" * 16, "fem", "fem-run")
    with recording(directory / "events.provenance.json", [("output", events, "event-table")], run_id="b" * 16,
                   kind="analysis", plugin=analysis.name, inputs=[("simulation", simulation)], **identity):
        analysis.run(analysis.params(), simulation, events)
    with recording(directory / "series.provenance.json", [("output", series, "timeseries")], run_id="c" * 16,
                   kind="solver", plugin="lever", **identity):
        write_timeseries(series)
    with redirect_stderr(io.StringIO()):
        ingest(directory / FILES["database"], find_records(directory), rebuild=True)
    return directory


# ------------------------------------------------------------------------------------------------ mutations

#: Values an attribute is set to.
HOSTILE_VALUES = ("", "not json", "[1]", "{}", "null", "[]", '{"a": [1, 2', -1, 0, 10**9, 2**62, -2**62, 1.5,
                  math.nan, math.inf, -math.inf, True, "1e9", b"\xff\xfe", np.arange(3), np.zeros((2, 2)))

#: Rows a growable dataset is resized to.
HOSTILE_ROWS = (0, 1, 10**6, 10**9, 2**40)

#: What each mutation does, with how often it is drawn (weights).
HDF5_MUTATIONS = {"attribute": 3, "shape": 2, "lie": 1, "replace": 1, "delete": 1, "hole": 1, "bomb": 1, "chunk": 2,
                  "metadata": 2, "truncate": 1}
DATABASE_MUTATIONS = {"flip": 4, "page": 2, "header": 1, "truncate": 1}


def _objects(file):
    found = [file]
    file.visititems(lambda name, item: found.append(item))
    return found


def _pick(rng, items):
    return items[int(rng.integers(len(items)))]


def _draw(rng, weights):
    names = list(weights)
    chances = np.asarray([weights[name] for name in names], dtype=float)
    return names[int(rng.choice(len(names), p=chances / chances.sum()))]


def _flip(path, where):
    """Invert the byte at ``where`` of the file ``path`` (0 beyond its end)."""
    with open(path, "r+b") as handle:
        handle.seek(where)
        byte = handle.read(1)
        handle.seek(where)
        handle.write(bytes([(byte[0] if byte else 0) ^ 0xFF]))


def _truncate(path, rng):
    size = path.stat().st_size
    keep = int(size * rng.uniform(0.05, 0.99))
    with open(path, "r+b") as handle:
        handle.truncate(keep)
    return f"cut at {keep} of {size} bytes", False


def _well_formed(old, new):
    """Whether an attribute's new value is of the old one's kind (a number for a number, text for text): the file
    is then well-formed, of other parameters, not damaged."""
    def kind(value):
        if isinstance(value, (bytes, np.bytes_)):
            try:
                value = value.decode("utf-8")
            except UnicodeDecodeError:
                return "bytes"
        if isinstance(value, np.ndarray):
            return "array" if value.ndim else kind(value[()])
        if isinstance(value, (bool, np.bool_)):
            return "bool"
        if isinstance(value, (int, np.integer)):
            return "int"
        if isinstance(value, (float, np.floating)):
            return "float" if math.isfinite(value) else "non-finite"
        if isinstance(value, str):
            try:
                found = json.loads(value)
            except ValueError:
                return "text"
            return f"json {type(found).__name__}" if isinstance(found, (dict, list)) else "text"
        return type(value).__name__

    old_kind, new_kind = kind(old), kind(new)
    return old_kind == new_kind or {old_kind, new_kind} <= {"int", "float", "bool"}


def _growable(datasets):
    return [d for d in datasets if d.maxshape and d.maxshape[0] is None and d.shape[0]]


def _hole(file, datasets, rng):
    """Rewrite a growable dataset with one chunk of its stored rows never written."""
    candidates = [d for d in _growable(datasets) if d.shape[0] > d.chunks[0]] or _growable(datasets)
    dataset = _pick(rng, candidates)
    name, parent, data = dataset.name, dataset.parent, dataset[()]
    rows = dataset.chunks[0]
    skipped = int(rng.integers(math.ceil(data.shape[0] / rows)))
    options = {"shape": data.shape, "dtype": data.dtype, "maxshape": dataset.maxshape, "chunks": dataset.chunks,
               "fletcher32": dataset.fletcher32}
    del parent[name.rsplit("/", 1)[1]]
    new = parent.create_dataset(name.rsplit("/", 1)[1], **options)
    for start in range(0, data.shape[0], rows):
        if start // rows != skipped:
            new[start:start + rows] = data[start:start + rows]
    return f"{name}: chunk {skipped} ({rows} rows) never written"


def _bomb(file, datasets, rng):
    """Replace a dataset by a gzip bomb of its dtype (``BOMB_ROWS`` zeros in chunks of 10^6); a growable one with
    ``nstored`` raised to it."""
    numeric = [d for d in datasets if d.dtype.kind in "biuf" and d.ndim == 1]
    dataset = _pick(rng, numeric)
    name, parent, dtype = dataset.name, dataset.parent, dataset.dtype
    growable = dataset.maxshape[0] is None
    del parent[name.rsplit("/", 1)[1]]
    rows = 10**6
    bomb = parent.create_dataset(name.rsplit("/", 1)[1], shape=(BOMB_ROWS,), dtype=dtype, chunks=(rows,),
                                 maxshape=(None,) if growable else (BOMB_ROWS,), compression="gzip")
    chunk = zlib.compress(np.zeros(rows, dtype=dtype).tobytes(), 9)
    for start in range(0, BOMB_ROWS, rows):
        bomb.id.write_direct_chunk((start,), chunk)
    if growable and "nstored" in file.attrs:
        file.attrs["nstored"] = BOMB_ROWS
    return f"{name}: a gzip bomb of {BOMB_ROWS} zeros{' and nstored' if growable else ''}"


def mutate(path, rng):
    """Change one thing of the HDF5 file ``path`` in place, drawn from ``rng``.

    Returns
    -------
    str, bool
        What was changed, and whether the file stays well-formed for its readers (an attribute set to another
        value of its kind; fewer rows committed): their reads need not give the intact file's numbers.
    """
    kind = _draw(rng, HDF5_MUTATIONS)
    if kind == "truncate":
        return _truncate(path, rng)
    with h5py.File(path, "r+") as file:
        objects = _objects(file)
        datasets = [item for item in objects if isinstance(item, h5py.Dataset)]
        if kind == "attribute":
            item = _pick(rng, [item for item in objects if len(item.attrs)] or objects)
            name = _pick(rng, list(item.attrs) or ["format"])
            old = item.attrs.get(name)
            if rng.random() < 0.15:
                del item.attrs[name]
                return f"attribute {item.name}:{name} deleted", False
            value = _pick(rng, HOSTILE_VALUES)
            item.attrs[name] = value
            return f"attribute {item.name}:{name} = {value!r}", old is not None and _well_formed(old, value)
        if kind == "lie":  # every growable dataset, and the count of stored rows, say 10^6 rows or more
            rows = _pick(rng, HOSTILE_ROWS[2:])
            for dataset in _growable(datasets):
                dataset.resize(rows, axis=0)
            if "nstored" in file.attrs:
                file.attrs["nstored"] = rows
            return f"every growable dataset and nstored: {rows} rows", False
        if kind == "hole" and _growable(datasets):
            return _hole(file, datasets, rng), False
        if kind == "bomb":
            return _bomb(file, datasets, rng), False
        if kind in ("shape", "replace", "hole"):
            growable = _growable(datasets)
            if kind == "shape" and growable:
                dataset = _pick(rng, growable)
                rows = _pick(rng, HOSTILE_ROWS)
                dataset.resize(rows, axis=0)
                told = rng.random() < 0.5 and "nstored" in file.attrs
                fewer = told and rows <= file.attrs["nstored"]  # a file of fewer committed rows: well-formed
                if told:
                    file.attrs["nstored"] = rows
                return f"{dataset.name} resized to {rows} rows{' and nstored' if told else ''}", bool(fewer)
            dataset = _pick(rng, datasets)
            name, parent = dataset.name, dataset.parent
            del parent[dataset.name.rsplit("/", 1)[1]]
            shape = _pick(rng, ((), (0,), (3, 5), (7,), (2, 2, 2)))
            dtype = _pick(rng, ("f8", "i8", "S4", "text"))
            if dtype == "text":
                parent.create_dataset(name.rsplit("/", 1)[1], data=np.full(shape, "x", dtype=object),
                                      dtype=h5py.string_dtype())
            else:
                parent.create_dataset(name.rsplit("/", 1)[1], data=np.zeros(shape, dtype=dtype))
            return f"{name} replaced by {shape} {dtype}", False
        if kind == "delete":
            item = _pick(rng, objects[1:])
            name = item.name
            del file[name]
            return f"{name} deleted", False
        if kind == "chunk":
            dataset = _pick(rng, [d for d in datasets if d.id.get_storage_size()])
            info = dataset.id.get_chunk_info(0) if dataset.chunks else None
            offset = info.byte_offset if info else dataset.id.get_offset()
            size = info.size if info else dataset.id.get_storage_size()
            where = offset + int(rng.integers(size))
        else:
            item = _pick(rng, objects)
            where = h5py.h5o.get_info(item.id).addr + int(rng.integers(4, 40))
    _flip(path, where)
    return f"{kind}: byte {where} flipped", False


def mutate_database(path, rng):
    """Damage the SQLite file ``path`` in place, drawn from ``rng``; returns what was done and False (as
    :func:`mutate`)."""
    kind = _draw(rng, DATABASE_MUTATIONS)
    size = path.stat().st_size
    if kind == "truncate":
        return _truncate(path, rng)
    if kind == "page":
        page = int(rng.integers(size // 4096)) * 4096
        with open(path, "r+b") as handle:
            handle.seek(page)
            handle.write(bytes(4096))
        return f"page at {page} zeroed", False
    where = int(rng.integers(100)) if kind == "header" else int(rng.integers(size))
    _flip(path, where)
    return f"{kind}: byte {where} flipped", False


def make_cases(valid, root, counts, seed, first=0):
    """Copies of the valid study under ``root``, one file of each copy mutated: ``counts[kind]`` of each kind, the
    cases ``first ...`` of the seeded sequence of each kind.

    Returns
    -------
    list[dict]
        ``kind``, ``path`` (the mutated file), ``mutation``, ``well_formed`` (:func:`mutate`).
    """
    cases = []
    for k, kind in enumerate(FILES):
        for case in range(first, first + counts.get(kind, 0)):
            directory = Path(root) / f"{kind}-{case}"
            shutil.copytree(valid, directory)
            path = directory / FILES[kind]
            rng = np.random.default_rng([seed, k, case])
            change = mutate_database if kind == "database" else mutate
            mutation, well_formed = change(path, rng)
            cases.append({"kind": kind, "path": str(path), "mutation": mutation, "well_formed": well_formed})
    return cases


# ------------------------------------------------------------------------------------------------ the worker

class _Hang(Exception):
    """A reader took more than :data:`CASE_SECONDS`."""


def _digest(*frames):
    """sha256 of the CSV text of tables (or of text), the first 16 characters."""
    text = "".join(f if isinstance(f, str) else f.to_csv(index=False, float_format="%.17g") for f in frames)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _cli(*argv):
    """``stickslip ARGV`` in this process: (exit status, stderr lines that are not progress or warnings)."""
    from stickslip.cli import main as cli

    err = io.StringIO()
    with redirect_stderr(err), redirect_stdout(io.StringIO()) as out:
        status = cli(list(map(str, argv)))
    lines = [line for line in err.getvalue().splitlines() if line.startswith("stickslip: error")
             or not line.startswith(("stickslip:", "fem increments", "ingest", "virtual experiment"))]
    return status, lines, out.getvalue()


class Refused(Exception):
    """A command's one-line refusal (exit status 2): its message."""


def _run_cli(*argv):
    """Run a command; its stdout if it succeeded, :class:`Refused` with its message if it refused, else an
    AssertionError (another status, or other output on stderr)."""
    status, lines, out = _cli(*argv)
    if status == 2 and len(lines) == 1 and lines[0].startswith("stickslip: error: "):
        raise Refused(lines[0][len("stickslip: error: "):])
    if status != 0 or lines:
        raise AssertionError(f"stickslip {' '.join(map(str, argv))}: exit {status}, stderr {lines!r}")
    return out


_QUERIES = ("SELECT n, plates, blocks, k_drive, phi, regime, seed, temperature FROM simulations ORDER BY run_id",
            "SELECT * FROM slip_events ORDER BY analysis_run_id, event, interface",
            "SELECT * FROM run_periodicity ORDER BY analysis_run_id")


def _database_digest(database):
    from stickslip.provenance.query import sql

    return _digest(*(sql(query, database) for query in _QUERIES))


def _rebuild(path):
    directory = path.parent
    _run_cli("db", "rebuild", "--results", directory, "--db", directory / "rebuilt.sqlite")
    return _database_digest(directory / "rebuilt.sqlite")


def _open_fem(path):
    import stickslip

    run = stickslip.open_run(path)
    events = run.events()
    return _digest(run.increments, *(events[name] for name in sorted(events)))


def _increments(path):
    out = path.parent / "increments.csv"
    _run_cli("increments", path, "-o", out, "--overwrite")
    return _digest(out.read_text())


def _resume(path):
    from stickslip.formats.fem_run import read_increments

    _run_cli("simulate", "--solver", "fem", *FEM_ARGS, "-o", path)
    return _digest(read_increments(path))


def _read_events(path):
    from stickslip.formats.event_table import read_periodicity, read_slip_events

    periodicity = read_periodicity(path)
    return _digest(read_slip_events(path), *([] if periodicity is None else [periodicity]))


def _open_timeseries(path):
    import stickslip

    events = stickslip.open_run(path).events()
    return _digest(*(events[name] for name in sorted(events)))


def _db_runs(path):
    return _digest(_run_cli("db", "runs", "--db", path, "--format", "csv"))


def _db_sql(path):
    return _digest(_run_cli("db", "sql", "SELECT * FROM slip_events_full", "--db", path, "--format", "csv"))


def _db_ingest(path):
    records = sorted(path.parent.glob("*.provenance.json"))
    _run_cli("db", "ingest", "--db", path, *records)
    return _database_digest(path)


#: Readers of each kind: (name, function, compared with the intact file's digest). A reader that changes the file
#: (the resume, an ingest) comes last.
READERS = {
    "fem": (("open_run", _open_fem, True), ("stickslip increments", _increments, True),
            ("db rebuild", _rebuild, True), ("resume", _resume, True)),
    "events": (("read_slip_events", _read_events, True), ("db rebuild", _rebuild, True)),
    "timeseries": (("open_run", _open_timeseries, True), ("db rebuild", _rebuild, True)),
    "database": (("db rebuild", _rebuild, True), ("db runs", _db_runs, False), ("db sql", _db_sql, False),
                 ("db ingest", _db_ingest, False)),
}


def _peak_reset():
    """Reset this process's peak resident memory (``VmHWM``; Linux: ``clear_refs`` 5)."""
    try:
        with open("/proc/self/clear_refs", "w") as handle:
            handle.write("5")
    except OSError:
        pass


def _peak_mib():
    from stickslip.machine_memory import _proc_field

    return (_proc_field("/proc/self/status", "VmHWM") or 0) / 2**20


def _read(kind, path):
    """Every reader of ``kind`` on ``path``: one result each (reader, outcome, message, digest, seconds, peak)."""
    from stickslip.cli import USER_ERRORS
    from stickslip.provenance.query import QueryError

    results = []
    for name, reader, compared in READERS[kind]:
        _peak_reset()
        started = time.perf_counter()
        signal.alarm(CASE_SECONDS)
        digest = ""
        try:
            digest, outcome, message = reader(path), "read", ""
        except (Refused, QueryError, *USER_ERRORS) as error:
            message = str(error)
            outcome = "refused" if "\n" not in message and path.name in message else "FAILED"
        except _Hang:
            outcome, message = "FAILED", f"no answer in {CASE_SECONDS} s (a hang)"
        except BaseException as error:  # noqa: BLE001 (every other end is the failure this harness finds)
            outcome, message = "FAILED", "".join(traceback.format_exception(error))[-1500:]
        finally:
            signal.alarm(0)
        results.append({"reader": name, "outcome": outcome, "message": message, "digest": digest,
                        "compared": compared, "seconds": time.perf_counter() - started, "peak_mib": _peak_mib()})
    return results


def _on_alarm(_signum, _frame):
    raise _Hang


def main(listing, headroom):
    """The worker: read every case of the JSON file ``listing``; print one JSON line of the results.

    The intact study (the first case's ``valid`` directory) is read first, as a warm-up (the fem kernels loaded, the
    readers imported) and for the intact digests; then the address space is limited to what the process has plus
    ``headroom`` bytes.
    """
    from stickslip import registry

    registry.available("solver"), registry.available("analysis")
    cases = json.loads(Path(listing).read_text())
    signal.signal(signal.SIGALRM, _on_alarm)
    intact = {}
    for kind in READERS:
        scratch = Path(cases[0]["scratch"]) / f"intact-{kind}"
        shutil.copytree(cases[0]["valid"], scratch)
        intact[kind] = _read(kind, scratch / FILES[kind])
    size = _proc_status_bytes("VmSize")
    limit = size + headroom
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    results = []
    for case in cases:
        for result in _read(case["kind"], Path(case["path"])):
            results.append({**{k: case[k] for k in ("kind", "path", "mutation", "well_formed")}, **result})
    print(json.dumps({"intact": intact, "results": results, "limit": limit,
                      "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))


def _proc_status_bytes(field):
    from stickslip.machine_memory import _proc_field

    return _proc_field("/proc/self/status", field) or 0


def run_worker(cases, valid, scratch, headroom=HEADROOM, timeout=3000):
    """Read ``cases`` in a worker process (:func:`main`); return its report.

    Returns
    -------
    dict
        ``intact`` (kind -> the intact file's results), ``results`` (one per case and reader), ``limit`` (the
        address-space limit [B]), ``peak_rss_mib``.
    """
    listing = Path(scratch) / "cases.json"
    listing.write_text(json.dumps([{**case, "valid": str(valid), "scratch": str(scratch)} for case in cases]))
    done = subprocess.run([sys.executable, __file__, str(listing), str(headroom)], capture_output=True, text=True,
                          timeout=timeout, env={**os.environ, "NUMBA_NUM_THREADS": "1"})
    if done.returncode != 0:
        raise AssertionError(f"the worker ended with {done.returncode}: {done.stderr[-4000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def judge(report):
    """The results as a table with their verdict: ``identical`` (a read giving the intact digest), ``refused``,
    ``well-formed`` (a read of a well-formed file), ``unchecked`` (a read not compared), or a failure.

    Returns
    -------
    pandas.DataFrame
        The results with a column ``verdict``; a failure's verdict starts with ``FAILED``.
    """
    results = pd.DataFrame(report["results"])
    intact = {(kind, row["reader"]): row for kind, rows in report["intact"].items() for row in rows}

    def verdict(row):
        reference = intact[(row["kind"], row["reader"])]
        if reference["outcome"] != "read":
            return f"FAILED: the intact file's read ended {reference['outcome']}: {reference['message']}"
        if row["outcome"] == "FAILED":
            return f"FAILED: {row['message']}"
        if row["outcome"] == "refused":
            return "refused"
        if row["digest"] == reference["digest"]:
            return "identical"
        if row["well_formed"]:
            return "well-formed"
        if not row["compared"]:
            return "unchecked"
        return "FAILED: read numbers that are not the intact file's"

    results["verdict"] = results.apply(verdict, axis=1)
    return results


def summary(results, limit, seconds):
    """The figures of a fuzz run: mutations, reads, refusals, identical reads, max memory and time (one line)."""
    verdicts = results["verdict"].str.split(":").str[0].value_counts().to_dict()
    files = results["path"].nunique()
    return (f"{files} mutated files, {len(results)} reads: {verdicts.get('refused', 0)} refused in one line, "
            f"{verdicts.get('identical', 0)} identical to the intact file's, {verdicts.get('well-formed', 0)} of a "
            f"well-formed file, {verdicts.get('unchecked', 0)} unchecked database reads, "
            f"{verdicts.get('FAILED', 0)} failed; max {results['peak_mib'].max():.0f} MiB resident in a read "
            f"(address space limited to {limit / 2**30:.2f} GiB), max {results['seconds'].max():.2f} s a read; "
            f"{seconds:.0f} s in all")


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]))
