"""docs/tutorial.md runs: every code block in order, and each prints the output shown after it.

The tutorial's blocks run in one namespace, as in a notebook, in a copy of the workflow that holds the
ci study's results (the session's ``ci_study``, run by `snakemake --cores 2` once for the tests that share
it): the tutorial's own `snakemake` block runs there and finds the study done, instead of computing it a
second time (~1 min). Its Python blocks run in this process.
"""

import contextlib
import io
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import REPO

TUTORIAL = REPO / "docs" / "tutorial.md"

#: A fenced block: its language and its lines.
FENCE = re.compile(r"^```(\w*)\n(.*?)^```\s*$", re.M | re.S)


def tutorial_blocks(text):
    """The blocks to run: (language, code, line of the code's first line, the output shown after it or None).

    A ``text`` block right after a ``python`` block is that block's printed output.
    """
    fences = [(m.group(1), m.group(2), text.count("\n", 0, m.start(2)) + 1, m) for m in FENCE.finditer(text)]
    blocks = []
    for index, (language, code, line, match) in enumerate(fences):
        if language not in ("python", "bash"):
            continue
        after = fences[index + 1] if index + 1 < len(fences) else None
        shown = (after[1] if after and after[0] == "text" and language == "python"
                 and not text[match.end():after[3].start()].strip() else None)
        blocks.append((language, code, line, shown))
    return blocks


def _lines(text):
    return [line.rstrip() for line in text.rstrip("\n").splitlines()]


def test_the_tutorial_has_blocks_with_outputs():
    blocks = tutorial_blocks(TUTORIAL.read_text(encoding="utf-8"))
    assert [language for language, *_ in blocks].count("bash") == 1
    assert sum(shown is not None for *_, shown in blocks) >= 8


@pytest.mark.slow
def test_every_block_of_the_tutorial_runs_and_prints_what_it_shows(ci_study, tmp_path, monkeypatch):
    directory = tmp_path / "repository"
    shutil.copytree(ci_study, directory, symlinks=True)
    monkeypatch.chdir(directory)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    environment = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    namespace = {"__name__": "__tutorial__"}
    for language, code, line, shown in tutorial_blocks(TUTORIAL.read_text(encoding="utf-8")):
        where = f"{TUTORIAL.name}, block at line {line}"
        if language == "bash":
            done = subprocess.run(["bash", "-euo", "pipefail", "-c", code], env=environment, capture_output=True,
                                  text=True, timeout=600)
            assert done.returncode == 0, f"{where}:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
            continue
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile("\n" * (line - 1) + code, str(TUTORIAL), "exec"), namespace)  # tracebacks: the doc's lines
        if shown is not None:
            assert _lines(printed.getvalue()) == _lines(shown), where
    assert (directory / "tutorial.png").stat().st_size > 10_000
