"""The README's and docs/database.md's query examples return what they say, on the ci study's database.

The examples are run as written, in a folder whose ``results/default`` is a copy of the ci study's
results (so ``stickslip db`` without ``--study`` reads it, and ``db rebuild`` writes the copy):
every query command and every pandas example must give rows. The examples do not name a solver (the
default study's virtual experiment is ``rate-state-lever``, the ci study's ``lever``).
"""

import re
import shutil

import pytest

from stickslip.cli import main
from test_docs_commands import ROOT, shell_commands

DOCUMENTS = [ROOT / "README.md", ROOT / "docs" / "database.md"]
QUERIES = [(path.name, tokens) for path in DOCUMENTS for tokens in shell_commands(path.read_text())
           if tokens[:2] == ["stickslip", "db"]]
PYTHON = re.compile(r"^```python\n(.*?)^```", re.S | re.M)

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def default_study(ci_study, tmp_path_factory):
    """A folder whose results/default is a copy of the ci study's results (the records point to results/ci)."""
    folder = tmp_path_factory.mktemp("docs-queries")
    shutil.copytree(ci_study / "results" / "ci", folder / "results" / "default")
    (folder / "results" / "ci").symlink_to(ci_study / "results" / "ci")
    return folder


def test_the_documents_have_query_examples():
    assert {name for name, _ in QUERIES} == {"README.md", "database.md"} and len(QUERIES) >= 7


@pytest.mark.parametrize("document, tokens", QUERIES, ids=[" ".join(t)[10:60] for _, t in QUERIES])
def test_a_query_example_gives_rows(default_study, monkeypatch, capsys, document, tokens):
    monkeypatch.chdir(default_study)
    capsys.readouterr()
    assert main(tokens[1:]) == 0
    out = capsys.readouterr().out
    assert out.strip() and "(no rows)" not in out and out.strip() not in ("[]", "{}"), f"{document}: {tokens}"
    if tokens[2] != "rebuild":
        assert len(out.strip().splitlines()) >= 2 or out.lstrip().startswith("[{"), out  # a header and a row


def test_the_pandas_examples_give_rows(default_study, monkeypatch):
    monkeypatch.chdir(default_study)
    namespace = {}
    for block in PYTHON.findall((ROOT / "docs" / "database.md").read_text()):
        exec(block, namespace)
    frames = {name: value for name, value in namespace.items() if hasattr(value, "empty")}
    assert set(frames) >= {"runs", "events", "mean_dmu", "slowest"}
    assert all(not frame.empty for frame in frames.values()), {name: len(frame) for name, frame in frames.items()}
    assert namespace["simulation"].header["n"] == 3 and namespace["simulation"].path.is_file()
