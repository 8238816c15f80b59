"""The GPU check of the ``cuda`` backend: fidelity and speed of both minimisation kernels, one part per process.

``bash benchmarks/gpu/run.sh OUTDIR`` runs the parts below in this order (``python benchmarks/gpu/gpu_check.py PART
DIR``), each in its own process under its own time limit (the CUDA kernels compile once per process); every figure
is one JSON object in ``DIR/results.jsonl`` (summary.py prints the table of docs/benchmarks.md). Every part keeps to
its budget (``GPU_CHECK_BUDGET`` seconds, set by run.sh a little under the part's limit): what would not fit is
recorded as skipped, so a part ends by itself rather than at its limit. Both kernels (:data:`KERNELS`: ``tiles``,
the default, and ``resident``) are measured side by side in the same process.

``preflight``
    the device's name and compute capability (a CUDA context made), NVVM's version, the packages (qdldl from the
    carried wheel): run.sh stops at once if this fails.
``warmup``
    the CPU kernels compiled into numba's cache (a structured-backend simulation at N = 9: load, kick, time steps,
    the exact relaxation), so that no timed part compiles them, and the CPU baseline beside the GPU parts neither.
``fidelity``
    the paper's N = 9 reference case (FixedLever_historic.h5, carried as .device/reference/) with each kernel (the
    tiles kernel on one block per realisation) against the reference on every increment, the two kernels' files
    byte for byte; a batch of 4 realisations (N = 162, 3 plates) run together against each run alone, per kernel.
``speed``
    time per step at N = 1458 with 2 and 6 plates, each configuration with both kernels one after the other: one
    realisation (the tiles kernel over all its tiles' blocks; the resident kernel over its tiles), batches of 8,
    32 and 128; element-steps per second. Steps timed after a warm launch, for about a second each.
``sanity``
    N = 162, 3 plates: after a kick, 300 time steps with a realisation spread over 1, 4, 16 and all its tiles'
    blocks (tiles kernel) and the resident kernel give the same bytes, and stay within round-off of the CPU.
``events``
    time per event with the dynamic relaxation (the paper's protocol), one realisation, 3 plates: N = 1458 stiff
    with both kernels first, then N = 162 stiff and compliant, then N = 1458 compliant, as the budget allows.
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
#: The minimisation kernels compared (``CudaBackend(kernel=...)``).
KERNELS = ("tiles", "resident")
#: Sizes of the parts: the paper's mesh (N = 1458), the ensembles' (N = 162), batches, the seconds a speed figure is
#: timed for, events, the steps of the sanity part and of the CPU baseline.
SIZES = ({"big": 9, "mid": 9, "mid_plates": 2, "big_plates": (2,), "launch": 2, "timed_seconds": 0.0,
          "sanity_steps": 2, "events": 0, "big_events": 1, "big_compliant_events": 0, "reference_increments": 1,
          "relaxation": "exact",
          "quiet_steps": 4, "sanity_groups": (1, 2), "batches": (2,), "seeds": (1, 2), "batch_increments": 1,
          "cpu_steps": 2}
         if SMOKE else
         {"big": 1458, "mid": 162, "mid_plates": 3, "big_plates": (2, 6), "launch": 512, "timed_seconds": 1.0,
          "sanity_steps": 300, "events": 4, "big_events": 1, "big_compliant_events": 1, "reference_increments": 0,
          "relaxation": "dynamic",
          "quiet_steps": 0, "sanity_groups": (1, 4, 16, None), "batches": (8, 32, 128), "seeds": (1, 2, 3, 4),
          "batch_increments": 24, "cpu_steps": 400})
PRODUCER = ("fem", "gpu-check")
#: Seconds a part keeps for its own end (results written, the process closed) within its budget.
RESERVE = 3.0


def emit(out, **record):
    """Append one measurement to ``out/results.jsonl`` and print it."""
    record["time"] = time.strftime("%H:%M:%S")
    line = json.dumps(record, default=float)
    print(line, flush=True)
    with open(Path(out) / "results.jsonl", "a") as file:
        file.write(line + "\n")


class Budget:
    """The seconds left to a part (``GPU_CHECK_BUDGET``, from the part's start; unlimited if unset)."""

    def __init__(self):
        self.total = float(os.environ.get("GPU_CHECK_BUDGET", "inf")) - RESERVE
        self.end = time.perf_counter() + self.total

    def left(self):
        return self.end - time.perf_counter()

    def allows(self, out, part, seconds, **what):
        """True if ``seconds`` fit in what is left; else the item is recorded as skipped."""
        if seconds <= self.left():
            return True
        emit(out, part=part, skipped=what, needs_seconds=seconds, seconds_left=self.left())
        return False


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


def same_bytes(first, second):
    """True if two sequences of arrays are equal byte for byte."""
    return all(a.tobytes() == b.tobytes() for a, b in zip(first, second))


# --- parts --------------------------------------------------------------------------------------------

def part_preflight(out, budget):
    # NVVM as the device compiles with it (also in the smoke mode, whose simulator compiles nothing), in a second
    # interpreter started first: it loads beside this one's CUDA context
    nvvm = subprocess.Popen([sys.executable, "-c", "from numba.cuda.cudadrv import nvvm; "
                             "print('.'.join(map(str, nvvm.NVVM().get_version())))"], stdout=subprocess.PIPE, text=True,
                            env={**os.environ, "NUMBA_ENABLE_CUDASIM": "0"})
    import numba.cuda
    from numba import cuda

    start = time.perf_counter()
    probe = cuda.to_device(np.arange(4.0)).copy_to_host()  # the CUDA context, made and used
    context_seconds = time.perf_counter() - start
    device = cuda.get_current_device()
    name = getattr(device, "name", "simulator")
    try:
        smi = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version,memory.total,clocks.max.sm",
                              "--format=csv,noheader"], capture_output=True, text=True, timeout=10).stdout.strip()
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
    version = nvvm.communicate(timeout=max(1.0, budget.left()))[0].strip()
    if nvvm.returncode:
        raise RuntimeError(f"NVVM cannot be loaded (exit status {nvvm.returncode})")
    emit(out, part="preflight", gpu=name.decode() if isinstance(name, bytes) else str(name), nvvm=version,
         compute_capability=list(getattr(device, "compute_capability", (0, 0))), context_seconds=context_seconds,
         context_ok=bool(probe[3] == 3.0), sm_count=getattr(device, "MULTIPROCESSOR_COUNT", 1), nvidia_smi=smi,
         cpu=cpu, cpus=os.cpu_count(), python=platform.python_version(), numba_cuda_path=str(Path(numba.cuda.__file__)
                                                                                              .parent), **versions)


def part_warmup(out, budget):
    """The CPU kernels the parts use, compiled into numba's cache (N = 9: the types are those of every size)."""
    from bench_fem import affine_response
    from stickslip.fem.backends import make_backend
    from stickslip.fem.parameters import FemParams
    from stickslip.mesh import MeshParams, build_stack_mesh

    start = time.perf_counter()
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    for relaxation in ("dynamic", "exact"):
        params = FemParams(N=9, plates=2, seed=1, k_drive=1e-3, relaxation=relaxation, nchunk=200)
        sim = kicked(params, mesh, make_backend(), affine_response(params, mesh))
        sim.backend.advance(2)
        sim.protocol.kick(params.margin)
    emit(out, part="warmup", what="structured backend at N = 9, both relaxations",
         seconds=time.perf_counter() - start)


def part_sanity(out, budget):
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
    states, last = {}, 0.0
    spreads = [("tiles", groups) for groups in SIZES["sanity_groups"]] + [("resident", None)]
    for kernel, groups in spreads:
        if not budget.allows(out, "sanity", 2 * last, kernel=kernel, groups=groups):
            continue
        start = time.perf_counter()
        backend = CudaBackend(groups=groups, kernel=kernel)
        gpu = kicked(dataclasses.replace(params, backend="cuda"), mesh, backend, response)
        gpu.backend.advance(steps)
        u, v, idx = states[kernel, groups] = gpu.backend.read("u", "v", "idx")
        last = time.perf_counter() - start
        emit(out, part="sanity", kernel=kernel, groups=groups,
             blocks_used=sorted(gpu.backend.batch.launcher.groups_used), seconds=last,
             u_vs_cpu=float(np.abs(u - reference[0]).max() / np.abs(reference[0]).max()),
             wells_equal_cpu=bool(np.array_equal(idx, reference[2])))
    first = next(iter(states.values()))
    emit(out, part="sanity", spreads=len(states), same_bytes_for_every_spread_and_kernel=all(
        same_bytes(first, state) for state in states.values()))


def _reference_run(path, kernel):
    from stickslip.fem.backends.cuda import CudaBackend
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.run import simulate_to_file
    from stickslip.mesh import MeshParams, build_stack_mesh

    params = FemParams(N=9, plates=2, seed=0, k_drive=1e-3, drive="fixed-lever", nchunk=200, yield_strains="stop",
                       max_increments=SIZES["reference_increments"], relaxation=SIZES["relaxation"],
                       quiet_steps=SIZES["quiet_steps"], backend="cuda")
    start = time.perf_counter()
    simulate_to_file(params, path, build_stack_mesh(MeshParams(N=9, plates=2)),
                     CudaBackend(groups=1 if kernel == "tiles" else None, kernel=kernel), producer=PRODUCER)
    return time.perf_counter() - start


def part_fidelity(out, budget):
    import h5py

    from stickslip.fem.backends.cuda import CudaBackend, run_ensemble
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.run import simulate_to_file
    from stickslip.fem.stiffness import PAPER_PHI
    from stickslip.formats.fem_run import read_increments
    from stickslip.mesh import MeshParams, build_stack_mesh

    directory = Path(out) / "fidelity"
    directory.mkdir(exist_ok=True)
    reference = Path(os.environ.get("GPU_CHECK_REFERENCE", ROOT / ".device" / "reference" / "FixedLever_historic.h5"))
    with h5py.File(reference) as ref:
        expected = {"epsd": ref["epsd"][...], "sigd": ref["sigd"][...], "fxdrive": ref["fxdrive_layers"][...]}
    files, last = {}, 0.0
    for kernel in KERNELS:
        if not budget.allows(out, "fidelity", 1.5 * last, check="reference N=9", kernel=kernel):
            continue
        files[kernel] = directory / f"reference-{kernel}.h5"
        last = _reference_run(files[kernel], kernel)
        table = read_increments(files[kernel])
        got = {"epsd": table["epsd"].to_numpy(), "sigd": table["sigd"].to_numpy(),
               "fxdrive": table[[f"fxdrive_{layer}" for layer in range(3)]].to_numpy()}
        worst = {}
        for name in got:
            n = min(len(got[name]), len(expected[name]))
            scale = np.maximum(np.abs(expected[name][:n]), 1e-12)
            worst[name] = float(np.max(np.abs(got[name][:n] - expected[name][:n]) / scale))
        emit(out, part="fidelity", check="reference N=9", kernel=kernel, increments=len(table),
             reference_increments=350, worst_relative=worst, seconds=last,
             within_1e_9=all(v < 1e-9 for v in worst.values()))
    if len(files) == len(KERNELS):
        first, *others = files.values()
        emit(out, part="fidelity", check="reference N=9: the kernels' files", same_bytes=all(
            first.read_bytes() == other.read_bytes() for other in others))
    N, plates, seeds = SIZES["mid"], SIZES["mid_plates"], SIZES["seeds"]
    mesh = build_stack_mesh(MeshParams(N=N, plates=plates))

    def params(seed):
        return FemParams(N=N, plates=plates, seed=seed, k_drive=k_drive(PAPER_PHI["stiff"], N), relaxation="exact",
                         quiet_steps=SIZES["quiet_steps"], max_increments=SIZES["batch_increments"], backend="cuda")

    last = 0.0
    for kernel in KERNELS:  # the first needs a quarter of the part's budget left
        if not budget.allows(out, "fidelity", 1.5 * last or budget.total / 4, check="batch member = alone",
                             kernel=kernel):
            continue
        start = time.perf_counter()
        for seed in seeds:
            simulate_to_file(params(seed), directory / f"alone-{kernel}-{seed}.h5", mesh, CudaBackend(kernel=kernel),
                             producer=PRODUCER)
        alone = time.perf_counter() - start
        start = time.perf_counter()
        run_ensemble([lambda backend, seed=seed: simulate_to_file(params(seed), directory / f"batch-{kernel}-{seed}.h5",
                                                                  mesh, backend, producer=PRODUCER)
                      for seed in seeds], kernel=kernel)
        last = time.perf_counter() - start + alone
        equal = [(directory / f"alone-{kernel}-{seed}.h5").read_bytes()
                 == (directory / f"batch-{kernel}-{seed}.h5").read_bytes() for seed in seeds]
        same = [(directory / f"batch-{kernel}-{seed}.h5").read_bytes()
                == (directory / f"batch-{KERNELS[0]}-{seed}.h5").read_bytes()
                if (directory / f"batch-{KERNELS[0]}-{seed}.h5").exists() else None for seed in seeds]
        emit(out, part="fidelity", check=f"batch member = alone (N={N}, {plates} plates, {SIZES['batch_increments']} "
             "increments)", kernel=kernel, equal=equal, same_bytes_as_tiles=same, seconds_alone=alone,
             seconds_batch=last - alone)


def _timed(batch, slots):
    """Microseconds per time step of ``slots``: a warm launch, then launches for about ``timed_seconds``."""
    launch = SIZES["launch"]
    batch.launcher.minimise(slots, batch.state, launch)  # compiles the kernel on its first launch
    start = time.perf_counter()
    batch.launcher.minimise(slots, batch.state, launch)
    first = time.perf_counter() - start
    rounds = max(1, int(SIZES["timed_seconds"] / max(first, 1e-9)))
    start = time.perf_counter()
    for _ in range(rounds):
        batch.launcher.minimise(slots, batch.state, launch)
    return 1e6 * (time.perf_counter() - start) / (rounds * launch), rounds * launch


def _compiled(launcher):
    """Registers, local and shared memory of the launcher's minimisation kernel as the driver compiled it (none on
    the simulator)."""
    overloads = list(getattr(getattr(launcher.kernels, launcher.minimiser), "overloads", {}).values())
    if not overloads or not hasattr(overloads[0], "regs_per_thread"):
        return {}
    return {"registers": overloads[0].regs_per_thread, "local_bytes_per_thread": overloads[0].local_mem_per_thread,
            "shared_bytes_per_block": overloads[0].shared_mem_per_block}


def _speed(out, budget, plates):
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
    model, state, epsy = sim.model, sim.stack.stored(), sim.stack.yield_strains
    last = {kernel: (0.0, 1) for kernel in KERNELS}  # seconds of the last configuration, its realisations
    for count in (1,) + SIZES["batches"]:
        for kernel in KERNELS:
            seconds, realisations = last[kernel]
            if not budget.allows(out, "speed", 1.2 * seconds * count / realisations, plates=plates, batch=count,
                                 kernel=kernel):
                continue
            start = time.perf_counter()
            batch = DeviceBatch(sim.backend.batch.mesh, model.law, count, None, kernel)
            members = [CudaBackend(kernel=kernel).bound(model, mesh, batch, epsy) for _ in range(count)]
            for member in members:
                member.set_load_direction(response.delta_u, response.delta_target, response.delta_lever)
                member.set_state(state.u, state.target, state.lever_target, state.t)
                batch.begin(member.slot, (0.0, 1, 10 ** 12, 0, False, 0))
            slots = [member.slot for member in members]
            try:
                per_step, steps = _timed(batch, slots)
            except ValueError as error:  # the resident kernel's realisation does not fit the device at once
                emit(out, part="speed", N=N, plates=plates, batch=count, kernel=kernel, does_not_fit=str(error))
                last[kernel] = (float("inf"), 1)
                continue
            last[kernel] = (time.perf_counter() - start, count)
            emit(out, part="speed", N=N, plates=plates, elements=mesh.nelem, dofs=model.ndof, batch=count,
                 kernel=kernel, blocks_per_realisation=max(batch.launcher.groups_used),
                 threads_per_block=batch.launcher.block, co_resident_blocks=batch.launcher.capacity,
                 tiles=batch.mesh.layout.ntile, steps_timed=steps, us_per_step=per_step,
                 us_per_realisation_step=per_step / count, element_steps_per_s=mesh.nelem * count / per_step * 1e6,
                 **_compiled(batch.launcher))
            del members, batch


def part_speed(out, budget):
    for plates in SIZES["big_plates"]:
        _speed(out, budget, plates)


def _events(out, budget, N, regime, count, kernels, meshes):
    from stickslip.fem.backends.cuda import CudaBackend
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.simulation import Simulation
    from stickslip.fem.stiffness import PAPER_PHI
    from stickslip.mesh import MeshParams, build_stack_mesh

    plates = SIZES["mid_plates"]
    if N not in meshes:
        meshes[N] = build_stack_mesh(MeshParams(N=N, plates=plates))
    params = FemParams(N=N, plates=plates, seed=1, k_drive=k_drive(PAPER_PHI[regime], N), backend="cuda",
                       relaxation=SIZES["relaxation"], quiet_steps=SIZES["quiet_steps"])
    for kernel in kernels:
        start = time.perf_counter()
        sim = Simulation(params, meshes[N], CudaBackend(kernel=kernel))
        setup = time.perf_counter() - start
        for _ in range(count):
            sim.loading.step(False)
            t0 = sim.stack.time
            start = time.perf_counter()
            sim.protocol.kick(params.margin)
            seconds = time.perf_counter() - start
            steps = round((sim.stack.time - t0) / sim.model.dt)
            emit(out, part="events", backend="cuda", kernel=kernel, N=N, plates=plates, regime=regime,
                 relaxation=params.relaxation, setup_seconds=setup, steps=steps, seconds=seconds,
                 us_per_step=1e6 * seconds / max(steps, 1),
                 paper_protocol_hours=2000 * seconds / 3600 if N == 1458 else None)
            if not budget.allows(out, "events", 2 * seconds, N=N, regime=regime, kernel=kernel, next_event=True):
                return False
    return True


def part_events(out, budget):
    meshes = {}
    plan = [(SIZES["big"], "stiff", SIZES["big_events"]), (SIZES["mid"], "stiff", SIZES["events"]),
            (SIZES["mid"], "compliant", SIZES["events"]), (SIZES["big"], "compliant", SIZES["big_compliant_events"])]
    for N, regime, count in plan:
        if count and not _events(out, budget, N, regime, count, KERNELS, meshes):
            return


def part_cpu_step(out, budget):
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


PARTS = {"preflight": part_preflight, "warmup": part_warmup, "fidelity": part_fidelity, "speed": part_speed,
         "sanity": part_sanity, "events": part_events, "cpu-step": part_cpu_step}


def main(argv=None):
    part, out = (sys.argv[1:] if argv is None else argv)[:2]
    Path(out).mkdir(parents=True, exist_ok=True)
    budget = Budget()
    emit(out, started=part, budget_seconds=budget.left() + RESERVE)
    start = time.perf_counter()
    try:
        with device_context():
            PARTS[part](out, budget)
    except Exception as error:  # the error is a result too; run.sh goes on with the next part
        emit(out, part=part, error=f"{type(error).__name__}: {error}")
        raise
    emit(out, ended=part, seconds=time.perf_counter() - start)


if __name__ == "__main__":
    main()
