"""A study's results opened for reading: its results tree, its database and its config.

A study (a workflow config) writes everything under ``results/{study}/`` in the workflow directory, where
Snakemake ran (:mod:`stickslip.study_plan`), its database at ``results/{study}/stickslip.sqlite``.
:class:`StudyResults` finds that directory from any folder below it (:mod:`stickslip.workdir`), finds the
study there from its name, its config file or its results tree, and queries the database with the functions
of :mod:`stickslip.provenance.query` (read-only connections), which ``stickslip db`` runs too. Its tables are
typed and carry their units (:mod:`stickslip.vocabulary`); its filters are those of ``stickslip db``
(:mod:`stickslip.provenance.filters`).
"""

import dataclasses
import re
import shutil
from pathlib import Path

import numpy as np
import yaml

from . import registry
from .errors import RunNotFoundError, StudyNotFoundError
from .h5io import FileFormatError
from .hashing import sha256_file
from .output_safety.atomic import atomic_output
from .plugin_params import ParameterError
from .provenance import query
from .provenance.filters import EVENT_FILTERS, RUN_FILTERS, with_filters
from .provenance.record import record_path, write_record
from .runs import open_run
from .study_plan import PATHS, RESULTS, study_name
from .workdir import ENVIRONMENT, find_workdir

__all__ = ["StudyResults", "CONFIGS"]

#: Where the shipped study configs are, relative to the workflow directory (the repository's root).
CONFIGS = "workflow/config"

_RUN_ID = re.compile(r"^[0-9a-f]{16}$")


def _read_config(path):
    """The config of a config file (a mapping), or raise FileFormatError naming the file."""
    try:
        config = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as error:
        raise FileFormatError(f"{path}: not a readable study config ({error})") from None
    if not isinstance(config, dict):
        raise FileFormatError(f"{path}: not a study config (expected a mapping of config keys)")
    return config


def _plugin_units(frame):
    """Units of the ``params.<name>`` columns of a runs table: the units its plugins declare."""
    units = {}
    for kind, plugin in frame[["kind", "plugin"]].drop_duplicates().itertuples(index=False):
        try:
            declared = registry.get(kind, plugin).params
        except (registry.PluginError, KeyError):
            continue  # a plugin that is not installed (or a mesh job): its parameters have no known unit
        for field in dataclasses.fields(declared):
            column = f"params.{field.name}"
            if column in frame.columns:
                unit = field.metadata.get("unit", "")
                units[column] = unit if units.get(column, unit) == unit else None  # plugins disagree: no one unit
    return units


class StudyResults:
    """One study's results: the results tree, the database, the config (see :func:`stickslip.study`).

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A study name (its results tree is ``results/{name}`` in the workflow directory, as for
        ``snakemake`` and ``stickslip db --study``), a config file (``*.yaml``: the study it names,
        whose tree is under ``results/`` in the workflow directory), or a study's results tree (a
        path with a directory separator, e.g. ``results/ci`` or an absolute path). Relative files are
        looked for in the current folder, then in the workflow directory.
    workdir : str or os.PathLike, optional
        The workflow directory; default: ``$STICKSLIP_WORKDIR``, else the nearest folder at or above the
        current one with a ``Snakefile`` (:func:`stickslip.workdir.find_workdir`).

    Attributes
    ----------
    name : str
    workdir : stickslip.workdir.Workdir
        The workflow directory and how it was found.
    root : pathlib.Path
        The results tree: ``sim/``, ``events/``, ``mesh/``, ``figures/``, ``logs/`` (:data:`stickslip.study_plan.PATHS`).
    database : pathlib.Path
        ``root / "stickslip.sqlite"``.
    config_file : pathlib.Path or None
        The config given, else ``workflow/config/{name}.yaml`` in the workflow directory if it exists and
        names this study, else None.
    config : dict or None
        Its content as written (the plugins' defaults are not filled in).

    Raises
    ------
    stickslip.errors.StudyNotFoundError
        A ``FileNotFoundError`` (and a ``FileFormatError``): there is neither a results tree nor a config of
        that study; the message says where it looked and how the workflow directory was found.
    stickslip.h5io.FileFormatError
        If the config is not readable.
    """

    def __init__(self, name_or_path="default", *, workdir=None):
        self.workdir = find_workdir(workdir)
        given = Path(name_or_path)
        if given.suffix in (".yaml", ".yml"):
            path = self._existing(given)
            self.config_file, self.config = path, _read_config(path)
            self.name = study_name(self.config, [path])
            self.root = self.workdir.path / RESULTS / self.name
        else:
            self.root = (self._existing(given) if given.is_absolute() or len(given.parts) > 1
                         else self.workdir.path / RESULTS / given)
            self.name = self.root.name
            candidate = self.root.parent.parent / CONFIGS / f"{self.name}.yaml"
            self.config_file, self.config = None, None
            if candidate.is_file():
                config = _read_config(candidate)
                if study_name(config, [candidate]) == self.name:
                    self.config_file, self.config = candidate, config
        if self.config is None and not self.root.is_dir():
            raise StudyNotFoundError(
                f"{self.root}: no results of study {self.name!r} (run `snakemake --cores 2` with its config there) "
                f"and no config {CONFIGS}/{self.name}.yaml; the workflow directory is {self.workdir} (another: "
                f"workdir= or ${ENVIRONMENT})")
        self.database = self.root / PATHS["database"]

    def _existing(self, given):
        """A relative path as given if it exists from the current folder, else in the workflow directory."""
        if given.is_absolute() or given.exists():
            return given
        return self.workdir.path / given

    def __repr__(self):
        return f"<StudyResults {self.name!r}: {self.root}, config {self.config_file}>"

    @with_filters(RUN_FILTERS)
    def runs(self, *, wide=False, **filters):
        """The study's runs with their parameters (:func:`stickslip.provenance.query.runs`; ``stickslip db runs``).

        Parameters
        ----------
        wide : bool, optional
            Every column: the provenance record's (``code_hash``, ``host``, library versions, ``record_path``, ...)
            and ``params.<name>``, one per parameter of the runs' plugins (about a hundred in a study with every
            plugin). Default: the narrow form, :data:`stickslip.provenance.query.RUN_COLUMNS`.
        {filters}
        **parameters
            Any parameter of a plugin, e.g. ``backend="cpu"`` (:func:`stickslip.params`).

        Returns
        -------
        stickslip.vocabulary.UnitFrame
            One row per run (solver, analysis, figure, mesh): ``run_id``, ``kind``, ``plugin``,
            ``plugin_version``, the simulation's parameters (``solver``, ``n``, ``plates``, ``blocks``, ``k_drive``,
            ``phi``, ``regime``, ...; missing for other runs), ``seed``, its cost, ``finished_at`` (UTC) and
            commit; typed, every missing value ``pd.NA``; ``attrs["units"]`` maps every column to its unit
            (``params.<name>``: the plugin's).

        Raises
        ------
        stickslip.plugin_params.ParameterError
            A ``ValueError`` naming a filter that does not exist or a value that does not fit it.
        """
        if not isinstance(wide, (bool, np.bool_)):
            raise ParameterError(f"wide: expected True or False, got {wide!r}")
        frame = query.runs(self.database, **filters)
        frame.attrs["units"].update(_plugin_units(frame))
        return frame if wide else frame[list(query.RUN_COLUMNS)]

    @with_filters(EVENT_FILTERS)
    def events(self, **filters):
        """Slip events with their simulation's parameters (:func:`stickslip.provenance.query.events`; ``db events``).

        Parameters
        ----------
        {filters}
        **parameters
            Any parameter of the simulation's or the analysis's plugin (:func:`stickslip.params`).

        Returns
        -------
        pandas.DataFrame
            One row per (event, slipping interface): ``interface``, ``multi`` (bool), ``dmu`` [1] (lab and
            virtual slips) or ``dmu_sig0`` [sig0] (the model's), ``slip`` [mm], ``time`` [s] or ``t`` [time], the
            analysis's further columns (``T``, ``dF``, ``B_a``, ``dgamma``, ...) and the simulation's parameters;
            ``attrs["units"]``.

        Raises
        ------
        stickslip.plugin_params.ParameterError
            A ``ValueError`` naming a filter that does not exist or a value that does not fit it.
        """
        return query.events(self.database, **filters)

    def figures(self):
        """The figures with the run that drew them (:func:`stickslip.provenance.query.figures`)."""
        return query.figures(self.database)

    def sql(self, statement, *, time_limit=query.TIME_LIMIT_S, max_rows=query.MAX_ROWS,
            memory_limit_mib=query.MEMORY_LIMIT_MIB):
        """One SQL query on a read-only connection (:func:`stickslip.provenance.query.sql`; ``db sql``).

        Tables and views: docs/database.md.

        Parameters
        ----------
        statement : str
        time_limit : float or None
            [s]; None or 0: no limit (``db sql --time-limit``).
        max_rows : int or None
            None or 0: no limit (``--max-rows``).
        memory_limit_mib : float or None
            SQLite's memory and the rows fetched [MiB]; None or 0: no limit (``--memory-limit``).

        Returns
        -------
        pandas.DataFrame
            Columns named as the vocabulary's are typed and have their units in ``attrs["units"]``.

        Raises
        ------
        stickslip.provenance.query.QueryError
            A ``ValueError``: bad SQL, a write, a bound reached or a bound that is not a number >= 0.
        """
        return query.sql(statement, self.database, time_limit=time_limit, max_rows=max_rows,
                         memory_limit_mib=memory_limit_mib)

    def open_run(self, run_id):
        """Open one simulation of the study by its run id (:func:`stickslip.runs.open_run`).

        Parameters
        ----------
        run_id : str
            16 hexadecimal characters (the ``run_id`` column of :meth:`runs`).

        Returns
        -------
        stickslip.runs.FemRun or stickslip.runs.TimeseriesRun

        Raises
        ------
        ValueError
            If ``run_id`` is not a run id.
        stickslip.errors.RunNotFoundError
            A ``LookupError`` (and a ``ValueError``): the database holds no simulation of that id.
        """
        if not isinstance(run_id, str) or not _RUN_ID.match(run_id):
            raise ValueError(f"run_id: expected 16 hexadecimal characters, got {run_id!r}")
        found = self.sql(f"SELECT path FROM simulations WHERE run_id = '{run_id}'")
        if found.empty:
            raise RunNotFoundError(f"run_id: {self.database} holds no simulation {run_id}")
        path = Path(found["path"].iloc[0])
        return open_run(path if path.is_absolute() else self.root.parent.parent / path)

    def open_runs(self, frame):
        """Open the simulations of a table's ``run_id`` column, one at a time (a generator).

        Parameters
        ----------
        frame : pandas.DataFrame or Iterable[str]
            A table with a column ``run_id`` (e.g. ``study.runs(kind="solver", n=3)``) or ``simulation_run_id``
            (``study.events(...)``: each simulation once), or run ids.

        Yields
        ------
        stickslip.runs.FemRun or stickslip.runs.TimeseriesRun
            In the table's order; each is closed when the next is opened (``with`` is not needed).

        Raises
        ------
        stickslip.errors.RunNotFoundError
            For a run id that is not a simulation of the study (e.g. an analysis's).
        """
        columns = getattr(frame, "columns", ())
        ids = frame["run_id"] if "run_id" in columns else frame["simulation_run_id"] if \
            "simulation_run_id" in columns else frame
        for run_id in dict.fromkeys(ids):
            with self.open_run(run_id) as run:
                yield run

    def add(self, run):
        """Add a simulation made outside the workflow (:func:`stickslip.simulate`) to the study.

        Its file and provenance record are copied to ``results/{study}/added/{solver}/{run_id}.h5`` (and
        ``.provenance.json``, the path in it rewritten) and the record is ingested into the study's database, so that
        :meth:`runs`, :meth:`open_run` and ``stickslip browse`` show it; the workflow's ``database`` rule ingests
        every record under ``added/`` too, so the next ``snakemake`` keeps it. The study's analyses and figures
        are those of its config: the run's own events are ``run.slip_events()``.

        Parameters
        ----------
        run : stickslip.runs.FemRun or stickslip.runs.TimeseriesRun
            A run with its provenance record beside its file (what :func:`stickslip.simulate` writes).

        Returns
        -------
        str
            The run id.

        Raises
        ------
        stickslip.h5io.FileFormatError
            If the run has no provenance record, or its file no longer has the sha256 the record states (it was
            changed or resumed after the record was written), or the study holds another file under its run id.
        """
        record = run.provenance
        if record is None:
            raise FileFormatError(f"{run.path}: no provenance record beside it ({record_path(run.path).name}); "
                                  "a run made by stickslip.simulate or `stickslip simulate` has one")
        output = record["outputs"][0]
        sha256 = sha256_file(run.path)
        if output["sha256"] != sha256:
            raise FileFormatError(f"{run.path}: sha256 {sha256[:16]}... is not the {output['sha256'][:16]}... of its "
                                  f"record {record_path(run.path)}: the file changed after the record was written")
        target = self.root / PATHS["added"].format(solver=record["plugin"], run_id=record["run_id"])
        if target.is_file() and sha256_file(target) != sha256:
            raise FileFormatError(f"{target}: the study holds another file of run {record['run_id']}")
        if not target.is_file():
            target.parent.mkdir(parents=True, exist_ok=True)
            with atomic_output(target) as partial:
                shutil.copyfile(run.path, partial)
        relative = target.relative_to(self.root.parent.parent).as_posix()
        added = {**record, "outputs": [{**output, "path": relative}, *record["outputs"][1:]]}
        write_record(record_path(target), added)
        from .provenance.ingest import ingest  # SQLAlchemy's ORM (~0.3 s): only where a record is ingested

        ingest(self.database, [record_path(target)])
        return record["run_id"]

    @with_filters(RUN_FILTERS[2:])
    def find(self, **filters):
        """The simulations that match the filters, opened one at a time: ``for run in study.find(n=3): ...``.

        :meth:`open_runs` of ``runs(kind="solver", **filters)``.

        Parameters
        ----------
        {filters}
        **parameters
            Any parameter of a solver (``backend="cpu"``).

        Yields
        ------
        stickslip.runs.FemRun or stickslip.runs.TimeseriesRun
        """
        yield from self.open_runs(self.runs(kind="solver", **filters))
