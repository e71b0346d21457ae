"""Crank arrangements and firing orders searched: every even-firing crank, ranked by what it frees.

For an engine's cylinders as its spec places them (planes, banks, which share a crank pin:
:meth:`~.model.Engine.throws`), every assignment of pin phases to the throws whose cylinders can
fire evenly — the firings ``Θ/n`` apart over the working cycle ``Θ`` (720° for a four-stroke,
360° for a two-stroke), each cylinder at its top dead centre ``bank − phase`` (or, in a
four-stroke, 360° later) — and every firing order each allows, cylinder 1 first. Throw 1 keeps
its phase (the crank's angle is a convention); the others take the phases that put their first
cylinder's top dead centre on a firing, ``bank − s − j·Θ/n`` (``s`` cylinder 1's).

Each candidate is judged by what it leaves free, from its cylinders' inertial loads alone (rods
and pistons, not the crankshaft's own masses, which the designer sizes after): a cylinder with
its pin at phase ``φ`` has its phase-0 phasors turned, order ``n``'s forward by ``e^{i·n·φ}``
and backward by ``e^{−i·n·φ}`` (:mod:`balancer.phasors`: its load is the phase-0 one at
``θ1 + φ``), and its couple is ``i·z`` times its force. Counterweights on the crank turn with it:
they can take the primary's forward whirl (force and couple) and nothing else, so the ranking is
by, in turn, the primary force's and couple's backward whirls, the secondary force and couple
(both whirls), each to the rounding of the engine's scale; then by the firings that follow one
another in the same half of the crank (fewer spreads the load along it: the in-line six's
1-5-3-6-2-4 alternates); then by the firing order. The classic answers come out on top by
themselves (the tests hold them): the flat-plane four, the in-line six, the cross-plane V8.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import TYPE_CHECKING

from .errors import SpecError
from .mechanisms import mechanism_of
from .mechanisms.engine.model import Crankshaft, Engine
from .phasors import phasors

if TYPE_CHECKING:  # (a balancing's result, where search --balance asks for one)
    from .balance.result import BalanceResult

#: Figures below this share of the engine's scale are rounding (zero) in the ranking.
ROUNDING = 1e-9
#: Most cylinders a search takes (the firing orders grow as the factorial).
MOST_CYLINDERS = 12
#: Most candidates a search judges.
MOST_CANDIDATES = 200_000


@dataclass(frozen=True)
class Arrangement:
    """One crank and firing order, and what it leaves free.

    Attributes
    ----------
    phases
        Each cylinder's crank pin phase, degrees in [0, 360), cylinder 1 first.
    firing_order
        The cylinders in the order they fire, cylinder 1 first.
    free
        What crank counterweights cannot take, N and N·m: ``force_1_backward``,
        ``couple_1_backward``, ``force_2``, ``couple_2`` (both whirls' magnitudes summed).
    counterweights
        What they can: ``force_1_forward``, ``couple_1_forward``, N and N·m.
    same_half
        Firings that follow one another in the same half of the crank (cyclically).
    rank
        Its place, from 1; equal for arrangements the ranking cannot tell apart (the same
        figures to rounding and the same ``same_half``).
    balanced
        The engine with it balanced as the spec's ``[balance]`` asks (``search --balance``),
        or ``None``.
    """

    phases: tuple[float, ...]
    firing_order: tuple[int, ...]
    free: dict[str, float]
    counterweights: dict[str, float]
    same_half: int
    rank: int = 0
    balanced: BalanceResult | None = None

    def as_dict(self) -> dict[str, object]:
        """An entry of ``search --json``'s ``arrangements``."""
        out: dict[str, object] = {
            "rank": self.rank, "phases_deg": list(self.phases),
            "firing_order": list(self.firing_order), **self.free, **self.counterweights,
            "same_half": self.same_half}
        if self.balanced is not None:
            b = self.balanced
            out["balanced"] = {"status": str(b.status), "objective": b.objective,
                               "lower_bound": b.lower_bound,
                               "terms": b.term_rms(b.after)}
        return out


@dataclass(frozen=True)
class Search:
    """Every even-firing crank of an engine, ranked (best first).

    Attributes
    ----------
    arrangements
        Ranked, best first.
    speed
        The speed the loads are at, rad/s.
    scale
        The engine's scale of force, N (a cylinder's reciprocating ``m·r·ω²``), by which
        figures are rounding.
    """

    arrangements: tuple[Arrangement, ...]
    speed: float
    scale: float


def _step(cycle: int, n: int) -> Fraction:
    """The firing interval ``cycle/n``, degrees."""
    return Fraction(cycle, n)


def _firing_orders(tdc: list[Fraction], start: Fraction, interval: Fraction, cycle: int
                   ) -> Iterator[tuple[int, ...]]:
    """Each order in which the cylinders (TDCs ``tdc``, degrees) fire evenly from ``start``.

    Cylinder 1 in the first slot; each other cylinder in a slot ``start + j·interval`` its top
    dead centre meets (mod ``cycle``; a four-stroke's cylinder at its TDC or 360° later).
    """
    n = len(tdc)
    options: list[list[int]] = []
    for t in tdc:
        slots = []
        for extra in (0, 360) if cycle == 720 else (0,):
            position = (t + extra - start) % cycle
            if position % interval == 0:
                slots.append(int(position / interval))
        options.append(sorted(set(slots)))
    if 0 not in options[0]:
        return
    taken = [0] * n
    order = [0] * n

    def place(c: int) -> Iterator[tuple[int, ...]]:
        if c == n:
            yield tuple(order)
            return
        for slot in options[c]:
            if not taken[slot]:
                taken[slot] = 1
                order[slot] = c + 1
                yield from place(c + 1)
                taken[slot] = 0

    taken[0] = 1
    order[0] = 1
    yield from place(1)


def search(engine: Engine, speed: float, top: int | None = None) -> Search:
    """Every even-firing crank of ``engine``'s cylinders and its firing orders, ranked.

    See the module docstring. ``top``: keep the best ``top`` only.

    Raises
    ------
    SpecError
        For more than :data:`MOST_CYLINDERS` cylinders, no even-firing crank at all, or an
        engine of several crankshafts.
    """
    if engine.crankshafts:
        raise SpecError("a search arranges the pins of one crankshaft: an engine with geared "
                        "crankshafts is not searched (their pins' phases are the spec's)",
                        key="crankshafts")
    cylinders = engine.cylinders
    n = len(cylinders)
    if n > MOST_CYLINDERS:
        raise SpecError(f"a search takes at most {MOST_CYLINDERS} cylinders (got {n})",
                        key="mechanism.cylinders")
    cycle = 720 if engine.strokes == 4 else 360
    interval = _step(cycle, n)
    throws = _pins(engine)
    banks = [Fraction(c.bank_deg).limit_denominator(10**6) for c in cylinders]
    first_phase = Fraction(cylinders[throws[0][0]].phase_deg).limit_denominator(10**6)
    start = (banks[0] - first_phase) % 360  # cylinder 1's TDC (throw 1's phase kept)
    candidates = [[first_phase]] + [
        sorted({(banks[t[0]] - start - j * interval) % 360 for j in range(n)})
        for t in throws[1:]]
    if math.prod(len(c) for c in candidates) > MOST_CANDIDATES:
        raise SpecError("too many cranks to judge: fewer throws, or cylinders sharing pins",
                        key="mechanism.cylinders")
    # each cylinder's phasors at phase 0: its rod and piston alone
    bare = Crankshaft(inertia=engine.crankshaft.inertia)
    unit = []
    for c in cylinders:
        one = replace(engine, cylinders=(replace(c, phase_deg=0.0),), crankshaft=bare,
                      balance_shafts=(), firing_order=None, gas=None, main_bearings=())
        p = phasors(mechanism_of(one), speed, (1, 2))
        unit.append({order: p.total_force(order) for order in (1, 2)})
    first = cylinders[0]
    rod = engine.rod
    scale = (engine.piston + rod.mass) * first.crank * speed**2 or 1.0
    zs = [c.z for c in cylinders]
    middle = (min(zs) + max(zs)) / 2
    half = [0 if z < middle else 1 for z in zs]
    out = []
    for choice in itertools.product(*candidates):
        phases = [Fraction(0)] * n
        for t, phase in zip(throws, choice, strict=True):
            for k in t:
                phases[k] = phase
        tdc = [(banks[k] - phases[k]) % 360 for k in range(n)]
        orders = list(_firing_orders(tdc, start, interval, cycle))
        if not orders:
            continue
        free, taken = _judge(unit, [float(p) for p in phases], zs)
        for order in orders:
            same = sum(half[order[i] - 1] == half[order[(i + 1) % n] - 1] for i in range(n))
            out.append(Arrangement(phases=tuple(float(p) for p in phases), firing_order=order,
                                   free=free, counterweights=taken, same_half=same))
    if not out:
        raise SpecError("no crank of these cylinders fires evenly (their banks and the working "
                        "cycle leave none)", key="mechanism.cylinders")
    length = max(zs) - min(zs) or first.crank

    def key(a: Arrangement) -> tuple[object, ...]:
        figures = [a.free["force_1_backward"] / scale, a.free["couple_1_backward"] / (
            scale * length), a.free["force_2"] / scale, a.free["couple_2"] / (scale * length)]
        return (*(0 if f <= ROUNDING else round(f, 9) for f in figures), a.same_half,
                a.firing_order, a.phases)

    ranked = sorted(out, key=key)
    places: list[Arrangement] = []
    for i, a in enumerate(ranked):
        tied = i and key(a)[:5] == key(ranked[i - 1])[:5]
        places.append(replace(a, rank=places[-1].rank if tied else i + 1))
    return Search(arrangements=tuple(places[:top] if top else places), speed=speed,
                  scale=scale)


def _pins(engine: Engine) -> list[tuple[int, ...]]:
    """The crank pins: each a tuple of cylinder indices, in the order of their first.

    Cylinders side by side along the crank in other banks with the same phase in the spec
    share one (a V's pair); a cylinder of an in-line bank has its own.
    """
    cylinders = engine.cylinders
    order = sorted(range(len(cylinders)), key=lambda i: (cylinders[i].z, i))
    pins: list[list[int]] = []
    for i in order:
        c = cylinders[i]
        if pins:
            last = cylinders[pins[-1][-1]]
            same = abs((c.phase_deg - last.phase_deg + 180.0) % 360.0 - 180.0) <= 1e-9
            banks = {cylinders[k].bank_deg % 360.0 for k in pins[-1]}
            if same and c.bank_deg % 360.0 not in banks:
                pins[-1].append(i)
                continue
        pins.append([i])
    return sorted((tuple(p) for p in pins), key=min)


def _judge(unit: list[dict[int, tuple[complex, complex]]], phases: list[float],
           zs: list[float]) -> tuple[dict[str, float], dict[str, float]]:
    """What the cylinders at ``phases`` (degrees) leave free and what counterweights take."""
    sums: dict[tuple[int, str], complex] = {}
    for u, phase, z in zip(unit, phases, zs, strict=True):
        for order in (1, 2):
            forward, backward = u[order]
            turn = complex(math.cos(math.radians(order * phase)),
                           math.sin(math.radians(order * phase)))
            f, b = forward * turn, backward * turn.conjugate()
            for what, value in (("ff", f), ("fb", b), ("cf", 1j * z * f), ("cb", 1j * z * b)):
                sums[(order, what)] = sums.get((order, what), 0j) + value
    free = {"force_1_backward": abs(sums[(1, "fb")]), "couple_1_backward": abs(sums[(1, "cb")]),
            "force_2": abs(sums[(2, "ff")]) + abs(sums[(2, "fb")]),
            "couple_2": abs(sums[(2, "cf")]) + abs(sums[(2, "cb")])}
    taken = {"force_1_forward": abs(sums[(1, "ff")]), "couple_1_forward": abs(sums[(1, "cf")])}
    return free, taken


__all__ = ["Arrangement", "Search", "search"]
