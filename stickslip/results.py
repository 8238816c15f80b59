"""A study's results opened for reading: its results tree, its database and its config.

A study (a workflow config) writes everything under ``results/{study}/`` in the directory where
Snakemake ran (:mod:`stickslip.study`), its database at ``results/{study}/stickslip.sqlite``.
:class:`StudyResults` finds them from a study's name, its config file or its results tree, and
queries the database with the functions of :mod:`stickslip.provenance.query` (read-only
connections), which ``stickslip db`` runs too.
"""

import re
from pathlib import Path

import yaml

from .h5io import FileFormatError
from .provenance import query
from .runs import open_run
from .study import PATHS, RESULTS, study_name

__all__ = ["StudyResults", "CONFIGS"]

#: Where the shipped study configs are, relative to the working directory (the repository's root).
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


class StudyResults:
    """One study's results: the results tree, the database, the config (see :func:`stickslip.study`).

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A study name (its results tree is ``results/{name}`` in the working directory, as for
        ``snakemake`` and ``stickslip db --study``), a config file (``*.yaml``: the study it names,
        whose tree is under ``results/`` in the working directory), or a study's results tree (a
        path with a directory separator, e.g. ``results/ci`` or an absolute path).

    Attributes
    ----------
    name : str
    root : pathlib.Path
        The results tree: ``sim/``, ``events/``, ``mesh/``, ``figures/``, ``logs/`` (:data:`stickslip.study.PATHS`).
    database : pathlib.Path
        ``root / "stickslip.sqlite"``.
    config_file : pathlib.Path or None
        The config given, else ``workflow/config/{name}.yaml`` beside the results tree if it exists and
        names this study, else None.
    config : dict or None
        Its content as written (the plugins' defaults are not filled in).

    Raises
    ------
    stickslip.h5io.FileFormatError
        If there is neither a results tree nor a config of that study, or the config is not readable.
    """

    def __init__(self, name_or_path="default"):
        given = Path(name_or_path)
        if given.suffix in (".yaml", ".yml"):
            self.config_file, self.config = given, _read_config(given)
            self.name = study_name(self.config, [given])
            self.root = Path(RESULTS) / self.name
        else:
            self.root = given if (given.is_absolute() or len(given.parts) > 1) else Path(RESULTS) / given
            self.name = self.root.name
            candidate = self.root.parent.parent / CONFIGS / f"{self.name}.yaml"
            self.config_file, self.config = None, None
            if candidate.is_file():
                config = _read_config(candidate)
                if study_name(config, [candidate]) == self.name:
                    self.config_file, self.config = candidate, config
        if self.config is None and not self.root.is_dir():
            raise FileFormatError(f"{self.root}: no results of study {self.name!r} (run `snakemake --cores 2` with its "
                                  f"config), and no config {CONFIGS}/{self.name}.yaml")
        self.database = self.root / PATHS["database"]

    def __repr__(self):
        return f"<StudyResults {self.name!r}: {self.root}, config {self.config_file}>"

    def runs(self, **filters):
        """The study's runs with their parameters (:func:`stickslip.provenance.query.runs`; ``stickslip db runs``).

        Parameters
        ----------
        **filters
            ``kind``, ``plugin``, ``solver``, ``n``, ``regime``, ``seed``.

        Returns
        -------
        pandas.DataFrame
        """
        return query.runs(self.database, **filters)

    def events(self, **filters):
        """Slip events with their simulation's parameters (:func:`stickslip.provenance.query.events`; ``db events``).

        Parameters
        ----------
        **filters
            ``solver``, ``analysis``, ``source`` ("numerical" or "experimental": their ``dmu`` are in other
            units), ``n``, ``interface``, ``regime``, ``seed``, ``run_id``.

        Returns
        -------
        pandas.DataFrame
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
            If ``run_id`` is not a run id, or the database holds no simulation of that id.
        """
        if not isinstance(run_id, str) or not _RUN_ID.match(run_id):
            raise ValueError(f"run_id: expected 16 hexadecimal characters, got {run_id!r}")
        found = self.sql(f"SELECT path FROM simulations WHERE run_id = '{run_id}'")
        if found.empty:
            raise ValueError(f"run_id: {self.database} holds no simulation {run_id}")
        path = Path(found["path"].iloc[0])
        return open_run(path if path.is_absolute() else self.root.parent.parent / path)
