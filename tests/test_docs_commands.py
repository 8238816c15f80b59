"""Every ``stickslip`` command in the README's and docs' shell blocks parses, and its plugin parameters are valid.

The commands are not run (most need a study's results); what would break them silently
(a renamed option or sub-command, a parameter that no longer exists or is out of range)
fails here.
"""

import re
import shlex
from pathlib import Path

import pytest

from stickslip import registry
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


def test_the_readmes_examples_write_different_files():
    """The README's Python example and its commands can run one after the other: no two write one file."""
    text = (ROOT / "README.md").read_text()
    outputs = [tokens[tokens.index("-o") + 1] for name, tokens in COMMANDS
               if name == "README.md" and tokens[1] == "simulate"]
    outputs += re.findall(r'stickslip\.simulate\("[^"]+", "([^"]+)"', text)
    assert len(outputs) >= 4 and len(outputs) == len(set(outputs)), outputs
