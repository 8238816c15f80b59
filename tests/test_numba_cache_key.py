"""numba's cache of a package kernel is keyed on its whole subpackage (stickslip.numba_options)."""

import os

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
