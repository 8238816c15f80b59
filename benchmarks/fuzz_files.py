"""The long run of the fuzz harness of hostile files: 1 000 mutated files read through every reader.

Usage::

    python benchmarks/fuzz_files.py --mutations 1000 --seed 59

Draws ``--mutations`` mutated files (tests/hostile_files.py: 40 % fem runs, 20 % each event tables, recordings and
databases), reads each in batches of ``--batch`` files in one worker process under an address-space limit (what its
imports took plus 1.5 GiB), and prints the figures docs/benchmarks.md records: mutations, reads, refusals in one
line, reads identical to the intact file's, reads of well-formed files, the largest memory and time of one read,
and every failure (a traceback, a message of more lines or without the file's name, a MemoryError, a hang, numbers
not the intact file's). Exit status 1 if any read failed.
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from hostile_files import FILES, judge, make_cases, run_worker, summary, write_study  # noqa: E402

#: Share of each kind of file among the mutations.
SHARES = {"fem": 0.4, "events": 0.2, "timeseries": 0.2, "database": 0.2}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutations", type=int, default=1000, help="mutated files in all (default 1000)")
    parser.add_argument("--batch", type=int, default=100, help="files read by one worker process (default 100)")
    parser.add_argument("--seed", type=int, default=59, help="root seed of the mutations (default 59)")
    args = parser.parse_args()
    started = time.perf_counter()
    counts = {kind: round(args.mutations * share) for kind, share in SHARES.items()}
    tables, limit = [], 0
    with tempfile.TemporaryDirectory() as scratch:
        valid = write_study(Path(scratch) / "valid")
        batches = max(1, -(-args.mutations // args.batch))
        for batch in range(batches):
            share = {kind: len(range(batch, count, batches)) for kind, count in counts.items()}
            first = {kind: sum(len(range(b, count, batches)) for b in range(batch)) for kind, count in counts.items()}
            root = Path(scratch) / f"batch{batch}"
            cases = [case for kind in FILES
                     for case in make_cases(valid, root / kind, {kind: share[kind]}, args.seed, first[kind])]
            report = run_worker(cases, valid, root)
            tables.append(judge(report))
            limit = report["limit"]
            print(f"batch {batch + 1}/{batches}: {summary(tables[-1], limit, time.perf_counter() - started)}",
                  flush=True)
    results = pd.concat(tables, ignore_index=True)
    print(summary(results, limit, time.perf_counter() - started))
    print(results.groupby(["kind", "reader"])["verdict"].agg(lambda v: v.str.split(":").str[0].value_counts().to_dict())
          .to_string())
    print(results.groupby(["kind", "reader"])[["seconds", "peak_mib"]].max().round(2).to_string())
    failed = results[results["verdict"].str.startswith("FAILED")]
    for row in failed.itertuples():
        print(f"FAILED {row.kind} ({row.mutation}) {row.reader}: {row.verdict}")
    return 1 if len(failed) else 0


if __name__ == "__main__":
    sys.exit(main())
