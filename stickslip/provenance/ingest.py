"""Ingest provenance records and event tables into the results database.

:func:`ingest` is idempotent (a run is keyed by its run id: ingesting the same
record twice leaves one set of rows) and transactional: it works on a copy of
the database in the same directory and renames it into place only when every
record went in, so an interrupted or failed ingest leaves the previous database
intact. A lock file beside the database serialises concurrent ingests, so two
processes ingesting at once lose no record.

What goes where (see :mod:`.database`); ingest reads formats and the lineage the records
carry, never file names, and needs no edit for a new solver or analysis:

- every record -> ``runs`` and ``artifacts`` (with each file's format and the run that made it);
- solver records -> ``simulations``: the source of the output's format and the columns its
  format describes (:func:`stickslip.formats.describe`);
- analysis records whose output is an ``event-table`` -> ``slip_events``, the file's
  ``slip_events`` table as it is, keyed by the simulation named in the record's lineage, and
  ``run_periodicity``, its ``periodicity`` table where it has one;
- figure records -> ``figures``.
"""

import fcntl
import json
import shutil
from contextlib import contextmanager
from pathlib import Path

import sqlalchemy.exc
from sqlalchemy import delete, insert
from sqlalchemy.orm import Session

from .. import __version__, formats, registry
from ..formats import event_table
from ..h5io import FileFormatError
from ..output_safety.atomic import atomic_output
from ..progress import iterate
from .database import ArtifactRow, Figure, Run, RunPeriodicity, Simulation, SlipEvent, create_schema, engine_for
from .record import read_record

__all__ = ["ingest", "find_records"]


def find_records(results):
    """Return every provenance record under a results directory (sorted).

    Parameters
    ----------
    results : str or pathlib.Path

    Returns
    -------
    list[pathlib.Path]

    Notes
    -----
    Cost: one directory walk.
    """
    return sorted(Path(results).rglob("*.provenance.json"))


@contextmanager
def _locked(database):
    lock_path = database.parent / f".{database.name}.lock"
    with open(lock_path, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _beside(record_file, path):
    """A record's files sit beside it: resolve ``path`` there, whatever the working directory was."""
    return Path(record_file).parent / Path(path).name


def _run_row(record, record_file):
    versions = record["versions"]
    return {
        "run_id": record["run_id"], "kind": record["kind"], "plugin": record["plugin"],
        "plugin_version": str(record["plugin_version"]), "code_hash": record["code_hash"],
        "package_version": record["package_version"], "git_commit": record["git_commit"],
        "git_dirty": record["git_dirty"], "params": json.dumps(record["params"], sort_keys=True),
        "seed": record["seed"], "threads": record["threads"], "python_version": versions.get("python"),
        "numpy_version": versions.get("numpy"), "numba_version": versions.get("numba"),
        "h5py_version": versions.get("h5py"), "versions": json.dumps(versions, sort_keys=True),
        "host": record["host"], "started_at": record["start"], "finished_at": record["end"],
        "wall_time_s": record["wall_time_s"], "peak_memory_mib": record["peak_memory_mib"],
        "record_path": Path(record_file).as_posix(),
    }


def _artifact_rows(record):
    return [{"run_id": record["run_id"], "direction": direction, "role": entry["role"], "path": entry["path"],
             "sha256": entry["sha256"], "bytes": entry["bytes"], "format": entry.get("format"),
             "made_by": entry.get("run_id")}
            for direction, key in (("input", "inputs"), ("output", "outputs")) for entry in record[key]]


def _format(name, where):
    try:
        return formats.get_format(name)
    except formats.FormatError as error:
        raise FileFormatError(f"{where}: {error} (is the plugin that writes it installed?)") from None


def _simulation_row(record, record_file):
    """The output's format: its source, and the columns it describes."""
    output = record["outputs"][0]
    fmt = _format(output["format"], record_file)
    row = {"run_id": record["run_id"], "solver": record["plugin"], "path": output["path"], "format": fmt.name,
           "source": fmt.source}
    row.update(formats.describe(fmt.name, _beside(record_file, output["path"])))
    return row


def _python(value):
    """A numpy scalar as the Python scalar SQLite takes (NaN as NULL)."""
    value = value.item() if hasattr(value, "item") else value
    return None if isinstance(value, float) and value != value else value


def _event_rows(record, record_file):
    """Rows of ``slip_events`` and of ``run_periodicity`` (a list of 0 or 1) of an ``event-table`` output."""
    output = record["outputs"][0]
    if output.get("format") != event_table.FORMAT:
        return [], []
    path = _beside(record_file, output["path"])
    table = event_table.read_slip_events(path)
    simulation = next(entry for entry in record["inputs"] if entry["role"] == "simulation")
    identity = {"analysis_run_id": record["run_id"], "simulation_run_id": simulation["run_id"],
                "analysis": record["plugin"]}
    events_identity = {**identity, "solver": simulation["plugin"],
                       "source": _format(simulation["format"], record_file).source}
    standard = [c for c in table.columns if c in event_table.COLUMNS]
    further = [c for c in table.columns if c not in event_table.COLUMNS]
    events = [{**events_identity, **{c: _python(row[c]) for c in standard},
               "extra": json.dumps({c: _python(row[c]) for c in further}) if further else None}
              for row in table.to_dict("records")]
    periodicity = event_table.read_periodicity(path)
    summary = [] if periodicity is None else [{**identity, **{c: _python(v) for c, v in row.items()}}
                                              for row in periodicity.to_dict("records")]
    return events, summary


def _figure_row(record):
    outputs = {entry["role"]: entry["path"] for entry in record["outputs"]}
    return {"run_id": record["run_id"], "figure": record["plugin"], "pdf": outputs.get("pdf"),
            "png": outputs.get("png")}


def _ingest_record(session, record, record_file):
    """Replace the rows of one run by those of its record; return the number of slip events added."""
    run_id = record["run_id"]
    for model, key in ((SlipEvent, SlipEvent.analysis_run_id), (RunPeriodicity, RunPeriodicity.analysis_run_id),
                       (ArtifactRow, ArtifactRow.run_id),
                       (Simulation, Simulation.run_id), (Figure, Figure.run_id), (Run, Run.run_id)):
        session.execute(delete(model).where(key == run_id))
    session.execute(insert(Run), [_run_row(record, record_file)])
    artifacts = _artifact_rows(record)
    if artifacts:
        session.execute(insert(ArtifactRow), artifacts)
    events = []
    if record["kind"] == "solver":
        session.execute(insert(Simulation), [_simulation_row(record, record_file)])
    elif record["kind"] == "analysis":
        events, periodicity = _event_rows(record, record_file)
        if events:
            session.execute(insert(SlipEvent), events)
        if periodicity:
            session.execute(insert(RunPeriodicity), periodicity)
    elif record["kind"] == "figure":
        session.execute(insert(Figure), [_figure_row(record)])
    return len(events)


def ingest(database, records, *, rebuild=False):
    """Add provenance records (and their event tables) to the database, atomically.

    Parameters
    ----------
    database : str or pathlib.Path
        SQLite file; created if missing.
    records : Iterable[str or pathlib.Path]
        Provenance record files (``*.provenance.json``).
    rebuild : bool
        Start from an empty database instead of the existing one (the result
        then holds exactly ``records``).

    Returns
    -------
    dict[str, int]
        Number of ingested ``records``, and rows of ``slip_events`` added.

    Raises
    ------
    FileFormatError
        If a record or an event file is missing or malformed (the message names
        it); the database is then left as it was.

    Notes
    -----
    Cost: reads every record, the header of every simulation and every ``slip_events``
    table; the database is copied once (its size) unless ``rebuild``.
    """
    registry.available("solver")  # plugins register the formats they write

    database = Path(database)
    database.parent.mkdir(parents=True, exist_ok=True)
    records = [Path(r) for r in records]
    with _locked(database), atomic_output(database) as tmp:  # an empty file is an empty SQLite database
        if database.exists() and not rebuild:
            shutil.copyfile(database, tmp)
        engine = engine_for(tmp)
        try:
            create_schema(engine, __version__)
            events = 0
            with Session(engine) as session, session.begin():
                for record_file in iterate(records, desc="ingest", unit="record"):
                    events += _ingest_record(session, read_record(record_file), record_file)
        except (sqlalchemy.exc.DatabaseError, UnicodeDecodeError) as error:
            raise _database_error(database, error) from None
        finally:
            engine.dispose()
    return {"records": len(records), "slip events": events}


#: SQLite's words for a file that is not a database, or a damaged one (a text value that is not UTF-8 is damage too:
#: SQLite keeps no checksums).
_DAMAGED = ("file is not a database", "malformed", "corrupt")


def _database_error(database, error):
    """The one-line error of SQLite failing on ``database`` during an ingest (the database is left as it was)."""
    cause = str(getattr(error, "orig", None) or error).strip()
    if isinstance(error, UnicodeDecodeError) or any(word in cause for word in _DAMAGED):
        return FileFormatError(f"{database}: not a readable SQLite database ({cause}): it is damaged or not a "
                               "database; `stickslip db rebuild` remakes it from the provenance records (left as it "
                               "was)")
    return FileFormatError(f"{database}: the ingest failed in SQLite ({cause}); the database is left as it was")
