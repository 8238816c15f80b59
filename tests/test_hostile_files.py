"""Readers of hostile files: a mutated run, event table, recording or database is refused in one line naming it, or
read as the intact file, in bounded memory and time (the fuzz harness tests/hostile_files.py, a short seeded run).

Every mutation of tests/hostile_files.py (lying attributes, lying sizes, chunks never written, gzip bombs, flipped
bytes in data and metadata, cut files, damaged databases) is drawn for every kind of file; one worker process reads
every mutated file through every reader (``open_run``, ``stickslip increments``, the resume, ``db rebuild``, the
event tables' readers, ``db runs``, ``db sql``, ``db ingest``) under an address-space limit of what its imports took
plus 1.5 GiB; no read may end in a traceback, a message of more lines or without the file's name, a MemoryError,
more than a minute, or other numbers than the intact file's (:func:`hostile_files.judge`).
benchmarks/fuzz_files.py runs 1 000 mutations (docs/benchmarks.md).
"""

import time

import pytest
from hostile_files import CASE_SECONDS, FILES, judge, make_cases, run_worker, summary, write_study

#: Mutated files of each kind: the CI run's size (about a minute on CI's 2 cores, the fem kernels compiled).
CASES = {"fem": 20, "events": 10, "timeseries": 10, "database": 12}

#: Root seed of the mutations (each case draws from its own stream).
SEED = 20261128


@pytest.fixture(scope="module")
def valid(tmp_path_factory):
    return write_study(tmp_path_factory.mktemp("valid") / "study")


@pytest.mark.slow
def test_hostile_files_are_refused_in_one_line_or_read_as_the_intact_file(valid, tmp_path):
    started = time.perf_counter()
    cases = make_cases(valid, tmp_path / "cases", CASES, SEED)
    report = run_worker(cases, valid, tmp_path)
    results = judge(report)
    failed = results[results["verdict"].str.startswith("FAILED")]
    assert failed.empty, "\n".join(f"{row.kind} ({row.mutation}) {row.reader}: {row.verdict}"
                                   for row in failed.itertuples())
    print("fuzz:", summary(results, report["limit"], time.perf_counter() - started))
    verdicts = results["verdict"].value_counts()
    assert verdicts["refused"] > len(cases) and verdicts["identical"] > len(cases)  # hostile, and some harmless
    assert set(results["kind"]) == set(FILES) and results["seconds"].max() < CASE_SECONDS
    mutations = " ".join(results["mutation"])
    for kind in ("attribute", "resized", "never written", "gzip bomb", "flipped", "cut at", "zeroed"):
        assert kind in mutations, kind  # every kind of mutation was drawn
