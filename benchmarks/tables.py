"""The benchmarks' one table printer: aligned text, or Markdown for docs/benchmarks.md."""

from __future__ import annotations

from collections.abc import Sequence


def print_table(header: Sequence[str], rows: Sequence[Sequence[str]], *,
                markdown: bool = False, right: Sequence[int] = ()) -> None:
    """Print ``rows`` (cells as strings) under ``header``.

    Text: columns padded to their widest cell (those in ``right`` aligned right), a rule under
    the header. Markdown: a pipe table.
    """
    table = [tuple(header), *(tuple(r) for r in rows)]
    if markdown:
        for i, r in enumerate(table):
            print("| " + " | ".join(c.replace("|", "\\|") for c in r) + " |")
            if i == 0:
                print("|" + "---|" * len(header))
        return
    widths = [max(len(r[i]) for r in table) for i in range(len(header))]
    for i, r in enumerate(table):
        print("  ".join(c.rjust(w) if j in right else c.ljust(w)
                        for j, (c, w) in enumerate(zip(r, widths, strict=True))).rstrip())
        if i == 0:
            print("  ".join("-" * w for w in widths))
