"""A full disk or an unwritable output ends a command with one line and exit 2: no crash, no temporary file left.

Real failures: a file-size limit (``RLIMIT_FSIZE``, ``EFBIG``; any user) and, as root, a real
tmpfs of 1 MB (``ENOSPC``) and a read-only one (``EROFS``). Before the write guard
(:mod:`stickslip.output_safety.write_guard`) the lever run on a full tmpfs ended in a segmentation fault.
"""

import hashlib
import os
import resource
import signal
import subprocess
import sys
import textwrap
from contextlib import contextmanager

import pytest

from stickslip import h5io
from stickslip.fem.run import FREE_SPACE_MARGIN
from stickslip.formats.fem_run import RunFile
from stickslip.output_safety.atomic import atomic_output

LEVER = ["simulate", "--solver", "lever", "--param", "n=2", "--param", "duration=600"]


def stickslip(args, fsize=None, env=None):
    """Run ``python -m stickslip ARGS`` (with a file-size limit of ``fsize`` bytes); return the process."""
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))

    return subprocess.run([sys.executable, "-m", "stickslip", *args], capture_output=True, text=True,
                          preexec_fn=limit if fsize is not None else None, env=env)


def errors(process):
    """stderr without the progress lines."""
    return [line for line in process.stderr.splitlines() if "simulated" not in line]


def leftovers(directory):
    return sorted(p.name for p in directory.iterdir() if p.name.startswith("."))


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.slow
def test_a_file_size_limit_is_a_one_line_error_and_the_rerun_gives_the_same_bytes(tmp_path):
    reference = tmp_path / "reference" / "lab.h5"
    assert stickslip(LEVER + ["-o", str(reference)]).returncode == 0
    size = reference.stat().st_size
    output = tmp_path / "limited" / "lab.h5"
    for fsize in (4096, size // 2, size - 2000):
        process = stickslip(LEVER + ["-o", str(output)], fsize=fsize)
        assert process.returncode == 2, process.stderr
        assert errors(process) == [f"stickslip: error: {output}: cannot write it (File too large)"]
        assert not output.exists() and leftovers(output.parent) == []
    assert stickslip(LEVER + ["-o", str(output)]).returncode == 0
    assert digest(output) == digest(reference)


@contextmanager
def tmpfs(path, options):
    """Mount a tmpfs at ``path``: skipped if not root, or if mount fails (saying why), failed instead where
    ``STICKSLIP_REQUIRE_TMPFS`` is set (.ci/run sets it as root)."""
    path.mkdir()
    if os.geteuid() != 0:
        reason = "mounting a tmpfs needs root"
    else:
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)], capture_output=True,
                                 text=True)
        reason = (f"mount -t tmpfs failed as root (exit {mounted.returncode}): "
                  f"{(mounted.stderr or mounted.stdout).strip()}") if mounted.returncode else None
    if reason:
        if os.environ.get("STICKSLIP_REQUIRE_TMPFS"):
            pytest.fail(reason)
        pytest.skip(reason)
    try:
        yield path
    finally:
        subprocess.run(["umount", str(path)], check=True)


@pytest.mark.slow
def test_a_full_tmpfs_and_a_read_only_one_are_one_line_errors(tmp_path):
    with tmpfs(tmp_path / "full", "size=1m") as full:
        for run in range(2):
            process = stickslip(["simulate", "--solver", "lever", "-o", str(full / "lab.h5")])
            assert process.returncode == 2, process.stderr
            assert errors(process) == [f"stickslip: error: {full}/lab.h5: cannot write it (No space left on device)"]
            assert list(full.iterdir()) == []
    with tmpfs(tmp_path / "read-only", "ro,size=1m") as read_only:
        process = stickslip(LEVER + ["-o", str(read_only / "lab.h5")])
        assert process.returncode == 2
        assert errors(process) == [f"stickslip: error: {read_only}/lab.h5: cannot write it (Read-only file system)"]


def test_an_output_that_is_a_directory_or_under_no_directory_is_refused_at_once(tmp_path):
    for output, cause in ((tmp_path, "Is a directory"), (tmp_path / "file" / "x.h5", "Not a directory")):
        (tmp_path / "file").touch()
        process = stickslip(["simulate", "--solver", "lever", "--param", "duration=1e9", "-o", str(output)])
        assert process.returncode == 2
        assert errors(process) == [f"stickslip: error: {output}: cannot write it ({cause})"]


WRITER = textwrap.dedent("""
    import os, signal, sys, time
    from stickslip import h5io
    from stickslip.output_safety.atomic import atomic_output
    with atomic_output(sys.argv[1]) as tmp, h5io.open_file(tmp, "w") as f:
        h5io.write_dataset(f, "x", list(range(100)))
        f.flush()
        print(tmp.name, flush=True)
        if sys.argv[2] == "die":
            os.kill(os.getpid(), signal.SIGKILL)
        time.sleep(60)
""")


def test_temporaries_of_killed_writers_are_removed_those_of_live_ones_kept(tmp_path):
    output = tmp_path / "out.h5"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}

    def writer(mode):
        process = subprocess.Popen([sys.executable, "-c", WRITER, str(output), mode], stdout=subprocess.PIPE,
                                   text=True, env=env)
        return process, process.stdout.readline().strip()

    live, running = writer("live")
    try:
        killed, stale = writer("die")  # its start leaves the live writer's temporary alone
        assert killed.wait() == -signal.SIGKILL
        assert sorted([stale, running]) == leftovers(tmp_path)
        other = tmp_path / ".other.h5.abcdefgh.tmp"  # another output's temporary: not ours to remove
        other.touch()
        with atomic_output(output) as tmp:
            assert sorted([running, tmp.name, other.name]) == leftovers(tmp_path)
            tmp.write_bytes(b"done")
        assert output.read_bytes() == b"done"
        assert sorted([running, other.name]) == leftovers(tmp_path)
    finally:
        live.kill()
        live.wait()
    with atomic_output(output) as tmp:
        pass
    assert leftovers(tmp_path) == [other.name]


@pytest.mark.slow
def test_a_fem_run_stops_cleanly_before_the_disk_is_full_and_resumes_to_the_same_bytes(tmp_path):
    fem = ["simulate", "--solver", "fem", "--param", "N=9", "--param", "plates=2", "--param", "nchunk=200",
           "--param", "yield_strains=stop", "--param", "max_increments=150"]
    reference = tmp_path / "reference.h5"
    assert stickslip(fem + ["-o", str(reference)]).returncode == 0
    with h5io.open_file(reference) as file:
        needed = 2 * RunFile(file).increment_bytes() + FREE_SPACE_MARGIN
    with tmpfs(tmp_path / "disk", "size=8m") as disk:
        filler = disk / "filler"
        free = needed + reference.stat().st_size // 2  # room for the header and some increments
        filler.write_bytes(bytes(os.statvfs(disk).f_bavail * os.statvfs(disk).f_frsize - free))
        output = disk / "run.h5"
        process = stickslip(fem + ["-o", str(output)])
        assert process.returncode == 2
        lines = [line for line in process.stderr.splitlines() if "fem increments" not in line]
        assert len(lines) == 1 and lines[0].startswith(f"stickslip: error: {output}: cannot write it: ")
        assert (f"free, the next write needs {needed / 2**20:.2f} MiB, 4.00 MiB of it a safety margin kept free: "
                f"HDF5 crashes on a full disk; free some space and rerun") in lines[0]
        with h5io.open_file(output) as file:
            assert 0 < file.attrs["nstored"] < 150
        filler.unlink()
        assert stickslip(fem + ["-o", str(output)]).returncode == 0
        assert digest(output) == digest(reference)
        assert sorted(p.name for p in disk.iterdir()) == ["run.h5", "run.provenance.json"]
