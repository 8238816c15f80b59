"""Every study config shipped in workflow/config is a valid workflow: a Snakemake dry run plans it."""

import os
import subprocess

import pytest

from conftest import REPO, copy_workflow, python_path

CONFIGS = sorted(path.name for path in (REPO / "workflow" / "config").glob("*.yaml"))


@pytest.mark.slow
@pytest.mark.parametrize("config", CONFIGS)
def test_a_shipped_study_config_plans_its_simulations(tmp_path, config):
    directory = copy_workflow(tmp_path)
    result = subprocess.run(["snakemake", "-n", "--cores", "2", "--configfile", f"workflow/config/{config}"],
                            cwd=directory, env=dict(os.environ, PYTHONPATH=python_path(REPO)),
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, f"{config}:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    stats = result.stdout + result.stderr
    assert "simulate" in stats and "database" in stats, stats[-3000:]
