"""Migrate a results database of an older schema to this one, keeping its rows (``stickslip db migrate``).

A study made by an older version keeps its database usable without remaking the study: schema 6 -> 7 renames
and splits columns into the package's vocabulary (:data:`stickslip.vocabulary.RENAMED`):

- ``simulations.a`` -> ``driven_slab``;
- ``run_periodicity.slips``, ``multi``, ``spanning`` -> ``n_slips``, ``n_multi``, ``n_spanning``;
- ``slip_events``: the numerical rows' ``dmu`` [sig0] -> ``dmu_sig0`` and ``time`` [time] -> ``t``, leaving
  ``dmu`` [1] and ``time`` [s] to the experimental rows; in ``extra``, the numerical rows' ``T``, ``B_a``,
  ``mu_before`` -> ``T_fe``, ``B_a_sig0``, ``mu_before_sig0``, and ``dR_from_dF`` -> ``slip_from_dF``;
- the views are made again.

Like ingest, the migration works on a copy beside the database and renames it into place only when every
statement went in (under the same lock), so an interrupted one leaves the database as it was. The rows keep
the plugin versions that made them; ``snakemake`` remakes the study with this version's analyses instead.
"""

import shutil
import sqlite3
from pathlib import Path

from ..h5io import FileFormatError
from ..output_safety.atomic import atomic_output
from .database import SCHEMA_VERSION, VIEWS
from .ingest import _locked

__all__ = ["MIGRATIONS", "migrate"]


def _renamed_keys(source, renames):
    """SQL renaming keys of ``extra`` in the rows of a source (None: every row)."""
    where = "" if source is None else f" AND source = '{source}'"
    return [f"UPDATE slip_events SET extra = json_set(json_remove(extra, '$.{old}'), '$.{new}', "
            f"json_extract(extra, '$.{old}')) WHERE json_type(extra, '$.{old}') IS NOT NULL{where}"
            for old, new in renames]


#: Statements that take a database from schema ``key`` to ``key + 1``.
MIGRATIONS = {
    6: [
        "ALTER TABLE simulations RENAME COLUMN a TO driven_slab",
        "ALTER TABLE run_periodicity RENAME COLUMN slips TO n_slips",
        "ALTER TABLE run_periodicity RENAME COLUMN multi TO n_multi",
        "ALTER TABLE run_periodicity RENAME COLUMN spanning TO n_spanning",
        "ALTER TABLE slip_events ADD COLUMN dmu_sig0 FLOAT",
        "ALTER TABLE slip_events ADD COLUMN t FLOAT",
        "UPDATE slip_events SET dmu_sig0 = dmu, dmu = NULL, t = time, time = NULL WHERE source = 'numerical'",
        *_renamed_keys("numerical", (("T", "T_fe"), ("B_a", "B_a_sig0"), ("mu_before", "mu_before_sig0"))),
        *_renamed_keys(None, (("dR_from_dF", "slip_from_dF"),)),
    ],
}


def migrate(database):
    """Migrate ``database`` in place to :data:`stickslip.provenance.database.SCHEMA_VERSION` (atomically).

    Parameters
    ----------
    database : str or pathlib.Path

    Returns
    -------
    tuple[int, int]
        The schema versions before and after (equal if there was nothing to do).

    Raises
    ------
    FileFormatError
        If there is no such database, or its schema is older than any migration (remake the study then).
    """
    database = Path(database)
    if not database.is_file():
        raise FileFormatError(f"{database}: no such database (run the workflow, or `stickslip db rebuild`)")
    with _locked(database), atomic_output(database) as tmp:
        shutil.copyfile(database, tmp)
        connection = sqlite3.connect(tmp)
        try:
            found = int(connection.execute("SELECT value FROM schema_info WHERE key = 'schema_version'").fetchone()[0])
            if found != SCHEMA_VERSION and found not in MIGRATIONS:
                raise FileFormatError(f"{database}: database schema version {found}: no migration to "
                                      f"{SCHEMA_VERSION} (from {', '.join(map(str, MIGRATIONS))} only): remake the "
                                      "study with `snakemake`")
            with connection:
                for name in VIEWS:
                    connection.execute(f"DROP VIEW IF EXISTS {name}")
                for version in range(found, SCHEMA_VERSION):
                    for statement in MIGRATIONS[version]:
                        connection.execute(statement)
                for name, select in VIEWS.items():
                    connection.execute(f"CREATE VIEW {name} AS {select}")
                connection.execute("UPDATE schema_info SET value = ? WHERE key = 'schema_version'",
                                   (str(SCHEMA_VERSION),))
        finally:
            connection.close()
    return found, SCHEMA_VERSION
