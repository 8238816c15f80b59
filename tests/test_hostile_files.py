"""Readers of hostile files: mutated run, event and time-series files give one line naming the file, in bounded memory.

A seeded generator (:func:`mutate`) changes one thing of a small valid file at a time: an attribute (garbage
text, JSON of another shape, huge, negative or non-finite numbers, arrays, deletion), a dataset's shape
(resized to 0 or to 10^9 rows and more, replaced by another shape or type, deleted), or its bytes (a chunk's
data, an object header's metadata, the file cut short). Every reader of the package then reads the file: the
fem run's header, observables and event tables (:func:`stickslip.open_run`), ``stickslip increments``, the
event table's readers, the time series and its analysis, the database's ingest of the records. A reader
may succeed or refuse; a refusal must be one of the package's errors, one line, naming the file; anything
else (a traceback of another exception, a MemoryError) fails the test. The readers run in a child process
whose address space is limited (``RLIMIT_AS``: what it needs to import, plus 1.5 GiB), so that a reader that
trusted a size the file declares would die there.

Also here: the reproductions of the audit (a fem file declaring 10^9 increments, an event table declaring 10^9
rows, a gzip dataset that expands a thousand-fold, damaged HDF5 metadata, a garbage ``arithmetic`` attribute).
"""

import json
import math
import os
import resource
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest

from stickslip.h5io import CorruptFileError, FileFormatError, ReadBudgetError, read_array

#: Cases per file kind (three kinds): the fuzz test's size, within a minute on CI's 2 cores.
CASES = 60

#: Root seed of the mutations (each case draws from its own stream).
SEED = 20261128

#: Address space the readers' process may take beyond what it has after its imports [B].
HEADROOM = 3 * 2**29


def _fem_header(N, plates):
    from stickslip.mesh import MeshParams, build_stack_mesh

    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    params = {"N": N, "plates": plates, "seed": 0, "max_increments": 40}
    header = {"solver": "fem", "solver_version": "4", "params": params, "N": N, "plates": plates,
              "n_interfaces": plates - 1, "k_drive": 1e-3, "seed": 0, "eps0": 5e-5, "sig0": 1e-4, "gamma0": 8e-4,
              "c_s": 0.707, "h": math.pi, "dt": 0.05, "phi": 3.4e-8, "regime": "compliant"}
    return mesh, header


def write_fem_run(path, N=9, plates=2, increments=41):
    """A small valid ``fem-run`` file (synthetic numbers: a sawtooth of load and slips, every 8th event a slip)."""
    from stickslip.formats.fem_run import StoredState, append_increment, create_file
    from stickslip.h5io import open_file

    mesh, header = _fem_header(N, plates)
    ndof, nlayer, ni = mesh.coor.size, mesh.nlayer, N * (plates - 1)
    layers = [f"{name}_{layer}" for name in ("epsd", "sigd", "ubar", "fxdrive") for layer in range(nlayer)]
    interfaces = [f"{name}_a{a}" for name in ("S", "A") for a in range(1, plates)]
    columns = ["t", "gamma", "epsd", "sigd", *layers, *interfaces]
    response = (np.linspace(0, 1, ndof), np.full((ni, 4, 3), 1e-3), np.arange(nlayer, dtype=float), 0.0)
    rng = np.random.default_rng(1)
    with open_file(path, "w") as file:
        create_file(file, header, mesh, response, columns)
        stress = 0.0
        for i in range(increments):
            kick = i % 2 == 0
            slip = kick and i % 16 == 0 and i > 0
            stress = stress * 0.5 if slip else stress + (0.0 if kick else 0.05 + 0.01 * rng.random())
            row = {"increment": i, "kick": kick, "yield_element": False, "t": float(i), "gamma": 0.1 * i,
                   "epsd": 0.1 * i, "sigd": stress, **{name: rng.random() for name in layers},
                   **{name: (N if slip else int(kick)) for name in interfaces}}
            append_increment(file, StoredState(rng.random(ndof), np.arange(nlayer, dtype=float), 0.0, float(i)), row)
    return path


def write_timeseries(path, frames=2000):
    """A small valid ``timeseries`` file (gzip-compressed datasets), a stack of 3 slabs driven at 2."""
    from stickslip.experiment.timeseries import ExperimentRecord
    from stickslip.experiment.timeseries import write_timeseries as write

    t = np.linspace(0.0, 200.0, frames)
    x = np.cumsum(np.where(np.arange(frames)[:, None] % 250 == 0, 0.05, 0.0) * np.ones((1, 3)), axis=0)
    record = ExperimentRecord(t_F=t, F=1.0 + 0.1 * np.sin(t), t_x=t, x=x + np.arange(3) * 10.0, n=2, n_slabs=3,
                              protocol="stack", a=0, normal_force=10.0, k_spring=1.0, h=5.0, H=100.0, V=0.01)
    write(path, record)
    return path


def write_study(directory):
    """A fem run, its ``numerical-events`` table and a time series, with provenance records as the workflow writes.

    Returns
    -------
    dict[str, pathlib.Path]
        ``fem``, ``events``, ``timeseries`` and ``records`` (the directory of the records).
    """
    from stickslip import registry
    from stickslip.lineage import Artifact
    from stickslip.provenance.record import recording

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    fem, events, series = directory / "run.h5", directory / "events.h5", directory / "series.h5"
    identity = {"plugin_version": "4", "code_hash": "0" * 16, "params": {}}
    with recording(directory / "run.provenance.json", [("output", fem, "fem-run")], run_id="a" * 16, kind="solver",
                   plugin="fem", **identity):
        write_fem_run(fem)
    analysis = registry.get("analysis", "numerical-events")
    simulation = Artifact(fem, "a" * 16, "fem", "fem-run")
    with recording(directory / "events.provenance.json", [("output", events, "event-table")], run_id="b" * 16,
                   kind="analysis", plugin=analysis.name, inputs=[("simulation", simulation)], **identity):
        analysis.run(analysis.params(), simulation, events)
    with recording(directory / "series.provenance.json", [("output", series, "timeseries")], run_id="c" * 16,
                   kind="solver", plugin="lever", **identity):
        write_timeseries(series)
    return {"fem": fem, "events": events, "timeseries": series}


# ------------------------------------------------------------------------------------------------ mutations

#: Values an attribute is set to.
HOSTILE_VALUES = ("", "not json", "[1]", "{}", "null", "[]", '{"a": [1, 2', -1, 0, 10**9, 2**62, -2**62, 1.5,
                  math.nan, math.inf, -math.inf, True, "1e9", b"\xff\xfe", np.arange(3), np.zeros((2, 2)))

#: Rows a growable dataset is resized to.
HOSTILE_ROWS = (0, 1, 10**6, 10**9, 2**40)


def _objects(file):
    found = [file]
    file.visititems(lambda name, item: found.append(item))
    return found


def _pick(rng, items):
    return items[int(rng.integers(len(items)))]


def mutate(path, rng):
    """Change one thing of the HDF5 file ``path`` in place, drawn from ``rng``; return what was changed."""
    kind = _pick(rng, ("attribute", "attribute", "shape", "shape", "lie", "replace", "delete", "chunk", "metadata",
                       "truncate"))
    if kind == "truncate":
        size = path.stat().st_size
        keep = int(size * rng.uniform(0.05, 0.99))
        with open(path, "r+b") as handle:
            handle.truncate(keep)
        return f"cut at {keep} of {size} bytes"
    with h5py.File(path, "r+") as file:
        objects = _objects(file)
        datasets = [item for item in objects if isinstance(item, h5py.Dataset)]
        if kind == "attribute":
            item = _pick(rng, [item for item in objects if len(item.attrs)] or objects)
            names = list(item.attrs) or ["format"]
            name = _pick(rng, names)
            if rng.random() < 0.15:
                del item.attrs[name]
                return f"attribute {item.name}:{name} deleted"
            value = _pick(rng, HOSTILE_VALUES)
            item.attrs[name] = value
            return f"attribute {item.name}:{name} = {value!r}"
        if kind == "lie":  # every growable dataset, and the count of stored rows, say 10^9 rows or more
            rows = _pick(rng, HOSTILE_ROWS[3:])
            for dataset in datasets:
                if dataset.maxshape and dataset.maxshape[0] is None:
                    dataset.resize(rows, axis=0)
            if "nstored" in file.attrs:
                file.attrs["nstored"] = rows
            return f"every growable dataset resized to {rows} rows"
        if kind in ("shape", "replace"):
            growable = [d for d in datasets if d.maxshape and d.maxshape[0] is None]
            if kind == "shape" and growable:
                dataset = _pick(rng, growable)
                rows = _pick(rng, HOSTILE_ROWS)
                dataset.resize(rows, axis=0)
                if rng.random() < 0.5 and "nstored" in file.attrs:
                    file.attrs["nstored"] = rows
                return f"{dataset.name} resized to {rows} rows"
            dataset = _pick(rng, datasets)
            name, parent = dataset.name, dataset.parent
            del parent[dataset.name.rsplit("/", 1)[1]]
            shape = _pick(rng, ((), (0,), (3, 5), (7,), (2, 2, 2)))
            dtype = _pick(rng, ("f8", "i8", "S4", "text"))
            if dtype == "text":
                parent.create_dataset(name.rsplit("/", 1)[1], data=np.full(shape, "x", dtype=object),
                                      dtype=h5py.string_dtype())
            else:
                parent.create_dataset(name.rsplit("/", 1)[1], data=np.zeros(shape, dtype=dtype))
            return f"{name} replaced by {shape} {dtype}"
        if kind == "delete":
            item = _pick(rng, objects[1:])
            name = item.name
            del file[name]
            return f"{name} deleted"
        if kind == "chunk":
            dataset = _pick(rng, [d for d in datasets if d.id.get_storage_size()])
            offset = (dataset.id.get_chunk_info(0).byte_offset if dataset.chunks else dataset.id.get_offset())
            size = dataset.id.get_storage_size() if not dataset.chunks else dataset.id.get_chunk_info(0).size
            where = offset + int(rng.integers(size))
            address = where
        else:
            item = _pick(rng, objects)
            address = h5py.h5o.get_info(item.id).addr + int(rng.integers(4, 40))
            where = address
    with open(path, "r+b") as handle:
        handle.seek(where)
        byte = handle.read(1)
        handle.seek(where)
        handle.write(bytes([(byte[0] if byte else 0) ^ 0xFF]))
    return f"{kind}: byte {address} flipped"


# ------------------------------------------------------------------------------------------------ the readers

READERS = textwrap.dedent("""
    import io, json, os, resource, shutil, sys, time, traceback
    from contextlib import redirect_stderr, redirect_stdout
    from pathlib import Path

    import stickslip
    from stickslip import registry
    from stickslip.cli import USER_ERRORS, main
    from stickslip.formats import describe
    from stickslip.formats.event_table import read_periodicity, read_slip_events
    from stickslip.provenance.ingest import ingest

    registry.available("solver"), registry.available("analysis")  # import every plugin before the limit
    limit = int(sys.argv[2])
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    def fem(path, scratch):
        run = stickslip.open_run(path)
        run.increments, run.events()
        yield "open_run"
        describe("fem-run", path)
        yield "describe"

    def events(path, scratch):
        read_slip_events(path), read_periodicity(path)
        yield "read"

    def timeseries(path, scratch):
        run = stickslip.open_run(path)
        run.events()
        yield "open_run"
        describe("timeseries", path)
        yield "describe"

    def cli(path, scratch):
        err = io.StringIO()
        with redirect_stderr(err), redirect_stdout(io.StringIO()):
            status = main(["increments", str(path), "-o", str(scratch / "increments.csv")])
        lines = err.getvalue().strip().splitlines()
        if status not in (0, 2) or (status == 2 and (len(lines) != 1 or path.name not in lines[0])):
            raise AssertionError(f"stickslip increments: exit {status}, stderr {lines!r}")
        yield "stickslip increments"

    def database(path, scratch):
        ingest(scratch / "stickslip.sqlite", sorted(scratch.glob("*.provenance.json")), rebuild=True)
        yield "ingest"

    READ = {"fem": (fem, cli, database), "events": (events, database), "timeseries": (timeseries, database)}

    results = []
    for case in json.loads(Path(sys.argv[1]).read_text()):
        path = Path(case["path"])
        for reader in READ[case["kind"]]:
            name = reader.__name__
            try:
                with redirect_stderr(io.StringIO()):
                    for name in reader(path, path.parent):
                        pass
                outcome, message = "read", ""
            except USER_ERRORS as error:
                message = str(error)
                one_line = "\\n" not in message and path.name in message
                outcome = "refused" if one_line else "FAILED"
            except Exception as error:
                outcome, message = "FAILED", "".join(traceback.format_exception(error))[-1500:]
            results.append({**case, "reader": name, "outcome": outcome, "message": message})
    usage = resource.getrusage(resource.RUSAGE_SELF)
    print(json.dumps({"results": results, "peak_rss_mib": usage.ru_maxrss / 1024}))
""")


def _address_space():
    """Address space of a Python that imported what the readers import [B]."""
    probe = ("import stickslip, stickslip.runs, stickslip.cli, stickslip.provenance.ingest; from stickslip import "
             "registry; registry.available('solver'); registry.available('analysis'); "
             "print(open('/proc/self/status').read().split('VmSize:')[1].split()[0])")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return int(done.stdout.strip()) * 1024


@pytest.fixture(scope="module")
def valid(tmp_path_factory):
    return write_study(tmp_path_factory.mktemp("valid"))


def test_hostile_files_get_one_line_naming_them_in_bounded_memory(valid, tmp_path):
    started = time.perf_counter()
    cases = []
    for k, kind in enumerate(("fem", "events", "timeseries")):
        for case in range(CASES):
            directory = tmp_path / f"{kind}-{case}"
            shutil.copytree(valid["fem"].parent, directory)
            path = directory / valid[kind].name
            rng = np.random.default_rng([SEED, k, case])
            cases.append({"kind": kind, "path": str(path), "mutation": mutate(path, rng)})
    listing = tmp_path / "cases.json"
    listing.write_text(json.dumps(cases))
    limit = _address_space() + HEADROOM
    done = subprocess.run([sys.executable, "-c", READERS, str(listing), str(limit)], capture_output=True, text=True,
                          timeout=600, env={**os.environ, "NUMBA_NUM_THREADS": "1"})
    assert done.returncode == 0, done.stderr[-4000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    results = pd.DataFrame(report["results"])
    failed = results[results["outcome"] == "FAILED"]
    assert failed.empty, "\n".join(f"{row.kind} {row.mutation} {row.reader}: {row.message}"
                                   for row in failed.itertuples())
    counts = results.groupby(["kind", "outcome"]).size().to_dict()
    print(f"fuzz: {len(cases)} files, {len(results)} reads {counts}, peak RSS {report['peak_rss_mib']:.0f} MiB "
          f"under an address-space limit of {limit / 2**30:.2f} GiB, {time.perf_counter() - started:.1f} s")
    assert (results["outcome"] == "refused").sum() > len(cases) / 3  # the mutations are hostile, not harmless
