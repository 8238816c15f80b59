"""How long a study takes on few cores under a scheduling policy: its jobs' measured times replayed.

    python benchmarks/schedule_replay.py SNAKEMAKE_LOG --configfile CONFIG [--cores 2] [--orders 40] [--cpu STUDY]

Reads the start and end of every job from the log of a Snakemake run (``snakemake --cores 2 ... > LOG 2>&1``), then
replays the jobs on ``--cores`` cores by list scheduling: whenever a core is free, the ready job (its run stored,
for an analysis; every run and analysis done, for a figure or the database) of the highest priority starts, ties in
a random order (``--orders`` of them; the order Snakemake took is replayed too). Two policies: no priorities, and
the workflow's for the study of ``CONFIG`` (:meth:`stickslip.study_plan.Study.run_priority` for a run, analyses
:data:`stickslip.study_plan.ANALYSIS_PRIORITY`). Prints the measured wall time, the jobs' summed time over
the cores (no schedule is shorter) and each policy's least, median and largest wall time [min]. The replay assumes
a job takes as long as it did in the log whatever runs beside it; a meshing job (seconds) is not waited for.
With ``--cpu STUDY`` (the study's results directory) a job takes its CPU time instead, from Snakemake's benchmark
files of the runs and analyses where the study has them (a job on an idle core of a single-threaded study takes its
CPU time: the wall time of a fresh clone on a quiet machine, where the logged times carry other users' load).
"""

import argparse
import datetime
import random
import re
from pathlib import Path

import yaml

from stickslip.study_plan import ANALYSIS_PRIORITY, Study

_STAMP = "%a %b %d %H:%M:%S %Y"
_GATHERING = ("figure", "database", "all")


def read_jobs(log):
    """The jobs of a Snakemake log: {jobid: {rule, solver, run_id, start, end [datetime]}} (finished jobs only)."""
    jobs, current, stamp, rule = {}, None, None, None
    for line in Path(log).read_text().splitlines():
        if line.startswith("[") and line.endswith("]"):
            try:
                stamp = datetime.datetime.strptime(line[1:-1], _STAMP)
            except ValueError:
                pass
        elif match := re.match(r"(?:local)?rule (\w+):", line):
            rule = match.group(1)
        elif match := re.match(r"\s+jobid: (\d+)", line):
            current = match.group(1)
            jobs[current] = {"rule": rule, "solver": None, "run_id": None, "start": stamp}
        elif (match := re.match(r"\s+wildcards: .*solver=([\w-]+), run_id=(\w+)", line)) and current:
            jobs[current]["solver"], jobs[current]["run_id"] = match.groups()
            if analysis := re.search(r"analysis=([\w@-]+)", line):
                jobs[current]["analysis"] = analysis.group(1)
        elif match := re.match(r"Finished jobid: (\d+)", line):
            jobs[match.group(1)]["end"] = stamp
    return {key: job for key, job in jobs.items() if "end" in job}


def replay(jobs, cores, priority, rank):
    """Wall time [s] of list scheduling ``jobs`` on ``cores`` cores (module docstring)."""
    runs = {job["run_id"]: key for key, job in jobs.items() if job["rule"] == "simulate"}
    work = {key for key, job in jobs.items() if job["rule"] in ("simulate", "events")}

    def waits_for(key):
        job = jobs[key]
        if job["rule"] == "events":
            return {runs[job["run_id"]]} if job["run_id"] in runs else set()
        if job["rule"].startswith(_GATHERING):
            return work
        return set()

    pending, running, done, now = set(jobs), [], {}, 0.0
    while pending or running:
        ready = sorted((key for key in pending if all(done.get(d, float("inf")) <= now for d in waits_for(key))),
                       key=lambda key: (-priority(key), rank[key]))
        while len(running) < cores and ready:
            key = ready.pop(0)
            pending.discard(key)
            running.append((now + jobs[key]["duration"], key))
        running.sort()
        now, key = running.pop(0)
        done[key] = now
    return now


def cpu_durations(jobs, study):
    """Replace the duration of every simulate and events job with its benchmark file's CPU time [s], where there is one
    (``STUDY/logs/benchmarks/{sim,events/<analysis>}/<solver>/<run_id>.tsv``); returns how many were replaced."""
    replaced = 0
    for job in jobs.values():
        if job["rule"] == "simulate":
            path = Path(study, "logs", "benchmarks", "sim", str(job["solver"]), f"{job['run_id']}.tsv")
        elif job["rule"] == "events":
            path = Path(study, "logs", "benchmarks", "events", str(job["analysis"]), str(job["solver"]),
                        f"{job['run_id']}.tsv")
        else:
            continue
        if path.exists():
            lines = path.read_text().splitlines()
            job["duration"] = float(lines[-1].split("\t")[lines[0].split("\t").index("cpu_time")])
            replaced += 1
    return replaced


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", help="the log of a Snakemake run (its standard output and error)")
    parser.add_argument("--configfile", required=True, help="the study's config (the one the log's run had)")
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--orders", type=int, default=40, help="random orders of the jobs of equal priority")
    parser.add_argument("--cpu", help="the study's results directory: jobs take their CPU time (module docstring)")
    args = parser.parse_args(argv)
    jobs = read_jobs(args.log)
    if not jobs:
        parser.error(f"log: no finished Snakemake job in {args.log}")
    study = Study(yaml.safe_load(Path(args.configfile).read_text()), [args.configfile])
    start = min(job["start"] for job in jobs.values())
    for job in jobs.values():
        job["duration"] = (job["end"] - job["start"]).total_seconds()
    if args.cpu:
        print(f"CPU times of {cpu_durations(jobs, args.cpu)} of the {len(jobs)} jobs from {args.cpu}")
    unknown = sorted({f"{job['solver']}/{job['run_id']}" for job in jobs.values() if job["rule"] == "simulate"}
                     - {f"{sim.solver}/{sim.run_id}" for sim in study.simulations})
    if unknown:
        parser.error(f"--configfile: runs {', '.join(unknown)} of the log are not in the study of {args.configfile} "
                     "(give the config the logged run had)")

    def workflow_priority(key):
        job = jobs[key]
        if job["rule"] == "events":
            return ANALYSIS_PRIORITY
        return study.run_priority(job["solver"], job["run_id"]) if job["rule"] == "simulate" else 0

    policies = {"no priorities": lambda key: 0, "the workflow's": workflow_priority}
    total = sum(job["duration"] for job in jobs.values())
    measured = (max(job["end"] for job in jobs.values()) - start).total_seconds()
    first = sum(workflow_priority(key) > 0 for key in jobs if jobs[key]["rule"] == "simulate")
    print(f"{len(jobs)} jobs, {first} runs first; measured {measured / 60:.1f} min; jobs' "
          f"time {total / 60:.1f} min, over {args.cores} cores {total / args.cores / 60:.1f} min")
    logged = {key: k for k, key in enumerate(sorted(jobs, key=lambda key: jobs[key]["start"]))}
    generator = random.Random(1)
    for name, priority in policies.items():
        times = [replay(jobs, args.cores, priority, logged) / 60]
        for _ in range(args.orders):
            order = generator.sample(sorted(jobs), len(jobs))
            times.append(replay(jobs, args.cores, priority, {key: k for k, key in enumerate(order)}) / 60)
        spread = sorted(times[1:]) or times
        print(f"- {name}: {times[0]:.1f} min in the logged order; over {args.orders} random orders "
              f"{spread[0]:.1f}, median {spread[len(spread) // 2]:.1f}, largest {spread[-1]:.1f} min")


if __name__ == "__main__":
    main()
