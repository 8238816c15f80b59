"""numba's cache of a package kernel is keyed on its whole subpackage (stickslip.numba_options)."""

import os
import subprocess
import sys

import pytest

from stickslip.fem.backends.cpu.forces import compute_force
from stickslip.numba_options import CACHE, PACKAGE_DIR, subpackage_digest


def test_the_digest_follows_every_source_of_the_subpackage_and_no_other(tmp_path):
    (tmp_path / "fem" / "laws").mkdir(parents=True)
    (tmp_path / "events").mkdir()
    kernel, law, other = tmp_path / "fem" / "forces.py", tmp_path / "fem" / "laws" / "cusp.py", tmp_path / "events" / "x.py"
    for path in (kernel, law, other):
        path.write_text("x = 1\n")
    first = subpackage_digest(kernel, tmp_path)
    assert subpackage_digest(law, tmp_path) == first  # one key for the whole subpackage
    other.write_text("x = 2\n")
    assert subpackage_digest(kernel, tmp_path) == first
    law.write_text("x = 2  # the law changed\n")
    os.utime(law, ns=(1, 1))  # a new modification time, whatever the clock's resolution
    changed = subpackage_digest(kernel, tmp_path)
    assert changed != first
    assert subpackage_digest(other, tmp_path) != changed


@pytest.mark.skipif(not CACHE, reason="STICKSLIP_NUMBA_CACHE=0: kernels are not cached")
def test_a_kernel_of_the_package_is_cached_under_its_subpackage_digest():
    stamp = compute_force._cache._impl.locator.get_source_stamp()
    assert stamp[1] == subpackage_digest(PACKAGE_DIR / "fem" / "backends" / "cpu" / "forces.py")


GHOST = '''
from collections import namedtuple
from stickslip.fem.laws import register_law
from stickslip.fem.laws.cusp import Cusp
from stickslip.numba_options import njit

@register_law
class Ghost(namedtuple("Ghost", ("K", "G"))):
    __slots__ = ()
    name, summary, yields, exact_relaxation, thermal = "ghost", "a law of another program", True, True, True
    deviatoric_factor = Cusp.deviatoric_factor
    well_energy = Cusp.well_energy
    forward_barrier = Cusp.forward_barrier
'''


@pytest.mark.skipif(not CACHE, reason="STICKSLIP_NUMBA_CACHE=0: kernels are not cached")
def test_a_cache_entry_for_a_type_of_another_program_is_a_miss_not_an_error(tmp_path):
    # a law registered by a user's module: the package kernels compiled for it are cached beside the
    # package's own; a process that cannot import that module must still load its own kernels
    (tmp_path / "ghost.py").write_text(GHOST)
    call = ("import sys; from stickslip.fem.laws import Cusp, well_stress; {extra}"
            "print(well_stress(Cusp(4.5, 1.0), 1e-4, 0.0, 2e-5, 0.0, 3e-4)[0])")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    user = call.format(extra="import ghost; well_stress(ghost.Ghost(4.5, 1.0), 1e-4, 0.0, 2e-5, 0.0, 3e-4); ")
    for script, cwd in ((user, tmp_path), (call.format(extra=""), tmp_path / "cache")):
        done = subprocess.run([sys.executable, "-c", script], cwd=cwd, env=env, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
    assert any((tmp_path / "cache").rglob("*.nbi"))
