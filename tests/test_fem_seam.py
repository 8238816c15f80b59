"""The fem core's seams, through the worked examples of docs/writing-a-plugin.md ("A law") and docs/developing.md
("Extending the fem solver").

The law example (``SoftCusp``) and the backend example (``CountingBackend``) are taken from the
documents as they are and run in a fresh Python (registering a law or a backend is global):

- a new law is one module: with ``c = 1`` it is the cusp bit for bit, its parameter is checked by name;
- the backend owns the state: the example backend counts every transfer between its state and the host
  (what a device backend would copy). A whole event with the dynamic relaxation moves the same number
  of arrays whatever its number of time steps; the exact relaxation adds exactly one exchange per
  Newton iteration; a thermal increment goes through the same seam.
"""

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from stickslip.fem.backends import make_backend
from stickslip.fem.parameters import FemParams
from stickslip.fem.simulation import Simulation
from stickslip.mesh import MeshParams, build_stack_mesh

DOCS = [Path(__file__).resolve().parents[1] / "docs" / name for name in ("developing.md", "writing-a-plugin.md")]

pytestmark = pytest.mark.slow


def _example(name):
    """The python block of the documents that defines ``name``."""
    blocks = [block for doc in DOCS for block in re.findall(r"```python\n(.*?)```", doc.read_text(), re.S)]
    found = [block for block in blocks if f"class {name}(" in block]
    assert len(found) == 1, f"docs: one example defining {name} expected"
    return found[0]


def _run(tmp_path, script, own_cache=False):
    """Run ``script`` in a fresh Python beside the two examples (as modules); returns its last line as JSON.

    ``own_cache``: the script's numba cache is its own, so that kernels compiled for the example law (a type of
    this test's module) stay out of the package's cache, which other processes share.
    """
    (tmp_path / "soft_cusp.py").write_text(_example("SoftCusp"))
    (tmp_path / "counting_backend.py").write_text(_example("CountingBackend"))
    env = {**os.environ, **({"NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")} if own_cache else {})}
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=900, env=env)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


PRELUDE = """
    import json
    import numpy as np
    import counting_backend, soft_cusp  # registering them is all it takes
    from stickslip.fem.backends import make_backend
    from stickslip.fem.parameters import FemParams
    from stickslip.fem.simulation import Simulation
    from stickslip.mesh import MeshParams, build_stack_mesh
    from stickslip.plugin_params import ParameterError, parse_params

    def events(sim, count):
        rows = []
        transfers = sim.backend.transfers
        for _ in range(count):
            sim.loading.step(False)
            before, t0 = dict(transfers), sim.stack.time
            assert sim.protocol.kick(5)[0]
            moved = {name: transfers[name] - before.get(name, 0) for name in transfers}
            rows.append((round((sim.stack.time - t0) / sim.model.dt), moved))
        return rows
"""


def _states(law, values):
    """Displacements after ten events of an N = 9 stack with ``law`` (hex of their bytes), from the linear response
    in ``response.npz`` (the elastic one, the same for every law)."""
    return f"""
    mesh = build_stack_mesh(MeshParams(N=9, plates=2))
    stored = np.load("response.npz")
    response = [stored[name] for name in ("delta_u", "delta_eps", "delta_target")] + [float(stored["delta_lever"])]
    sim = Simulation(FemParams(N=9, plates=2, seed=2, interface_law="{law}", law_params={values!r}, dt_scale=4.0),
                     mesh, make_backend(), response=response)
    states = []
    for _ in range(10):
        sim.loading.step(False)
        sim.protocol.kick(5)
        states.append(sim.backend.read("u")[0].tobytes().hex())
    """


def test_a_law_is_one_module_the_soft_cusp_at_c_one_is_the_cusp_bit_for_bit(tmp_path, monkeypatch):
    # the cusp here (its kernels in the package's cache), the example law in a process with a cache of its own
    monkeypatch.chdir(tmp_path)
    params = FemParams(N=9, plates=2, seed=2, dt_scale=4.0)
    np.savez("response.npz", **Simulation(params, build_stack_mesh(MeshParams(N=9, plates=2)),
                                          make_backend()).loading.response._asdict())
    namespace = {}
    exec(textwrap.dedent(PRELUDE.replace("import counting_backend, soft_cusp", "") + _states("cusp", ())), namespace)
    result = _run(tmp_path, PRELUDE + _states("soft-cusp", (1.0,)) + """
    errors = []
    for values in ((), (1.5,)):
        try:
            parse_params(FemParams, {"interface_law": "soft-cusp", "law_params": values})
        except ParameterError as error:
            errors.append(str(error))
    soft = Simulation(FemParams(N=9, plates=2, interface_law="soft-cusp", law_params=(0.5,)), mesh, make_backend(),
                      response=response)
    print(json.dumps({"states": states, "errors": errors, "law": repr(soft.model.law)}))
    """, own_cache=True)
    assert result["states"] == namespace["states"]
    assert result["law"] == "SoftCusp(K=4.5, G=1.0, c=0.5)"
    assert all(error.startswith("parameter 'law_params'") for error in result["errors"])
    assert "takes 1 parameters after K and G: expected the values of (c), got 0" in result["errors"][0]
    assert "c = 1.5 is outside (0, 1]" in result["errors"][1]


def test_the_backend_owns_the_state_transfers_per_event_do_not_grow_with_the_time_steps(tmp_path):
    result = _run(tmp_path, PRELUDE + """
    mesh = build_stack_mesh(MeshParams(N=18, plates=3))
    out = {}
    for relaxation in ("dynamic", "exact"):
        params = FemParams(N=18, plates=3, seed=1, k_drive=1e-4, relaxation=relaxation, backend="counting")
        out[relaxation] = events(Simulation(params, mesh, make_backend("counting")), 12)
    hot = FemParams(N=9, plates=2, seed=1, k_drive=1e-3, relaxation="exact", dt_scale=4.0, temperature=2e-3,
                    drive_rate=1e-5, backend="counting")
    sim = Simulation(hot, build_stack_mesh(MeshParams(N=9, plates=2)), make_backend("counting"))
    transfers = sim.backend.transfers
    thermal = []
    for increment in range(1, 21):
        before = dict(transfers)
        row = sim.protocol.step(5, increment)
        moved = {name: transfers[name] - before.get(name, 0) for name in transfers}
        thermal.append((row["hop_block"], sum(moved.values()) - moved.get("correct", 0)))
    out["thermal"] = thermal
    print(json.dumps(out))
    """)
    dynamic, exact = result["dynamic"], result["exact"]
    steps = [n for n, _ in dynamic]
    assert max(steps) > 2 * min(steps) > 1000  # events of very different lengths
    counts = {sum(moved.values()) for _, moved in dynamic}
    assert len(counts) == 1 and counts.pop() < 40  # the same few arrays per event, whatever its length
    assert all(set(k for k, v in moved.items() if v) == {"read"} for _, moved in dynamic)
    # exact: the same transfers as a dynamic event plus one exchange (force out, correction in) per Newton iteration
    for _, moved in exact:
        assert moved["correct"] > 0
        assert sum(moved.values()) - moved["correct"] == sum(dynamic[0][1].values())
    # thermal increments go through the seam too (hops and threshold kicks): besides the Newton iterations of the
    # exact relaxation, a few dozen arrays per increment
    thermal = result["thermal"]
    assert any(block >= 0 for block, _ in thermal) and any(block < 0 for block, _ in thermal)
    assert max(count for _, count in thermal) < 60


#: A thermal run's transfers, hop by hop: every draw of the kinetic Monte Carlo is marked when it returns, every hop
#: when it starts, and a hop's transfers are those from the draw that chose it to the next draw's return (or the end
#: of the load increment): the load to the hop, the hop, its relaxation, the rollback if it fell back, and what the
#: next draw needs then. Hops that fall back are rare in these runs (none in 40 increments): the first draw of every
#: fourth load increment is a backward hop instead (these fall back), and the draw after it must find the stack as the
#: hop found it, bit for bit.
HOPS = """
    from counting_backend import TRANSFERS
    from stickslip.fem.thermal.barriers import BACKWARD
    from stickslip.fem.thermal.sampler import HOP
    from stickslip.fem.thermal.sources import Draw

    def hops_and_loads(**values):
        params = FemParams(N=9, plates=2, seed=1, k_drive=1e-3, dt_scale=4.0, temperature=2e-3, drive_rate=1e-5,
                           backend="counting", **values)
        sim = Simulation(params, build_stack_mesh(MeshParams(N=9, plates=2)), make_backend("counting"))
        transfers, protocol, source, marks = sim.backend.transfers, sim.protocol, sim.protocol.source, []
        draw, hop, next_event = source.draw, protocol.hop, protocol.next_event
        forced, back = {}, []

        def marked_draw(t, allowed, speed, until, stream):
            u = sim.backend.state.u.tobytes()  # the CPU backend's own array: not a transfer
            if forced.get("from") is not None:  # the draw after a forced hop that fell back: the stack as it found it
                back.append(u == forced.pop("from"))
            if forced.pop("now", False):
                sim.stack.read("idx", "eps")  # what a draw reads
                forced["from"] = u
                result = Draw(HOP, forced["block"], BACKWARD, 0.0, t, getattr(source, "offset", 0.0))
            else:
                result = draw(t, allowed, speed, until, stream)
            marks.append(("draw", dict(transfers)))
            return result

        def marked_hop(*args):
            marks.append(("hop", dict(transfers)))
            return hop(*args)

        def marked_next_event(margin, increment):
            forced.update(now=increment % 8 == 1, block=increment % 9)
            result = next_event(margin, increment)
            forced.pop("from", None)  # the forced hop did not fall back
            marks.append(("end", dict(transfers)))
            return result

        source.draw, protocol.hop, protocol.next_event = marked_draw, marked_hop, marked_next_event
        loads = []
        for increment in range(1, 41):
            before = dict(transfers)
            row = protocol.step(5, increment)
            if not row["kick"]:
                attempts = row["failed_hops"] + int(row["hop_block"] >= 0)
                loads.append((attempts, {name: transfers[name] - before.get(name, 0) for name in TRANSFERS}))
        hops = []
        for i, (name, _) in enumerate(marks):
            if name == "hop":
                start = next(counts for mark, counts in reversed(marks[:i]) if mark == "draw")
                end = next(counts for mark, counts in marks[i + 1:] if mark in ("draw", "end"))
                hops.append({key: end.get(key, 0) - start.get(key, 0) for key in TRANSFERS})
        return {"hops": hops, "loads": loads, "back": back}

    print(json.dumps({"dynamic": hops_and_loads(relaxation="dynamic"), "exact": hops_and_loads(relaxation="exact"),
                      "aging": hops_and_loads(relaxation="exact", junction_strengthening=5.0)}))
"""


def test_a_hop_copies_one_array_to_the_host_and_a_thermal_load_increment_three_more(tmp_path):
    """A hop of the kinetic Monte Carlo (issue 57): the load to it, the shear, the relaxation, the rollback of one that
    fell back and the checks that it moved are done where the state is (checkpoints, counts of changed wells); one
    array comes to the host, the interface strains at the event (the hop's amplitude; the next draw after a hop that
    fell back reads nothing: the stack is back at a state it read). Uploads: the shear (16 numbers) and, with junction
    aging, the yield strains of junctions redrawn before the hop. The exact relaxation's own exchanges (force out,
    correction in, one per Newton iteration) come on top; the dynamic relaxation has none. A thermal load increment
    reads at most the displacement, strains and wells of its start (the threshold and the draws) besides its hops."""
    result = _run(tmp_path, PRELUDE + HOPS)
    for name, measured in result.items():
        hops, loads, back = measured["hops"], measured["loads"], measured["back"]
        assert len(hops) >= 20 and len(back) >= 2 and all(back), name  # hops that fell back, rolled back bit for bit
        for hop in hops:
            assert hop["read"] <= 1 and hop["add_u"] <= 1 and hop["set_state"] == 0, (name, hop)
            assert hop["set_yield_strains"] <= (1 if name == "aging" else 0), (name, hop)
            assert hop["correct"] == 0 or name != "dynamic", (name, hop)
        for attempts, moved in loads:
            assert moved["read"] <= 3 + attempts and moved["set_state"] == 0, (name, attempts, moved)
