"""The part that makes a counterweight, as the spec states it: a shape family, its room, a material.

A counterweight (``[balance.<link>] counterweight``) may name the part that realises it in
its ``part`` table::

    [balance.crank.counterweight]
    mass = [0.01, 6.3]                      # kg
    radius = 1.0                            # m, of its centre from com_about
    part = { shape = "ring", material = "steel", inner_radius = 0.01, outer_radius = 0.12,
             thickness = 0.08 }             # m

Each family is a prism of thickness ``t`` along the crank's axis, centred on the link's plane,
whose profile is (all lengths m, in the link's frame):

``ring``
    An annulus centred on the counterweight's centre (a ring on a stud): ``inner_radius`` (the
    stud's hole) given; the outer radius (at most ``outer_radius``) and the thickness (at most
    ``thickness``) solved.
``washers``
    A stack of ISO 7089 washers of one ``size`` (``"M12"``) on a stud at the counterweight's
    centre: their count solved, the stack at most ``thickness`` high.
``sector``
    A crank-web crescent: an annular sector whose arcs are centred on the link's ``com_about``
    point (the crank's pivot), ``inner_radius`` (the hub) given; its outer radius (at most
    ``outer_radius``), its angle (at most ``angle_deg``) and its thickness (at most
    ``thickness``) solved, its bisector through the counterweight's centre.
``block``
    A rectangle centred on the counterweight's centre, ``length`` along the link's x-axis
    given; its width (at most ``width``) and thickness (at most ``thickness``) solved.
``insert``
    A cylindrical pocket in the link at the counterweight's centre, filled with a denser
    ``material`` than the link's own (``host``): the pocket's radius (at most ``radius``) and
    depth (at most ``thickness``) solved. What it adds is the insert less the material the
    pocket took away: a body of density ``density − host_density``.

:mod:`balancer.parts.shapes` gives the families' mass properties and solves their dimensions;
this module holds the data only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from ..errors import SpecError
from ..validate import LENGTH_RANGE

#: The shape families (the spec's ``part.shape``).
SHAPES = ("ring", "washers", "sector", "block", "insert")

#: Named materials and their densities, kg/m³ (steel as the counterweight report's disc;
#: a tungsten heavy alloy of 90–95 % W; pure lead; free-cutting brass).
MATERIALS: dict[str, float] = {
    "steel": 7850.0,
    "brass": 8500.0,
    "tungsten-alloy": 17000.0,
    "lead": 11340.0,
}

#: ISO 7089 (form A) plain washers: size → (inner diameter d1, outer diameter d2, thickness h),
#: m (the nominal values: d1 min, d2 max, h nominal).
WASHERS: dict[str, tuple[float, float, float]] = {
    "M3": (3.2e-3, 7e-3, 0.5e-3),
    "M4": (4.3e-3, 9e-3, 0.8e-3),
    "M5": (5.3e-3, 10e-3, 1.0e-3),
    "M6": (6.4e-3, 12e-3, 1.6e-3),
    "M8": (8.4e-3, 16e-3, 1.6e-3),
    "M10": (10.5e-3, 20e-3, 2.0e-3),
    "M12": (13e-3, 24e-3, 2.5e-3),
    "M16": (17e-3, 30e-3, 3.0e-3),
    "M20": (21e-3, 37e-3, 3.0e-3),
    "M24": (25e-3, 44e-3, 4.0e-3),
    "M30": (31e-3, 56e-3, 4.0e-3),
    "M36": (37e-3, 66e-3, 5.0e-3),
}


@dataclass(frozen=True, kw_only=True)
class Material:
    """A material: its name (for the report and the files) and density, kg/m³ (positive)."""

    name: str
    density: float

    def __post_init__(self) -> None:
        """Check the density."""
        if not (isinstance(self.density, int | float) and math.isfinite(self.density)
                and self.density > 0):
            raise SpecError("must be a positive density in kg/m³", key="density",
                            value=self.density)

    @classmethod
    def named(cls, name: str) -> Material:
        """One of :data:`MATERIALS` by name (:class:`SpecError` naming ``material`` if unknown)."""
        if name not in MATERIALS:
            raise SpecError(f"must be one of {', '.join(MATERIALS)} (or give `density`)",
                            key="material", value=name)
        return cls(name=name, density=MATERIALS[name])


STEEL = Material(name="steel", density=MATERIALS["steel"])


def _length(value: float, key: str, *, zero: bool = False, infinite: bool = False) -> float:
    """A positive length in m (0 where ``zero``, ``inf`` where ``infinite``), else SpecError."""
    ok = isinstance(value, int | float) and not isinstance(value, bool) and value == value
    if ok and not infinite:
        ok = math.isfinite(value)
    if ok:
        ok = value >= 0 if zero else value > 0
    if not ok:
        what = "zero or a positive length" if zero else "a positive length"
        raise SpecError(f"must be {what} in m", key=key, value=value)
    if math.isfinite(value) and value > LENGTH_RANGE[1]:  # (a room's volume, a reach's cube)
        raise SpecError(f"must be at most {LENGTH_RANGE[1]:g} m (its fourth power must stay "
                        "within double precision)", key=key, value=value)
    return float(value)


@dataclass(frozen=True, kw_only=True)
class Ring:
    """An annulus on a stud at the counterweight's centre (module docstring), lengths m.

    ``inner_radius`` given (0: a disc); the outer radius at most ``outer_radius`` and the
    thickness at most ``thickness`` (``inf``: no limit) are solved.
    """

    shape: ClassVar[str] = "ring"
    inner_radius: float
    outer_radius: float
    thickness: float
    material: Material = STEEL

    def __post_init__(self) -> None:
        """Check the room: lengths, and the outer radius beyond the inner."""
        _length(self.inner_radius, "inner_radius", zero=True)
        _length(self.outer_radius, "outer_radius", infinite=True)
        _length(self.thickness, "thickness", infinite=True)
        if self.outer_radius <= self.inner_radius:
            raise SpecError("must exceed inner_radius", key="outer_radius",
                            value=self.outer_radius)


@dataclass(frozen=True, kw_only=True)
class Washers:
    """A stack of ISO 7089 washers of ``size`` (:data:`WASHERS`) at most ``thickness`` m high."""

    shape: ClassVar[str] = "washers"
    size: str
    thickness: float
    material: Material = STEEL

    def __post_init__(self) -> None:
        """Check the size, and that one washer fits."""
        if self.size not in WASHERS:
            raise SpecError(f"must be an ISO 7089 size: one of {', '.join(WASHERS)}",
                            key="size", value=self.size)
        _length(self.thickness, "thickness", infinite=True)
        if self.thickness < self.washer[2]:
            raise SpecError(f"holds no washer {self.size} ({1e3 * self.washer[2]:g} mm thick)",
                            key="thickness", value=self.thickness)

    @property
    def washer(self) -> tuple[float, float, float]:
        """One washer's inner diameter, outer diameter and thickness, m."""
        return WASHERS[self.size]


@dataclass(frozen=True, kw_only=True)
class Sector:
    """A crank-web crescent about the link's ``com_about`` point (module docstring).

    ``inner_radius`` m given; outer radius at most ``outer_radius`` m, full angle at most
    ``angle_deg`` degrees (at most 360; :attr:`angle` in rad), thickness at most ``thickness``
    m, solved.
    """

    shape: ClassVar[str] = "sector"
    inner_radius: float
    outer_radius: float
    angle_deg: float
    thickness: float
    material: Material = STEEL

    def __post_init__(self) -> None:
        """Check the room."""
        _length(self.inner_radius, "inner_radius", zero=True)
        _length(self.outer_radius, "outer_radius")
        _length(self.thickness, "thickness", infinite=True)
        if self.outer_radius <= self.inner_radius:
            raise SpecError("must exceed inner_radius", key="outer_radius",
                            value=self.outer_radius)
        if not (isinstance(self.angle_deg, int | float) and 0 < self.angle_deg <= 360):
            raise SpecError("must be an angle in (0, 360] degrees", key="angle_deg",
                            value=self.angle_deg)

    @property
    def angle(self) -> float:
        """The largest full angle, rad."""
        return math.radians(self.angle_deg)


@dataclass(frozen=True, kw_only=True)
class Block:
    """A rectangle at the counterweight's centre, ``length`` m along the link's x-axis.

    Its width at most ``width`` m and thickness at most ``thickness`` m are solved.
    """

    shape: ClassVar[str] = "block"
    length: float
    width: float
    thickness: float
    material: Material = STEEL

    def __post_init__(self) -> None:
        """Check the room."""
        _length(self.length, "length")
        _length(self.width, "width", infinite=True)
        _length(self.thickness, "thickness", infinite=True)


@dataclass(frozen=True, kw_only=True)
class Insert:
    """A cylindrical pocket in the link filled with a denser material (module docstring).

    Its radius at most ``radius`` m and depth at most ``thickness`` m are solved; ``host`` is
    the link's own material, which the pocket takes away.
    """

    shape: ClassVar[str] = "insert"
    radius: float
    thickness: float
    material: Material
    host: Material = STEEL

    def __post_init__(self) -> None:
        """Check the room and that the insert is denser than the link."""
        _length(self.radius, "radius")
        _length(self.thickness, "thickness")
        if self.material.density <= self.host.density:
            raise SpecError(f"must be denser than the link's {self.host.name} "
                            f"({self.host.density:g} kg/m³)", key="material",
                            value=self.material.name)

    @property
    def net_density(self) -> float:
        """The insert's density less the host's, kg/m³: what a unit of pocket adds."""
        return self.material.density - self.host.density


#: The room of a part: one of the families.
Part = Ring | Washers | Sector | Block | Insert
