"""Provenance records and code hashes."""

import hashlib
import json
import shutil
from pathlib import Path

import pytest

from stickslip import registry
from stickslip.h5io import FileFormatError
from stickslip.plugin_params import parse_params
from stickslip.provenance import code
from stickslip.hashing import sha256_file
from stickslip.provenance.record import (REQUIRED_FIELDS, read_record, record_path, recording,
                                         write_record)


def test_code_hash_follows_package_imports():
    sources = {p.relative_to(code.ROOT).as_posix() for p in code.module_sources("stickslip.cli.simulate")}
    # direct (registry), through another package module (registry -> plugin_params), and the package inits
    assert {"cli/simulate.py", "registry.py", "plugin_params.py", "numba_options.py", "__init__.py",
            "cli/__init__.py"} <= sources
    assert "figures/style.py" not in sources
    assert len(code.code_hash("stickslip.h5io")) == 16


def test_a_module_of_another_package_is_followed_into_this_one(toy_plugins):
    sources = code.module_sources("stickslip_toy")  # a third-party plugin: one file importing the package
    assert {"stickslip_toy", "stickslip.registry", "stickslip.formats.analysis_file"} <= set(sources.values())
    assert len(code.code_hash("stickslip_toy")) == 16


def test_the_public_api_is_in_no_plugins_code_hash(tmp_path, monkeypatch):
    # stickslip/__init__.py binds the API (stickslip.api, runs, results, ...): its imports are not the plugins'
    sources = {p.relative_to(code.ROOT).as_posix() for p in code.module_sources("stickslip.solvers.fem")}
    assert "__init__.py" in sources and "fem/run.py" in sources
    assert not {"api.py", "runs.py", "study_results.py", "events/extraction.py", "provenance/query.py"} & sources
    package = tmp_path / "stickslip"
    shutil.copytree(code.ROOT, package, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(code, "ROOT", package)
    code.module_sources.cache_clear()
    try:
        before = {name: code.code_hash(name) for name in ("stickslip.solvers.fem", "stickslip.events.plugin")}
        extraction = package / "events" / "extraction.py"
        extraction.write_text(extraction.read_text() + "\n# edited\n")
        assert code.code_hash("stickslip.solvers.fem") == before["stickslip.solvers.fem"]
        assert code.code_hash("stickslip.events.plugin") != before["stickslip.events.plugin"]
    finally:
        code.module_sources.cache_clear()


def test_code_hash_changes_with_the_sources(tmp_path, monkeypatch):
    package = tmp_path / "stickslip"
    shutil.copytree(code.ROOT, package, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(code, "ROOT", package)
    code.module_sources.cache_clear()
    try:
        before = code.code_hash("stickslip.cli.simulate")
        unrelated = code.code_hash("stickslip.figures.style")
        params = package / "plugin_params.py"
        params.write_text(params.read_text() + "\n# edited\n")
        assert code.code_hash("stickslip.cli.simulate") != before  # imported through registry
        assert code.code_hash("stickslip.figures.style") == unrelated
    finally:
        code.module_sources.cache_clear()


@pytest.fixture
def package(tmp_path, monkeypatch):
    """A copy of the package, whose sources the code hashes read (``code.ROOT``)."""
    package = tmp_path / "stickslip"
    shutil.copytree(code.ROOT, package, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(code, "ROOT", package)
    code.module_sources.cache_clear()
    yield package
    code.module_sources.cache_clear()


def _job_hashes():
    """The code hash of a job of each kind: fem runs by law and backend, other plugins, the database."""
    fem = registry.get("solver", "fem")
    hashes = {f"fem {law} {backend}": code.plugin_code_hash(fem, parse_params(fem.params, {
        "interface_law": law, "backend": backend})) for law in ("cusp", "smooth") for backend in ("structured", "cuda")}
    for kind, name in (("solver", "lever"), ("analysis", "numerical-events"), ("analysis", "experiment-events"),
                       ("figure", "fig3"), ("figure", "figS-sequences")):
        plugin = registry.get(kind, name)
        hashes[name] = code.plugin_code_hash(plugin, plugin.params())
    hashes["database"] = code.code_hash("stickslip.provenance.ingest")
    return hashes


def _append(path):
    """A change inside a module: a comment at its end."""
    path.write_text(path.read_text() + "# a change\n")


def _edit(path, old, new):
    text = path.read_text()
    assert text.count(old) == 1, (path, old)
    path.write_text(text.replace(old, new))


def test_a_new_law_backend_plugin_or_vocabulary_entry_changes_no_jobs_code_hash(package):
    before = _job_hashes()
    assert len(set(before.values())) == len(before)
    (package / "fem" / "laws" / "softening.py").write_text(
        '"""A law no run chooses."""\n\nfrom .generic import register_law\nfrom .cusp import Cusp\n')
    (package / "fem" / "backends" / "counting.py").write_text(
        '"""A backend no run chooses."""\n\nfrom .cpu.structured import StructuredBackend\n')
    for folder in ("solvers", "events", "figures"):  # a new solver, analysis and figure (the toy plugin's module)
        shutil.copy(Path(__file__).parent / "toy_plugin" / "stickslip_toy.py", package / folder / "toy.py")
    _edit(package / "vocabulary.py", '    "kind": _q(',
          '    "new_quantity": _q("float64", "1", "a quantity no code names"),\n    "kind": _q(')
    assert _job_hashes() == before


def test_a_change_in_a_law_or_backend_changes_the_hash_of_the_runs_that_choose_it_only(package):
    before = _job_hashes()
    _append(package / "fem" / "laws" / "cusp.py")
    after = _job_hashes()
    assert {name for name in before if after[name] != before[name]} == {"fem cusp structured", "fem cusp cuda"}
    _append(package / "fem" / "backends" / "cuda" / "kernels.py")
    again = _job_hashes()
    assert {name for name in before if again[name] != after[name]} == {"fem cusp cuda", "fem smooth cuda"}


def test_a_vocabulary_entry_counts_in_the_jobs_whose_code_names_it(package):
    before = _job_hashes()
    # "R_slow": a column of the experimental analysis, which fig3 reads; no other job here names it
    _edit(package / "vocabulary.py", '"fraction of the sliding made by slow slip',
          '"share of the sliding made by slow slip')
    assert {name for name, value in _job_hashes().items() if value != before[name]} == {"experiment-events", "fig3"}
    _edit(package / "vocabulary.py", '"interface (slab) a, 1 = lowest"', '"interface (slab) a, from 1 at the bottom"')
    assert {"numerical-events", "experiment-events", "database"} <= {
        name for name, value in _job_hashes().items() if value != before[name]}


def test_record_fields_hashes_and_atomic_write(tmp_path):
    source = tmp_path / "in.txt"
    source.write_text("input")
    output = tmp_path / "out.h5"
    record_file = record_path(output)
    assert record_file.name == "out.provenance.json"
    with recording(record_file, [("output", output)], run_id="0" * 16, kind="solver", plugin="p",
                   plugin_version="1", code_hash="c", params={"seed": 7, "x": 1.5}, threads=2,
                   inputs=[("mesh", source)]):
        output.write_bytes(b"result")
    record = read_record(record_file)
    assert set(REQUIRED_FIELDS) <= set(record)
    assert record["seed"] == 7 and record["threads"] == 2 and record["params"] == {"seed": 7, "x": 1.5}
    assert record["outputs"][0]["sha256"] == sha256_file(output)
    assert record["inputs"][0]["sha256"] == hashlib.sha256(b"input").hexdigest()
    assert record["outputs"][0]["bytes"] == 6
    assert record["wall_time_s"] >= 0 and record["peak_memory_mib"] > 10
    assert record["versions"]["numpy"] and record["versions"]["python"]
    # the arithmetic: what decides the bits (checked at a resume) and what the host chose (recorded only)
    assert record["arithmetic"]["decisive"]["numpy"] == record["versions"]["numpy"]
    assert record["arithmetic"]["host"]["cpu_model"] and record["arithmetic"]["host"]["blas"][0]["kernel"]
    assert record["versions"]["scipy"] and record["versions"]["llvmlite"] and record["versions"]["qdldl"]
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary left


def test_a_failed_job_writes_no_record(tmp_path):
    output = tmp_path / "out.h5"
    with pytest.raises(RuntimeError):
        with recording(record_path(output), [("output", output)], run_id="0" * 16, kind="solver", plugin="p",
                       plugin_version="1", code_hash="c", params={}):
            raise RuntimeError("solver failed")
    assert not record_path(output).exists()


def test_bad_records_are_reported_by_name(tmp_path):
    broken = tmp_path / "a.provenance.json"
    broken.write_text("{not json")
    with pytest.raises(FileFormatError, match="a.provenance.json: not a valid provenance record"):
        read_record(broken)
    write_record(broken, {"schema_version": 1, "run_id": "x"})
    with pytest.raises(FileFormatError, match="lacks kind, plugin"):
        read_record(broken)
    with pytest.raises(FileFormatError, match="no such provenance record"):
        read_record(tmp_path / "missing.provenance.json")
    assert json.loads(broken.read_text())["run_id"] == "x"
