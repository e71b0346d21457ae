"""The entries of the spec's schema: a key (:class:`Key`) and a table of them (:class:`Section`).

The mechanism types' names too. :mod:`balancer.spec.schema` lists the spec's tables with these;
the motions' tables are in :mod:`balancer.spec.schema_motions`.
"""

from __future__ import annotations

from dataclasses import dataclass

FOUR_BAR = "four-bar"
SLIDER_CRANK = "slider-crank"
LINKAGE = "linkage"
ENGINE = "engine"
#: The values of ``[mechanism] type``.
MECHANISMS = (FOUR_BAR, SLIDER_CRANK, LINKAGE, ENGINE)


@dataclass(frozen=True)
class Key:
    """One key of a table.

    Attributes
    ----------
    name
        The key as written in the spec (an entry for names the spec chooses: ``<point>``).
    unit
        Its unit (SI), ``—`` for none (a name, a flag, a weight without dimension), or
        ``table`` for a table of its own.
    default
        What an absent key means (``required`` where it must be given).
    meaning
        What it is, its bounds and where it applies.
    mechanisms
        The mechanism types whose specs accept it.
    example
        A TOML value for it (empty for a table described by a section of its own).
    """

    name: str
    unit: str
    default: str
    meaning: str
    mechanisms: tuple[str, ...] = MECHANISMS
    example: str = ""


@dataclass(frozen=True)
class Section:
    """A table of the spec (by its pattern) and its keys.

    Attributes
    ----------
    pattern
        The table's dotted path, ``<link>`` for a link's name, ``[]`` for an array of tables.
    summary
        What the table is.
    keys
        Its fixed keys (a name may have one entry per set of mechanisms).
    mechanisms
        The mechanism types whose specs may have the table.
    names
        For a table whose keys are names the spec chooses: the entry that describes them.
    """

    pattern: str
    summary: str
    keys: tuple[Key, ...]
    mechanisms: tuple[str, ...] = MECHANISMS
    names: Key | None = None

    def keys_for(self, mechanism: str | None = None) -> tuple[Key, ...]:
        """The entries of the fixed keys that apply to ``mechanism`` (``None``: any)."""
        return tuple(k for k in self.keys if mechanism is None or mechanism in k.mechanisms)

    @property
    def header(self) -> str:
        """The table as TOML writes it (``[links.<link>]``, ``[[springs]]``, top level)."""
        if not self.pattern:
            return "top level"
        if self.pattern.endswith("[]"):
            return f"[[{self.pattern[:-2]}]]"
        return f"[{self.pattern}]"
