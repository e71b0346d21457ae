"""The design specs shipped with the package, by name."""

from __future__ import annotations

from .. import examples
from ..model import Design


def example(name: str) -> Design:
    """A design spec shipped with the package, by name (``balancer example`` lists them)."""
    return examples.load(name)
