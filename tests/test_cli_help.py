"""`stickslip --help` speaks to users: what the tool is for and where to start, not how the code is laid out."""

from stickslip.cli import build_parser


def test_the_help_speaks_to_users():
    text = build_parser().format_help()
    assert "one module per sub-command" not in text  # the developers' docstring, shown before
    assert "snakemake --cores 2" in text and "stickslip simulate --solver fem" in text
    assert "`stickslip COMMAND --help`" in text
