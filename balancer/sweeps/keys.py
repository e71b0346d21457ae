"""Dotted spec keys: the number a key names in a parsed spec, a spec with keys set, units.

A key is a dotted path into the spec's TOML (``mechanism.lengths.coupler``,
``mechanism.points.B.1``, ``links.crank.mass``: a list's entry by its index); it must name a
number. :func:`with_values` sets keys on a copy of the spec (a sweep's point), :func:`check_key`
refuses a key that names no number with the spec's closest keys, :func:`key_unit` gives a key's
unit for axes and titles.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..errors import SpecError


def key_value(data: dict[str, Any], key: str) -> float:
    """The number a dotted key names in a parsed spec."""
    node, index = _locate(data, key)
    return float(node[index])


def spec_values(spec: str | os.PathLike[str], keys: Sequence[str]) -> dict[str, float]:
    """The spec's own value of each dotted key: where its design lies among a sweep's points."""
    import tomllib

    data = tomllib.loads(Path(spec).read_text(encoding="utf-8-sig"))
    return {key: key_value(data, key) for key in keys}


#: The unit of a spec key by its last name (list indices skipped): SI, as the spec takes them.
KEY_UNITS = {"mass": "kg", "inertia": "kg·m²", "counter_rotor": "kg·m²",
             "e": "m", "f": "m", "s": "m", "at": "m", "com_radius": "m", "min_gyration": "m",
             "radius": "m", "gyration": "m", "free_length": "m", "sigma": "rad",
             "theta1": "rad", "speed": "rad/s", "omega1": "rad/s", "force": "N",
             "moment": "N·m", "stiffness": "N/m", "gravity": "m/s²", "duration": "s",
             "z": "m", "planes": "m", "mr": "kg·m", "max_mr": "kg·m", "bank_deg": "°",
             "phase_deg": "°", "crankcase": "Pa"}


def key_unit(key: str) -> str:
    """The unit of the number a dotted spec key names (``""`` if it has none, or is unknown).

    Every entry of ``mechanism.lengths`` and ``mechanism.points`` is a length (m); otherwise
    :data:`KEY_UNITS` by the key's last name (``links.crank.com.s`` m, ``links.crank.mass``
    kg, ``balance.crank.mass.1`` kg, ``links.crank.force.0`` N).
    """
    parts = key.split(".")
    if parts[:2] in (["mechanism", "lengths"], ["mechanism", "points"]):
        return "m"
    names = [part for part in parts if not part.isdigit()]
    return KEY_UNITS.get(names[-1], "") if names else ""



def _locate(data: dict[str, Any], key: str) -> tuple[Any, Any]:
    """The container and index of the number a dotted key names.

    A list's entry is named by its index; :class:`SpecError` names the key if it names none.
    """
    node: Any = data
    parts = key.split(".")
    for i, part in enumerate(parts):
        if isinstance(node, list) and part.isdigit() and int(part) < len(node):
            index: Any = int(part)
        elif isinstance(node, dict) and part in node:
            index = part
        else:
            raise SpecError("no such number in the spec", key=key)
        if i == len(parts) - 1:
            if isinstance(node[index], bool) or not isinstance(node[index], int | float):
                raise SpecError("names no number in the spec", key=key)
            return node, index
        node = node[index]
    raise SpecError("no such number in the spec", key=key)  # an empty key


def number_keys(data: Any, prefix: str = "") -> list[str]:
    """Every dotted key that names a number in a parsed spec (a list's entries by index)."""
    items: Iterable[tuple[str, Any]]
    if isinstance(data, dict):
        items = data.items()
    elif isinstance(data, list):
        items = ((str(i), x) for i, x in enumerate(data))
    else:
        return [prefix] if isinstance(data, int | float) and not isinstance(data, bool) \
            else []
    return [key for name, value in items
            for key in number_keys(value, f"{prefix}.{name}" if prefix else str(name))]


def check_key(data: dict[str, Any], key: str, option: str) -> None:
    """Raise :class:`SpecError` naming ``option`` if ``key`` names no number of the spec.

    The message suggests the spec's closest keys (a typo such as ``links.crank.mas``).
    """
    try:
        _locate(data, key)
    except SpecError:
        import difflib  # only for a key that is wrong

        close = difflib.get_close_matches(key, number_keys(data), n=3, cutoff=0.6)
        hint = ("; did you mean " + " or ".join(f"'{c}'" for c in close) + "?") if close \
            else "; give the dotted key of a number of the spec, e.g. links.crank.mass"
        raise SpecError(f"names no number of the spec{hint}", key=option, value=key) from None


def with_values(data: dict[str, Any], values: dict[str, float]) -> dict[str, Any]:
    """A copy of a parsed spec with each dotted key set.

    The key must name a number in the spec (``mechanism.lengths.coupler``,
    ``mechanism.points.B.1``, ``links.crank.mass``).
    """
    for key in values:
        _locate(data, key)  # (names a number: SpecError naming the key if not)
    out = _copy_along(data, [key.split(".") for key in values])
    for key, value in values.items():
        node, index = _locate(out, key)
        node[index] = float(value)
    return out


def _copy_along(node: Any, paths: list[list[str]]) -> Any:
    """``node`` with every container on ``paths`` copied, the rest shared with ``node``.

    What :func:`with_values` changes is then the copy's alone (a point's spec costs a few
    containers, not a deep copy of the whole document).
    """
    if not paths or not isinstance(node, dict | list):
        return node
    heads: dict[str, list[list[str]]] = {}
    for path in paths:
        if path:
            heads.setdefault(path[0], []).append(path[1:])
    out = copy.copy(node)
    for head, rest in heads.items():
        index: Any = int(head) if isinstance(node, list) else head
        out[index] = _copy_along(node[index], [r for r in rest if r])
    return out
