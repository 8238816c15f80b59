"""The results database: SQLAlchemy models of runs, files, simulations, slip events and figures.

One SQLite file per study (``results/{study}/stickslip.sqlite``) written only by the workflow's
``database`` rule or ``stickslip db ingest|rebuild`` (:mod:`.ingest`); read by
:mod:`.query`, ``stickslip db`` and any SQLite client. docs/database.md
documents every table and column.

Column names, types and docs come from :mod:`stickslip.vocabulary`.

Tables
------
schema_info   key/value: ``schema_version`` (:data:`SCHEMA_VERSION`), ``package_version``.
runs          one row per job (simulation, analysis, figure, mesh): its provenance record.
artifacts     every input and output file of every run, with sha256 and size.
simulations   one row per solver run: typed physics parameters.
slip_events   one row per slip of one interface in one event (numerical and experimental).
run_periodicity  one row per analysed run: periodicity and synchronisation of its slip events.
figures       one row per figure: its PDF and PNG.

Views ``slip_events_full`` and ``periodicity_full``: slip_events and run_periodicity joined with
the parameters of their simulation.
"""

import sqlite3
import urllib.parse
from pathlib import Path

from sqlalchemy import URL, Boolean, Float, ForeignKey, Index, Integer, String, Text, create_engine, event, text
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column

from ..h5io import FileFormatError
from ..vocabulary import QUANTITIES

__all__ = ["SCHEMA_VERSION", "SCHEMA_HINT", "Base", "SchemaInfo", "Run", "ArtifactRow", "Simulation", "SlipEvent", "RunPeriodicity",
           "Figure", "VIEWS", "engine_for", "create_schema"]

#: Version of the table layout; a database of another version is migrated (``stickslip db migrate``, from 6:
#: :mod:`.migrate`) or rebuilt. 2: ``simulations.phi``; 3: lineage (``artifacts.format``, ``artifacts.made_by``,
#: ``simulations.format``), ``slip_events`` is the ``event-table`` file's table as it is;
#: 4: ``run_periodicity`` and the view ``periodicity_full``; 5: ``simulations.temperature``,
#: ``attempt_rate``, ``drive_rate`` (thermal fem runs); 6: ``simulations.junction_strengthening``,
#: ``junction_glass_temperature``, ``junction_attempt_rate`` (fem runs with junction aging); 7: the package's
#: vocabulary (:mod:`stickslip.vocabulary`): ``slip_events.dmu_sig0`` and ``t`` (numerical rows; ``dmu`` and
#: ``time`` are the experimental ones), ``simulations.driven_slab`` (was ``a``), ``run_periodicity.n_slips``,
#: ``n_multi``, ``n_spanning`` (were ``slips``, ``multi``, ``spanning``).
SCHEMA_VERSION = 7


#: What to do with a database of another schema version.
SCHEMA_HINT = ("run `stickslip db migrate` (keeps its rows; from schema 6) or `snakemake` (remakes the study with "
               "this version)")


def _doc(name):
    """The column doc of the vocabulary (docs/database.md shows it)."""
    quantity = QUANTITIES[name]
    return f"{quantity.doc} [{quantity.unit}]" if quantity.unit else quantity.doc


def _column(name, kind, *args, **kwargs):
    """A mapped column named and documented by the vocabulary."""
    return mapped_column(kind, *args, doc=_doc(name), **kwargs)


class Base(DeclarativeBase):
    """Declarative base of the results database."""


class SchemaInfo(Base):
    """Key/value facts about the database itself (``schema_version``, ``package_version``)."""

    __tablename__ = "schema_info"
    key: Mapped[str] = _column("key", String, primary_key=True)
    value: Mapped[str] = _column("value", String)


class Run(Base):
    """One job of the workflow, from its provenance record."""

    __tablename__ = "runs"
    run_id: Mapped[str] = _column("run_id", String(16), primary_key=True)
    kind: Mapped[str] = _column("kind", String, index=True)
    plugin: Mapped[str] = _column("plugin", String, index=True)
    plugin_version: Mapped[str] = _column("plugin_version", String)
    code_hash: Mapped[str] = _column("code_hash", String)
    package_version: Mapped[str] = _column("package_version", String)
    git_commit: Mapped[str | None] = _column("git_commit", String)
    git_dirty: Mapped[bool | None] = _column("git_dirty", Boolean)
    params: Mapped[str] = _column("params", Text)
    seed: Mapped[int | None] = _column("seed", Integer)
    threads: Mapped[int] = _column("threads", Integer)
    python_version: Mapped[str] = _column("python_version", String)
    numpy_version: Mapped[str | None] = _column("numpy_version", String)
    numba_version: Mapped[str | None] = _column("numba_version", String)
    h5py_version: Mapped[str | None] = _column("h5py_version", String)
    versions: Mapped[str] = _column("versions", Text)
    host: Mapped[str] = _column("host", String)
    started_at: Mapped[str] = _column("started_at", String)
    finished_at: Mapped[str] = _column("finished_at", String)
    wall_time_s: Mapped[float] = _column("wall_time_s", Float)
    peak_memory_mib: Mapped[float] = _column("peak_memory_mib", Float)
    record_path: Mapped[str] = _column("record_path", String)


class ArtifactRow(Base):
    """One input or output file of a run (a row of ``artifacts``; in memory: :class:`stickslip.lineage.Artifact`)."""

    __tablename__ = "artifacts"
    id: Mapped[int] = _column("id", Integer, primary_key=True, autoincrement=True)
    run_id: Mapped[str] = _column("run_id", ForeignKey("runs.run_id", ondelete="CASCADE"), index=True)
    direction: Mapped[str] = _column("direction", String)
    role: Mapped[str] = _column("role", String)
    path: Mapped[str] = _column("path", String, index=True)
    sha256: Mapped[str] = _column("sha256", String(64), index=True)
    bytes: Mapped[int] = _column("bytes", Integer)
    format: Mapped[str | None] = _column("format", String)
    made_by: Mapped[str | None] = _column("made_by", String(16), index=True)


class Simulation(Base):
    """One solver run with its key physics parameters as typed columns (NULL where not a parameter)."""

    __tablename__ = "simulations"
    run_id: Mapped[str] = _column("run_id", ForeignKey("runs.run_id", ondelete="CASCADE"), primary_key=True)
    solver: Mapped[str] = _column("solver", String, index=True)
    path: Mapped[str] = _column("path", String)
    format: Mapped[str] = _column("format", String)
    source: Mapped[str | None] = _column("source", String)
    protocol: Mapped[str | None] = _column("protocol", String)
    n: Mapped[int | None] = _column("n", Integer, index=True)
    driven_slab: Mapped[int | None] = _column("driven_slab", Integer)
    plates: Mapped[int | None] = _column("plates", Integer)
    blocks: Mapped[int | None] = _column("blocks", Integer)
    k_drive: Mapped[float | None] = _column("k_drive", Float)
    phi: Mapped[float | None] = _column("phi", Float, index=True)
    regime: Mapped[str | None] = _column("regime", String, index=True)
    seed: Mapped[int | None] = _column("seed", Integer)
    temperature: Mapped[float | None] = _column("temperature", Float)
    attempt_rate: Mapped[float | None] = _column("attempt_rate", Float)
    drive_rate: Mapped[float | None] = _column("drive_rate", Float)
    junction_strengthening: Mapped[float | None] = _column("junction_strengthening", Float)
    junction_glass_temperature: Mapped[float | None] = _column("junction_glass_temperature", Float)
    junction_attempt_rate: Mapped[float | None] = _column("junction_attempt_rate", Float)


class SlipEvent(Base):
    """The slip of one interface in one event: a row of an ``event-table`` file's ``slip_events`` table.

    Numerical events come from ``numerical-events`` (and ``thermal-events``), experimental ones from
    ``experiment-events``; any analysis that produces the format adds its own.
    """

    __tablename__ = "slip_events"
    id: Mapped[int] = _column("id", Integer, primary_key=True, autoincrement=True)
    analysis_run_id: Mapped[str] = _column("analysis_run_id", ForeignKey("runs.run_id", ondelete="CASCADE"),
                                           index=True)
    simulation_run_id: Mapped[str] = _column("simulation_run_id", String(16), index=True)
    analysis: Mapped[str] = _column("analysis", String, index=True)
    solver: Mapped[str] = _column("solver", String, index=True)
    source: Mapped[str | None] = _column("source", String, index=True)
    event: Mapped[int] = _column("event", Integer)
    interface: Mapped[int | None] = _column("interface", Integer, index=True)
    multi: Mapped[bool | None] = _column("multi", Boolean)
    slip: Mapped[float | None] = _column("slip", Float)
    dmu: Mapped[float | None] = _column("dmu", Float)
    dmu_sig0: Mapped[float | None] = _column("dmu_sig0", Float)
    time: Mapped[float | None] = _column("time", Float)
    t: Mapped[float | None] = _column("t", Float)
    increment: Mapped[int | None] = _column("increment", Integer)
    extra: Mapped[str | None] = _column("extra", Text)


class RunPeriodicity(Base):
    """Periodicity and synchronisation of one run's slip events: the ``periodicity`` table of an
    ``event-table`` file (:mod:`stickslip.events.periodicity`), one row per analysis run."""

    __tablename__ = "run_periodicity"
    analysis_run_id: Mapped[str] = _column("analysis_run_id", ForeignKey("runs.run_id", ondelete="CASCADE"),
                                           primary_key=True)
    simulation_run_id: Mapped[str] = _column("simulation_run_id", String(16), index=True)
    analysis: Mapped[str] = _column("analysis", String)
    n_slips: Mapped[int] = _column("n_slips", Integer)
    n_multi: Mapped[int] = _column("n_multi", Integer)
    n_spanning: Mapped[int] = _column("n_spanning", Integer)
    interval_cv: Mapped[float | None] = _column("interval_cv", Float)
    drop_cv: Mapped[float | None] = _column("drop_cv", Float)
    multi_fraction: Mapped[float | None] = _column("multi_fraction", Float)
    spanning_fraction: Mapped[float | None] = _column("spanning_fraction", Float)
    alternation_cv: Mapped[float | None] = _column("alternation_cv", Float)
    runs_z: Mapped[float | None] = _column("runs_z", Float)


class Figure(Base):
    """One figure file pair."""

    __tablename__ = "figures"
    run_id: Mapped[str] = _column("run_id", ForeignKey("runs.run_id", ondelete="CASCADE"), primary_key=True)
    figure: Mapped[str] = _column("figure", String, index=True)
    pdf: Mapped[str] = _column("pdf", String)
    png: Mapped[str | None] = _column("png", String)


Index("ix_slip_events_sim_interface", SlipEvent.simulation_run_id, SlipEvent.interface)

#: Views created with the tables: name -> SELECT.
VIEWS = {
    "slip_events_full": (
        "SELECT e.*, s.protocol, s.n, s.driven_slab, s.plates, s.blocks, s.k_drive, s.phi, s.regime, s.seed, "
        "s.temperature, "
        "s.attempt_rate, s.drive_rate, s.junction_strengthening, s.junction_glass_temperature, s.junction_attempt_rate "
        "FROM slip_events AS e LEFT JOIN simulations AS s ON s.run_id = e.simulation_run_id"),
    "periodicity_full": (
        "SELECT p.*, s.solver, s.n, s.plates, s.blocks, s.k_drive, s.phi, s.regime, s.seed, "
        "json_extract(r.params, '$.dt_scale') AS dt_scale FROM run_periodicity AS p "
        "LEFT JOIN simulations AS s ON s.run_id = p.simulation_run_id "
        "LEFT JOIN runs AS r ON r.run_id = p.simulation_run_id"),
}


def engine_for(path, *, readonly=False):
    """Return an SQLAlchemy engine on an SQLite file.

    Parameters
    ----------
    path : str or pathlib.Path
    readonly : bool
        Open with ``mode=ro``: any write raises ``sqlite3.OperationalError``.

    Returns
    -------
    sqlalchemy.engine.Engine
    """
    if readonly:  # a URI, its path escaped: '?', '#' and '%' are a file name's characters, not the URI's
        uri = f"file:{urllib.parse.quote(str(Path(path).absolute()))}?mode=ro"
        engine = create_engine("sqlite+pysqlite://", creator=lambda: sqlite3.connect(uri, uri=True))
    else:
        engine = create_engine(URL.create("sqlite+pysqlite", database=str(path)))

    @event.listens_for(engine, "connect")
    def _foreign_keys(connection, _record):
        connection.execute("PRAGMA foreign_keys = ON")

    return engine


def create_schema(engine, package_version):
    """Create the tables and views if missing, and record the schema version.

    Parameters
    ----------
    engine : sqlalchemy.engine.Engine
    package_version : str

    Raises
    ------
    FileFormatError
        If the database has another schema version (it must be rebuilt).
    """
    Base.metadata.create_all(engine)
    with engine.begin() as connection:
        for name, select in VIEWS.items():
            connection.execute(text(f"CREATE VIEW IF NOT EXISTS {name} AS {select}"))
        found = connection.execute(text("SELECT value FROM schema_info WHERE key = 'schema_version'")).scalar()
        if found is not None and int(found) != SCHEMA_VERSION:
            raise FileFormatError(f"{engine.url.database}: database schema version {found}, expected {SCHEMA_VERSION}: "
                                  f"{SCHEMA_HINT}")
        connection.execute(text("INSERT OR REPLACE INTO schema_info (key, value) VALUES "
                                "('schema_version', :v), ('package_version', :p)"),
                           {"v": str(SCHEMA_VERSION), "p": package_version})
