"""numba's on-disk cache entries are written under an exclusive lock (stickslip.numba_options)."""

import fcntl
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

KERNEL = textwrap.dedent("""
    import sys
    from stickslip.numba_options import njit

    @njit
    def twice(x):
        return 2 * x

    print(twice(int(sys.argv[1])) if sys.argv[2] == "int" else twice(float(sys.argv[1])))
""")


def _compile(tmp_path, kind):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), STICKSLIP_NUMBA_CACHE="1",
               PYTHONPATH=os.pathsep.join(sys.path))
    return subprocess.Popen([sys.executable, str(tmp_path / "kernel.py"), "3", kind], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _waiting_for(process, path, timeout=120):
    """Whether ``process`` comes to wait for the flock of ``path`` (Linux /proc/locks: a ``->`` line) in time."""
    inode = str(os.stat(path).st_ino)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and process.poll() is None:
        for line in Path("/proc/locks").read_text().splitlines():
            fields = line.split()
            if "->" in fields:
                fields.remove("->")
                if fields[1] == "FLOCK" and fields[4] == str(process.pid) and fields[5].split(":")[-1] == inode:
                    return True
        time.sleep(0.02)
    return False


@pytest.mark.slow
def test_a_new_cache_entry_waits_for_the_lock_of_its_function(tmp_path):
    (tmp_path / "kernel.py").write_text(KERNEL)
    first = _compile(tmp_path, "int")
    assert first.communicate(timeout=120)[0].strip() == "6"
    [index] = (tmp_path / "cache").rglob("*.nbi")
    lock_path = str(index) + ".lock"
    assert os.path.exists(lock_path)
    with open(lock_path, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        before = index.stat().st_mtime_ns
        second = _compile(tmp_path, "float")  # a new signature: a new entry in the same index
        # seen blocked on the lock by the kernel (not merely slow: a loaded machine delays a child too)
        assert _waiting_for(second, lock_path), "the cache entry was written without waiting for the lock"
        time.sleep(0.5)
        assert second.poll() is None and index.stat().st_mtime_ns == before  # nothing written while it waits
        mtime = index.stat().st_mtime_ns
        fcntl.flock(lock, fcntl.LOCK_UN)
    assert second.communicate(timeout=120)[0].strip() == "6.0"
    assert index.stat().st_mtime_ns > mtime
    assert len(list((tmp_path / "cache").rglob("*.nbc"))) == 2
