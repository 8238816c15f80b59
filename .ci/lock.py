"""Lock the install: every package that environment.txt and .ci/requirements.txt pull in, at the version pip
resolves today, into constraints.txt; and the workflow's conda environment (workflow/envs/stickslip.yaml) from
the same versions.

Run it after changing environment.txt or .ci/requirements.txt, with the project's Python (3.11, Linux x86-64:
the machines the lock is for), and commit both files::

    python .ci/lock.py

It asks pip (``pip install --dry-run --ignore-installed --report``: nothing is installed) to resolve the
requirements without the old constraints, once for the users' set (environment.txt) and once for CI's, and
refuses to write a lock in which the two sets disagree on a version. tests/test_install.py checks that the
files are in step.
"""

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENVIRONMENT = ROOT / "environment.txt"
CI = ROOT / ".ci" / "requirements.txt"
CONSTRAINTS = ROOT / "constraints.txt"
CONDA = ROOT / "workflow" / "envs" / "stickslip.yaml"

#: A requirement line pinned to one version: name, version.
PIN = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)(?:\[[^]]*\])?==([^\s;#]+)")


def pins(path):
    """The ``name==version`` lines of a requirements file and of the files it includes with ``-r`` (not ``-c``)."""
    found = {}
    for line in path.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line.startswith("-r "):
            found.update(pins((path.parent / line[3:].strip()).resolve()))
        elif (match := PIN.match(line)):
            found[normalise(match.group(1))] = match.group(2)
    return found


def normalise(name):
    """A distribution name as pip compares them (PEP 503)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def resolve(path):
    """{name: version} of everything pip would install for ``path`` in a fresh environment (the package itself out)."""
    with tempfile.TemporaryDirectory() as folder:
        requirements = Path(folder) / "requirements.txt"  # without the constraints and the editable package
        requirements.write_text("\n".join(f"{name}=={version}" for name, version in pins(path).items()) + "\n")
        report = Path(folder) / "report.json"
        subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--dry-run", "--ignore-installed",
                        "--report", str(report), "-r", str(requirements)], check=True)
        installed = json.loads(report.read_text())["install"]
    return {normalise(item["metadata"]["name"]): item["metadata"]["version"] for item in installed}


def conda_environment(users):
    """The workflow's conda environment: this Python and the users' locked packages from PyPI (as pip installs them)."""
    lines = ["# The software of every workflow job under `snakemake --software-deployment-method conda`, written by",
             "# `python .ci/lock.py` from environment.txt and constraints.txt (tests/test_install.py keeps them in step):",
             "# the same packages at the same versions, from PyPI through pip, as `pip install -r environment.txt`.",
             "# The stickslip package itself comes from this repository: run",
             "#   PYTHONPATH=$PWD snakemake --cores 2 --software-deployment-method conda",
             "# Without that option (the default), jobs use the Python environment that runs snakemake.",
             "channels:", "  - conda-forge", "  - nodefaults", "dependencies:",
             f"  - python={sys.version_info.major}.{sys.version_info.minor}", "  - pip", "  - pip:"]
    lines += [f"      - {name}=={version}" for name, version in sorted(users.items())]
    return "\n".join(lines) + "\n"


def main():
    users, ci = resolve(ENVIRONMENT), resolve(CI)
    disagree = {name: (users[name], ci[name]) for name in users if name in ci and users[name] != ci[name]}
    if disagree:
        raise SystemExit(f"the users' and CI's requirements resolve to other versions: {disagree}")
    header = ["# Every package that environment.txt and .ci/requirements.txt install, at one version (pip constraints),",
              f"# for Python {sys.version_info.major}.{sys.version_info.minor} on Linux x86-64. Written by "
              "`python .ci/lock.py`; do not edit by hand."]
    CONSTRAINTS.write_text("\n".join(header + [f"{name}=={version}" for name, version in sorted(ci.items())]) + "\n")
    CONDA.write_text(conda_environment(users))
    print(f"{CONSTRAINTS.name}: {len(ci)} packages ({len(users)} for users); {CONDA.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
