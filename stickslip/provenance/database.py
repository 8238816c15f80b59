"""The results database: SQLAlchemy models of runs, files, simulations, slip events and figures.

One SQLite file per study (``results/{study}/stickslip.sqlite``) written only by the workflow's
``database`` rule or ``stickslip db ingest|rebuild`` (:mod:`.ingest`); read by
:mod:`.query`, ``stickslip db`` and any SQLite client. docs/database.md
documents every table and column.

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

from ..formats.event_table import PERIODICITY_COLUMNS
from ..h5io import FileFormatError

__all__ = ["SCHEMA_VERSION", "Base", "SchemaInfo", "Run", "ArtifactRow", "Simulation", "SlipEvent", "RunPeriodicity",
           "Figure", "VIEWS", "engine_for", "create_schema"]

#: Version of the table layout; a database of another version must be rebuilt (``stickslip db
#: rebuild``). 2: ``simulations.phi``; 3: lineage (``artifacts.format``, ``artifacts.made_by``,
#: ``simulations.format``), ``slip_events`` is the ``event-table`` file's table as it is;
#: 4: ``run_periodicity`` and the view ``periodicity_full``; 5: ``simulations.temperature``,
#: ``attempt_rate``, ``drive_rate`` (thermal fem runs); 6: ``simulations.junction_strengthening``,
#: ``junction_glass_temperature``, ``junction_attempt_rate`` (fem runs with junction aging).
SCHEMA_VERSION = 6


class Base(DeclarativeBase):
    """Declarative base of the results database."""


class SchemaInfo(Base):
    """Key/value facts about the database itself (``schema_version``, ``package_version``)."""

    __tablename__ = "schema_info"
    key: Mapped[str] = mapped_column(String, primary_key=True)
    value: Mapped[str] = mapped_column(String)


class Run(Base):
    """One job of the workflow, from its provenance record."""

    __tablename__ = "runs"
    run_id: Mapped[str] = mapped_column(String(16), primary_key=True, doc="job id (16 hex)")
    kind: Mapped[str] = mapped_column(String, index=True, doc="solver, analysis, figure or mesh")
    plugin: Mapped[str] = mapped_column(String, index=True, doc="plugin name")
    plugin_version: Mapped[str] = mapped_column(String)
    code_hash: Mapped[str] = mapped_column(String, doc="hash of the plugin's package sources")
    package_version: Mapped[str] = mapped_column(String)
    git_commit: Mapped[str | None] = mapped_column(String)
    git_dirty: Mapped[bool | None] = mapped_column(Boolean)
    params: Mapped[str] = mapped_column(Text, doc="all parameters, JSON")
    seed: Mapped[int | None] = mapped_column(Integer)
    threads: Mapped[int] = mapped_column(Integer)
    python_version: Mapped[str] = mapped_column(String)
    numpy_version: Mapped[str | None] = mapped_column(String)
    numba_version: Mapped[str | None] = mapped_column(String)
    h5py_version: Mapped[str | None] = mapped_column(String)
    versions: Mapped[str] = mapped_column(Text, doc="all library versions, JSON")
    host: Mapped[str] = mapped_column(String)
    started_at: Mapped[str] = mapped_column(String, doc="ISO 8601, UTC")
    finished_at: Mapped[str] = mapped_column(String, doc="ISO 8601, UTC")
    wall_time_s: Mapped[float] = mapped_column(Float, doc="[s]")
    peak_memory_mib: Mapped[float] = mapped_column(Float, doc="peak resident memory of the job [MiB]")
    record_path: Mapped[str] = mapped_column(String, doc="the provenance JSON file")


class ArtifactRow(Base):
    """One input or output file of a run (a row of ``artifacts``; in memory: :class:`stickslip.lineage.Artifact`)."""

    __tablename__ = "artifacts"
    id: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=True)
    run_id: Mapped[str] = mapped_column(ForeignKey("runs.run_id", ondelete="CASCADE"), index=True)
    direction: Mapped[str] = mapped_column(String, doc="input or output")
    role: Mapped[str] = mapped_column(String, doc="output, pdf, png, mesh, simulation, analysis:<name>, ...")
    path: Mapped[str] = mapped_column(String, index=True)
    sha256: Mapped[str] = mapped_column(String(64), index=True)
    bytes: Mapped[int] = mapped_column(Integer)
    format: Mapped[str | None] = mapped_column(String, doc="the file's format (stickslip.formats)")
    made_by: Mapped[str | None] = mapped_column(String(16), index=True,
                                                doc="inputs: run id of the job that wrote the file (lineage)")


class Simulation(Base):
    """One solver run with its key physics parameters as typed columns (NULL where not a parameter)."""

    __tablename__ = "simulations"
    run_id: Mapped[str] = mapped_column(ForeignKey("runs.run_id", ondelete="CASCADE"), primary_key=True)
    solver: Mapped[str] = mapped_column(String, index=True)
    path: Mapped[str] = mapped_column(String, doc="the simulation HDF5 file")
    format: Mapped[str] = mapped_column(String, doc="its format: fem-run, timeseries, ...")
    source: Mapped[str | None] = mapped_column(String, doc="experimental or numerical: the format's source")
    protocol: Mapped[str | None] = mapped_column(String, doc="stack or individual (lever)")
    n: Mapped[int | None] = mapped_column(Integer, index=True, doc="number of driven interfaces / slabs")
    a: Mapped[int | None] = mapped_column(Integer, doc="slab driven alone (individual protocol)")
    plates: Mapped[int | None] = mapped_column(Integer, doc="number of elastic plates (fem)")
    blocks: Mapped[int | None] = mapped_column(Integer, doc="N, blocks per interface (fem); SQLite names "
                                                           "are case-insensitive, so not 'N' beside 'n'")
    k_drive: Mapped[float | None] = mapped_column(Float, doc="drive spring stiffness (solver units)")
    phi: Mapped[float | None] = mapped_column(Float, index=True, doc="rigidity ratio Phi = K / K_s of the drive "
                                                                   "(fem; stickslip.fem.stiffness)")
    regime: Mapped[str | None] = mapped_column(String, index=True, doc="driving regime, e.g. stiff or compliant")
    seed: Mapped[int | None] = mapped_column(Integer)
    temperature: Mapped[float | None] = mapped_column(Float, doc="thermal activation (fem: 0 for the athermal "
                                                                "protocol) [G eps0^2 h^2]")
    attempt_rate: Mapped[float | None] = mapped_column(Float, doc="attempt rate of a thermal fem run [1/time]")
    drive_rate: Mapped[float | None] = mapped_column(Float, doc="drive rate of a thermal fem run [eps0/time]")
    junction_strengthening: Mapped[float | None] = mapped_column(
        Float, doc="junction aging of a thermal fem run: widening of a well per unit junction depth (0: no aging) "
                   "[eps0 / (G eps0^2 h^2)]")
    junction_glass_temperature: Mapped[float | None] = mapped_column(
        Float, doc="scale T_g of the junction depths of a fem run with aging [G eps0^2 h^2]")
    junction_attempt_rate: Mapped[float | None] = mapped_column(
        Float, doc="attempt rate of the junction redraws of a fem run with aging [1/time]")


class SlipEvent(Base):
    """The slip of one interface in one event: a row of an ``event-table`` file's ``slip_events`` table.

    Numerical events come from ``numerical-events``, experimental ones from
    ``experiment-events``; any analysis that produces the format adds its own.
    """

    __tablename__ = "slip_events"
    id: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=True)
    analysis_run_id: Mapped[str] = mapped_column(ForeignKey("runs.run_id", ondelete="CASCADE"), index=True)
    simulation_run_id: Mapped[str] = mapped_column(String(16), index=True,
                                                   doc="run id of the analysed simulation (from the lineage)")
    analysis: Mapped[str] = mapped_column(String, index=True)
    solver: Mapped[str] = mapped_column(String, index=True)
    source: Mapped[str | None] = mapped_column(String, index=True,
                                               doc="numerical or experimental: the simulation format's source")
    event: Mapped[int] = mapped_column(Integer, doc="event index within the run")
    interface: Mapped[int | None] = mapped_column(Integer, index=True, doc="interface (slab) a, 1 = lowest")
    slip: Mapped[float | None] = mapped_column(Float, doc="slip dR of the interface (experimental) [mm]")
    dmu: Mapped[float | None] = mapped_column(Float, doc="drop of friction coefficient (experimental) [-] or "
                                                        "of interface stress (numerical) [sig0]")
    multi: Mapped[bool | None] = mapped_column(Boolean, doc="more than one interface slipped in the event")
    time: Mapped[float | None] = mapped_column(Float, doc="time of the slip (experimental) [s]")
    increment: Mapped[int | None] = mapped_column(Integer, doc="increment of the event (numerical)")
    extra: Mapped[str | None] = mapped_column(Text, doc="the table's further columns, JSON")


class RunPeriodicity(Base):
    """Periodicity and synchronisation of one run's slip events: the ``periodicity`` table of an
    ``event-table`` file (:mod:`stickslip.events.periodicity`), one row per analysis run."""

    __tablename__ = "run_periodicity"
    analysis_run_id: Mapped[str] = mapped_column(ForeignKey("runs.run_id", ondelete="CASCADE"), primary_key=True)
    simulation_run_id: Mapped[str] = mapped_column(String(16), index=True,
                                                   doc="run id of the analysed simulation (from the lineage)")
    analysis: Mapped[str] = mapped_column(String)
    slips: Mapped[int] = mapped_column(Integer, doc=PERIODICITY_COLUMNS["slips"][1])
    multi: Mapped[int] = mapped_column(Integer, doc=PERIODICITY_COLUMNS["multi"][1])
    spanning: Mapped[int] = mapped_column(Integer, doc=PERIODICITY_COLUMNS["spanning"][1])
    interval_cv: Mapped[float | None] = mapped_column(Float, doc=PERIODICITY_COLUMNS["interval_cv"][1])
    drop_cv: Mapped[float | None] = mapped_column(Float, doc=PERIODICITY_COLUMNS["drop_cv"][1])
    multi_fraction: Mapped[float | None] = mapped_column(Float, doc=PERIODICITY_COLUMNS["multi_fraction"][1])
    spanning_fraction: Mapped[float | None] = mapped_column(Float, doc=PERIODICITY_COLUMNS["spanning_fraction"][1])
    alternation_cv: Mapped[float | None] = mapped_column(Float, doc=PERIODICITY_COLUMNS["alternation_cv"][1])
    runs_z: Mapped[float | None] = mapped_column(Float, doc=PERIODICITY_COLUMNS["runs_z"][1])


class Figure(Base):
    """One figure file pair."""

    __tablename__ = "figures"
    run_id: Mapped[str] = mapped_column(ForeignKey("runs.run_id", ondelete="CASCADE"), primary_key=True)
    figure: Mapped[str] = mapped_column(String, index=True)
    pdf: Mapped[str] = mapped_column(String)
    png: Mapped[str | None] = mapped_column(String)


Index("ix_slip_events_sim_interface", SlipEvent.simulation_run_id, SlipEvent.interface)

#: Views created with the tables: name -> SELECT.
VIEWS = {
    "slip_events_full": (
        "SELECT e.*, s.protocol, s.n, s.a, s.plates, s.blocks, s.k_drive, s.phi, s.regime, s.seed, s.temperature, "
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
                               "run `stickslip db rebuild`")
        connection.execute(text("INSERT OR REPLACE INTO schema_info (key, value) VALUES "
                                "('schema_version', :v), ('package_version', :p)"),
                           {"v": str(SCHEMA_VERSION), "p": package_version})
