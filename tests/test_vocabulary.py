"""One vocabulary (stickslip/vocabulary.py): every table the package writes or returns, the database schema and
docs/database.md use its names, dtypes and units."""

import re
from pathlib import Path

import numpy as np
import pandas as pd
from sqlalchemy import Boolean, Float, Integer, String, Text

import stickslip
from stickslip import vocabulary
from stickslip.events import extraction, thermal
from stickslip.events.plugin import event_tables
from stickslip.formats import event_table
from stickslip.provenance.database import SCHEMA_VERSION, VIEWS, Base
from test_events_extraction import EVENTS, N, history

DOCS = Path(__file__).resolve().parents[1] / "docs" / "database.md"

#: The vocabulary's dtype of each SQL type (datetimes are stored as ISO 8601 text).
SQL = {Boolean: ("bool",), Integer: ("int64",), Float: ("float64",), String: ("str", "datetime"),
       Text: ("str",)}


def assert_speaks_the_vocabulary(name, frame):
    """Every column of ``frame`` is a vocabulary name in its dtype, and ``attrs["units"]`` gives its unit."""
    for column in frame.columns:
        quantity = vocabulary.quantity(column)
        assert quantity is not None, f"{name}: column {column!r} is not in the vocabulary"
        assert vocabulary.dtype_matches(frame[column].dtype, quantity.dtype), \
            f"{name}: column {column!r} is {frame[column].dtype}, the vocabulary says {quantity.dtype}"
    assert frame.attrs.get("units") == vocabulary.units(frame.columns), f"{name}: attrs['units']"


def test_a_name_is_one_quantity():
    assert not set(vocabulary.QUANTITIES) & {p.replace("{}", "1") for p in vocabulary.PATTERNS}
    for name, quantity in vocabulary.QUANTITIES.items():
        assert quantity.dtype in ("bool", "int64", "float64", "str", "datetime", "object"), name
    # SQLite's column names ignore case: no two names of the database may differ only in case
    for table in Base.metadata.tables.values():
        names = [column.name.lower() for column in table.columns]
        assert len(set(names)) == len(names), table.name
    assert vocabulary.unit("dmu") == "1" and vocabulary.unit("dmu_sig0") == "sig0"
    assert vocabulary.unit("time") == "s" and vocabulary.unit("t") == "time" and vocabulary.unit("sigd_3") == "sig0"


def test_every_database_column_is_in_the_vocabulary_with_its_type_and_doc():
    for table in Base.metadata.tables.values():
        for column in table.columns:
            quantity = vocabulary.quantity(column.name)
            assert quantity is not None, f"{table.name}.{column.name}"
            assert quantity.dtype in next(dtypes for kind, dtypes in SQL.items() if isinstance(column.type, kind)), \
                f"{table.name}.{column.name}: {column.type} against {quantity.dtype}"
            assert column.doc.startswith(quantity.doc), f"{table.name}.{column.name}"
            if quantity.unit:
                assert column.doc.endswith(f"[{quantity.unit}]"), f"{table.name}.{column.name}"
    # the event-table format's standard columns are the database's, in the vocabulary's dtypes
    columns = Base.metadata.tables["slip_events"].columns
    for name, (dtype, doc) in {**event_table.COLUMNS, **event_table.PERIODICITY_COLUMNS}.items():
        assert (dtype, doc) == (vocabulary.QUANTITIES[name].dtype, vocabulary.QUANTITIES[name].doc)
    assert set(event_table.COLUMNS) <= {c.name for c in columns}
    assert set(event_table.PERIODICITY_COLUMNS) <= {c.name for c in Base.metadata.tables["run_periodicity"].columns}


def _documented(text):
    """docs/database.md's tables: {table: {column: its row's text}} (a row may document several columns)."""
    tables, current = {}, None
    for line in text.splitlines():
        heading = re.match(r"^### (?:View )?`(\w+)`", line)
        if heading:
            current = tables.setdefault(heading.group(1), {})
            continue
        if current is not None and line.startswith("| `"):
            cell, meaning = line.split("|")[1:3]
            for name in re.findall(r"`(\w+)`", cell):
                current[name] = meaning
        elif line.startswith("## "):
            current = None
    return tables


def test_docs_database_md_documents_every_column_with_its_unit_and_the_schema_version():
    text = DOCS.read_text(encoding="utf-8")
    documented = _documented(text)
    for table in Base.metadata.tables.values():
        columns = {column.name for column in table.columns}
        assert set(documented[table.name]) == columns, table.name
        for name, meaning in documented[table.name].items():
            unit = vocabulary.unit(name)
            if unit not in ("", "1"):
                assert f"[{unit}]" in meaning, f"docs/database.md: {table.name}.{name} does not say its unit [{unit}]"
    assert f"currently {SCHEMA_VERSION};" in text
    for view in VIEWS:
        assert f"### View `{view}`" in text


def test_every_table_of_a_fem_run_speaks_the_vocabulary(tmp_path):
    run = stickslip.simulate("fem", tmp_path / "run.h5", N=9, plates=2, k_drive=1.472e-2, seed=2, max_increments=80)
    assert_speaks_the_vocabulary("increments", run.increments)
    tables = run.events()
    for name, table in tables.items():
        assert_speaks_the_vocabulary(name, table)
    assert tables["slips"]["multi"].dtype == bool and "single" not in tables["slips"]
    kick = int(tables["slips"]["increment"].iloc[0])
    assert_speaks_the_vocabulary("failures", run.failures(kick))
    with stickslip.open_run(run.path) as again:
        assert again.increments.equals(run.increments)
    assert "increments" not in again.__dict__  # freed at the end of the block; it reads the file again if asked


def test_every_table_of_a_virtual_experiment_speaks_the_vocabulary(tmp_path):
    run = stickslip.simulate("lever", tmp_path / "lab.h5", n=3, seed=1, duration=2000.0)
    for name, table in run.events().items():
        assert_speaks_the_vocabulary(name, table)
    assert_speaks_the_vocabulary("truth", run.truth())
    assert_speaks_the_vocabulary("truth interfaces", run.truth("interfaces"))
    assert_speaks_the_vocabulary("aging bins", run.aging().bins)
    slips = run.events()["slips"]
    assert slips["multi"].dtype == bool and list(slips.columns[:3]) == ["event", "time", "interface"]
    assert slips.attrs["units"]["dmu"] == "1" and slips.attrs["units"]["slip"] == "mm"


def test_the_thermal_slip_table_names_the_model_units_apart():
    increments = history(N, EVENTS)
    table = thermal.slip_table(increments, extraction.classify_increments(increments, N), N, T0=1.0)
    assert_speaks_the_vocabulary("thermal slip_events", vocabulary.with_units(table))
    assert {"dmu_sig0", "t", "T_fe", "B_a_sig0", "mu_before_sig0"} <= set(table.columns)
    assert not {"dmu", "time", "T", "B_a", "mu_before"} & set(table.columns)  # the lab's names, the lab's units
    numerical = event_tables(increments, N)["slip_events"]
    assert "dmu_sig0" in numerical and "dmu" not in numerical


def test_the_plugin_tables_speak_the_vocabulary():
    assert_speaks_the_vocabulary("plugins", stickslip.plugins())
    assert_speaks_the_vocabulary("formats", stickslip.plugins("format"))
    assert_speaks_the_vocabulary("params", stickslip.params("fem"))
    # a plugin parameter that is a database column has the column's unit
    for name in ("k_drive", "temperature", "attempt_rate", "drive_rate", "junction_strengthening",
                 "junction_glass_temperature", "junction_attempt_rate"):
        assert stickslip.params("fem").loc[name, "unit"] == vocabulary.unit(name), name


def test_typed_keeps_what_does_not_fit():
    frame = pd.DataFrame({"multi": [0.25, 0.5], "n": [1.0, np.nan], "git_dirty": [1.0, np.nan],
                          "started_at": ["2026-11-28T18:36:24.162+00:00", None], "interface": [1, 2]})
    typed = vocabulary.typed(frame)
    assert typed["multi"].dtype == float  # an average named multi stays an average
    assert str(typed["n"].dtype) == "Int64" and str(typed["git_dirty"].dtype) == "boolean"
    assert isinstance(typed["started_at"].dtype, pd.DatetimeTZDtype) and typed["interface"].dtype == np.int64


def test_expand_json_names_a_taken_key_after_its_column():
    frame = pd.DataFrame({"n": [1, 2], "extra": ['{"n": 3, "T": 1.5}', None]})
    expanded = vocabulary.expand_json(frame, "extra")
    assert list(expanded.columns) == ["n", "extra.n", "T"] and expanded["T"].isna().iloc[1]
