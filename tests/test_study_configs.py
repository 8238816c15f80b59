"""Every study config shipped in workflow/config is a valid workflow: a Snakemake dry run plans it; a config that
writes into another config's study (its ``study`` key, a part run alone to keep within the budget) plans runs of it."""

import functools
import os
import re
import subprocess

import pytest
import yaml

from conftest import REPO, copy_workflow, python_path

CONFIG_FOLDER = REPO / "workflow" / "config"
CONFIGS = sorted(path.name for path in CONFIG_FOLDER.glob("*.yaml"))

#: The parts of a study, by the config of the whole: a config whose ``study`` key names another shipped config.
PARTS = {}
for _name in CONFIGS:
    _study = (yaml.safe_load((CONFIG_FOLDER / _name).read_text()) or {}).get("study")
    if _study and f"{_study}.yaml" in CONFIGS and f"{_study}.yaml" != _name:
        PARTS.setdefault(f"{_study}.yaml", []).append(_name)

#: Wholes whose parts are meant to plan every run of them (the others' parts are subsets, e.g. a scan alone).
WHOLE_BY_PARTS = {"calibration.yaml", "size-series.yaml"}


@pytest.fixture(scope="module")
def dry_run(tmp_path_factory):
    """``dry_run(config)``: the stdout and stderr of ``snakemake -n`` on a shipped config (run once per config)."""
    directory = copy_workflow(tmp_path_factory.mktemp("workflow"))

    @functools.cache
    def run(config):
        result = subprocess.run(["snakemake", "-n", "--cores", "2", "--configfile", f"workflow/config/{config}"],
                                cwd=directory, env=dict(os.environ, PYTHONPATH=python_path(REPO)),
                                capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, f"{config}:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
        return result.stdout + result.stderr

    return run


def planned_simulations(output):
    """The simulation outputs (``results/<study>/sim/<solver>/<run id>.h5``) a dry run's output names."""
    return set(re.findall(r"results/[\w.-]+/sim/[\w-]+/[0-9a-f]+\.h5", output))


@pytest.mark.slow
@pytest.mark.parametrize("config", CONFIGS)
def test_a_shipped_study_config_plans_its_simulations(dry_run, config):
    stats = dry_run(config)
    assert "simulate" in stats and "database" in stats, stats[-3000:]


def test_the_calibration_and_the_size_series_have_parts():
    assert set(PARTS) >= WHOLE_BY_PARTS and len(PARTS["calibration.yaml"]) == 2, PARTS


@pytest.mark.slow
@pytest.mark.parametrize("whole", sorted(PARTS))
def test_the_parts_of_a_study_plan_runs_of_its_whole_with_the_same_ids(dry_run, whole):
    runs = planned_simulations(dry_run(whole))
    parts = {part: planned_simulations(dry_run(part)) for part in PARTS[whole]}
    for part, part_runs in parts.items():
        assert part_runs and part_runs <= runs, (part, sorted(part_runs - runs))
    if whole in WHOLE_BY_PARTS:
        assert set().union(*parts.values()) == runs, sorted(runs - set().union(*parts.values()))
