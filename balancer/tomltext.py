r"""TOML text that reads back to the same values: numbers, strings and keys.

The writers of :mod:`balancer.spec` (a design) and :mod:`balancer.balance.problem` (its
``[balance]`` table) share these, so that whatever a spec may name (a link called ``a.b``, a
point with a quote in its name) is written as TOML reads it (TOML 1.0: a bare key is ASCII
letters, digits, ``-`` and ``_``; a basic string escapes ``"``, ``\`` and the control
characters).
"""

from __future__ import annotations


def number(x: float) -> str:
    """The shortest text that reads back to the same float (``repr``); an int as it is."""
    if isinstance(x, bool):
        raise TypeError("a bool is not a number")
    if isinstance(x, int):
        return str(x)
    return repr(float(x))


def string(text: str) -> str:
    """A TOML basic string of ``text``."""
    out = []
    for c in text:
        if c in '"\\':
            out.append("\\" + c)
        elif c == "\n":
            out.append("\\n")
        elif c == "\t":
            out.append("\\t")
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append(f"\\u{ord(c):04X}")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'


def key(name: str) -> str:
    """A TOML key: bare if it can be, else quoted."""
    bare = bool(name) and name.isascii() and all(c.isalnum() or c in "-_" for c in name)
    return name if bare else string(name)
