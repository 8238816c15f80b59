"""The GPU check of the ``cuda`` backend: fidelity and speed on a machine with an NVIDIA GPU, in one call.

``bash benchmarks/gpu/run.sh OUTDIR`` runs every part below in order, each in its own process with a
time limit (a part that fails or hangs does not stop the others), and writes every figure to OUTDIR
(``results.jsonl``: one JSON object per measurement; ``summary.txt``: the table of docs/benchmarks.md).
The CPU baselines run at the same time on the machine's other cores, one thread each.

Parts (``python benchmarks/gpu/gpu_check.py PART OUTDIR``):

``env``
    GPU model, driver, CUDA, CPU model, package versions.
``sanity``
    N = 162, 3 plates: after a kick, 300 time steps with a realisation spread over 1, 4 and 16 blocks
    give the same bytes (the fixed-order sums and the barrier), and stay within round-off of the CPU.
``fidelity``
    the paper's N = 9 reference case (shared/reference/FixedLever_historic.h5, carried as
    .device/reference/) on the GPU against the reference on every increment; the same run twice: the
    same bytes; a batch of 4 realisations (N = 162, n = 2) run together against each run alone: the
    same bytes, file for file.
``speed``
    time per step at N = 1458 with 2 and 6 plates: one realisation spread over 16-132 blocks, batches of
    8, 32 and 128; element-steps per second.
``events``
    time per event with the dynamic relaxation (the paper's protocol) at N = 162 and 1458, stiff and
    compliant (n = 2), and its time steps.
``ensemble``
    N = 162, n = 2, stiff and compliant, 6 seeds each, exact relaxation, on the GPU as one batch per
    regime; with ``ensemble-cpu`` (the same runs on the CPU backend): rho(S) and P(Delta mu_a), a
    two-sample Kolmogorov-Smirnov test each.
``cpu-step``, ``cpu-events``, ``ensemble-cpu``
    the CPU baselines (structured backend, one thread), started in the background.
"""

import dataclasses
import faulthandler
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from stickslip.fem.backends import make_backend
from stickslip.fem.backends.cuda import CudaBackend, run_ensemble
from stickslip.fem.backends.cuda import batch as batch_module
from stickslip.fem.backends.cuda.batch import STEPS_PER_LAUNCH, DeviceBatch
from stickslip.fem.parameters import FemParams
from stickslip.fem.run import run_simulation
from stickslip.fem.simulation import Simulation
from stickslip.fem.stiffness import PAPER_PHI, stiffness_ratio
from stickslip.mesh import MeshParams, build_stack_mesh

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from bench_fem import affine_response  # noqa: E402  (the load direction of the CPU benchmark: the same steps)

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / ".device" / "reference" / "FixedLever_historic.h5"
PRODUCER = ("fem", "gpu-check")

#: ``GPU_CHECK_SMOKE=1``: every part on tiny meshes and few steps, to try the script on numba's simulator
#: (``NUMBA_ENABLE_CUDASIM=1``) before a GPU is lent; its figures mean nothing.
SMOKE = os.environ.get("GPU_CHECK_SMOKE") == "1"
#: Sizes of the parts: the paper's (N = 1458), the ensembles' (N = 162), steps timed, events, ensemble runs.
SIZES = ({"big": 18, "mid": 9, "steps": 8, "launch": 4, "events": 0, "big_events": 0, "increments": 1, "seeds": 2,
          "reference_increments": 1, "relaxation": "exact", "quiet_steps": 4, "alone_groups": (1,),
          "batches": (2,), "batch_increments": 1}
         if SMOKE else
         {"big": 1458, "mid": 162, "steps": 8192, "launch": STEPS_PER_LAUNCH, "events": 8, "big_events": 2,
          "increments": 300, "seeds": 6, "reference_increments": 0, "relaxation": "dynamic", "quiet_steps": 0,
          "alone_groups": None, "batches": (8, 32, 128), "batch_increments": 24})


def emit(out, **record):
    """Append one measurement to ``out/results.jsonl`` and print it."""
    record["time"] = time.strftime("%H:%M:%S")
    line = json.dumps(record, default=float)
    print(line, flush=True)
    with open(Path(out) / "results.jsonl", "a") as file:
        file.write(line + "\n")


def k_drive(phi, N):
    """The drive stiffness of rigidity ratio ``phi`` at ``N`` blocks (``stiffness_ratio`` is linear in it)."""
    return phi / stiffness_ratio(1.0, N)


# --- parts --------------------------------------------------------------------------------------------

def part_env(out):
    from numba import cuda

    device = cuda.get_current_device()
    name = getattr(device, "name", "simulator")
    try:
        smi = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version,memory.total,clocks.max.sm",
                              "--format=csv,noheader"], capture_output=True, text=True).stdout.strip()
    except FileNotFoundError:
        smi = "nvidia-smi not found"
    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                if line.startswith("model name")), platform.processor())
    versions = {}
    for package in ("numpy", "numba", "numba_cuda", "llvmlite", "scipy", "h5py", "pandas"):
        try:
            versions[package] = __import__(package).__version__
        except Exception as error:  # reported, not fatal
            versions[package] = repr(error)
    emit(out, part="env", gpu=name.decode() if isinstance(name, bytes) else str(name),
         compute_capability=list(getattr(device, "compute_capability", (0, 0))),
         sm_count=getattr(device, "MULTIPROCESSOR_COUNT", 1),
         nvidia_smi=smi, cpu=cpu, cpus=os.cpu_count(), python=platform.python_version(), **versions)


def _kicked(params, mesh, backend, response):
    sim = Simulation(params, mesh, backend, response=response)
    sim.loading.step(False)
    sim.loading.step(True)
    return sim


def part_sanity(out):
    N, steps = SIZES["mid"], 4 if SMOKE else 300
    params = FemParams(N=N, plates=3, seed=1, k_drive=k_drive(PAPER_PHI["stiff"], N), nchunk=200)
    mesh = build_stack_mesh(MeshParams(N=N, plates=3))
    response = affine_response(params, mesh)
    cpu = _kicked(params, mesh, make_backend(), response)
    cpu.backend.advance(steps)
    reference = cpu.backend.read("u", "v", "idx")
    states = {}
    for groups in (1, 4, 16):
        start = time.perf_counter()
        gpu = _kicked(dataclasses.replace(params, backend="cuda"), mesh, CudaBackend(groups=groups), response)
        gpu.backend.advance(steps)
        states[groups] = gpu.backend.read("u", "v", "idx")
        emit(out, part="sanity", groups=groups, seconds=time.perf_counter() - start,
             u_vs_cpu=float(np.abs(states[groups][0] - reference[0]).max() / np.abs(reference[0]).max()),
             wells_equal_cpu=bool(np.array_equal(states[groups][2], reference[2])))
    same = all(all(a.tobytes() == b.tobytes() for a, b in zip(states[1], states[g])) for g in (4, 16))
    emit(out, part="sanity", same_bytes_for_1_4_16_blocks=same)


def _reference_run(path, groups=None):
    params = FemParams(N=9, plates=2, seed=0, k_drive=1e-3, drive="fixed-lever", nchunk=200, yield_strains="stop",
                       max_increments=SIZES["reference_increments"], relaxation=SIZES["relaxation"],
                       quiet_steps=SIZES["quiet_steps"], backend="cuda")
    start = time.perf_counter()
    run_simulation(params, path, build_stack_mesh(MeshParams(N=9, plates=2)), CudaBackend(groups=groups),
                   producer=PRODUCER)
    return time.perf_counter() - start


def part_fidelity(out):
    import h5py

    from stickslip.formats.fem_run import read_increments

    directory = Path(out) / "fidelity"
    directory.mkdir(exist_ok=True)
    first, second = directory / "reference-a.h5", directory / "reference-b.h5"
    seconds = _reference_run(first)
    _reference_run(second)
    table = read_increments(first)
    worst = {}
    with h5py.File(REFERENCE) as ref:
        expected = {"epsd": ref["epsd"][...], "sigd": ref["sigd"][...], "fxdrive": ref["fxdrive_layers"][...]}
    got = {"epsd": table["epsd"].to_numpy(), "sigd": table["sigd"].to_numpy(),
           "fxdrive": table[[f"fxdrive_{layer}" for layer in range(3)]].to_numpy()}
    for name in got:
        n = min(len(got[name]), len(expected[name]))
        scale = np.maximum(np.abs(expected[name][:n]), 1e-12)
        worst[name] = float(np.max(np.abs(got[name][:n] - expected[name][:n]) / scale))
    emit(out, part="fidelity", check="reference N=9", increments=len(table), reference_increments=350,
         worst_relative=worst, seconds=seconds, within_1e_9=all(v < 1e-9 for v in worst.values()),
         same_bytes_twice=first.read_bytes() == second.read_bytes())
    for path in (first, second):
        path.unlink()
    # a batch against each run alone
    N = SIZES["mid"]
    mesh = build_stack_mesh(MeshParams(N=N, plates=3))
    seeds = (1, 2, 3, 4)

    def params(seed):
        return FemParams(N=N, plates=3, seed=seed, k_drive=k_drive(PAPER_PHI["stiff"], N), relaxation="exact",
                         quiet_steps=SIZES["quiet_steps"], max_increments=SIZES["batch_increments"], backend="cuda")

    start = time.perf_counter()
    for seed in seeds:
        run_simulation(params(seed), directory / f"alone-{seed}.h5", mesh, CudaBackend(), producer=PRODUCER)
    alone = time.perf_counter() - start
    start = time.perf_counter()
    run_ensemble([lambda backend, seed=seed: run_simulation(params(seed), directory / f"batch-{seed}.h5", mesh, backend,
                                                            producer=PRODUCER) for seed in seeds])
    together = time.perf_counter() - start
    equal = [(directory / f"alone-{seed}.h5").read_bytes() == (directory / f"batch-{seed}.h5").read_bytes()
             for seed in seeds]
    emit(out, part="fidelity", check=f"batch member = alone (N={N} n=2, {SIZES['batch_increments']} increments, exact)",
         equal=equal,
         seconds_alone=alone, seconds_batch=together)


def _speed(out, plates, sizes, groups_alone, steps):
    """Time per step: one realisation over several block counts, and batches."""
    N = SIZES["big"]
    params = FemParams(N=N, plates=plates, nchunk=200, window=64, backend="cuda")  # few wells held: memory
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    response = affine_response(dataclasses.replace(params, backend="structured"), mesh)
    sim = _kicked(params, mesh, CudaBackend(), response)
    model = sim.model
    nelem = mesh.nelem
    state = sim.stack.stored()
    for count, groups in [(1, g) for g in groups_alone] + [(b, None) for b in sizes]:
        batch = DeviceBatch(sim.backend.batch.mesh, model.law, count, groups)
        members = [CudaBackend().bound(model, batch) for _ in range(count)]
        for member in members:
            member.set_load_direction(response.delta_u, response.delta_target, response.delta_lever)
            member.set_state(*state)
        slots = [member.slot for member in members]
        for slot in slots:
            batch._begin(slot, 0.0, 1, 10 ** 9, 0, False, 0)
        batch.launch(slots)  # warm up (compiles on the first launch)
        start = time.perf_counter()
        rounds = max(1, steps // SIZES["launch"])
        for _ in range(rounds):
            batch.launch(slots)
        seconds = time.perf_counter() - start
        per_step = seconds / (rounds * SIZES["launch"])
        emit(out, part="speed", N=N, plates=plates, elements=nelem, dofs=model.ndof, batch=count,
             blocks_per_realisation=batch._groups(count), us_per_step=per_step * 1e6,
             us_per_realisation_step=per_step * 1e6 / count, element_steps_per_s=nelem * count / per_step)
        del members, batch


def part_speed(out):
    _speed(out, 2, SIZES["batches"], SIZES["alone_groups"] or (16, 33, 66, 132), SIZES["steps"])
    _speed(out, 6, SIZES["batches"], SIZES["alone_groups"] or (33, 66, 132), SIZES["steps"])


def _events(out, backend_name, N, regime, count, groups=None):
    if not count:
        return
    params = FemParams(N=N, plates=3, seed=1, k_drive=k_drive(PAPER_PHI[regime], N), backend=backend_name,
                       relaxation=SIZES["relaxation"], quiet_steps=SIZES["quiet_steps"])
    mesh = build_stack_mesh(MeshParams(N=N, plates=3))
    backend = CudaBackend(groups=groups) if backend_name == "cuda" else make_backend(backend_name)
    start = time.perf_counter()
    sim = Simulation(params, mesh, backend)
    setup = time.perf_counter() - start
    dt = sim.model.dt
    steps, seconds, sizes = [], [], []
    for _ in range(count):
        sim.loading.step(False)
        before, t0 = sim.stack.well_index()[:, 0], sim.stack.time
        start = time.perf_counter()
        sim.protocol.kick(params.margin)
        seconds.append(time.perf_counter() - start)
        steps.append(round((sim.stack.time - t0) / dt))
        sizes.append(int(np.count_nonzero(sim.stack.well_index()[:, 0] != before)))
    emit(out, part="events" if backend_name == "cuda" else "cpu-events", backend=backend_name, N=N, plates=3,
         regime=regime, relaxation=params.relaxation, events=count, setup_seconds=setup, steps=steps, seconds=seconds,
         sizes=sizes, us_per_step=1e6 * sum(seconds) / sum(steps))


def part_events(out):
    for N, count in ((SIZES["mid"], SIZES["events"]), (SIZES["big"], SIZES["big_events"])):
        for regime in ("stiff", "compliant"):
            _events(out, "cuda", N, regime, count)


def part_cpu_events(out):
    for regime in ("stiff", "compliant"):
        _events(out, "structured", SIZES["mid"], regime, SIZES["big_events"])


def part_cpu_step(out):
    from stickslip.numba_options import set_num_threads

    set_num_threads(1)
    N, steps = SIZES["big"], SIZES["steps"] if SMOKE else 400
    for plates in (2, 6):
        params = FemParams(N=N, plates=plates, nchunk=200)
        mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
        sim = _kicked(params, mesh, make_backend(), affine_response(params, mesh))
        sim.backend.advance(20)
        start = time.perf_counter()
        sim.backend.advance(steps)
        per_step = (time.perf_counter() - start) / steps
        emit(out, part="cpu-step", backend="structured", threads=1, N=N, plates=plates, elements=mesh.nelem,
             us_per_step=per_step * 1e6, element_steps_per_s=mesh.nelem / per_step)


ENSEMBLE_SEEDS = tuple(range(1, SIZES["seeds"] + 1))
ENSEMBLE_INCREMENTS = SIZES["increments"]


def _ensemble_params(regime, seed, backend):
    N = SIZES["mid"]
    return FemParams(N=N, plates=3, seed=seed, k_drive=k_drive(PAPER_PHI[regime], N), relaxation="exact",
                     quiet_steps=SIZES["quiet_steps"], max_increments=ENSEMBLE_INCREMENTS, backend=backend)


def part_ensemble(out):
    mesh = build_stack_mesh(MeshParams(N=SIZES["mid"], plates=3))
    directory = Path(out) / "ensemble"
    directory.mkdir(exist_ok=True)
    for regime in ("stiff", "compliant"):
        start = time.perf_counter()
        run_ensemble([lambda backend, seed=seed: run_simulation(
            _ensemble_params(regime, seed, "cuda"), directory / f"gpu-{regime}-{seed}.h5", mesh, backend,
            producer=PRODUCER) for seed in ENSEMBLE_SEEDS])
        emit(out, part="ensemble", regime=regime, realisations=len(ENSEMBLE_SEEDS), increments=ENSEMBLE_INCREMENTS,
             seconds=time.perf_counter() - start)


def part_ensemble_cpu(out, regime, seed):
    mesh = build_stack_mesh(MeshParams(N=SIZES["mid"], plates=3))
    directory = Path(out) / "ensemble"
    directory.mkdir(exist_ok=True)
    start = time.perf_counter()
    run_simulation(_ensemble_params(regime, seed, "structured"), directory / f"cpu-{regime}-{seed}.h5", mesh,
                   make_backend(), producer=PRODUCER)
    emit(out, part="ensemble-cpu", regime=regime, seed=seed, seconds=time.perf_counter() - start)


def part_compare(out):
    """Two-sample tests of the GPU and CPU ensembles: event sizes S and the slips' Delta mu_a."""
    from scipy import stats

    from stickslip.events.extraction import classify_increments, slip_interfaces
    from stickslip.formats.fem_run import read_increments

    directory = Path(out) / "ensemble"
    for regime in ("stiff", "compliant"):
        samples = {}
        for side in ("gpu", "cpu"):
            sizes, drops = [], []
            for seed in ENSEMBLE_SEEDS:
                path = directory / f"{side}-{regime}-{seed}.h5"
                if not path.exists():
                    continue
                table = read_increments(path)
                kicks = table[table["kick"]].iloc[1:]
                sizes += list(kicks[[c for c in table.columns if c.startswith("S_a")]].sum(axis=1))
                drops += list(slip_interfaces(classify_increments(table, SIZES["mid"]), SIZES["mid"])["dmu_sig0"])
            samples[side] = (np.asarray(sizes, float), np.asarray(drops, float))
        if any(samples[side][0].size == 0 for side in samples):
            emit(out, part="compare", regime=regime, error="an ensemble is missing")
            continue
        size_test = stats.ks_2samp(samples["gpu"][0], samples["cpu"][0])
        record = {"events_gpu": int(samples["gpu"][0].size), "events_cpu": int(samples["cpu"][0].size),
                  "ks_S": float(size_test.statistic), "p_S": float(size_test.pvalue)}
        if samples["gpu"][1].size and samples["cpu"][1].size:
            drop_test = stats.ks_2samp(samples["gpu"][1], samples["cpu"][1])
            record.update(slips_gpu=int(samples["gpu"][1].size), slips_cpu=int(samples["cpu"][1].size),
                          ks_dmu=float(drop_test.statistic), p_dmu=float(drop_test.pvalue))
        emit(out, part="compare", regime=regime, **record)


#: The GPU parts in order, each with its time limit [s]: run in one process (the kernels compile once),
#: a part that ended (or was started and never ended: a crash or a hang) is not run again.
GPU_PARTS = (("env", part_env, 60), ("sanity", part_sanity, 100), ("fidelity", part_fidelity, 150),
             ("speed", part_speed, 150), ("events", part_events, 120), ("ensemble", part_ensemble, 150))

PARTS = {"cpu-step": part_cpu_step, "cpu-events": part_cpu_events, "compare": part_compare}


def _recorded(out):
    path = Path(out) / "results.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def gpu_sequence(out):
    """The GPU parts not yet started, in order, each under its time limit (the process exits at a limit)."""
    batch_module.STEPS_PER_LAUNCH = SIZES["launch"]
    started = {r["started"] for r in _recorded(out) if "started" in r}
    for name, part, limit in GPU_PARTS:
        if name in started:
            continue
        limit *= 20 if SMOKE else 1  # the simulator is slow
        emit(out, started=name, limit_s=limit)
        faulthandler.dump_traceback_later(limit, exit=True)
        start = time.perf_counter()
        try:
            part(out)
        except Exception as error:  # the other parts go on; the error is a result too
            emit(out, part=name, error=f"{type(error).__name__}: {error}")
        faulthandler.cancel_dump_traceback_later()
        emit(out, ended=name, seconds=time.perf_counter() - start)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    part, out = argv[0], argv[1]
    Path(out).mkdir(parents=True, exist_ok=True)
    if part == "gpu":
        gpu_sequence(out)
    elif part == "seeds":
        print(" ".join(map(str, ENSEMBLE_SEEDS)))
    elif part == "ensemble-cpu":
        part_ensemble_cpu(out, argv[2], int(argv[3]))
    else:
        PARTS[part](out)


if __name__ == "__main__":
    main()
