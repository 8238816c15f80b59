"""The ``cuda`` backend's realisations spread over several blocks, on numba's simulator: no hang, the same bytes.

numba's simulator runs a launch's blocks one after another and reports one co-resident block, so the
multi-block paths (the barrier of a time step, sums over the tiles of other blocks, events recorded by
several blocks) never ran there. :func:`stickslip.fem.backends.cuda.simulator.concurrent_blocks` runs the
blocks of a launch at once and reports a given number of co-resident blocks; each check runs in a fresh
Python with a time limit, so a hang fails it. The checks, each against the same realisation on one block
(and the ``structured`` CPU backend's recorded events):

- a realisation spread over three blocks (every tile of an N = 9 stack its own block);
- three runs of an ensemble whose blocks per realisation change between launches as runs end (2, then 3);
- an event buffer of two rows that a step overflows (emptied between launches, grown for the step);
- blocks that cannot be co-resident (the simulator's sequential blocks, a device claimed to hold two):
  the barrier's deadline ends the launch with an error, not a hang.

The resident kernel (:mod:`stickslip.fem.backends.cuda.resident`, every tile its own block for a launch) runs
each check beside the tiles kernel and gives its bytes: velocities, forces, strains and stresses written at the
end of a launch only, realisations that do not fit the device at once in further launches.
"""

import json
import os
import subprocess
import sys
import textwrap

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.usefixtures("numba_cuda")]

#: Seconds a check may take (a hang fails it).
TIMEOUT = int(os.environ.get("STICKSLIP_CUDA_SIM_TIMEOUT", "900"))


PRELUDE = """
    import json
    import numpy as np
    from stickslip.fem.backends import make_backend
    from stickslip.fem.backends.cuda import CudaBackend, run_ensemble
    from stickslip.fem.backends.cuda import batch as batch_module, launch as launch_module
    from stickslip.fem.backends.cuda.simulator import co_resident, concurrent_blocks
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.simulation import Simulation
    from stickslip.fem.thermal.hop import shear_modes
    from stickslip.mesh import MeshParams, build_stack_mesh

    MESH = build_stack_mesh(MeshParams(N=9, plates=2))  # 72 nodes: 3 tiles of 32
    VALUES = {"N": 9, "plates": 2, "k_drive": 1e-3, "dt_scale": 4.0}
    RESPONSE = Simulation(FemParams(**VALUES, seed=1), MESH, make_backend()).loading.response

    def kicked(backend, seed=1, amplitude=2e-2):
        # block 4 sheared a few wells ahead after a load step: its neighbours change wells in the first steps
        params = FemParams(**VALUES, seed=seed, backend=backend.name)
        sim = Simulation(params, MESH, backend, response=RESPONSE)
        sim.loading.step(False)
        sim.loading.step(True)
        sim.backend.add_u(sim.model.iface_dofs[4], amplitude * shear_modes(MESH)[4])
        return sim

    def state(sim):
        return [sim.backend.read(name)[0].tobytes().hex() for name in ("u", "v", "a", "f", "eps", "sig", "idx", "t")]

    def groups(sim):
        return {int(g): n for g, n in sim.backend.batch.launcher.groups_used.items()}
"""


def _run(script):
    """Run ``script`` on the simulator in a fresh Python (at most :data:`TIMEOUT` s); its last line, as JSON."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1"}
    try:
        done = subprocess.run([sys.executable, "-c", textwrap.dedent(PRELUDE) + textwrap.dedent(script)],
                              capture_output=True, text=True, timeout=TIMEOUT, env=env)
    except subprocess.TimeoutExpired:
        pytest.fail(f"the check did not end within {TIMEOUT} s (a hang)")
    assert done.returncode == 0, done.stderr[-4000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_realisation_spread_over_three_blocks_gives_the_bytes_of_one_block_with_either_kernel():
    result = _run("""
    cpu = kicked(make_backend())
    expected = cpu.backend.minimise(1e-5, 20, 6, 0, True, 0)
    out = {"cpu": [list(expected[:2]), expected[2].tolist()]}
    for name, G, kernel in (("1", 1, "tiles"), ("3", 3, "tiles"), ("resident", None, "resident")):
        with concurrent_blocks(6):
            sim = kicked(CudaBackend(groups=G, kernel=kernel))
            status, steps, events = sim.backend.minimise(1e-5, 20, 6, 0, True, 0)
        out[name] = [[status, steps], events.tolist(), state(sim), groups(sim)]
    print(json.dumps(out))
    """)
    assert result["3"][3] == {"3": 1} and result["1"][3] == {"1": 1}  # one launch, spread over 3 blocks / on 1
    assert result["resident"][3] == {"3": 1}  # every tile its block
    assert result["3"][:3] == result["1"][:3] == result["resident"][:3]  # the same status, events and bytes
    assert result["1"][:2] == result["cpu"] and len(result["cpu"][1]) == 10  # the CPU's well changes, in its order


def test_blocks_per_realisation_change_between_launches_while_runs_leave():
    # three runs of an ensemble on a device that holds 6 blocks, launches of 2 steps: the first launch spreads the
    # 3 realisations over 2 blocks each; one run then ends, and the next launch spreads the other two over 3
    # blocks, in the middle of their residual criterion's window of 3 steps (they converge at step 3)
    result = _run("""
    launch_module.STEPS_PER_LAUNCH = 2

    def converging(seed, backend):
        params = FemParams(**VALUES, seed=seed, relaxation="exact", backend=backend.name)
        sim = Simulation(params, MESH, backend, response=RESPONSE)
        solved = sim.relaxation.solve_in_wells(sim.backend)  # its Newton iterations on the device
        status = sim.backend.minimise(1e-5, 3, 100, 0, False, 0)[:2]
        return [solved, list(status), state(sim), groups(sim)]

    def ending(backend):
        sim = kicked(backend, 3, 6e-3)
        return [True, list(sim.backend.minimise(1e-5, 20, 2, 0, False, 0)[:2]), state(sim), groups(sim)]

    runs = [lambda backend: converging(1, backend), lambda backend: converging(2, backend), ending]
    with concurrent_blocks(6):
        alone = [run(CudaBackend()) for run in runs]
        together = run_ensemble(runs)
        resident = run_ensemble(runs, kernel="resident")
    print(json.dumps({"alone": alone, "together": together, "resident": resident}))
    """)
    alone, together, resident = result["alone"], result["together"], result["resident"]
    assert [a[:2] for a in alone] == [[True, [1, 3]], [True, [1, 3]], [True, [-1, 2]]]
    assert [a[:3] for a in alone] == [t[:3] for t in together]  # every member's bytes as alone
    assert [t[3] for t in together] == [{"2": 1, "3": 1}, {"2": 1, "3": 1}, {"2": 1}]
    assert [a[3] for a in alone] == [{"3": 2}, {"3": 2}, {"3": 1}]
    # the resident kernel: 3 realisations of 3 tiles on a device of 6 blocks, two launches in each of the rounds
    # where all three run (the first), one where two run
    assert [a[:3] for a in alone] == [r[:3] for r in resident]
    assert [r[3] for r in resident] == [{"3": 3}, {"3": 3}, {"3": 2}]


def test_an_event_buffer_that_a_step_overflows_is_emptied_and_grown_not_dropped():
    result = _run("""
    batch_module.EVENT_CAPACITY = 2  # a step of this minimisation changes 5 wells
    cpu = kicked(make_backend())
    expected = cpu.backend.minimise(1e-5, 20, 6, 0, True, 0)
    out = {"cpu": [list(expected[:2]), expected[2].tolist()]}
    for kernel in ("tiles", "resident"):
        with concurrent_blocks(6):
            sim = kicked(CudaBackend(groups=3, kernel=kernel))
            got = sim.backend.minimise(1e-5, 20, 6, 0, True, 0)
        out[kernel] = {"gpu": [list(got[:2]), got[2].tolist()], "groups": groups(sim), "state": state(sim),
                       "rows": sim.backend.batch.state.control["events"].shape[1]}
    print(json.dumps(out))
    """)
    for kernel in ("tiles", "resident"):
        assert result[kernel]["gpu"] == result["cpu"] and len(result["cpu"][1]) == 10
        assert result[kernel]["groups"]["3"] > 1  # relaunched after the buffer filled
        assert result[kernel]["rows"] == 5  # grown to the largest step's well changes
    assert result["tiles"]["state"] == result["resident"]["state"]


def test_blocks_that_never_meet_raise_an_error_instead_of_hanging():
    # the simulator runs blocks one after another: claimed co-resident, 2 blocks per realisation never meet
    result = _run("""
    import time
    launch_module.DEADLINE_CYCLES = 200_000_000  # 0.2 s (nanoseconds on the simulator)
    out = {}
    for kernel, capacity in (("tiles", 2), ("resident", 3), ("resident", 2)):
        with co_resident(capacity):
            sim = kicked(CudaBackend(groups=2, kernel=kernel))
            start = time.perf_counter()
            try:
                sim.backend.advance(3)
                error = None
            except (launch_module.BarrierTimeout, ValueError) as caught:
                error = f"{type(caught).__name__}: {caught}"
        out[f"{kernel}:{capacity}"] = {"error": error, "seconds": time.perf_counter() - start}
    print(json.dumps(out))
    """)
    for name in ("tiles:2", "resident:3"):
        error = result[name]["error"]
        assert error.startswith("BarrierTimeout: ") and "did not meet at a barrier" in error
        assert result[name]["seconds"] < 60
    # a device that cannot hold the 3 blocks of a realisation: the resident kernel is refused before a launch
    assert result["resident:2"]["error"] == ("ValueError: cuda: the resident kernel needs the 3 blocks of a "
                                             "realisation at once; the device holds 2 (choose kernel='tiles')")


def test_both_kernels_meet_once_per_step_and_pass_the_same_block_barriers():
    # the barriers a time step costs, counted on the simulator (thread 0 of every block; two launches of 1 and 3
    # steps, the difference): each of the 3 blocks arrives once per step at the realisation's barrier (its counter
    # ends at G x steps), and passes 2 block barriers in its elements, log2(tile) + 2 in its tile's tree, 2 in the
    # grid barrier, log2(LEAVES) + 2 in the sums over the tiles, 1 in the drive and 1 in the verdict
    result = _run("""
    import collections
    import threading
    from numba.cuda.simulator.kernelapi import FakeCUDAModule

    passed = collections.Counter()
    original = FakeCUDAModule.syncthreads

    def counting(self):
        thread = threading.current_thread()
        if thread.threadIdx.x == 0:
            passed[thread.blockIdx.x] += 1
        original(self)

    FakeCUDAModule.syncthreads = counting
    out = {}
    for kernel in ("tiles", "resident"):
        with concurrent_blocks(6):
            sim = kicked(CudaBackend(groups=3, kernel=kernel))
            batch, slot = sim.backend.batch, sim.backend.slot
            batch.begin(slot, (0.0, 1, 10 ** 6, 0, False, 0))
            launches = []
            for nsteps in (1, 3):
                passed.clear()
                batch.launcher.minimise([slot], batch.state, nsteps)
                launches.append({"block_barriers": [passed[b] for b in range(3)],
                                 "arrivals": int(batch.state.control["counter"][slot])})
        out[kernel] = {"launches": launches, "tile": sim.backend.batch.mesh.layout.tile}
    print(json.dumps(out))
    """)
    from stickslip.fem.backends.cuda.layout import LEAVES

    for kernel in ("tiles", "resident"):
        one, three = result[kernel]["launches"]
        assert (one["arrivals"], three["arrivals"]) == (3, 9)  # one grid barrier per step, each of the 3 blocks
        per_step = {(b - a) / 2 for a, b in zip(one["block_barriers"], three["block_barriers"])}
        tile = result[kernel]["tile"]
        assert per_step == {2 + (tile.bit_length() - 1 + 2) + 2 + (LEAVES.bit_length() - 1 + 2) + 1 + 1}, kernel


def test_the_resident_kernel_stops_by_the_quiet_window_and_the_margin_and_drives_a_free_lever_as_the_tiles_kernel():
    # the criteria the other checks do not reach (tests/test_fem_cuda.py runs them against the CPU with the tiles
    # kernel): the same statuses and bytes with both kernels
    result = _run("""
    free = {**VALUES, "seed": 1, "drive": "free-lever"}
    free_response = Simulation(FemParams(**free), MESH, make_backend()).loading.response
    out = {}
    for kernel in ("tiles", "resident"):
        with concurrent_blocks(6):
            runs = []
            sim = Simulation(FemParams(**VALUES, seed=1, backend="cuda"), MESH, CudaBackend(kernel=kernel),
                             response=RESPONSE)
            sim.loading.step(False)
            runs.append([list(sim.backend.minimise(1e-5, 50, 100, 0, False, 3)[:2]), state(sim)])  # quiet window
            sim = kicked(CudaBackend(kernel=kernel), amplitude=0.0)
            ny = sim.stack.yield_strains.shape[1]
            runs.append([list(sim.backend.minimise(1e-5, 20, 100, ny - 1, False, 0)[:2]), state(sim)])  # margin
            sim = Simulation(FemParams(**free, backend="cuda"), MESH, CudaBackend(kernel=kernel),
                             response=free_response)
            sim.loading.step(False)
            sim.loading.step(True)
            sim.backend.advance(3)
            lever = [sim.backend.read(name)[0].tobytes().hex() for name in ("ubar", "lever")]
            runs.append([[0, 3], state(sim) + lever])
        out[kernel] = runs
    print(json.dumps(out))
    """)
    assert [run[0] for run in result["tiles"]] == [[2, 3], [0, 1], [0, 3]]  # quiet, margin, free lever
    assert result["resident"] == result["tiles"]
