"""An engine's crank arrangements and firing orders, searched (``balancer search``)."""

from __future__ import annotations

from dataclasses import replace

from ..arrangements import Arrangement, Search
from ..arrangements import search as search_cranks
from ..errors import SpecError
from ..mechanisms.engine.model import Engine
from ..model import Design


def search(design: Design, top: int | None = None, *, balance: bool = False,
           step: float | None = None) -> Search:
    """Every even-firing crank of the design's engine and its firing orders, ranked.

    At the operating speed (``[operation]``, its samples per revolution for the driving
    torque), best first (:mod:`balancer.arrangements`); ``top``: the best ``top`` only.
    ``step``: uneven firing too, every crank whose pins' phases are multiples of ``step``
    (degrees) from cylinder 1's and every firing order that fits in the working cycle.
    ``balance``: each kept arrangement balanced as the spec's
    ``[balance]`` asks (its counterweights and shafts, the certified convex optimum of
    :func:`balancer.optimize` on the engine built with that crank and firing order), its
    result in :attr:`~balancer.arrangements.Arrangement.balanced`.

    Raises
    ------
    SpecError
        For a design that is not an engine, without ``[operation]``, or whose cylinders have
        no even-firing crank (no crank on ``step`` that fires within the working cycle), or a
        ``step`` that does not divide 360°.
    """
    engine = design.mechanism
    if not isinstance(engine, Engine):
        raise SpecError("searches an engine's cranks and firing orders: the spec's mechanism "
                        "must be an engine", key="mechanism.type", value=engine.type)
    if design.operation is None:
        raise SpecError("missing required key: the loads are judged at the operating speed",
                        key="operation.speed")
    if balance and design.balance is None:
        raise SpecError("balances each crank as [balance] asks: the spec has none",
                        key="--balance")
    found = search_cranks(engine, design.operation.speed, top, step=step,
                          samples=design.operation.samples)
    if not balance:
        return found
    from ..balance.optimizer import optimize

    out = []
    for a in found.arrangements:
        result = optimize(replace(design, mechanism=arranged(engine, a)), "convex")
        out.append(replace(a, balanced=result))
    return replace(found, arrangements=tuple(out))


def arranged(engine: Engine, arrangement: Arrangement) -> Engine:
    """``engine`` with ``arrangement``'s crank and firing order.

    Each crankshaft mass (a pin, a web, a counterweight) turns with the cylinder nearest its
    plane: its phase moves by as much as that cylinder's pin.
    """
    cylinders = engine.cylinders
    turned = [new - c.phase_deg for c, new in zip(cylinders, arrangement.phases, strict=True)]
    masses = []
    for m in engine.crankshaft.masses:
        nearest = min(range(len(cylinders)), key=lambda k: (abs(cylinders[k].z - m.z), k))
        masses.append(replace(m, phase_deg=(m.phase_deg + turned[nearest]) % 360.0))
    return replace(engine, firing_order=arrangement.firing_order,
                   crankshaft=replace(engine.crankshaft, masses=tuple(masses)),
                   cylinders=tuple(replace(c, phase_deg=p) for c, p in zip(
                       cylinders, arrangement.phases, strict=True)))


__all__ = ["arranged", "search"]
