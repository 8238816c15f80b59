"""The install is lean and locked: environment.txt (the users'), .ci/requirements.txt (CI's GPU compile tools),
constraints.txt (every version, `python .ci/lock.py`) and the workflow's conda environment are in step."""

import re
import sys
import tomllib
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / ".ci"))
from lock import CI, CONDA, CONSTRAINTS, ENVIRONMENT, normalise, pins  # noqa: E402

#: What only a GPU or CI's cuda tests need: never in the users' requirements.
GPU_TOOLS = re.compile(r"^(numba-cuda|cuda-.*|nvidia-.*)$")


def _constraints():
    return {normalise(name): version for name, version in
            (line.split("==") for line in CONSTRAINTS.read_text().splitlines() if line and not line.startswith("#"))}


def test_the_users_requirements_hold_no_cuda_compiler_and_ci_adds_them():
    users, ci = pins(ENVIRONMENT), pins(CI)
    assert not [name for name in users if GPU_TOOLS.match(name)]
    assert {"numba-cuda", "nvidia-nvvm", "nvidia-cuda-nvrtc", "nvidia-nvjitlink"} <= set(ci) and users.items() <= ci.items()
    assert "-r .ci/requirements.txt" in (ROOT / ".ci" / "run").read_text()
    assert "STICKSLIP_REQUIRE_CUDA_TOOLS=1" in (ROOT / ".ci" / "run").read_text()
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert any(item.startswith("numba-cuda") for item in project["optional-dependencies"]["gpu"])
    # every runtime dependency of the package is pinned for users
    for requirement in project["dependencies"]:
        assert normalise(re.split(r"[<>=!~ ]", requirement)[0]) in users, requirement


def test_the_lock_pins_every_requirement_at_its_version():
    locked = _constraints()
    assert ENVIRONMENT.read_text().splitlines().count("-c constraints.txt") == 1  # pip applies it to every install
    for name, version in pins(CI).items():
        assert locked.get(name) == version, name
    assert len(locked) > len(pins(CI)) + 30  # the transitive ones too (85 at the lock of 2026-11-28)
    assert "stickslip" not in locked


def test_the_conda_environment_is_the_lock_of_the_users_requirements():
    environment = yaml.safe_load(CONDA.read_text())
    python = next(item for item in environment["dependencies"] if isinstance(item, str) and item.startswith("python"))
    header = re.search(r"for Python (\d+\.\d+)", CONSTRAINTS.read_text()).group(1)
    assert python == f"python={header}"
    from_pip = next(item["pip"] for item in environment["dependencies"] if isinstance(item, dict))
    conda = dict(line.split("==") for line in from_pip)
    locked = _constraints()
    assert conda.items() <= locked.items()  # the lock's versions
    assert pins(ENVIRONMENT).items() <= conda.items()  # every requirement of the users
    assert not [name for name in conda if GPU_TOOLS.match(name)]


def test_the_readme_sets_up_a_venv_in_two_commands_and_the_license_is_mit():
    readme = (ROOT / "README.md").read_text()
    assert "python3 -m venv .venv && . .venv/bin/activate" in readme
    assert "pip install -r environment.txt && snakemake --cores 2" in readme
    assert "pip install -r environment.txt && pytest" in readme
    assert "pip install stickslip[gpu]" not in readme  # the package is not published: from a clone
    license_text = (ROOT / "LICENSE").read_text()
    assert license_text.startswith("MIT License") and "Copyright (c) 2026 the stickslip authors" in license_text
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT" and project["license-files"] == ["LICENSE"]
