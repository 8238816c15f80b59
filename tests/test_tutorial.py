"""docs/tutorial.md runs: every code block in order, and each prints the output shown after it.

The blocks run in one fresh Python process and one namespace, as in a notebook's kernel (this module,
run as a script, is that process), in a copy of the workflow that holds the ci study's results (the
session's ``ci_study``, run by `snakemake --cores 2` once for the tests that share it): the tutorial's
own `snakemake` block runs there and finds the study done instead of computing it a second time (~1 min).
"""

import contextlib
import io
import json
import os
import re
import shutil
import subprocess
import sys
import traceback
from pathlib import Path

import pytest

TUTORIAL = Path(__file__).resolve().parents[1] / "docs" / "tutorial.md"

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


def run_blocks(blocks):
    """Run the blocks in order in this process; yield (line, what a python block printed, or the error)."""
    namespace = {"__name__": "__tutorial__"}
    for language, code, line, _ in blocks:
        if language == "bash":
            done = subprocess.run(["bash", "-euo", "pipefail", "-c", code], capture_output=True, text=True)
            if done.returncode:
                yield line, done.stdout, f"exit status {done.returncode}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
                return
            yield line, done.stdout, None
            continue
        printed = io.StringIO()
        try:
            with contextlib.redirect_stdout(printed):
                exec(compile("\n" * (line - 1) + code, str(TUTORIAL), "exec"), namespace)  # tracebacks: the doc's lines
        except Exception:
            yield line, printed.getvalue(), traceback.format_exc()
            return
        yield line, printed.getvalue(), None


def _lines(text):
    return [line.rstrip() for line in text.rstrip("\n").splitlines()]


def test_the_tutorial_has_blocks_with_outputs():
    blocks = tutorial_blocks(TUTORIAL.read_text(encoding="utf-8"))
    assert [language for language, *_ in blocks].count("bash") == 1
    assert sum(shown is not None for *_, shown in blocks) >= 8


@pytest.mark.slow
def test_every_block_of_the_tutorial_runs_and_prints_what_it_shows(ci_study, tmp_path):
    directory = tmp_path / "repository"
    shutil.copytree(ci_study, directory, symlinks=True)
    environment = dict(os.environ, MPLBACKEND="Agg",
                       PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    done = subprocess.run([sys.executable, __file__, tmp_path / "results.json"], cwd=directory, env=environment,
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    results = {line: (printed, error) for line, printed, error in json.loads((tmp_path / "results.json").read_text())}
    blocks = tutorial_blocks(TUTORIAL.read_text(encoding="utf-8"))
    for language, _, line, shown in blocks:
        assert line in results, f"{TUTORIAL.name}: the block at line {line} did not run"
        printed, error = results[line]
        assert error is None, f"{TUTORIAL.name}, block at line {line}:\n{error}"
        if shown is not None:
            assert _lines(printed) == _lines(shown), f"{TUTORIAL.name}, block at line {line}"
    assert (directory / "tutorial.png").stat().st_size > 10_000


if __name__ == "__main__":  # the fresh process of the test above: python test_tutorial.py RESULTS.json
    outcome = list(run_blocks(tutorial_blocks(TUTORIAL.read_text(encoding="utf-8"))))
    Path(sys.argv[1]).write_text(json.dumps(outcome))
