"""The shipped example specs (package data): the paper's four-bar, PB1 and PB2, engines, six-bars.

They are the TOML files beside this module (``examples/`` at the repository's root is a link
to this folder, so that the README's paths work in a checkout); ``balancer example NAME`` writes
one out. Nothing here imports the numerics.

>>> from balancer import examples
>>> "pb1" in examples.names()
True
>>> design = examples.load("meijaard2020")  # doctest: +SKIP
"""

from __future__ import annotations

import tomllib
from importlib import resources
from importlib.resources.abc import Traversable

from ..errors import SpecError
from ..model import Design
from ..spec import loads_design


def names() -> tuple[str, ...]:
    """The examples' names (their file names without ``.toml``), sorted."""
    folder = resources.files(__name__)
    return tuple(sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml")))


def _resource(name: str) -> Traversable:
    stem = name[:-5] if name.endswith(".toml") else name
    if stem not in names():
        raise SpecError(f"no such example; choose from {', '.join(names())}", key="example",
                        value=name)
    return resources.files(__name__) / f"{stem}.toml"


def text(name: str) -> str:
    """The spec of example ``name`` (with or without ``.toml``) as TOML text.

    Raises
    ------
    SpecError
        If there is no such example (naming those there are).
    """
    return _resource(name).read_text(encoding="utf-8")


def title(name: str) -> str:
    """The example's ``title``, or its first comment line, or ``""``."""
    body = text(name)
    found = tomllib.loads(body).get("title")
    if isinstance(found, str) and found:
        return found
    for line in body.splitlines():
        if line.startswith("#"):
            return line.lstrip("# ").strip()
    return ""


def load(name: str) -> Design:
    """The example's :class:`~balancer.model.Design` (its errors name the example's file)."""
    return loads_design(text(name), source=f"example {name}")
