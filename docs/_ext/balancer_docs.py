"""The pages of balancer's site that are generated from the code while it is built.

``<!-- spec-schema -->`` in a page is replaced, as the page is read, by the reference of every
spec key from :mod:`balancer.spec.schema` (the reader's own list: a key the reader accepts has
its entry there). Nothing is written to the source folder.
"""

from __future__ import annotations

from balancer.spec import schema

MARKER = "<!-- spec-schema -->"
#: How a set of mechanisms reads in the reference.
_EVERY = "all"


def mechanisms(names: tuple[str, ...]) -> str:
    """The mechanisms of an entry as the reference writes them."""
    return _EVERY if set(names) == set(schema.MECHANISMS) else ", ".join(names)


def _cell(text: str) -> str:
    """Text for a cell of a Markdown table (its pipes escaped)."""
    return text.replace("|", "\\|").replace("\n", " ")


def label(pattern: str) -> str:
    """The page's anchor of a table: ``spec-links-link-com`` for ``links.<link>.com``.

    (An underscore stays: ``balance_shafts[]`` and ``balance.shafts[]`` are two tables.)
    """
    slug = "".join(c if c.isalnum() or c == "_" else "-" for c in pattern.lower())
    return "spec-" + "-".join(part for part in slug.split("-") if part) if pattern else "spec-top"


def reference() -> str:
    """Every table of the spec and its keys, as Markdown: unit, default, mechanisms, meaning."""
    out: list[str] = []
    for section in schema.SECTIONS:
        out += [f"({label(section.pattern)})=", f"### `{section.header}`", "",
                section.summary, ""]
        if set(section.mechanisms) != set(schema.MECHANISMS):
            out += [f"Only in a spec of a {' or a '.join(section.mechanisms)}.", ""]
        out += ["| key | unit | default | mechanisms | meaning |", "|---|---|---|---|---|"]
        entries = [*section.keys, *([section.names] if section.names else [])]
        for key in entries:
            meaning = key.meaning
            if key.example:
                name = key.name if not key.name.startswith("<") else "A1"
                meaning += f" Example: `{name} = {key.example}`."
            out.append("| " + " | ".join(_cell(c) for c in (
                f"`{key.name}`", key.unit, key.default, mechanisms(key.mechanisms),
                meaning)) + " |")
        out.append("")
    return "\n".join(out)


def _source_read(app, docname: str, source: list[str]) -> None:
    if MARKER in source[0]:
        source[0] = source[0].replace(MARKER, reference())


def setup(app):
    """Register the generators with Sphinx."""
    app.connect("source-read", _source_read)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
