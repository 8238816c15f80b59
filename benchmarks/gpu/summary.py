"""The table of a GPU check (benchmarks/gpu/run.sh): reads DIR/results.jsonl, prints the summary.

Every part of the check is named in the last line: its time, or FAILED (an error) or MISSING (started and never
ended: its limit, or a crash; or never started). The exit status is 1 if a part FAILED or is MISSING (run.sh
exits with it), else 0.
"""

import json
import sys
from pathlib import Path

#: The parts run.sh runs, in order (cpu-step beside those after the warmup).
PARTS = ("preflight", "warmup", "fidelity", "speed", "sanity", "events", "cpu-step")


def main(directory):
    """Print the summary of ``directory``'s results; returns the exit status (module docstring)."""
    path = Path(directory) / "results.jsonl"
    records = [json.loads(line) for line in path.read_text().splitlines() if line.strip()] if path.exists() else []
    by = {}
    for record in records:
        if "error" not in record and "skipped" not in record and "part" in record:
            by.setdefault(record["part"], []).append(record)
    for r in by.get("preflight", []):
        print(f"GPU {r['gpu']} (cc {r['compute_capability']}, {r['sm_count']} SMs; {r['nvidia_smi']}), NVVM {r['nvvm']}, "
              f"CPU {r['cpu']} x {r['cpus']}, Python {r['python']}, numba {r['numba']}, numba-cuda {r['numba_cuda']}, "
              f"numpy {r['numpy']}, qdldl {r['qdldl']} ({r['qdldl_from']})")
    cpu = {r["plates"]: r for r in by.get("cpu-step", [])}
    print("\nspeed (kernel; us per step of the batch; per realisation-step; element-steps/s; ratio to one CPU core)")
    for r in by.get("speed", []):
        if "does_not_fit" in r:
            print(f"  N {r['N']} plates {r['plates']} batch {r['batch']:4d} {r['kernel']:8s}: {r['does_not_fit']}")
            continue
        base = cpu.get(r["plates"])
        ratio = f"{r['element_steps_per_s'] / base['element_steps_per_s']:.0f}x" if base else "(no CPU baseline)"
        compiled = (f"; {r['registers']} registers, {r['local_bytes_per_thread']} B local" if "registers" in r
                    else "")
        print(f"  N {r['N']} plates {r['plates']} batch {r['batch']:4d} {r['kernel']:8s} blocks/realisation "
              f"{r['blocks_per_realisation']:4d} x {r['threads_per_block']} threads (tiles {r['tiles']}, "
              f"{r['co_resident_blocks']} co-resident{compiled}): {r['us_per_step']:10.2f} us "
              f"{r['us_per_realisation_step']:9.3f} us {r['element_steps_per_s']:.3e} {ratio}")
    for plates, r in sorted(cpu.items()):
        print(f"  CPU one core, plates {plates}: {r['us_per_step']:.1f} us per step, {r['element_steps_per_s']:.3e} "
              "element-steps/s")
    print("\nevents, one realisation (N, regime: s per event, steps, us per step; the paper's 2000 events at N = 1458)")
    for r in by.get("events", []):
        hours = f", 2000 events: {r['paper_protocol_hours']:.2f} h" if r.get("paper_protocol_hours") else ""
        print(f"  {r['backend']} {r['kernel']} N {r['N']} {r['regime']} {r['relaxation']}: {r['seconds']:.3f} s, "
              f"{r['steps']} steps, "
              f"{r['us_per_step']:.2f} us per step{hours}")
    print("\nfidelity and sanity")
    for r in by.get("fidelity", []) + by.get("sanity", []) + by.get("warmup", []):
        if "skipped" not in r:
            print("  " + json.dumps({k: v for k, v in r.items() if k != "time"}))
    for r in records:
        if "skipped" in r:
            print("SKIPPED (budget) " + json.dumps({k: v for k, v in r.items() if k != "time"}))
    for r in records:
        if "error" in r:
            print("ERROR " + json.dumps(r))
    ended = {r["ended"]: r["seconds"] for r in records if "ended" in r}
    failed = {r["part"] for r in records if "error" in r}
    print("\nparts: " + ", ".join(f"{name} FAILED" if name in failed else f"{name} {ended[name]:.0f} s" if name in ended
                                  else f"{name} MISSING" for name in PARTS))
    return 1 if failed or set(PARTS) - set(ended) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
