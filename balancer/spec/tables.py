"""A TOML table read with the spec's rules: every key named by its path, unknown keys refused."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any, Literal, overload

from .. import validate as v
from ..errors import SpecError
from . import schema


def _as_number(
    value: Any, key: str, check: Callable[[float], bool] | None, requirement: str
) -> float:
    x = v.number(value, key)
    if check is not None and not check(x):
        raise SpecError(f"must be {requirement}", key=key, value=value)
    return x


class Table:
    """A TOML table being read.

    Typed access by key, with the dotted path for messages, and a check that every key was used.
    """

    def __init__(self, data: dict[str, Any], path: str) -> None:
        self.data = data
        self.path = path
        self.used: set[str] = set()
        self.known: tuple[str, ...] | None = schema.screen(path)
        if self.known is not None:
            self.expect(self.known)

    def expect(self, known: tuple[str, ...]) -> None:
        """Declare the keys this table may hold, and report a typo now.

        Before the missing key it causes ("mas" before "mass is missing").
        """
        self.known = tuple(known)
        for name in self.data:
            if name not in self.known:
                self._unknown(name)

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def has(self, name: str) -> bool:
        return name in self.data

    def raw(self, name: str) -> Any:
        self.used.add(name)
        return self.data[name]

    def _missing(self, name: str) -> SpecError:
        return SpecError("missing required key", key=self.key(name))

    @overload
    def table(self, name: str, *, required: Literal[True] = True) -> Table: ...
    @overload
    def table(self, name: str, *, required: bool) -> Table | None: ...

    def table(self, name: str, *, required: bool = True) -> Table | None:
        if name not in self.data:
            if required:
                raise self._missing(name)
            return None
        value = self.raw(name)
        if not isinstance(value, dict):
            raise SpecError("must be a table", key=self.key(name), value=value)
        return Table(value, self.key(name))

    def number(
        self,
        name: str,
        *,
        default: float | None = None,
        check: Callable[[float], bool] | None = None,
        requirement: str = "",
    ) -> float:
        if name not in self.data:
            if default is None:
                raise self._missing(name)
            return default
        value = self.raw(name)
        return _as_number(value, self.key(name), check, requirement)

    def positive(self, name: str, *, default: float | None = None) -> float:
        return self.number(name, default=default, check=lambda x: x > 0, requirement="positive")

    def nonnegative(self, name: str, *, default: float | None = None) -> float:
        return self.number(
            name, default=default, check=lambda x: x >= 0, requirement="zero or positive"
        )

    def value(self, name: str, default: Any) -> Any:
        """The raw value (checked by the model object it goes into), or ``default``."""
        return self.raw(name) if name in self.data else default

    def string(self, name: str, *, choices: tuple[str, ...], default: str | None = None) -> str:
        if name not in self.data:
            if default is None:
                raise self._missing(name)
            return default
        return v.choice(self.raw(name), self.key(name), choices)

    def text(self, name: str, *, default: str) -> str:
        if name not in self.data:
            return default
        value = self.raw(name)
        if not isinstance(value, str):
            raise SpecError("must be a string", key=self.key(name), value=value)
        return value

    def vector2(self, name: str, *, default: tuple[float, float]) -> tuple[float, float]:
        if name not in self.data:
            return default
        return v.vector2(self.raw(name), self.key(name))

    def tables(self, name: str) -> list[Table]:
        """An array of tables (``[[name]]``, or a list of inline tables), each as a table.

        Their paths are indexed (``springs[0]``); absent: none.
        """
        if not self.has(name):
            return []
        raw = self.raw(name)
        key = self.key(name)
        if not isinstance(raw, list) or not all(isinstance(item, dict) for item in raw):
            raise SpecError(f"must be an array of tables ([[{key}]])", key=key, value=raw)
        return [Table(entry, v.item(key, i)) for i, entry in enumerate(raw)]

    def finish(self) -> None:
        """Raise on the first key that was not used (unknown, or a typo)."""
        for name in self.data:
            if name not in self.used:
                self._unknown(name)

    def _unknown(self, name: str) -> None:
        raise SpecError(f"unknown key '{name}'{hint(name, self.known or ())}",
                        key=self.key(name))


def meant(name: str, known: Iterable[str]) -> str | None:
    """The known name a mistyped ``name`` most likely meant, or ``None``.

    First a name that the typed one begins, or that begins it, ignoring case (``bank`` →
    ``bank_deg``, ``mass_kg`` → ``mass``); then one with its stem, the part before the first
    underscore (``phase_rad`` → ``phase_deg``); then the closest spelling (``mas`` → ``mass``).
    Among several, the closest spelling.
    """
    import difflib  # only for a spec that is wrong

    names = sorted(set(known))
    low = name.lower()

    def closest(candidates: list[str]) -> str:
        return max(candidates,
                   key=lambda k: difflib.SequenceMatcher(None, low, k.lower()).ratio())

    prefixed = [k for k in names if k.lower().startswith(low) or low.startswith(k.lower())]
    if low and prefixed:
        return closest(prefixed)
    stem = low.split("_", 1)[0]
    stemmed = [k for k in names if "_" in k + low and k.lower().split("_", 1)[0] == stem]
    if stem and stemmed:
        return closest(stemmed)
    close = difflib.get_close_matches(name, names, n=1)
    return close[0] if close else None


def hint(name: str, known: Iterable[str]) -> str:
    """``"; did you mean '…'?"`` for a mistyped ``name`` (:func:`meant`), or ``""``.

    Never ``name`` itself (a key known elsewhere but refused here).
    """
    found = meant(name, [k for k in known if k != name])
    return f"; did you mean '{found}'?" if found is not None else ""
