"""Every ``stickslip`` command in the README's and docs' shell blocks parses, and its plugin parameters are valid;
the plugin package of docs/writing-a-plugin.md, built from the page's code blocks, runs its study.

The commands are not run (most need a study's results); what would break them silently
(a renamed option or sub-command, a parameter that no longer exists or is out of range)
fails here.
"""

import re
import shlex
import tomllib
from pathlib import Path

import h5py
import numpy as np
import pytest

from stickslip import registry
from stickslip.provenance import query
from stickslip.cli import build_parser
from stickslip.plugin_params import parse_assignments, parse_params

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```(?:bash|sh|console)\n(.*?)^```", re.S | re.M)
#: Tokens that end a command's arguments (redirections, pipes, command lists).
ENDS = {">", ">>", "2>", "|", "&&", "||", ";", "&"}


def shell_commands(text):
    """The commands of the shell blocks of a Markdown text, as token lists (continuations and quotes joined)."""
    for block in BLOCK.findall(text):
        pending = ""
        for line in block.replace("\\\n", " ").splitlines():
            pending += re.sub(r"^\$ ", "", line) + "\n"
            try:
                tokens = shlex.split(pending, comments=True)
            except ValueError:  # a quote still open: the command goes on
                continue
            pending = ""
            if tokens:
                end = next((i for i, token in enumerate(tokens) if token in ENDS), len(tokens))
                yield tokens[:end]


COMMANDS = [(path.name, tokens) for path in DOCUMENTS for tokens in shell_commands(path.read_text())
            if tokens[0] == "stickslip"]


def test_the_docs_have_stickslip_commands():
    assert len(COMMANDS) >= 15 and {"README.md", "database.md"} <= {name for name, _ in COMMANDS}


@pytest.mark.parametrize("document, tokens", COMMANDS, ids=[" ".join(t)[:60] for _, t in COMMANDS])
def test_documented_command_parses(document, tokens):
    args = build_parser().parse_args(tokens[1:])
    if args.command == "simulate":
        plugin = registry.get("solver", args.solver)
        parse_params(plugin.params, parse_assignments(args.param), owner=f"solver '{plugin.name}'")


#: docs/writing-a-plugin.md: a file of the example package is a line "`<path>`:" followed by its code block.
PLUGIN_PAGE = ROOT / "docs" / "writing-a-plugin.md"
FILE_BLOCK = re.compile(r"^`([\w./-]+)`:\n\n```\w*\n(.*?)^```", re.S | re.M)


def install_from_page(site):
    """Install the package of docs/writing-a-plugin.md into ``site`` as pip would: its modules and a dist-info folder
    with the entry points of its pyproject.toml (no build backend: CI builds nothing from the network).

    Returns
    -------
    dict[str, str]
        The page's files by path (``my-study.yaml``, ``mystudy/laws.py``, ...).
    """
    files = dict(FILE_BLOCK.findall(PLUGIN_PAGE.read_text()))
    project = tomllib.loads(files["pyproject.toml"])["project"]
    (site / project["name"]).mkdir(parents=True)
    (site / project["name"] / "__init__.py").write_text("")
    for path, text in files.items():
        if path.startswith(f"{project['name']}/"):
            (site / path).write_text(text)
    info = site / f"{project['name']}-{project['version']}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {project['name']}\nVersion: {project['version']}\n")
    (info / "entry_points.txt").write_text("".join(
        f"[{group}]\n" + "".join(f"{name} = {module}\n" for name, module in entries.items()) + "\n"
        for group, entries in project["entry-points"].items()))
    return files


@pytest.mark.slow
def test_the_plugin_package_of_the_docs_runs_a_study_and_reruns_what_its_law_changes(tmp_path, monkeypatch):
    """docs/writing-a-plugin.md: a package outside stickslip with a law, a solver, an analysis and a figure runs a
    study through its entry points alone (no change to stickslip); a change in its law reruns the runs that chose it
    and what reads them."""
    from conftest import copy_workflow
    from test_workflow import planned_jobs, snakemake

    site = tmp_path / "site"
    files = install_from_page(site)
    assert {"mystudy/laws.py", "mystudy/block.py", "mystudy/largest.py", "mystudy/figures.py"} <= set(files)
    (tmp_path / "clone").mkdir()
    workflow = copy_workflow(tmp_path / "clone")
    (workflow / "my-study.yaml").write_text(files["my-study.yaml"])
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba-cache"))  # kernels of the page's law: not shared
    snakemake(workflow, "--cores", "2", "--configfile", "my-study.yaml", distribution=site)

    database = workflow / "results" / "my-study" / "stickslip.sqlite"
    runs = query.runs(database)
    assert sorted(runs["plugin"]) == ["fem", "figS-largest", "largest-slips", "mesh", "numerical-events",
                                      "spring-block", "spring-block"]
    fem = runs[runs["plugin"] == "fem"].iloc[0]
    assert (fem["params.interface_law"], fem["params.law_params"]) == ("soft-cusp", [0.8])
    # the analysis: the largest stress drop of every interface, as the package's own event extraction finds them
    events = query.events(database)
    largest = events[events["analysis"] == "largest-slips"].set_index("interface")["dmu_sig0"]
    expected = events[events["analysis"] == "numerical-events"].groupby("interface")["dmu_sig0"].max()
    assert len(largest) >= 1 and largest.sort_index().to_dict() == expected.to_dict()
    # the solver: the spring force at every slip is the drive's stretch, k (V t - position of the block)
    for row in runs[runs["plugin"] == "spring-block"].itertuples():
        with h5py.File(workflow / row.path) as file:
            t, slip, F = file["t"][...], file["slip"][...], file["F"][...]
        position = np.concatenate([[0.0], np.cumsum(slip)[:-1]])
        np.testing.assert_allclose(F, 1.0 * (0.1 * t - position), rtol=1e-12)
        assert row.seed in (1, 2) and len(t) == 100
    figure = workflow / "results" / "my-study" / "figures" / "figS-largest.pdf"
    assert figure.stat().st_size > 1000 and figure.with_suffix(".png").stat().st_size > 1000

    def planned():
        result = snakemake(workflow, "-n", "--cores", "2", "--configfile", "my-study.yaml", distribution=site)
        return {} if "Nothing to be done" in result.stdout + result.stderr else planned_jobs(result.stdout)

    assert planned() == {}
    law = site / "mystudy" / "laws.py"
    line = "    x, half = eq - 0.5 * (lo + hi), 0.5 * (hi - lo)\n"
    assert line in law.read_text()
    law.write_text(law.read_text().replace(line, line[:-1] + "  # x: from the well's centre\n"))
    assert planned() == {"simulate": 1, "events": 2, "figure_figS_largest": 1, "database": 1, "all": 1}


def test_the_readmes_examples_write_different_files():
    """The README's Python example and its commands can run one after the other: no two write one file."""
    text = (ROOT / "README.md").read_text()
    outputs = [tokens[tokens.index("-o") + 1] for name, tokens in COMMANDS
               if name == "README.md" and tokens[1] == "simulate"]
    outputs += re.findall(r'stickslip\.simulate\("[^"]+", "([^"]+)"', text)
    assert len(outputs) >= 4 and len(outputs) == len(set(outputs)), outputs
