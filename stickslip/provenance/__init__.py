"""Provenance of the workflow's results: run records, the results database, queries.

- :mod:`.record`: the JSON record written beside every output;
- :mod:`.code`: the code hash of a plugin (what changed, reruns);
- :mod:`.database`: the SQLAlchemy models of the results database;
- :mod:`.ingest`: records and event tables into the database (idempotent, atomic);
- :mod:`.query`: DataFrames from the database (read-only), typed and with units;
- :mod:`.filters`: the queries' keyword filters (``stickslip db`` and :func:`stickslip.study` share them);
- :mod:`.migrate`: a database of an older schema brought to this one (``stickslip db migrate``).

The submodules are imported on demand, so that a job importing the record
helpers does not load SQLAlchemy.
"""
