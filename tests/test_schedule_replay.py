"""benchmarks/schedule_replay.py: a Snakemake log's jobs replayed on few cores, with and without priorities."""

import importlib.util

from conftest import REPO

SPEC = importlib.util.spec_from_file_location("schedule_replay", REPO / "benchmarks" / "schedule_replay.py")
schedule_replay = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(schedule_replay)

LOG = """\
[Sun Nov 29 11:00:00 2026]
localrule simulate:
    jobid: 1
    wildcards: solver=fem, run_id=aaaa
[Sun Nov 29 11:00:00 2026]
localrule simulate:
    jobid: 2
    wildcards: solver=fem, run_id=bbbb
[Sun Nov 29 11:01:00 2026]
Finished jobid: 1 (Rule: simulate)
[Sun Nov 29 11:01:00 2026]
Finished jobid: 2 (Rule: simulate)
[Sun Nov 29 11:01:00 2026]
localrule simulate:
    jobid: 3
    wildcards: solver=fem, run_id=tttt
[Sun Nov 29 11:02:00 2026]
Finished jobid: 3 (Rule: simulate)
[Sun Nov 29 11:02:00 2026]
localrule events:
    jobid: 4
    wildcards: analysis=thermal-events, solver=fem, run_id=tttt
[Sun Nov 29 11:03:40 2026]
Finished jobid: 4 (Rule: events)
[Sun Nov 29 11:03:40 2026]
localrule database:
    jobid: 5
[Sun Nov 29 11:03:41 2026]
Finished jobid: 5 (Rule: database)
"""


def test_the_replay_reads_the_log_and_puts_the_long_chain_first(tmp_path):
    log = tmp_path / "snakemake.log"
    log.write_text(LOG)
    jobs = schedule_replay.read_jobs(log)
    assert [(job["rule"], job["run_id"]) for job in jobs.values()] == [
        ("simulate", "aaaa"), ("simulate", "bbbb"), ("simulate", "tttt"), ("events", "tttt"), ("database", None)]
    for job in jobs.values():
        job["duration"] = (job["end"] - job["start"]).total_seconds()
    logged = {key: k for k, key in enumerate(jobs)}
    # in the logged order the thermal run waits for a core: 60 + 60 + 100 + 1 s; first, its analysis overlaps a run
    assert schedule_replay.replay(jobs, 2, lambda key: 0, logged) == 221.0
    first = {"3": 1, "4": 2}
    assert schedule_replay.replay(jobs, 2, lambda key: first.get(key, 0), logged) == 161.0
    assert schedule_replay.replay(jobs, 1, lambda key: 0, logged) == 281.0  # one core: the jobs' sum
