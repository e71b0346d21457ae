"""How a report prints a figure: rounding of its quantity's scale as 0, a speed with its rpm.

The one rule (:class:`Scales`) by which every readable report — ``analyze``, ``simulate``,
``optimize``, ``verify``, the order tables, an engine's tables, a balancing's verdict — prints
a figure that the arithmetic made, not the machine, as 0, and a ratio of such a figure as ``0``
or ``—``. JSON documents and CSV files keep every digit.
"""

from __future__ import annotations

import math
from collections.abc import Iterable


def figure_text(x: float, width: int = 12) -> str:
    """A figure in a table's column of ``width``: 6 digits, or 4 in exponent form."""
    if x == 0:
        return f"{0:>{width}.4g}"
    if abs(x) >= 1e5 or abs(x) < 1e-3:
        return f"{x:>{width}.4e}"
    return f"{x:>{width}.6g}"


#: A direction within this of 0° (either side), degrees, is 0°: no part is made finer, and the
#: arithmetic's wrap below 0 would print it as 360° on one machine and 0° on another.
WRAP_DEG = 1e-6


def direction_deg(z: complex) -> float:
    """The direction of the vector ``z`` from +x towards +y, degrees in [0, 360).

    Within :data:`WRAP_DEG` of 0° (a hair above it, or a hair below it that ``% 360`` turns into
    360° less a hair): 0°.
    """
    angle = math.degrees(math.atan2(z.imag, z.real)) % 360.0
    return 0.0 if angle < WRAP_DEG or angle > 360.0 - WRAP_DEG else angle


#: rpm per rad/s.
RPM = 30.0 / math.pi


def speed_text(speed: float) -> str:
    """A crank speed as a designer reads it: ``"628.319 rad/s (6000 rpm)"`` from rad/s."""
    return f"{speed:g} rad/s ({speed * RPM:.4g} rpm)"


#: A figure within this share of its quantity's scale is the arithmetic's rounding: a text
#: table prints it as 0 (:class:`Scales`).
ROUNDING = 1e-10


class Scales:
    """The natural scale of each quantity in one report, and what is rounding of it.

    A figure the tool prints is a sum of terms of the size of its quantity's scale: a shaking
    force sums the reactions on the frame, a shaking moment their moments with the motor's
    torque, an order's amplitude the samples of its cycle. Double precision holds each term to
    ε = 2.2e-16 of itself, and the computation loses a few decades more — closed forms and
    Newton's method to rounding, each dyad's linear solve (condition up to ~1e3 near a toggle,
    where the general core hands over to closed forms), sums and a DFT over at most 1440
    samples (N·ε) —: where a figure should be zero (a balanced force, a mean that cancels, an
    order the layout frees) it comes out between 1e-17 and 1e-12 of its scale. :data:`ROUNDING`
    (1e-10) is two decades above the worst of that, and still four below the tolerance an
    optimum is certified to (1e-6 of its problem's scale): a figure below it says nothing about
    the machine, only about the arithmetic, so a table prints it as 0 (JSON and CSV keep every
    digit).

    The scale of a quantity is the largest figure of its unit in the report: a force's with
    every force printed beside it (the reactions the shaking force sums, a guide's normal
    force, the counterweights' centrifugal forces), a moment's with every moment and torque;
    before and after together, the original's with the design's. Figures that measure an error
    (an optimality gap, a residual, an energy balance, a force level) are not a quantity's
    figures: they are printed as they are.

    Parameters
    ----------
    figures
        ``(unit, value)`` pairs: every figure of the report, each under its unit (``"N"``,
        ``"N·m"``, …); values that do not exist (NaN, ``None``) are left out.
    """

    def __init__(self, figures: Iterable[tuple[str, float | None]] = ()) -> None:
        self.scale: dict[str, float] = {}
        self.add(figures)

    def add(self, figures: Iterable[tuple[str, float | None]]) -> Scales:
        """Take more figures into the scales (this object, for chaining)."""
        for unit, value in figures:
            if value is not None and math.isfinite(value):
                self.scale[unit] = max(self.scale.get(unit, 0.0), abs(float(value)))
        return self

    def rounding(self, value: float, unit: str) -> bool:
        """Whether ``value`` is rounding of its unit's scale (:data:`ROUNDING`)."""
        return math.isfinite(value) and abs(value) <= ROUNDING * self.scale.get(unit, 0.0)

    def fmt(self, value: float, unit: str, width: int = 12) -> str:
        """``value`` as a table prints it: 0 where it is rounding."""
        return figure_text(0.0 if self.rounding(value, unit) else value, width)

    def number(self, value: float, unit: str, spec: str = ".6g") -> str:
        """``value`` formatted by ``spec``: ``0`` where it is rounding."""
        return "0" if self.rounding(value, unit) else format(value, spec)

    def ratio(self, a: float | None, b: float | None, unit: str, spec: str = ".3g") -> str:
        """``a/b`` as a table prints it.

        ``—`` where there is nothing to compare with (``b`` missing, zero or rounding: both
        rounding, or a figure that rose from rounding), ``0`` where ``a`` is rounding of a
        ``b`` that is not.
        """
        if a is None or b is None or b == 0 or self.rounding(b, unit):
            return "—"
        if self.rounding(a, unit):
            return "0"
        return format(a / b, spec)
