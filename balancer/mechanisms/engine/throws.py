"""A crank throw's balance as engine designers quote it: the balance factor.

:class:`Throw` and :func:`shaft_throws`, one crankshaft's throws
(:meth:`balancer.mechanisms.engine.model.Engine.throws`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from ...model.links import Link

#: The label of a counterweight that balancing may replace.
COUNTERWEIGHT = "counterweight"


class CylinderLike(Protocol):
    """What a throw reads of a cylinder: its plane, its pin's phase, its lengths (m, °)."""

    @property
    def z(self) -> float: ...
    @property
    def phase_deg(self) -> float: ...
    @property
    def crank(self) -> float: ...
    @property
    def rod(self) -> float: ...


class MassLike(Protocol):
    """What a throw reads of a crankshaft's mass·radius (kg·m, °, m; its label)."""

    @property
    def mr(self) -> float: ...
    @property
    def phase_deg(self) -> float: ...
    @property
    def z(self) -> float: ...
    @property
    def label(self) -> str: ...


@dataclass(frozen=True, kw_only=True)
class Throw:
    """One crank throw: the cylinders on one crank pin, and the mass·radius that balances it.

    As engine designers quote a throw's **balance factor**: its counterweights' mass·radius
    against its rotating mass·radius plus half its reciprocating one (each rod split into two
    point masses at its pins by its centre of mass: ``m_rod·(1 − e/l)`` rotating at the big
    end, ``m_rod·e/l`` reciprocating with the piston). 100 % balances the rotating masses and
    half the reciprocating ones (what a single's "50 %" means); an in-line four with eight
    counterweights runs about 80 %, with four about 57 %.

    Attributes
    ----------
    cylinders
        Its cylinders, numbered from 1.
    phase_deg
        Its crank pin's angle at θ1 = 0, degrees.
    rotating_mr
        Its rotating mass·radius along its pin, kg·m: the crankshaft's masses not labelled
        ``"counterweight"`` nearest to it (pin, webs; each by its component along the pin)
        and each rod's big-end share ``m_rod·(1 − e/l)·r``.
    reciprocating_mr
        ``Σ (m_piston + m_rod·e/l)·r`` over its cylinders, kg·m.
    counterweight_mr
        The counterweights nearest to it, each by its component opposite the pin, kg·m.
    """

    cylinders: tuple[int, ...]
    phase_deg: float
    rotating_mr: float
    reciprocating_mr: float
    counterweight_mr: float

    @property
    def factor(self) -> float:
        """The balance factor, ``counterweight_mr / (rotating_mr + reciprocating_mr/2)``."""
        return self.counterweight_mr / (self.rotating_mr + self.reciprocating_mr / 2)

    def as_dict(self) -> dict[str, object]:
        """An entry of ``optimize --json``'s ``balance_factors``."""
        return {"cylinders": list(self.cylinders), "phase_deg": self.phase_deg,
                "rotating_mr": self.rotating_mr, "reciprocating_mr": self.reciprocating_mr,
                "counterweight_mr": self.counterweight_mr, "factor": self.factor}


def shaft_throws(cylinders: Sequence[CylinderLike], numbers: Sequence[int],
                 masses: Sequence[MassLike], webs: Sequence[float], rod: Link,
                 piston: float) -> list[Throw]:
    """One crankshaft's throws and their balance factors (:meth:`.model.Engine.throws`).

    ``cylinders`` on it and their ``numbers`` (from 1), its ``masses``, the planes ``webs`` of
    another design's counterweights on it (m), the engine's ``rod`` and ``piston`` (kg).
    """
    order = sorted(range(len(cylinders)), key=lambda i: cylinders[i].z)
    walls = sorted({m.z for m in masses if m.label == COUNTERWEIGHT and m.mr > 0}
                   | set(webs))
    groups: list[list[int]] = []
    for i in order:
        c = cylinders[i]
        if groups:
            last = cylinders[groups[-1][-1]]
            turn = (c.phase_deg - last.phase_deg) % 360.0
            if min(turn, 360.0 - turn) <= 1e-9 and not any(last.z < w < c.z for w in walls):
                groups[-1].append(i)
                continue
        groups.append([i])
    rotating = [0.0] * len(groups)
    reciprocating = [0.0] * len(groups)
    counter = [0.0] * len(groups)
    rod = rod
    for g, members in enumerate(groups):
        for i in members:
            c = cylinders[i]
            share = rod.e / c.rod  # of the rod's mass at the small end
            rotating[g] += rod.mass * (1 - share) * c.crank
            reciprocating[g] += (piston + rod.mass * share) * c.crank
    spans = [(min(cylinders[i].z for i in m), max(cylinders[i].z for i in m))
             for m in groups]
    length = max(hi for _, hi in spans) - min(lo for lo, _ in spans)
    for mass in masses:
        gaps = [max(lo - mass.z, mass.z - hi, 0.0) for lo, hi in spans]
        nearest = [g for g, d in enumerate(gaps) if d <= min(gaps) + 1e-12 * length]
        for g in nearest:
            pin = cylinders[groups[g][0]].phase_deg
            along = mass.mr * math.cos(math.radians(mass.phase_deg - pin)) / len(nearest)
            if mass.label == COUNTERWEIGHT:
                counter[g] -= along
            else:
                rotating[g] += along
    return [Throw(cylinders=tuple(numbers[i] for i in members),
                  phase_deg=cylinders[members[0]].phase_deg,
                  rotating_mr=rotating[g], reciprocating_mr=reciprocating[g],
                  counterweight_mr=counter[g])
            for g, members in enumerate(groups)]


__all__ = ["COUNTERWEIGHT", "Throw", "shaft_throws"]
