"""An engine's crank arrangements and firing orders, searched (``balancer search``)."""

from __future__ import annotations

from ..arrangements import Search
from ..arrangements import search as search_cranks
from ..errors import SpecError
from ..mechanisms.engine.model import Engine
from ..model import Design


def search(design: Design, top: int | None = None) -> Search:
    """Every even-firing crank of the design's engine and its firing orders, ranked.

    At the operating speed (``[operation]``), best first (:mod:`balancer.arrangements`);
    ``top``: the best ``top`` only.

    Raises
    ------
    SpecError
        For a design that is not an engine, without ``[operation]``, or whose cylinders have
        no even-firing crank.
    """
    engine = design.mechanism
    if not isinstance(engine, Engine):
        raise SpecError("searches an engine's cranks and firing orders: the spec's mechanism "
                        "must be an engine", key="mechanism.type", value=engine.type)
    if design.operation is None:
        raise SpecError("missing required key: the loads are judged at the operating speed",
                        key="operation.speed")
    return search_cranks(engine, design.operation.speed, top)


__all__ = ["search"]
