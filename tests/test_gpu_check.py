"""The GPU check (benchmarks/gpu/run.sh) in its smoke mode on numba's simulator, where qdldl is not installed.

The GPU machine is bare: no qdldl (the check carries its wheel in ``.device/wheels``, benchmarks/gpu/prepare.sh),
the reference file beside it, a few device minutes per session. The smoke mode runs every part of the check
on tiny meshes on the simulator, so that a broken script is found here and not in the device's minutes. Here
qdldl is hidden from the check's Python (a ``sitecustomize`` on ``PYTHONPATH`` that finds it only outside
site-packages) and the carried wheel is one made of the installed qdldl's files: the check must take qdldl
from that wheel, as on the GPU machine, or stop at its preflight. docs/benchmarks.md ("GPU") lists what the
check writes and its time budget.
"""

import importlib.metadata
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT.parent / "shared" / "reference" / "FixedLever_historic.h5"

#: The parts the check runs (benchmarks/gpu/summary.py).
PARTS = ("preflight", "warmup", "fidelity", "speed", "sanity", "events", "cpu-step")
#: Seconds the whole check may take: the device call's limit (docs/benchmarks.md, "GPU").
CALL_SECONDS = 420
#: Files the device tool brings back from the output folder at most.
MAX_FILES = 8

HIDE_QDLDL = '''
"""qdldl as on the bare GPU machine: not installed (found only outside site-packages, e.g. a carried wheel)."""
import importlib.machinery
import sys


class HideInstalledQdldl:
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name != "qdldl":
            return None
        outside = [p for p in sys.path if "site-packages" not in p and "dist-packages" not in p]
        spec = importlib.machinery.PathFinder.find_spec(name, outside)
        if spec is None:
            raise ModuleNotFoundError("No module named 'qdldl'", name=name)
        return spec


sys.meta_path.insert(0, HideInstalledQdldl)
'''


def _device_folder(tmp_path, wheel):
    """A ``.device`` folder as prepare.sh makes it: the reference file and (if ``wheel``) a qdldl wheel for this
    Python, made of the installed qdldl's files."""
    device = tmp_path / "device"
    (device / "wheels").mkdir(parents=True)
    (device / "reference").mkdir()
    shutil.copy(REFERENCE, device / "reference")
    if wheel:
        dist = importlib.metadata.distribution("qdldl")
        tag = f"cp{sys.version_info[0]}{sys.version_info[1]}"
        with zipfile.ZipFile(device / "wheels" / f"qdldl-{dist.version}-{tag}-{tag}-linux_x86_64.whl", "w") as zipped:
            for file in dist.files:
                zipped.write(dist.locate_file(file), str(file))
    return device


def _smoke(tmp_path, wheel):
    """Run the smoke mode with qdldl hidden and numba's cache empty (a cold, bare machine); returns (exit status,
    seconds, the output folder)."""
    for required, variable, what in ((importlib.util.find_spec("numba_cuda") is not None,
                                      "STICKSLIP_REQUIRE_CUDA_TOOLS", "numba-cuda is not installed"),
                                     (REFERENCE.is_file(), "STICKSLIP_REQUIRE_REFERENCE", f"{REFERENCE} is missing")):
        if not required:
            (pytest.fail if os.environ.get(variable) else pytest.skip)(what)
    hide = tmp_path / "hide"
    hide.mkdir()
    (hide / "sitecustomize.py").write_text(HIDE_QDLDL)
    out = tmp_path / "out"
    env = {**os.environ, "GPU_CHECK_SMOKE": "1", "NUMBA_ENABLE_CUDASIM": "1", "PYTHON": sys.executable,
           "DEVICE_DIR": str(_device_folder(tmp_path, wheel)), "TMPDIR": str(tmp_path),
           "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache"), "STICKSLIP_NUMBA_CACHE": "1",
           "PYTHONPATH": os.pathsep.join([str(hide)] + [p for p in [os.environ.get("PYTHONPATH")] if p])}
    start = time.perf_counter()
    done = subprocess.run(["bash", str(ROOT / "benchmarks" / "gpu" / "run.sh"), str(out)], env=env, timeout=900,
                          capture_output=True, text=True)
    return done.returncode, time.perf_counter() - start, out


@pytest.mark.slow
def test_the_smoke_mode_from_a_cold_cache_runs_every_part_in_the_call_s_time_with_qdldl_from_the_carried_wheel(
        tmp_path):
    status, seconds, out = _smoke(tmp_path, wheel=True)
    summary = (out / "summary.txt").read_text()
    assert status == 0, summary + (out / "gpu.log").read_text()[-4000:]
    files = [p for p in out.rglob("*") if p.is_file()]
    assert len(files) <= MAX_FILES
    assert sorted(p.name for p in files) == ["gpu.log", "rest.tar.gz", "results.jsonl", "summary.txt"]
    assert "FAILED" not in summary and "MISSING" not in summary and "ERROR" not in summary
    assert seconds < CALL_SECONDS, summary
    # both kernels measured side by side, with the same bytes
    assert re.search(r"batch +1 tiles .*\n.*batch +1 resident ", summary), summary
    assert '"check": "reference N=9: the kernels\' files", "same_bytes": true' in summary, summary
    last = summary.strip().splitlines()[-2]  # the parts, then the wall seconds
    assert re.fullmatch(", ".join(rf"{part} \d+ s" for part in PARTS), last.removeprefix("parts: ")), last
    assert re.search(r"NVVM \d+\.\d+", summary)
    carried = re.search(r"qdldl ([^ ]+) \(([^)]+)\)", summary)
    assert carried and carried[1] == importlib.metadata.version("qdldl") and "site-packages" not in carried[2]
    assert not list(tmp_path.glob("stickslip-gpu-check.*"))  # the scratch folder is removed
    print(f"smoke mode: {seconds:.0f} s")


def test_without_qdldl_and_its_wheel_the_preflight_stops_the_check_at_once(tmp_path):
    status, seconds, out = _smoke(tmp_path, wheel=False)
    summary = (out / "summary.txt").read_text()
    assert status == 1
    assert "No module named 'qdldl'" in (out / "gpu.log").read_text()
    # the warmup ran beside the preflight (it needs qdldl too: it failed or was stopped); no part after them started
    assert re.search(r"parts: preflight FAILED, warmup (FAILED|MISSING), " + ", ".join(
        f"{part} MISSING" for part in PARTS[2:]), summary), summary
