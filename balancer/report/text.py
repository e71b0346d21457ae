"""Text, tables, JSON and CSV as every command writes them: the forms, not the figures."""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import SolverError


def table(rows: Sequence[Sequence[str]], header: Sequence[str]) -> str:
    """A plain text table: first column left-aligned, the others right-aligned."""
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    lines = []
    for r in [header, *rows]:
        cells = [
            str(c).ljust(w) if i == 0 else str(c).rjust(w)
            for i, (c, w) in enumerate(zip(r, widths, strict=True))
        ]
        lines.append("  ".join(cells).rstrip())
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A GitHub-flavoured markdown table (first column left-aligned, the others right)."""
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join([":---"] + ["---:"] * (len(header) - 1)) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def dumps_json(doc: dict[str, Any]) -> str:
    """JSON text with a trailing newline; NaN and infinity are not allowed.

    Raises
    ------
    SolverError
        Naming the first field that holds NaN or infinity (a computation that failed; strict
        JSON has no such numbers, and a reader must not get them).
    """
    where = _nonfinite(doc, "")
    if where is not None:
        raise SolverError(f"the results are not finite numbers (at {where}): the computation "
                          "lost its precision")
    import json  # here: a table needs no JSON

    return json.dumps(doc, indent=2, allow_nan=False) + "\n"


def _nonfinite(value: Any, path: str) -> str | None:
    """The path of the first NaN or infinity in a JSON-like document, or ``None``."""
    if isinstance(value, float):
        return None if math.isfinite(value) else (path or "the top")
    if isinstance(value, dict):
        for key, item in value.items():
            found = _nonfinite(item, f"{path}.{key}" if path else str(key))
            if found is not None:
                return found
    elif isinstance(value, list | tuple):
        for i, item in enumerate(value):
            found = _nonfinite(item, f"{path}[{i}]")
            if found is not None:
                return found
    return None


def csv_text(columns: Sequence[str], values: Sequence[np.ndarray]) -> str:
    """CSV with a header row; numbers written so that they read back exactly.

    A value that does not exist (a reaction at the change point of a change-point linkage,
    unbounded there) is an empty cell, never a literal ``nan``.
    """
    data = np.column_stack([np.broadcast_to(np.asarray(v, dtype=float), np.shape(values[0]))
                            for v in values])
    buf = io.StringIO()
    np.savetxt(buf, data, delimiter=",", fmt="%.17g")
    lines = buf.getvalue().splitlines()
    for i in np.flatnonzero(~np.isfinite(data).all(axis=1)):
        lines[i] = ",".join("" if not np.isfinite(x) else cell
                            for x, cell in zip(data[i], lines[i].split(","), strict=True))
    return "\n".join([",".join(columns), *lines]) + "\n"


# ----------------------------------------------------------------------------------------------
# simulate
