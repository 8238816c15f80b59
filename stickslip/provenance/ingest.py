"""Ingest provenance records and event tables into the results database.

:func:`ingest` is idempotent (a run is keyed by its run id: ingesting the same
record twice leaves one set of rows) and transactional: it works on a copy of
the database in the same directory and renames it into place only when every
record went in, so an interrupted or failed ingest leaves the previous database
intact. A lock file beside the database serialises concurrent ingests, so two
processes ingesting at once lose no record.

What goes where (see :mod:`.database`):

- every record -> ``runs`` and ``artifacts``;
- solver records -> ``simulations`` (typed columns from the parameters);
- analysis records -> ``slip_events``, from the output's event table (:data:`EVENT_TABLES`);
- figure records -> ``figures``.
"""

import fcntl
import json
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from sqlalchemy import delete, insert, text
from sqlalchemy.orm import Session

from ..h5io import open_file, read_table
from ..progress import iterate
from .database import Artifact, Figure, Run, Simulation, SlipEvent, create_schema, engine_for
from .record import read_record

__all__ = ["ingest", "find_records", "EVENT_TABLES", "EVENT_COLUMNS"]

#: Tables of an analysis output read into ``slip_events``, the first found: one row per
#: (event, slipping interface). Numerical: ``slip_interfaces`` (events.plugin); experimental:
#: ``slips`` (experiment.analysis).
EVENT_TABLES = ("slip_interfaces", "slips")

#: Column of an event table -> column of ``slip_events``; the table's other columns go to ``extra``.
EVENT_COLUMNS = {"event": "event", "a": "interface", "dR": "slip", "dmu": "dmu", "t": "time",
                 "increment": "increment", "multi": "multi"}

#: Column of ``simulations`` -> names it comes from, first found: a parameter of the run, else a
#: root attribute of the simulation file (fem runs have ``plates``; their files say ``n_interfaces``).
SIMULATION_COLUMNS = {"protocol": ("protocol",), "n": ("n", "n_interfaces"), "a": ("a",), "plates": ("plates",),
                      "blocks": ("N",), "k_drive": ("k_drive",), "phi": ("phi",),
                      "regime": ("regime",), "seed": ("seed",)}

#: A simulation's driving regime, when its parameters do not state it, is the one its analysis
#: output states (numerical-events: from k_drive); set once both records are in the same ingest.
REGIME_FROM_ANALYSES = "UPDATE simulations SET regime = :regime WHERE run_id = :run_id AND regime IS NULL"

#: An event's source is its simulation's (known once both records are in).
SOURCE_FROM_SIMULATIONS = ("UPDATE slip_events SET source = (SELECT s.source FROM simulations AS s "
                           "WHERE s.run_id = slip_events.simulation_run_id) WHERE source IS NULL")


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
             "sha256": entry["sha256"], "bytes": entry["bytes"]}
            for direction, key in (("input", "inputs"), ("output", "outputs")) for entry in record[key]]


def _simulation_row(record, record_file):
    """Typed columns from the parameters, else from the simulation file's root attributes."""
    path = record["outputs"][0]["path"]
    with open_file(_beside(record_file, path)) as handle:
        attrs = {key: _python(value) for key, value in handle.attrs.items()}
        source = "experimental" if "t_F" in handle else "numerical"
    row = {"run_id": record["run_id"], "solver": record["plugin"], "path": path, "source": source}
    for column, names in SIMULATION_COLUMNS.items():
        found = [source[name] for name in names for source in (record["params"], attrs) if name in source]
        value = found[0] if found else None
        row[column] = value.decode() if isinstance(value, bytes) else value
    return row


def _python(value):
    """A numpy scalar as the Python scalar SQLite takes (NaN as NULL)."""
    value = value.item() if hasattr(value, "item") else value
    return None if isinstance(value, float) and value != value else value


def _event_rows(record, record_file):
    """Rows of ``slip_events`` from an analysis output, and the output's ``regime`` attribute (or None)."""
    output = _beside(record_file, record["outputs"][0]["path"])
    with open_file(output) as handle:
        regime = _python(handle.attrs.get("regime"))
        name = next((table for table in EVENT_TABLES if table in handle), None)
        if name is None:
            return [], regime
        table = read_table(handle, name)
    if "single" in table.columns and "multi" not in table.columns:
        table["multi"] = ~table.pop("single").astype(bool)
    if "event" not in table.columns and "increment" in table.columns:
        table.insert(0, "event", table["increment"].rank(method="dense").astype(int) - 1)
    simulation = record["inputs"][0]
    identity = {"analysis_run_id": record["run_id"], "simulation_run_id": Path(simulation["path"]).stem,
                "analysis": record["plugin"], "solver": simulation["role"].partition(":")[2], "source": None}
    extra_columns = [c for c in table.columns if c not in EVENT_COLUMNS]
    rows = []
    for index, item in enumerate(table.to_dict("records")):
        row = dict(identity)
        row.update({column: _python(item.get(name)) for name, column in EVENT_COLUMNS.items()})
        if row["event"] is None:
            row["event"] = index
        row["extra"] = json.dumps({c: _python(item[c]) for c in extra_columns}) if extra_columns else None
        rows.append(row)
    return rows, regime


def _figure_row(record):
    outputs = {entry["role"]: entry["path"] for entry in record["outputs"]}
    return {"run_id": record["run_id"], "figure": record["plugin"], "pdf": outputs.get("pdf"),
            "png": outputs.get("png")}


def _ingest_record(session, record, record_file):
    """Replace the rows of one run by those of its record.

    Returns
    -------
    tuple[int, dict[str, str]]
        Slip events added; simulation run id -> driving regime stated by an analysis output.
    """
    run_id = record["run_id"]
    for model, key in ((SlipEvent, SlipEvent.analysis_run_id), (Artifact, Artifact.run_id),
                       (Simulation, Simulation.run_id), (Figure, Figure.run_id), (Run, Run.run_id)):
        session.execute(delete(model).where(key == run_id))
    session.execute(insert(Run), [_run_row(record, record_file)])
    artifacts = _artifact_rows(record)
    if artifacts:
        session.execute(insert(Artifact), artifacts)
    events, regimes = [], {}
    if record["kind"] == "solver":
        session.execute(insert(Simulation), [_simulation_row(record, record_file)])
    elif record["kind"] == "analysis":
        events, regime = _event_rows(record, record_file)
        if events:
            session.execute(insert(SlipEvent), events)
        if regime is not None:
            regimes[Path(record["inputs"][0]["path"]).stem] = regime
    elif record["kind"] == "figure":
        session.execute(insert(Figure), [_figure_row(record)])
    return len(events), regimes


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
    Cost: reads every record and every analysis output's ``slips`` table; the
    database is copied once (its size) unless ``rebuild``.
    """
    from .. import __version__

    database = Path(database)
    database.parent.mkdir(parents=True, exist_ok=True)
    records = [Path(r) for r in records]
    with _locked(database):
        fd, tmp = tempfile.mkstemp(prefix=f".{database.name}.", suffix=".tmp", dir=database.parent)
        os.close(fd)
        tmp = Path(tmp)
        try:
            if database.exists() and not rebuild:
                shutil.copyfile(database, tmp)
            else:
                tmp.unlink()
            engine = engine_for(tmp)
            try:
                create_schema(engine, __version__)
                events = 0
                with Session(engine) as session, session.begin():
                    regimes = {}
                    for record_file in iterate(records, desc="ingest", unit="record"):
                        added, found = _ingest_record(session, read_record(record_file), record_file)
                        events += added
                        regimes.update(found)
                    session.execute(text(SOURCE_FROM_SIMULATIONS))
                    if regimes:
                        session.execute(text(REGIME_FROM_ANALYSES),
                                        [{"run_id": k, "regime": v} for k, v in regimes.items()])
            finally:
                engine.dispose()
            os.replace(tmp, database)
        finally:
            if tmp.exists():
                tmp.unlink()
    return {"records": len(records), "slip events": events}
