"""The stack is the only face of a run's state: nothing in the package reaches past it, and it hands out no way in.

The backend that owns the state is private to :class:`stickslip.fem.stack.Stack` (and handed, prepared, to the
:class:`stickslip.fem.simulation.Simulation` that composes a run, for backend-level tests and benchmarks); the model's
static parts are passed to those who need them; the yield strains the backend holds now are the stack's
(:attr:`~stickslip.fem.stack.Stack.yield_strains`); junction aging is a yield-strain modifier that its protocol
registers, so the stack imports nothing of the protocols (and the parameters nothing of the thermal package).
"""

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from stickslip.fem.backends import make_backend
from stickslip.fem.parameters import FemParams
from stickslip.fem.simulation import Simulation
from stickslip.mesh import MeshParams, build_stack_mesh

PACKAGE = Path(__file__).resolve().parents[1] / "stickslip"

#: What reaches past the stack: its backend or model, the simulation's backend, the stack's private names.
REACH_THROUGH = re.compile(r"\bstack\.(backend|model|_\w+)\b|\bsimulation\.backend\b|\bs\.backend\b|\._backend\b")

#: The modules that may name the backend: the stack, its window of yield strains, its host copies of the state and
#: the composition of a run.
CORE = {"fem/stack.py", "fem/window.py", "fem/host_copies.py", "fem/simulation.py"}


def test_no_module_of_the_package_reaches_past_the_stack():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        name = path.relative_to(PACKAGE).as_posix()
        if name in CORE:
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if REACH_THROUGH.search(line):
                found.append(f"{name}:{number}: {line.strip()}")
    assert not found, "\n".join(found)


def _imports(name):
    tree = ast.parse((PACKAGE / "fem" / name).read_text())
    imported = [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
    return imported + [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names]


def test_the_stack_imports_nothing_of_the_protocols_nor_the_parameters_of_the_thermal_package():
    imported = _imports("stack.py")
    assert not [m for m in imported if "thermal" in m or "protocol" in m], imported
    imported = _imports("parameters.py")
    assert imported and not [m for m in imported if "thermal" in m], imported


def test_the_grep_finds_a_reach_through():
    assert REACH_THROUGH.search("idx = self.stack.backend.read('idx')")
    assert REACH_THROUGH.search("law = sim.stack.model.law")
    assert REACH_THROUGH.search("stack._modifier.depth[0] = 1")
    assert not REACH_THROUGH.search("idx = self.stack.read('idx')")


@pytest.fixture(scope="module")
def aging():
    params = FemParams(N=9, plates=2, relaxation="exact", temperature=1e-3, drive_rate=2e-8, junction_strengthening=5.0)
    return Simulation(params, build_stack_mesh(MeshParams(N=9, plates=2)), make_backend())


def test_what_the_stack_hands_out_cannot_change_the_state(aging):
    stack = aging.stack
    for name in ("u", "idx", "eps", "t"):
        (array,) = stack.read(name)
        with pytest.raises(ValueError, match="read-only"):
            array[...] = 0
    with pytest.raises(ValueError, match="read-only"):
        stack.yield_strains[0, 0] = 0.0


def test_a_checkpoint_counts_the_changes_of_well_since_and_rolls_back_bit_for_bit(aging):
    stack = aging.stack
    token, wells, u = stack.checkpoint(), stack.well_index(), aging.backend.read("u")[0].tobytes()
    aging.loading.step(False)
    assert stack.changed_since(token) == 0
    aging.loading.step(True)
    assert stack.changed_since(token) == np.count_nonzero(stack.well_index() != wells) > 0
    block = int(np.flatnonzero(np.any(stack.well_index() != wells, axis=1))[0])
    assert stack.changed_since(token, elements=np.array([block])) == np.count_nonzero(stack.well_index()[block]
                                                                                      != wells[block])
    stack.rollback(token)
    assert stack.changed_since(token) == 0 and np.array_equal(stack.well_index(), wells)
    assert aging.backend.read("u")[0].tobytes() == u  # the backend's state, not only the stack's copies


def test_a_rollback_returns_to_the_junctions_of_its_checkpoint(aging):
    stack, junctions = aging.stack, aging.protocol.junctions
    token = stack.checkpoint()
    held, depth = stack.yield_strains.copy(), junctions.depth.copy()
    junctions.depth[:] += 1.0
    stack.push_yield_strains()
    assert not np.array_equal(stack.yield_strains, held)
    stack.rollback(token)
    assert np.array_equal(stack.yield_strains, held) and np.array_equal(junctions.depth, depth)


def test_a_rollback_returns_to_the_windows_of_its_checkpoint_and_changes_are_counted_in_global_wells():
    """Events move the windows (20 wells held): a change of well is counted in global wells whatever the moves, and
    the rollback returns to the windows and the backend's state bit for bit, from which the same events follow."""
    sim = Simulation(FemParams(N=9, plates=2, window=20, dt_scale=4.0), build_stack_mesh(MeshParams(N=9, plates=2)),
                     make_backend())
    stack = sim.stack

    def events_until_the_windows_move():
        offset, states = stack.wells.offset.copy(), []
        while np.array_equal(stack.wells.offset, offset):
            sim.loading.step(False)
            assert sim.protocol.kick(5)[0]
            states.append(stack.read("u")[0].tobytes())
        return states

    events_until_the_windows_move()  # the windows away from the origin
    token, wells, offset, held = stack.checkpoint(), stack.well_index(), stack.wells.offset.copy(), stack.yield_strains
    fields = [array.tobytes() for array in sim.backend.read("u", "v", "f", "idx", "eps", "sig", "target", "t")]
    states = events_until_the_windows_move()
    assert stack.changed_since(token) == np.count_nonzero(stack.well_index() != wells) > 0
    stack.rollback(token)
    assert np.array_equal(stack.wells.offset, offset) and stack.yield_strains is held
    assert stack.changed_since(token) == 0 and np.array_equal(stack.well_index(), wells)
    assert [array.tobytes() for array in sim.backend.read("u", "v", "f", "idx", "eps", "sig", "target", "t")] == fields
    assert events_until_the_windows_move() == states


def test_the_aging_protocol_registers_its_junctions_and_a_stored_state_holds_them(aging):
    stack, junctions = aging.stack, aging.protocol.junctions
    assert stack.modifier is junctions
    state = stack.stored()
    assert set(state.further) == {"junction_depth", "junction_well"}
    assert np.array_equal(stack.yield_strains, junctions.modify(stack.wells))  # the widened window is held
    with pytest.raises(ValueError, match="modified by"):
        stack.modify_yield_strains(junctions)
