"""`stickslip --help` speaks to users: what the tool is for and where to start, not how the code is laid out."""

from stickslip.cli import build_parser


def test_the_help_speaks_to_users():
    text = build_parser().format_help()
    assert "one module per sub-command" not in text  # the developers' docstring, shown before
    assert "snakemake --cores 2" in text and "stickslip simulate --solver fem" in text
    assert "`stickslip COMMAND --help`" in text


def _parsers(parser, name="stickslip"):
    """Every (command name, parser) of the command line, sub-commands of sub-commands included."""
    import argparse

    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub, child in action.choices.items():
                yield from _parsers(child, f"{name} {sub}")


def test_every_help_is_plain_text_and_every_option_says_what_it_is():
    """No reST markup in any --help, every option has a help line, no two options differ only in case (--h, --H)."""
    for name, parser in _parsers(build_parser()):
        text = parser.format_help()
        assert "``" not in text and ":mod:" not in text and ":func:" not in text, name
        options = [option for action in parser._actions for option in action.option_strings]
        lowered = [option.lower() for option in options]
        assert len(set(lowered)) == len(lowered), (name, options)
        for action in parser._actions:
            if action.option_strings and action.help is None:
                raise AssertionError(f"{name} {action.option_strings[0]}: no help")
