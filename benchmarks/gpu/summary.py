"""The table of a GPU check (benchmarks/gpu/run.sh): reads OUTDIR/results.jsonl, prints the summary."""

import json
import sys
from pathlib import Path


def main(out):
    records = [json.loads(line) for line in (Path(out) / "results.jsonl").read_text().splitlines() if line.strip()]
    by = {}
    for record in records:
        if "error" not in record:
            by.setdefault(record.get("part"), []).append(record)
    for record in by.get("env", []):
        print(f"GPU {record['gpu']} (cc {record['compute_capability']}, {record['sm_count']} SMs; {record['nvidia_smi']}),"
              f" CPU {record['cpu']} x {record['cpus']}, Python {record['python']}, numba {record['numba']}, "
              f"numba-cuda {record['numba_cuda']}, numpy {record['numpy']}")
    cpu = {r["plates"]: r for r in by.get("cpu-step", [])}
    print("\nspeed, N = 1458 (us per step of the batch; per realisation; element-steps/s; ratio to one CPU core)")
    for r in by.get("speed", []):
        base = cpu.get(r["plates"])
        ratio = f"{r['element_steps_per_s'] / base['element_steps_per_s']:.0f}x" if base else "(no CPU baseline)"
        print(f"  plates {r['plates']} batch {r['batch']:4d} blocks/realisation {r['blocks_per_realisation']:4d}: "
              f"{r['us_per_step']:9.1f} us  {r['us_per_realisation_step']:8.2f} us  {r['element_steps_per_s']:.3e}  {ratio}")
    for plates, r in sorted(cpu.items()):
        print(f"  CPU one core, plates {plates}: {r['us_per_step']:.1f} us per step, {r['element_steps_per_s']:.3e} "
              "element-steps/s")
    print("\nevents, dynamic relaxation (N, regime: s per event mean, steps per event mean, us per step)")
    for r in by.get("events", []) + by.get("cpu-events", []):
        n = len(r["steps"])
        print(f"  {r['backend']:10s} N {r['N']:5d} {r['regime']:9s}: {sum(r['seconds']) / n:8.3f} s  "
              f"{sum(r['steps']) / n:9.0f} steps  {r['us_per_step']:8.2f} us  (setup {r['setup_seconds']:.1f} s)")
    print("\nfidelity and sanity")
    for r in by.get("sanity", []) + by.get("fidelity", []) + by.get("compare", []):
        print("  " + json.dumps({k: v for k, v in r.items() if k not in ("time",)}))
    for r in records:
        if "error" in r:
            print("ERROR " + json.dumps(r))
    ended = {r["ended"]: r["seconds"] for r in records if "ended" in r}
    started = [r["started"] for r in records if "started" in r]
    print("\nparts: " + ", ".join(f"{name} {ended[name]:.0f} s" if name in ended else f"{name} DID NOT END"
                                  for name in started))


if __name__ == "__main__":
    main(sys.argv[1])
