"""One event loop with named hooks, composed event sources and a clock that only its protocol advances.

- The loop (:class:`stickslip.fem.protocol.EventLoop`) is the same for every protocol; a protocol overrides its hooks
  (``next_event``, ``perform``, ``after_event``), not the loop: the aging protocol has no load of its own, and no class
  of the fem core outgrows 150 lines.
- An event source is composed, not inherited: the example of docs/developing.md ("A new event source": the drive runs
  at its rate to the athermal threshold, no thermal activation) given to the thermal protocol makes the athermal
  run's states bit for bit, each load increment lasting its drive offset over the drive's speed, each event none.
- A thermal run's time is its protocol's clock: relaxations do not advance it, nothing sets it back, and no
  ``set_time`` is left anywhere (the backend counts the time of its dynamics only).
"""

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from stickslip.fem.backends import make_backend
from stickslip.fem.clock import Clock
from stickslip.fem.parameters import FemParams
from stickslip.fem.simulation import Simulation
from stickslip.fem.thermal import ThermalProtocol
from stickslip.fem.thermal.aging import AgingProtocol
from stickslip.mesh import MeshParams, build_stack_mesh

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "stickslip"


def _doc_example(name):
    """The class ``name`` of the python block of docs/developing.md that defines it."""
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "developing.md").read_text(), re.S)
    found = [block for block in blocks if f"class {name}" in block]
    assert len(found) == 1, f"docs/developing.md: one example defining {name} expected"
    namespace = {}
    exec(compile(found[0], f"docs/developing.md:{name}", "exec"), namespace)
    return namespace[name]


def _simulation(**params):
    return Simulation(FemParams(N=9, plates=2, seed=3, **params), build_stack_mesh(MeshParams(N=9, plates=2)),
                      make_backend())


def test_the_docs_event_source_composed_into_the_thermal_protocol_makes_the_athermal_run_in_drive_time():
    athermal = _simulation()
    thermal = _simulation(temperature=1e-3, drive_rate=1e-4)
    source = _doc_example("DriveToThreshold")(thermal.loading)
    s = thermal
    protocol = ThermalProtocol(s.stack, s.model, s.loading, s.relaxation, s.params, s.mesh, s.constants, source)
    assert protocol.clock is s.stack.clock  # the clock of the run's own protocol, taken over
    scale = thermal.loading.response.delta_target[-1]
    slips = 0
    for increment in range(1, 31):
        event = increment % 2 == 0
        assert athermal.protocol.step(5, increment)["kick"] == event  # each protocol knows what comes next
        before = thermal.stack.stored()
        row = protocol.step(5, increment)
        assert row["kick"] == event and row["hop_block"] == -1 and row["failed_hops"] == 0
        after = thermal.stack.stored()
        assert np.array_equal(after.u, athermal.stack.read("u")[0])  # the athermal state, bit for bit
        assert np.array_equal(after.target, athermal.stack.read("target")[0])
        elapsed = after.t - before.t
        if event:
            slips += 1
            assert elapsed == 0.0  # avalanches take no time
        else:  # the drive offset to the brink at the drive's speed
            offset = (after.target[-1] - before.target[-1]) / scale
            assert elapsed == pytest.approx(offset / protocol.speed, rel=1e-12)
            assert elapsed > 0.0
    assert slips == 15


def test_relaxations_leave_a_protocol_clock_alone_and_it_never_goes_back():
    sim = _simulation(temperature=1e-3, drive_rate=1e-4)
    stack, clock = sim.stack, sim.stack.clock
    assert clock is sim.protocol.clock and stack.time == 0.0
    clock.advance_to(2.5)
    sim.loading.step(False)
    assert sim.protocol.kick(5)[0]  # a whole avalanche: the backend's dynamics ran, the clock did not
    assert stack.time == 2.5 and stack.stored().t == 2.5
    with pytest.raises(ValueError, match="cannot go back"):
        clock.advance_to(1.0)
    with pytest.raises(ValueError, match="cannot go back"):
        Clock(3.0).advance_to(2.999)
    state = stack.stored()
    clock.advance_to(7.0)
    stack.restore(state)  # a restore sets the stored state's time with the rest of it
    assert stack.time == 2.5
    athermal = _simulation()
    athermal.loading.step(False)
    assert athermal.stack.clock is None and athermal.protocol.kick(5)[0]
    assert athermal.stack.time > 0.0  # without a clock the stack's time is the dynamics'


def test_a_protocol_overrides_hooks_not_the_loop():
    assert "step" not in vars(ThermalProtocol) and "step" not in vars(AgingProtocol)
    assert not {"next_event", "_load", "step"} & set(vars(AgingProtocol))
    assert {"perform", "after_event"} <= set(vars(AgingProtocol))


def test_no_class_of_the_fem_core_outgrows_150_lines_and_nothing_sets_a_time():
    long, setters = [], []
    for path in sorted((PACKAGE / "fem").rglob("*.py")):
        tree = ast.parse(path.read_text())
        name = path.relative_to(PACKAGE).as_posix()
        long += [f"{name}:{node.name} {node.end_lineno - node.lineno + 1}" for node in ast.walk(tree)
                 if isinstance(node, ast.ClassDef) and node.end_lineno - node.lineno + 1 > 150]
    for path in sorted(PACKAGE.rglob("*.py")):
        setters += [f"{path.relative_to(PACKAGE)}:{n}" for n, line in enumerate(path.read_text().splitlines(), 1)
                    if "set_time" in line]
    assert not long, long
    assert not setters, setters
