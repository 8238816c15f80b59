"""Shared fixtures: the toy plugin distribution (entry points) and a workflow copy."""

import shutil
import sys
from pathlib import Path

import pytest

from stickslip import registry

REPO = Path(__file__).resolve().parent.parent
TOY = Path(__file__).resolve().parent / "toy_plugin" / "stickslip_toy.py"

ENTRY_POINTS = """[stickslip.solvers]
toy = stickslip_toy

[stickslip.analyses]
toy = stickslip_toy

[stickslip.figures]
toy = stickslip_toy
"""


@pytest.fixture(scope="session")
def toy_distribution(tmp_path_factory):
    """A directory holding the toy plugin module and its installed-distribution metadata.

    Put it on ``sys.path`` (or ``PYTHONPATH``) and the entry points make
    ``stickslip`` find the ``toy-*`` plugins, as for a ``pip install``-ed package.
    """
    root = tmp_path_factory.mktemp("site")
    shutil.copy(TOY, root / TOY.name)
    info = root / "stickslip_toy-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: stickslip-toy\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(ENTRY_POINTS)
    return root


@pytest.fixture
def toy_plugins(toy_distribution, monkeypatch):
    """Make the toy plugins discoverable in this process (the registry rescans entry points)."""
    monkeypatch.syspath_prepend(str(toy_distribution))
    monkeypatch.setattr(registry, "_loaded", False)
    return toy_distribution


def copy_workflow(destination):
    """Copy the workflow (Snakefile, workflow/, profiles/) into ``destination``; return it."""
    destination = Path(destination)
    shutil.copy(REPO / "Snakefile", destination / "Snakefile")
    shutil.copytree(REPO / "workflow", destination / "workflow",
                    ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(REPO / "profiles", destination / "profiles")
    return destination


def python_path(*extra):
    """A PYTHONPATH with ``extra`` directories first."""
    return ":".join([*map(str, extra), *sys.path[1:]])
