"""benchmarks/schedule_replay.py: a Snakemake log's jobs replayed on few cores, with and without priorities."""

import importlib.util

from conftest import REPO

SPEC = importlib.util.spec_from_file_location("schedule_replay", REPO / "benchmarks" / "schedule_replay.py")
schedule_replay = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(schedule_replay)

#: (jobid, rule, wildcards, start, end [s after 11:00]): two athermal runs, a thermal run and its analysis, the database
JOBS = [("1", "simulate", "solver=fem, run_id=aaaa", 0, 60), ("2", "simulate", "solver=fem, run_id=bbbb", 0, 60),
        ("3", "simulate", "solver=fem, run_id=tttt", 60, 120),
        ("4", "events", "analysis=thermal-events, solver=fem, run_id=tttt", 120, 220), ("5", "database", "", 220, 221)]


def snakemake_log(jobs):
    """A Snakemake log of ``jobs``: a stamped block where each starts, a stamped line where each ends (ends first)."""
    def stamp(seconds):
        return f"[Sun Nov 29 11:{seconds // 60:02d}:{seconds % 60:02d} 2026]"

    lines = []
    for jobid, rule, wildcards, start, end in jobs:
        block = f"localrule {rule}:\n    jobid: {jobid}\n" + (f"    wildcards: {wildcards}\n" if wildcards else "")
        lines += [(start, 1, f"{stamp(start)}\n{block}"),
                  (end, 0, f"{stamp(end)}\nFinished jobid: {jobid} (Rule: {rule})\n")]
    return "".join(text for *_, text in sorted(lines))


def test_the_replay_reads_the_log_and_puts_the_long_chain_first(tmp_path):
    log = tmp_path / "snakemake.log"
    log.write_text(snakemake_log(JOBS))
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


def test_the_jobs_take_their_cpu_time_where_the_study_has_benchmark_files(tmp_path):
    log = tmp_path / "snakemake.log"
    log.write_text(snakemake_log(JOBS))
    jobs = schedule_replay.read_jobs(log)
    for job in jobs.values():
        job["duration"] = (job["end"] - job["start"]).total_seconds()
    header = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
    for path, cpu in (("sim/fem/tttt.tsv", 30.5), ("events/thermal-events/fem/tttt.tsv", 12.25)):
        target = tmp_path / "study" / "logs" / "benchmarks" / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(header + f"99.0\t0:01:39\t1\t1\t1\t1\t0\t0\t50\t{cpu}\n")
    assert schedule_replay.cpu_durations(jobs, tmp_path / "study") == 2
    assert [job["duration"] for job in jobs.values()] == [60.0, 60.0, 30.5, 12.25, 1.0]
    assert jobs["4"]["analysis"] == "thermal-events"
