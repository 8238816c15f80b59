"""The ``cuda`` backend without a GPU: its kernels on numba's CUDA simulator against the CPU, and compiled for the H100.

numba-cuda runs kernels on its simulator with ``NUMBA_ENABLE_CUDASIM=1`` (read when numba-cuda is
imported: every simulated check runs in a fresh Python). The simulator runs each thread as a Python
thread, a time step of an N = 9 stack in ~0.1-0.3 s: the checks are short sequences, each against the
``structured`` CPU backend from the same state (states within round-off, wells and statuses equal):
the force evaluation (fixed and free lever), time steps after a kick, a minimisation stopped by each of
its criteria (step limit, quiet window, residual, margin) with the recorded well changes, the exact
relaxation's direct solve, a thermal increment, a checkpoint (the changes of well since it counted on the device,
the rollback across a change of the held yield strains), and a batch of three realisations whose every member
equals the same realisation run alone, bit for bit. The simulator checks no types: every kernel is also
compiled to PTX for sm_90 (the H100) with numba-cuda's NVVM. Skipped without numba-cuda (failed instead
where ``STICKSLIP_REQUIRE_CUDA_TOOLS`` is set, as .ci/run does); the checks that need a real GPU are in
benchmarks/gpu/ (docs/benchmarks.md).
"""

import json
import os
import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.slow


def _run(script, timeout=1800, simulator=True):
    """Run ``script`` in a fresh Python (on numba's CUDA simulator unless ``simulator`` is False); its last line, as
    JSON."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1" if simulator else "0"}
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(PRELUDE) + textwrap.dedent(script)],
                          capture_output=True, text=True, timeout=timeout, env=env)
    assert done.returncode == 0, done.stderr[-4000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


PRELUDE = """
    import json
    import numpy as np
    from stickslip.fem.backends import make_backend
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.simulation import Simulation
    from stickslip.mesh import MeshParams, build_stack_mesh

    FIELDS = ("u", "v", "a", "f", "eps", "sig", "ubar", "target", "lever", "t")
    CHECKED = ("u", "v", "a", "f", "idx", "eps", "sig", "ubar", "target", "lever", "t")

    def pair(**values):
        values = {"N": 9, "plates": 2, "seed": 1, "k_drive": 1e-3, "dt_scale": 4.0, **values}
        mesh = build_stack_mesh(MeshParams(N=values["N"], plates=values["plates"]))
        cpu = Simulation(FemParams(**values), mesh, make_backend())
        gpu = Simulation(FemParams(**values, backend="cuda"), mesh, make_backend("cuda"),
                         response=cpu.loading.response)
        return cpu, gpu

    def compare(cpu, gpu):
        out = {"idx": bool(np.array_equal(cpu.backend.read("idx")[0], gpu.backend.read("idx")[0]))}
        for name in FIELDS:
            a, b = cpu.backend.read(name)[0], gpu.backend.read(name)[0]
            scale = float(np.abs(a).max())
            out[name] = float(np.abs(a - b).max()) / scale if scale else float(np.abs(b).max())
        return out
"""

#: Relative difference allowed between the device's and the CPU's arrays (to their largest entry) after a force
#: evaluation: round-off of other summation orders.
EVALUATION = 1e-12
#: The same after a few time steps: that round-off grown by the dynamics (a layer's average enters the drive as
#: ``ubar - target``, a difference of nearly equal numbers; a block sheared ten wells ahead moves violently).
ROUND_OFF = 1e-9


def _close(differences, tolerance=ROUND_OFF):
    assert differences.pop("idx"), "the wells differ"
    assert all(value < tolerance for value in differences.values()), differences


def test_every_kernel_compiles_for_sm_90_with_one_grid_barrier_per_step_no_spills_and_no_floating_point_atomics(
        numba_cuda):
    # every kernel for the cusp law; the law's own for the smooth law (the others do not depend on it); compiled to
    # PTX by NVVM, then to machine code by ptxas (nvJitLink) under the launch's register cap
    result = _run("""
    from stickslip.fem.backends.cuda.compile import KERNELS, kernel_figures
    from stickslip.fem.constants import derived_constants
    from stickslip.fem.stack import stack_model
    out = {}
    for law, kernels in (("cusp", KERNELS), ("smooth", ("minimise", "resident", "evaluate"))):
        params = FemParams(N=9, plates=2, nchunk=30, interface_law=law)
        mesh = build_stack_mesh(MeshParams(N=9, plates=2))
        model, _ = stack_model(params, mesh, derived_constants(params, mesh))
        for name, figures in kernel_figures(model, mesh, kernels).items():
            out[f"{law}:{name}"] = figures
    print(json.dumps(out))
    """, simulator=False)
    from stickslip.fem.backends.cuda.kernels import MAX_REGISTERS

    assert len(result) == 15
    minimisers = ("minimise", "resident")
    for name, figures in result.items():
        assert figures["target"] == "sm_90", name
        assert figures["float_atomics"] == [], name  # no atom. or red. on .f16/.f32/.f64
        assert figures["shared_bytes"] <= 48 * 1024, name  # static shared memory of one block
        # the minimisation kernels' one barrier arrival sits in their time-step loop, its poll after it (the compiler
        # may copy the poll's load); no other kernel has either
        minimiser = name.split(":")[1] in minimisers
        assert figures["grid_barriers"] == minimiser and (figures["barrier_spins"] > 0) == minimiser, name
        # no spills, and the minimisation kernels under their cap
        assert figures["spill_store_bytes"] == figures["spill_load_bytes"] == 0, (name, figures)
        if minimiser:
            assert figures["registers"] <= MAX_REGISTERS, (name, figures)
    print({name: {k: figures[k] for k in ("registers", "stack_bytes", "block_barriers", "shared_bytes")}
           for name, figures in result.items() if name.split(":")[1] in minimisers})


def test_the_count_of_changed_wells_compiles_for_sm_90_with_integer_atomics_only(numba_cuda):
    result = _run("""
    import numba
    from numba import cuda
    from stickslip.fem.backends.cuda.changed_wells import count_changed
    from stickslip.fem.backends.cuda.compile import ptx_figures
    wells, rows = np.zeros((9, 4), np.int64), np.zeros(9, np.int64)
    signature = tuple(numba.typeof(array) for array in (wells, wells, rows, rows, np.zeros(1, np.int64)))
    text, _ = cuda.compile(count_changed.py_func, signature, device=False, cc=(9, 0), abi="numba", output="ptx")
    print(json.dumps({**ptx_figures(text), "integer_atomics": text.count("atom.global.add.u64")}))
    """, simulator=False)
    assert result["target"] == "sm_90" and result["float_atomics"] == [] and result["integer_atomics"] == 1


@pytest.fixture(scope="module")
def simulated(numba_cuda):
    """Every check on the simulator, in one fresh Python (module docstring); results by check."""
    return _run("""
    from stickslip.fem.backends.cuda import run_ensemble
    from stickslip.fem.thermal.hop import shear_modes
    out = {}
    # the force evaluation and time steps after a kick, fixed and free lever, 3 plates
    for drive in ("fixed-lever", "free-lever"):
        cpu, gpu = pair(plates=3, drive=drive)
        out[f"{drive}:origin"] = compare(cpu, gpu)
        for sim in (cpu, gpu):
            sim.loading.step(False)
            sim.loading.step(True)
        out[f"{drive}:kick"] = compare(cpu, gpu)
        for sim in (cpu, gpu):
            sim.backend.advance(3)
        out[f"{drive}:steps"] = compare(cpu, gpu)
        out[f"{drive}:residual"] = abs(cpu.backend.residual() / gpu.backend.residual() - 1)
    # the step limit, with the well changes of Gauss point 0 recorded: block 4 sheared ~10 wells ahead (it and
    # its neighbours change wells in the first steps)
    cpu, gpu = pair()
    mode = shear_modes(cpu.mesh)[4]
    for sim in (cpu, gpu):
        sim.loading.step(False)
        sim.loading.step(True)
        sim.backend.add_u(sim.model.iface_dofs[4], 6e-3 * mode)
    runs = [sim.backend.minimise(1e-5, 20, 6, 0, True, 0) for sim in (cpu, gpu)]
    out["limit"] = [runs[0][:2], runs[1][:2], bool(np.array_equal(runs[0][2], runs[1][2])), len(runs[0][2]),
                    compare(cpu, gpu)]
    # the quiet window: from a state at rest after a load step no well changes
    cpu, gpu = pair()
    for sim in (cpu, gpu):
        sim.loading.step(False)
    runs = [sim.backend.minimise(1e-5, 50, 100, 0, False, 3)[:2] for sim in (cpu, gpu)]
    out["quiet"] = [runs[0], runs[1], compare(cpu, gpu)]
    # the residual criterion, after the exact relaxation's direct solve (its Newton iterations on the device)
    cpu, gpu = pair(relaxation="exact")
    solved = [sim.relaxation.solve_in_wells(sim.backend) for sim in (cpu, gpu)]
    runs = [sim.backend.minimise(1e-5, 3, 100, 0, False, 0)[:2] for sim in (cpu, gpu)]
    out["converged"] = [solved, runs[0], runs[1], compare(cpu, gpu), float(np.abs(gpu.backend.read("v")[0]).max())]
    # the margin: a kicked point in well 1 with a margin that allows none beyond well 0
    cpu, gpu = pair()
    for sim in (cpu, gpu):
        sim.loading.step(False)
        sim.loading.step(True)
    ny = cpu.stack.yield_strains.shape[1]
    out["margin"] = [sim.backend.minimise(1e-5, 20, 100, ny - 1, False, 0)[:2] for sim in (cpu, gpu)]
    # a thermal load increment (kinetic Monte Carlo on the host, the hop's relaxation on the device)
    cpu, gpu = pair(relaxation="exact", quiet_steps=3, temperature=2e-3, drive_rate=1e-5)
    out["thermal"] = [[sim.protocol.step(5, 1)] for sim in (cpu, gpu)]
    out["thermal_state"] = compare(cpu, gpu)
    out["thermal_wells"] = bool(np.array_equal(cpu.stack.well_index(), gpu.stack.well_index()))
    # a checkpoint on the device: the changes of well since it counted there, and the rollback across a change of
    # the held yield strains (the windows widened since)
    cpu, gpu = pair()
    out["checkpoint"] = []
    for sim in (cpu, gpu):
        stack = sim.stack
        sim.loading.step(False)
        token, ny, wells = stack.checkpoint(), stack.yield_strains.shape[1], stack.well_index()
        kept = [array.tobytes().hex() for array in sim.backend.read(*CHECKED)]
        sim.loading.step(True)
        stack.widen_wells()
        changed = [stack.changed_since(token), stack.changed_since(token, elements=np.arange(3)),
                   int(np.count_nonzero(stack.well_index() != wells)),
                   int(np.count_nonzero(stack.well_index()[:3] != wells[:3]))]
        stack.rollback(token)
        back = [array.tobytes().hex() for array in sim.backend.read(*CHECKED)]  # the backend's, not the stack's copies
        out["checkpoint"].append(changed + [stack.changed_since(token), back == kept, stack.yield_strains.shape[1] == ny])
    # a batch of three realisations whose minimisations end at different launches, against each alone
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    steps = {1: 3, 2: 5, 3: 2}

    def run(seed, backend):
        sim = Simulation(FemParams(N=9, plates=2, seed=seed, dt_scale=4.0, relaxation="exact", backend="cuda"), mesh,
                         backend)  # exact: the linear response by one solve (the simulator is slow)
        sim.loading.step(False)
        sim.loading.step(True)
        status = sim.backend.minimise(1e-5, 20, steps[seed], 0, False, 0)[:2]
        return [status] + [sim.backend.read(name)[0].tobytes().hex() for name in ("u", "v", "a", "f", "idx")]

    from stickslip.fem.backends.cuda import launch
    launch.STEPS_PER_LAUNCH = 2  # several launches per minimisation
    alone = [run(seed, make_backend("cuda")) for seed in steps]
    together = run_ensemble([lambda backend, seed=seed: run(seed, backend) for seed in steps])
    out["batch"] = {"equal": [a == b for a, b in zip(alone, together)], "status": [a[0] for a in alone]}
    print(json.dumps(out))
    """)


def test_the_force_evaluation_and_time_steps_after_a_kick_equal_the_cpu(simulated):
    for drive in ("fixed-lever", "free-lever"):
        for stage, tolerance in (("origin", EVALUATION), ("kick", EVALUATION), ("steps", ROUND_OFF)):
            _close(dict(simulated[f"{drive}:{stage}"]), tolerance)
        assert simulated[f"{drive}:residual"] < ROUND_OFF


def test_a_minimisation_stops_as_on_the_cpu_by_each_criterion_and_records_the_same_well_changes(simulated):
    limit_cpu, limit_gpu, same_events, nevents, state = simulated["limit"]
    assert limit_cpu == limit_gpu == [-1, 6] and same_events and nevents > 0
    _close(state)
    assert simulated["quiet"][0] == simulated["quiet"][1] == [2, 3]
    _close(simulated["quiet"][2])
    solved, converged_cpu, converged_gpu, state, speed = simulated["converged"]
    assert solved == [True, True] and converged_cpu == converged_gpu == [1, 3] and speed == 0.0
    _close(state)
    assert simulated["margin"][0] == simulated["margin"][1] == [0, 1]


def test_a_thermal_increment_draws_the_same_event_on_the_device(simulated):
    cpu, gpu = simulated["thermal"]
    assert cpu == gpu
    assert simulated["thermal_wells"]
    differences = dict(simulated["thermal_state"])
    assert differences.pop("idx")
    assert all(value < 1e-9 for value in differences.values()), differences  # exact solves: tol^2 residuals


def test_a_checkpoint_on_the_device_counts_the_changes_of_well_and_rolls_back_bit_for_bit(simulated):
    cpu, gpu = simulated["checkpoint"]
    assert cpu == gpu
    changed, in_three, wells, wells_in_three, after, equal, width = gpu
    assert changed == wells > 0 and in_three == wells_in_three
    assert after == 0 and equal and width  # the yield strains held at the checkpoint held again


def test_a_batch_member_equals_the_same_realisation_run_alone_bit_for_bit(simulated):
    assert simulated["batch"]["status"] == [[-1, 3], [-1, 5], [-1, 2]]
    assert simulated["batch"]["equal"] == [True, True, True]


def test_a_thermal_run_with_junction_aging_draws_and_relaxes_the_same_hop_after_the_same_redraws(numba_cuda, tmp_path):
    # a run file of each backend: the junctions drawn at the start and pushed to the device, the kinetic Monte Carlo
    # on the host (77 redraws, each changing the yield strains the device holds, then a hop), the hop relaxed on the
    # device: the same events and junctions as the structured backend, times and stresses to round-off. One load
    # increment: the event increment's renewals relax for minutes on the simulator (their minimisations are those
    # of the checks above)
    result = _run(f"""
    from stickslip.fem.run import simulate_to_file
    from stickslip.formats.fem_run import RunFile, read_increments
    from stickslip.h5io import open_file

    values = dict(N=9, plates=2, seed=1, relaxation="exact", temperature=1e-3,
                  drive_rate=2e-8, junction_strengthening=5.0, max_increments=1)
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    out = {{}}
    for backend in ("structured", "cuda"):
        path = {str(tmp_path)!r} + "/" + backend + ".h5"
        simulate_to_file(FemParams(**values, backend=backend), path, mesh, make_backend(backend), producer=("fem", "test"))
        table = read_increments(path)
        with open_file(path, "r") as file:
            run = RunFile(file)
            junctions = [run.state(i)[4] for i in range(run.nstored)]
        out[backend] = {{
            "events": table[["kick", "hop_block", "hop_direction", "failed_hops", "redraws", "redraw_block", "S_a1",
                             "A_a1"]].to_numpy().tolist(),
            "wells": [j["junction_well"].tolist() for j in junctions],
            "depths": np.array([j["junction_depth"] for j in junctions]),
            "floats": table[["t", "sigd", "epsd"]].to_numpy()}}
    cpu, gpu = out["structured"], out["cuda"]
    print(json.dumps({{"events": [cpu["events"], gpu["events"]], "wells": cpu["wells"] == gpu["wells"],
                      "depths": float(np.abs(cpu["depths"] - gpu["depths"]).max()),
                      "floats": float((np.abs(cpu["floats"] - gpu["floats"]) / np.abs(cpu["floats"]).max(axis=0)).max())}}))
    """)
    cpu, gpu = result["events"]
    assert cpu == gpu
    assert cpu[1][1] >= 0 and cpu[1][4] > 10  # a hop after redraws: the run has both to compare
    assert result["wells"] and result["depths"] == 0.0  # the junctions: drawn on the host from the same streams
    assert result["floats"] < ROUND_OFF


def test_the_cuda_backend_without_a_gpu_is_one_line_before_any_file_is_touched(tmp_path, capsys):
    from stickslip.cli import main
    from stickslip.fem.backends.cuda import CudaBackend

    if not CudaBackend.unavailable():
        pytest.skip("a GPU is available here")
    output = tmp_path / "run.h5"
    assert main(["simulate", "--solver", "fem", "--param", "N=9", "--param", "backend=cuda", "-o", str(output)]) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith("stickslip: error: parameter 'backend': 'cuda' cannot run on this machine: ")
    assert len(error.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []
    # another run's file is left as it is, even with --overwrite
    output.write_bytes(b"another run")
    assert main(["simulate", "--solver", "fem", "--param", "N=9", "--param", "backend=cuda", "--overwrite", "-o",
                 str(output)]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"] and output.read_bytes() == b"another run"


GPU_STUDY = """
gpu_batch: 2
solvers:
  fem:
    - params: {N: 9, max_increments: 1, backend: cuda, relaxation: exact}  # the linear response by one solve
      grid:
        plates: [2]
        seed: [1, 2]
    - params: {N: 9, max_increments: 1, backend: cuda, relaxation: exact, temperature: 1.0e-3, drive_rate: 2.0e-8,
               junction_strengthening: 5.0}  # a thermal run with junction aging in the same batches
      grid:
        plates: [2]
        seed: [3]
    - params: {N: 9, max_increments: 1}
      grid:
        plates: [2]
        seed: [1]
analyses:
  numerical-events: {}
figures: {}
"""


def test_a_gpu_batch_is_one_job_that_writes_every_run_s_usual_file(numba_cuda, tmp_path):
    # three runs of fem on the GPU in batches of at most 2 (one job each; a thermal run with junction aging among
    # them), beside a CPU run; on the simulator, one load increment each: the files, records and database rows are the
    # usual ones
    from conftest import copy_workflow
    from test_workflow import planned_jobs, snakemake

    directory = copy_workflow(tmp_path)
    (directory / "gpu.yaml").write_text(GPU_STUDY)
    planned = planned_jobs(snakemake(directory, "-n", "--cores", "2", "--configfile", "gpu.yaml").stdout)
    assert planned["simulate"] == 1 and sum(v for k, v in planned.items() if k.startswith("simulate_batch_")) == 2
    os.environ["NUMBA_ENABLE_CUDASIM"] = "1"  # read by the jobs (numba-cuda's simulator)
    try:
        snakemake(directory, "--cores", "2", "--configfile", "gpu.yaml")
    finally:
        del os.environ["NUMBA_ENABLE_CUDASIM"]
    results = directory / "results" / "gpu"
    runs = sorted((results / "sim" / "fem").glob("*.h5"))
    assert len(runs) == 4 and all(run.with_suffix(".provenance.json").is_file() for run in runs)
    logs = sorted(p.name for p in (results / "logs" / "sim" / "fem").glob("batch-*.log"))
    assert len(logs) == 2
    import sqlite3

    with sqlite3.connect(results / "stickslip.sqlite") as db:
        backends = sorted(json.loads(params).get("backend", "structured")
                          for (params,) in db.execute("SELECT r.params FROM runs AS r JOIN simulations AS s "
                                                      "ON s.run_id = r.run_id"))
    assert backends == ["cuda", "cuda", "cuda", "structured"]
    with sqlite3.connect(results / "stickslip.sqlite") as db:
        temperatures = sorted(json.loads(params).get("temperature", 0.0) for (params,) in db.execute(
            "SELECT r.params FROM runs AS r JOIN simulations AS s ON s.run_id = r.run_id"))
    assert temperatures == [0.0, 0.0, 0.0, 1e-3]


def test_an_ensemble_computes_a_linear_response_in_a_batch_of_the_elastic_law(numba_cuda):
    # Elastic(K, G) and Cusp(K, G) are equal tuples: the linear response of an ensemble's run was once computed by
    # the cusp law's kernels in the run's own batch (its infinite yield strains gave NaN, the solve failed)
    result = _run("""
    from stickslip.fem.backends.cuda.batch import DeviceBatch
    from stickslip.fem.backends.cuda.ensemble import Ensemble
    from stickslip.fem.constants import derived_constants
    from stickslip.fem.laws import Elastic
    from stickslip.fem.stack import stack_model

    params = FemParams(N=9, plates=2, nchunk=30)
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    model, _ = stack_model(params, mesh, derived_constants(params, mesh))
    elastic = model._replace(law=Elastic(*model.law))
    ensemble = Ensemble(1)
    cusp_batch, elastic_batch = ensemble.batch_for(model, mesh), ensemble.batch_for(elastic, mesh)
    try:
        DeviceBatch(cusp_batch.mesh, model.law, 1).attach(elastic, object())
        refused = ""
    except ValueError as error:
        refused = str(error)
    print(json.dumps({"laws": [type(cusp_batch.law).__name__, type(elastic_batch.law).__name__],
                      "same": cusp_batch is elastic_batch, "refused": refused}))
    """)
    assert result["laws"] == ["Cusp", "Elastic"] and not result["same"]
    assert result["refused"].startswith("a batch computes one law: Elastic(")


def test_runs_minimising_in_different_batches_at_once_meet_in_one_round(numba_cuda):
    # two members of an ensemble: one in the batch of its interface law, one in the batch of the elastic law (its
    # linear response) at the same time; and a third that leaves while the others wait (its run ended)
    result = _run("""
    import threading
    from stickslip.fem.backends.cuda.ensemble import Ensemble

    class Batch:
        def __init__(self, name):
            self.name, self.launches = name, []

        def launch(self, slots):
            self.launches.append(slots)
            return {slot: 10 * slot + 1 for slot in slots}

    ensemble, cusp, elastic = Ensemble(3), Batch("cusp"), Batch("elastic")
    members = [ensemble.join() for _ in range(3)]
    results = {}

    def run(name, member, batch, slot):
        if batch is not None:
            results[name] = member.meet(batch, slot)
        member.leave()

    threads = [threading.Thread(target=run, args=args, daemon=True)
               for args in (("a", members[0], cusp, 0), ("b", members[1], elastic, 3), ("c", members[2], None, None))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=60)
    print(json.dumps({"alive": [thread.is_alive() for thread in threads], "results": results,
                      "launches": [cusp.launches, elastic.launches], "active": ensemble._active}))
    """)
    assert result["alive"] == [False, False, False]  # no run waits for another in another batch
    assert result["results"] == {"a": 1, "b": 31}
    assert result["launches"] == [[[0]], [[3]]]  # one launch per batch in the round
    assert result["active"] == 0
