"""The GPU check of the ``cuda`` backend: fidelity and speed on a machine with an NVIDIA GPU, one part per process.

``bash benchmarks/gpu/run.sh OUTDIR`` runs the parts below (``python benchmarks/gpu/gpu_check.py PART DIR``),
each in its own process under its own time limit (the kernels compile once per process); every figure is
one JSON object in ``DIR/results.jsonl`` (summary.py prints the table of docs/benchmarks.md).

``preflight``
    the device's name and compute capability, NVVM's version, the packages (qdldl from the carried wheel):
    run.sh stops at once if this fails.
``sanity``
    N = 162, 3 plates: after a kick, 300 time steps with a realisation spread over 1, 4, 16 and all its
    tiles' blocks give the same bytes, and stay within round-off of the CPU.
``fidelity``
    the paper's N = 9 reference case (FixedLever_historic.h5, carried as .device/reference/) on one block per
    realisation (``groups = 1``) against the reference on every increment; the same run twice: the same
    bytes; a batch of 4 realisations (N = 162, 3 plates) run together against each run alone: the same bytes.
``speed``
    time per step at N = 1458 with 2 and 6 plates: one realisation over several block counts, batches of 8,
    32, 128 and 264; element-steps per second.
``events``
    time per event with the dynamic relaxation (the paper's protocol) at N = 162 and 1458, stiff and
    compliant (3 plates), its time steps; the paper's 2 000 events at N = 1458 from it.
``cpu-step``
    the CPU baseline (structured backend, one thread) per step at N = 1458, 2 and 6 plates, beside the GPU parts.

``GPU_CHECK_SMOKE=1``: every part on tiny meshes and few steps, to try the script on numba's simulator
(``NUMBA_ENABLE_CUDASIM=1``, blocks run at once: :func:`stickslip.fem.backends.cuda.simulator.concurrent_blocks`)
before a GPU is lent; its figures mean nothing.
"""

import contextlib
import dataclasses
import importlib.metadata
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

SMOKE = os.environ.get("GPU_CHECK_SMOKE") == "1"
#: Sizes of the parts: the paper's mesh (N = 1458), the ensembles' (N = 162), steps timed, events, batches.
SIZES = ({"big": 9, "mid": 9, "mid_plates": 2, "big_plates": (2,), "regimes": ("stiff",), "steps": 2, "launch": 2,
          "sanity_steps": 2, "events": 0, "big_events": 1, "reference_increments": 1, "relaxation": "exact",
          "quiet_steps": 4, "alone_groups": (1, 2), "sanity_groups": (1, 2), "batches": (2,), "seeds": (1, 2),
          "batch_increments": 1, "cpu_steps": 2}
         if SMOKE else
         {"big": 1458, "mid": 162, "mid_plates": 3, "big_plates": (2, 6), "regimes": ("stiff", "compliant"),
          "steps": 4096, "launch": 1024, "sanity_steps": 300, "events": 4, "big_events": 1, "reference_increments": 0,
          "relaxation": "dynamic", "quiet_steps": 0, "alone_groups": (16, 33, 66, None),
          "sanity_groups": (1, 4, 16, None), "batches": (8, 32, 128, 264), "seeds": (1, 2, 3, 4),
          "batch_increments": 24, "cpu_steps": 400})
PRODUCER = ("fem", "gpu-check")


def emit(out, **record):
    """Append one measurement to ``out/results.jsonl`` and print it."""
    record["time"] = time.strftime("%H:%M:%S")
    line = json.dumps(record, default=float)
    print(line, flush=True)
    with open(Path(out) / "results.jsonl", "a") as file:
        file.write(line + "\n")


def device_context():
    """On the simulator, blocks run at once (several blocks per realisation); nothing on a GPU."""
    from numba import config

    if config.ENABLE_CUDASIM:
        from stickslip.fem.backends.cuda.simulator import concurrent_blocks

        return concurrent_blocks(8)
    return contextlib.nullcontext()


def k_drive(phi, N):
    """The drive stiffness of rigidity ratio ``phi`` at ``N`` blocks (``stiffness_ratio`` is linear in it)."""
    from stickslip.fem.stiffness import stiffness_ratio

    return phi / stiffness_ratio(1.0, N)


def kicked(params, mesh, backend, response):
    from stickslip.fem.simulation import Simulation

    sim = Simulation(params, mesh, backend, response=response)
    sim.loading.step(False)
    sim.loading.step(True)
    return sim


# --- parts --------------------------------------------------------------------------------------------

def part_preflight(out):
    from numba import cuda

    # NVVM as the device compiles with it (also in the smoke mode, whose simulator compiles nothing)
    version = subprocess.run([sys.executable, "-c", "from numba.cuda.cudadrv import nvvm; "
                              "print('.'.join(map(str, nvvm.NVVM().get_version())))"], capture_output=True, text=True,
                             timeout=8, env={**os.environ, "NUMBA_ENABLE_CUDASIM": "0"}, check=True).stdout.strip()
    device = cuda.get_current_device()
    name = getattr(device, "name", "simulator")
    try:
        smi = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version,memory.total,clocks.max.sm",
                              "--format=csv,noheader"], capture_output=True, text=True, timeout=5).stdout.strip()
    except (FileNotFoundError, subprocess.TimeoutExpired):
        smi = "nvidia-smi not found"
    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                if line.startswith("model name")), platform.processor())
    versions = {}
    for package in ("numpy", "numba", "numba_cuda", "scipy", "h5py", "qdldl"):
        __import__(package)  # importable, not only installed
        versions[package] = importlib.metadata.version(package.replace("_", "-"))
    import qdldl

    versions["qdldl_from"] = str(Path(qdldl.__file__).parent)
    emit(out, part="preflight", gpu=name.decode() if isinstance(name, bytes) else str(name), nvvm=version,
         compute_capability=list(getattr(device, "compute_capability", (0, 0))),
         sm_count=getattr(device, "MULTIPROCESSOR_COUNT", 1), nvidia_smi=smi, cpu=cpu, cpus=os.cpu_count(),
         python=platform.python_version(), **versions)


def part_sanity(out):
    from bench_fem import affine_response
    from stickslip.fem.backends import make_backend
    from stickslip.fem.backends.cuda import CudaBackend
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.stiffness import PAPER_PHI
    from stickslip.mesh import MeshParams, build_stack_mesh

    N, plates, steps = SIZES["mid"], SIZES["mid_plates"], SIZES["sanity_steps"]
    params = FemParams(N=N, plates=plates, seed=1, k_drive=k_drive(PAPER_PHI["stiff"], N), nchunk=200)
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    response = affine_response(params, mesh)
    cpu = kicked(params, mesh, make_backend(), response)
    cpu.backend.advance(steps)
    reference = cpu.backend.read("u", "v", "idx")
    states = {}
    for groups in SIZES["sanity_groups"]:
        start = time.perf_counter()
        backend = CudaBackend(groups=groups)
        gpu = kicked(dataclasses.replace(params, backend="cuda"), mesh, backend, response)
        gpu.backend.advance(steps)
        states[groups] = gpu.backend.read("u", "v", "idx")
        used = sorted(gpu.backend.batch.launcher.groups_used)
        emit(out, part="sanity", groups=groups, blocks_used=used, seconds=time.perf_counter() - start,
             u_vs_cpu=float(np.abs(states[groups][0] - reference[0]).max() / np.abs(reference[0]).max()),
             wells_equal_cpu=bool(np.array_equal(states[groups][2], reference[2])))
    first = states[SIZES["sanity_groups"][0]]
    same = all(all(a.tobytes() == b.tobytes() for a, b in zip(first, state)) for state in states.values())
    emit(out, part="sanity", same_bytes_for_every_spread=same)


def _reference_run(path):
    from stickslip.fem.backends.cuda import CudaBackend
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.run import simulate_to_file
    from stickslip.mesh import MeshParams, build_stack_mesh

    params = FemParams(N=9, plates=2, seed=0, k_drive=1e-3, drive="fixed-lever", nchunk=200, yield_strains="stop",
                       max_increments=SIZES["reference_increments"], relaxation=SIZES["relaxation"],
                       quiet_steps=SIZES["quiet_steps"], backend="cuda")
    start = time.perf_counter()
    simulate_to_file(params, path, build_stack_mesh(MeshParams(N=9, plates=2)), CudaBackend(groups=1),
                   producer=PRODUCER)
    return time.perf_counter() - start


def part_fidelity(out):
    import h5py

    from stickslip.fem.backends.cuda import CudaBackend, run_ensemble
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.run import simulate_to_file
    from stickslip.fem.stiffness import PAPER_PHI
    from stickslip.formats.fem_run import read_increments
    from stickslip.mesh import MeshParams, build_stack_mesh

    directory = Path(out) / "fidelity"
    directory.mkdir(exist_ok=True)
    first, second = directory / "reference-a.h5", directory / "reference-b.h5"
    seconds = _reference_run(first)
    table = read_increments(first)
    reference = Path(os.environ.get("GPU_CHECK_REFERENCE", ROOT / ".device" / "reference" / "FixedLever_historic.h5"))
    with h5py.File(reference) as ref:
        expected = {"epsd": ref["epsd"][...], "sigd": ref["sigd"][...], "fxdrive": ref["fxdrive_layers"][...]}
    got = {"epsd": table["epsd"].to_numpy(), "sigd": table["sigd"].to_numpy(),
           "fxdrive": table[[f"fxdrive_{layer}" for layer in range(3)]].to_numpy()}
    worst = {}
    for name in got:
        n = min(len(got[name]), len(expected[name]))
        scale = np.maximum(np.abs(expected[name][:n]), 1e-12)
        worst[name] = float(np.max(np.abs(got[name][:n] - expected[name][:n]) / scale))
    emit(out, part="fidelity", check="reference N=9, one block", increments=len(table), reference_increments=350,
         worst_relative=worst, seconds=seconds, within_1e_9=all(v < 1e-9 for v in worst.values()))
    _reference_run(second)
    emit(out, part="fidelity", check="reference N=9 twice", same_bytes_twice=first.read_bytes() == second.read_bytes())
    N, plates, seeds = SIZES["mid"], SIZES["mid_plates"], SIZES["seeds"]
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))

    def params(seed):
        return FemParams(N=N, plates=plates, seed=seed, k_drive=k_drive(PAPER_PHI["stiff"], N), relaxation="exact",
                         quiet_steps=SIZES["quiet_steps"], max_increments=SIZES["batch_increments"], backend="cuda")

    start = time.perf_counter()
    for seed in seeds:
        simulate_to_file(params(seed), directory / f"alone-{seed}.h5", mesh, CudaBackend(), producer=PRODUCER)
    alone = time.perf_counter() - start
    start = time.perf_counter()
    run_ensemble([lambda backend, seed=seed: simulate_to_file(params(seed), directory / f"batch-{seed}.h5", mesh, backend,
                                                            producer=PRODUCER) for seed in seeds])
    equal = [(directory / f"alone-{seed}.h5").read_bytes() == (directory / f"batch-{seed}.h5").read_bytes()
             for seed in seeds]
    emit(out, part="fidelity", check=f"batch member = alone (N={N}, {plates} plates, {SIZES['batch_increments']} "
         "increments)", equal=equal, seconds_alone=alone, seconds_batch=time.perf_counter() - start)


def _speed(out, plates):
    from bench_fem import affine_response
    from stickslip.fem.backends.cuda import CudaBackend
    from stickslip.fem.backends.cuda.batch import DeviceBatch
    from stickslip.fem.parameters import FemParams
    from stickslip.mesh import MeshParams, build_stack_mesh

    N = SIZES["big"]
    params = FemParams(N=N, plates=plates, nchunk=200, window=64, backend="cuda")  # few wells held: memory
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    response = affine_response(dataclasses.replace(params, backend="structured"), mesh)
    sim = kicked(params, mesh, CudaBackend(), response)
    model, state = sim.model, sim.stack.stored()
    for count, groups in [(1, g) for g in SIZES["alone_groups"]] + [(b, None) for b in SIZES["batches"]]:
        batch = DeviceBatch(sim.backend.batch.mesh, model.law, count, groups)
        members = [CudaBackend().bound(model, mesh, batch, sim.stack.yield_strains) for _ in range(count)]
        for member in members:
            member.set_load_direction(response.delta_u, response.delta_target, response.delta_lever)
            member.set_state(state.u, state.target, state.lever_target, state.t)
            batch.begin(member.slot, (0.0, 1, 10 ** 12, 0, False, 0))
        slots = [member.slot for member in members]
        batch.launcher.minimise(slots, batch.state, SIZES["launch"])  # compiles on the first launch
        rounds = max(1, SIZES["steps"] // SIZES["launch"])
        start = time.perf_counter()
        for _ in range(rounds):
            batch.launcher.minimise(slots, batch.state, SIZES["launch"])
        per_step = (time.perf_counter() - start) / (rounds * SIZES["launch"])
        emit(out, part="speed", N=N, plates=plates, elements=mesh.nelem, dofs=model.ndof, batch=count,
             blocks_per_realisation=max(batch.launcher.groups_used), tiles=batch.mesh.layout.ntile,
             us_per_step=per_step * 1e6, us_per_realisation_step=per_step * 1e6 / count,
             element_steps_per_s=mesh.nelem * count / per_step)
        del members, batch


def part_speed(out):
    for plates in SIZES["big_plates"]:
        _speed(out, plates)


def _events(out, backend_name, N, regime, count):
    from stickslip.fem.backends import make_backend
    from stickslip.fem.backends.cuda import CudaBackend
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.simulation import Simulation
    from stickslip.fem.stiffness import PAPER_PHI
    from stickslip.mesh import MeshParams, build_stack_mesh

    if not count:
        return
    plates = SIZES["mid_plates"]
    params = FemParams(N=N, plates=plates, seed=1, k_drive=k_drive(PAPER_PHI[regime], N), backend=backend_name,
                       relaxation=SIZES["relaxation"], quiet_steps=SIZES["quiet_steps"])
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
    start = time.perf_counter()
    sim = Simulation(params, mesh, CudaBackend() if backend_name == "cuda" else make_backend(backend_name))
    setup = time.perf_counter() - start
    steps, seconds = [], []
    for _ in range(count):
        sim.loading.step(False)
        t0 = sim.stack.time
        start = time.perf_counter()
        sim.protocol.kick(params.margin)
        seconds.append(time.perf_counter() - start)
        steps.append(round((sim.stack.time - t0) / sim.model.dt))
        emit(out, part="events", backend=backend_name, N=N, plates=plates, regime=regime, relaxation=params.relaxation,
             setup_seconds=setup, steps=steps[-1], seconds=seconds[-1],
             us_per_step=1e6 * seconds[-1] / max(steps[-1], 1),
             paper_protocol_hours=2000 * seconds[-1] / 3600 if N == 1458 else None)


def part_events(out):
    for N, count in ((SIZES["mid"], SIZES["events"]), (SIZES["big"], SIZES["big_events"])):
        for regime in SIZES["regimes"]:
            _events(out, "cuda", N, regime, count)


def part_cpu_step(out):
    from bench_fem import affine_response
    from stickslip.fem.backends import make_backend
    from stickslip.fem.parameters import FemParams
    from stickslip.mesh import MeshParams, build_stack_mesh
    from stickslip.numba_options import set_num_threads

    set_num_threads(1)
    N, steps = SIZES["big"], SIZES["cpu_steps"]
    for plates in SIZES["big_plates"]:
        params = FemParams(N=N, plates=plates, nchunk=200)
        mesh = build_stack_mesh(MeshParams(N=N, plates=plates))
        sim = kicked(params, mesh, make_backend(), affine_response(params, mesh))
        sim.backend.advance(20)
        start = time.perf_counter()
        sim.backend.advance(steps)
        per_step = (time.perf_counter() - start) / steps
        emit(out, part="cpu-step", backend="structured", threads=1, N=N, plates=plates, elements=mesh.nelem,
             us_per_step=per_step * 1e6, element_steps_per_s=mesh.nelem / per_step)


PARTS = {"preflight": part_preflight, "sanity": part_sanity, "fidelity": part_fidelity, "speed": part_speed,
         "events": part_events, "cpu-step": part_cpu_step}


def main(argv=None):
    part, out = (sys.argv[1:] if argv is None else argv)[:2]
    Path(out).mkdir(parents=True, exist_ok=True)
    emit(out, started=part)
    start = time.perf_counter()
    try:
        with device_context():
            PARTS[part](out)
    except Exception as error:  # the error is a result too; run.sh goes on with the next part
        emit(out, part=part, error=f"{type(error).__name__}: {error}")
        raise
    emit(out, ended=part, seconds=time.perf_counter() - start)


if __name__ == "__main__":
    main()
