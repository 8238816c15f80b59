"""docs/tutorial.md runs: every code block in order, each prints the output shown after it, and the repository
is left as it was (the tutorial's files go to its temporary folder ``work``).

The blocks run in one fresh Python process and one namespace, as in a notebook's kernel (this module,
run as a script, is that process), in a copy of the workflow that holds the ci study's results (the
session's ``ci_study``, run by `snakemake --cores 2` once for the tests that share it): the tutorial's
own `snakemake` block runs there and finds the study done instead of computing it a second time (~1 min).
(The blocks are not run in a Jupyter kernel through jupytext and nbclient: that would add ipykernel,
jupyter_client, pyzmq and debugpy, ~40 MB, to CI for this one test; this runner executes the same code in
one process and namespace, as the kernel would, and compares the printed text.)
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


def run_blocks(blocks, namespace):
    """Run the blocks in order in this process, in ``namespace``; yield (line, what a python block printed, or
    the error)."""
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


def _files(directory):
    """Every file under ``directory`` but the study's results and Snakemake's state (ignored by git)."""
    return sorted(str(path.relative_to(directory)) for path in directory.rglob("*")
                  if path.relative_to(directory).parts[0] not in ("results", ".snakemake"))


@pytest.mark.slow
def test_every_block_of_the_tutorial_runs_and_prints_what_it_shows(ci_study, tmp_path):
    directory = tmp_path / "repository"
    shutil.copytree(ci_study, directory, symlinks=True)
    before = _files(directory)
    environment = dict(os.environ, MPLBACKEND="Agg", TMPDIR=str(tmp_path),
                       PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    environment.pop("STICKSLIP_WORKDIR", None)
    done = subprocess.run([sys.executable, __file__, tmp_path / "results.json"], cwd=directory, env=environment,
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    outcome = json.loads((tmp_path / "results.json").read_text())
    results = {line: (printed, error) for line, printed, error in outcome["blocks"]}
    blocks = tutorial_blocks(TUTORIAL.read_text(encoding="utf-8"))
    for language, _, line, shown in blocks:
        assert line in results, f"{TUTORIAL.name}: the block at line {line} did not run"
        printed, error = results[line]
        assert error is None, f"{TUTORIAL.name}, block at line {line}:\n{error}"
        if shown is not None:
            assert _lines(printed) == _lines(shown), f"{TUTORIAL.name}, block at line {line}"
    work = Path(outcome["work"])
    assert work.parent == tmp_path and (work / "tutorial.png").stat().st_size > 10_000
    assert _files(directory) == before  # nothing written into the repository


if __name__ == "__main__":  # the fresh process of the test above: python test_tutorial.py RESULTS.json
    namespace = {"__name__": "__tutorial__"}
    outcome = list(run_blocks(tutorial_blocks(TUTORIAL.read_text(encoding="utf-8")), namespace))
    Path(sys.argv[1]).write_text(json.dumps({"blocks": outcome, "work": str(namespace.get("work"))}))
