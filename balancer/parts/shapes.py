"""The profiles counterweights are made of, and their mass properties in closed form.

Every part is a prism: a plane profile in the link's frame (x along the link, y across it,
lengths m) extruded to a thickness ``t`` (m) along the crank's axis, centred on the link's
plane, of one density ``ρ`` (kg/m³). Its planar mass properties are those of the profile
times ``ρ·t``:

- mass ``m = ρ·t·A`` (kg), ``A`` the profile's area (m²);
- centre ``c̄`` (m, complex ``x + i·y`` in the link's frame), the profile's centroid;
- inertia about the axis through ``c̄`` along z, ``I = ρ·t·∫(|r̄ − c̄|²) dA`` (kg·m²).

Three profiles make every family of :mod:`balancer.model.parts`: an :class:`Annulus` (a ring, a
stack of washers, an insert's pocket; a disc with inner radius 0), an :class:`AnnularSector`
(a crank-web crescent about a pivot) and a :class:`Rectangle` (a block). Each also gives its
outline as loops of lines and arcs (:meth:`loops`), from which the CAD files and the drawing are
made (:mod:`balancer.parts.cad`, :mod:`balancer.plots.parts`): the CAD kernel's own mass
properties of that outline are the check of the formulas here.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass


@dataclass(frozen=True)
class MassProperties:
    """A planar body's mass properties in a link's frame.

    Attributes
    ----------
    mass
        kg.
    centre
        Its centre of mass ``e + i·f`` in the link's frame, m.
    inertia
        About the axis along z through its centre, kg·m².
    """

    mass: float
    centre: complex
    inertia: float

    @property
    def inertial_parameters(self) -> tuple[float, float, float, float]:
        """``(m, m·e, m·f, J)``, ``J = I + m·|c̄|²`` about the frame's origin (kg, kg·m, kg·m²)."""
        m, c = self.mass, self.centre
        return m, m * c.real, m * c.imag, self.inertia + m * abs(c) ** 2


# -- outlines: loops of lines and arcs -----------------------------------------------------------

@dataclass(frozen=True)
class Line:
    """A straight edge from ``start`` to ``end`` (complex, m)."""

    start: complex
    end: complex


@dataclass(frozen=True)
class Arc:
    """A circular edge about ``centre`` (complex, m) of ``radius`` m.

    From angle ``start`` to ``end`` (rad): counter-clockwise where ``end > start``, clockwise
    where ``end < start``; ``|end − start| = 2π``: the whole circle.
    """

    centre: complex
    radius: float
    start: float
    end: float

    @property
    def closed(self) -> bool:
        """Whether the arc is a whole circle."""
        return math.isclose(abs(self.end - self.start), 2 * math.pi, rel_tol=0, abs_tol=1e-12)

    def point(self, angle: float) -> complex:
        """The point of the circle at ``angle`` rad."""
        return self.centre + cmath.rect(self.radius, angle)


Edge = Line | Arc
#: A closed loop of edges, each ending where the next starts (a whole circle is one edge).
Loop = tuple[Edge, ...]


# -- the profiles ----------------------------------------------------------------------------------

def _check_positive(**values: float) -> None:
    for name, value in values.items():
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} must be positive and finite, not {value!r}")


@dataclass(frozen=True, kw_only=True)
class Annulus:
    """A ring: radii ``inner`` (0: a disc) and ``outer``, m, about ``centre`` (complex, m).

    ``A = π·(Ro² − Ri²)``; centroid the centre; ``∫|r̄ − c̄|² dA = π·(Ro⁴ − Ri⁴)/2 = A·(Ro² +
    Ri²)/2``, so ``I = m·(Ro² + Ri²)/2``.
    """

    centre: complex
    inner: float
    outer: float
    thickness: float

    def __post_init__(self) -> None:
        """Check the dimensions."""
        _check_positive(outer=self.outer, thickness=self.thickness)
        if not 0 <= self.inner < self.outer:
            raise ValueError(f"inner radius {self.inner!r} must be in [0, outer)")

    @property
    def area(self) -> float:
        """The profile's area, m²."""
        return math.pi * (self.outer**2 - self.inner**2)

    def mass_properties(self, density: float) -> MassProperties:
        """Mass (kg), centre (m) and inertia about it (kg·m²) at ``density`` kg/m³."""
        m = density * self.thickness * self.area
        return MassProperties(m, self.centre, m * (self.outer**2 + self.inner**2) / 2)

    def loops(self) -> tuple[Loop, ...]:
        """The outer circle, then the hole's (none for a disc)."""
        outer: Loop = (Arc(self.centre, self.outer, 0.0, 2 * math.pi),)
        if self.inner == 0:
            return (outer,)
        return outer, (Arc(self.centre, self.inner, 0.0, 2 * math.pi),)


def sector_reach(inner: float, outer: float) -> float:
    """``g = (2/3)·(Ro³ − Ri³)/(Ro² − Ri²)``, m: the reach of a thin annular sector.

    An annular sector's centroid distance from its pivot is ``g·sin(φ/2)/(φ/2)`` for a
    full angle ``φ``; ``g`` itself is the limit of a thin sector (φ → 0). Written as
    ``(2/3)·(Ro² + Ro·Ri + Ri²)/(Ro + Ri)``, which has no 0/0 but at a point (0 there).
    """
    if outer + inner == 0:
        return 0.0
    return 2.0 / 3.0 * (outer * outer + outer * inner + inner * inner) / (outer + inner)


def sinc(x: float) -> float:
    """``sin(x)/x`` (1 at 0)."""
    return math.sin(x) / x if x != 0 else 1.0


@dataclass(frozen=True, kw_only=True)
class AnnularSector:
    """A crescent between radii ``inner`` and ``outer`` (m) about ``pivot`` (complex, m).

    Of full angle ``angle`` (rad, in (0, 2π]), symmetric about the direction ``direction`` (rad).

    With ``α = angle/2``: ``A = α·(Ro² − Ri²)``; the centroid on the bisector at
    ``d = g·sin α/α`` from the pivot (:func:`sector_reach`); the polar second moment about the
    pivot ``α·(Ro⁴ − Ri⁴)/2 = A·(Ro² + Ri²)/2``, so about the centroid (parallel axes)
    ``I = m·((Ro² + Ri²)/2 − d²)``.
    """

    pivot: complex
    inner: float
    outer: float
    angle: float
    direction: float
    thickness: float

    def __post_init__(self) -> None:
        """Check the dimensions."""
        _check_positive(outer=self.outer, thickness=self.thickness, angle=self.angle)
        if not 0 <= self.inner < self.outer:
            raise ValueError(f"inner radius {self.inner!r} must be in [0, outer)")
        if self.angle > 2 * math.pi * (1 + 1e-15):
            raise ValueError(f"angle {self.angle!r} rad exceeds a whole turn")

    @property
    def area(self) -> float:
        """The profile's area, m²."""
        return self.angle / 2 * (self.outer**2 - self.inner**2)

    @property
    def reach(self) -> float:
        """The centroid's distance from the pivot, m."""
        return sector_reach(self.inner, self.outer) * sinc(self.angle / 2)

    def mass_properties(self, density: float) -> MassProperties:
        """Mass (kg), centre (m) and inertia about it (kg·m²) at ``density`` kg/m³."""
        m = density * self.thickness * self.area
        d = self.reach
        return MassProperties(m, self.pivot + cmath.rect(d, self.direction),
                              m * ((self.outer**2 + self.inner**2) / 2 - d * d))

    def loops(self) -> tuple[Loop, ...]:
        """Outer arc (counter-clockwise), line in, inner arc back (clockwise), line out.

        A whole annulus (angle 2π) as its two circles.
        """
        if math.isclose(self.angle, 2 * math.pi, rel_tol=1e-15):
            return Annulus(centre=self.pivot, inner=self.inner, outer=self.outer,
                           thickness=self.thickness).loops()
        a0, a1 = self.direction - self.angle / 2, self.direction + self.angle / 2
        outer = Arc(self.pivot, self.outer, a0, a1)
        if self.inner == 0:
            return ((outer, Line(outer.point(a1), self.pivot),
                     Line(self.pivot, outer.point(a0))),)
        inner = Arc(self.pivot, self.inner, a1, a0)
        return ((outer, Line(outer.point(a1), inner.point(a1)), inner,
                 Line(inner.point(a0), outer.point(a0))),)


@dataclass(frozen=True, kw_only=True)
class Rectangle:
    """A rectangle ``length`` × ``width`` (m) about ``centre`` (complex, m).

    Its length along the direction ``direction`` (rad).

    ``A = a·b``; centroid the centre; ``∫|r̄ − c̄|² dA = a·b·(a² + b²)/12``, so
    ``I = m·(a² + b²)/12``.
    """

    centre: complex
    length: float
    width: float
    direction: float
    thickness: float

    def __post_init__(self) -> None:
        """Check the dimensions."""
        _check_positive(length=self.length, width=self.width, thickness=self.thickness)

    @property
    def area(self) -> float:
        """The profile's area, m²."""
        return self.length * self.width

    def mass_properties(self, density: float) -> MassProperties:
        """Mass (kg), centre (m) and inertia about it (kg·m²) at ``density`` kg/m³."""
        m = density * self.thickness * self.area
        return MassProperties(m, self.centre, m * (self.length**2 + self.width**2) / 12)

    def corners(self) -> tuple[complex, complex, complex, complex]:
        """The four corners, counter-clockwise, m."""
        u = cmath.rect(1.0, self.direction)
        half = (self.length * u + 1j * self.width * u) / 2
        other = (self.length * u - 1j * self.width * u) / 2
        c = self.centre
        return c - half, c + other, c + half, c - other

    def loops(self) -> tuple[Loop, ...]:
        """The four sides, counter-clockwise."""
        p = self.corners()
        return (tuple(Line(p[i], p[(i + 1) % 4]) for i in range(4)),)


#: A profile with a thickness: what a part is made of.
Profile = Annulus | AnnularSector | Rectangle


def union(*bodies: MassProperties) -> MassProperties:
    """The mass properties of rigid bodies joined (their inertial parameters add).

    ``m = Σ mᵢ``; ``m·c̄ = Σ mᵢ·c̄ᵢ``; ``I + m·|c̄|² = Σ (Iᵢ + mᵢ·|c̄ᵢ|²)`` (parallel axes about
    the frame's origin). A negative mass or inertia takes a body away.
    """
    m = math.fsum(b.mass for b in bodies)
    first = complex(math.fsum(b.mass * b.centre.real for b in bodies),
                    math.fsum(b.mass * b.centre.imag for b in bodies))
    j = math.fsum(b.inertial_parameters[3] for b in bodies)
    c = first / m
    return MassProperties(m, c, j - m * abs(c) ** 2)
