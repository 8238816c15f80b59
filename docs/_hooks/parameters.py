"""MkDocs hook: the parameter tables of docs/parameters.md, generated from the plugins' declarations at build time.

Replaces the marker ``<!-- stickslip:parameters -->`` with one table per solver and analysis: name, type,
default, unit, the range a value must lie in, and what it is (:mod:`stickslip.plugin_params`).
"""

import dataclasses

MARKER = "<!-- stickslip:parameters -->"


def _range(metadata):
    """The accepted values of a parameter, from its declaration."""
    parts = []
    if metadata.get("choices") is not None:
        parts.append("one of " + ", ".join(f"`{choice}`" for choice in metadata["choices"]))
    if metadata.get("exclusive_minimum") is not None:
        parts.append(f"> {metadata['exclusive_minimum']:g}")
    if metadata.get("minimum") is not None:
        parts.append(f">= {metadata['minimum']:g}")
    if metadata.get("maximum") is not None:
        parts.append(f"<= {metadata['maximum']:g}")
    return "; ".join(parts)


def _cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def tables():
    """The Markdown of every solver's and analysis's parameter table."""
    from stickslip import registry
    from stickslip.plugin_params import describe

    out = []
    for kind in ("solver", "analysis"):
        for name, plugin in sorted(registry.available(kind).items()):
            fields = {field.name: field for field in dataclasses.fields(plugin.params)}
            out += [f"## {kind} `{name}` (version {plugin.version})", "", _cell(plugin.summary), "",
                    "| parameter | type | default | unit | range | what it is |", "|---|---|---|---|---|---|"]
            for parameter, kind_name, default, unit, doc in describe(plugin.params):
                out.append(f"| `{parameter}` | {kind_name} | `{default!r}` | {_cell(unit)} | "
                           f"{_cell(_range(fields[parameter].metadata))} | {_cell(doc)} |")
            out.append("")
    return "\n".join(out)


def on_page_markdown(markdown, page, config, files):
    """MkDocs' hook: fill the marker where a page has it."""
    return markdown.replace(MARKER, tables()) if MARKER in markdown else markdown
