"""Immutable model objects: links, mechanisms, operating conditions and a whole design.

Notation (Meijaard & van der Wijk 2020, Sect. 2–3, Fig. 1): link ``k`` runs from its first joint
to its second; its centre of mass relative to the first joint, in the frame along the link, is
``s̄k = sk·exp(iσk) = ek + i·fk``; ``Ik`` is its moment of inertia about that centre of mass.
Applied loads are a constant force ``F̄k`` (global axes) at the centre of mass and a moment ``Mk``.
A counter-rotor is a disc coaxial with the link's ground pivot geared to turn at −1 times the
link's angular velocity; only its inertia counts.

All quantities are SI: m, kg, kg·m², rad, s, N, N·m. Objects are frozen; make variants with
:func:`dataclasses.replace` or the ``with_*`` helpers. Every object checks its values when it is
made (:mod:`balancer.validate`, the same checks as the spec loader's) and raises
:class:`~balancer.errors.SpecError` naming the field: a link, a mechanism or a design built in a
notebook is as safe as one read from a spec.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import ClassVar, Literal

from . import validate as v
from .errors import AssemblyError, SpecError

Branch = Literal["+", "-"]
Drive = Literal["free", "constant-speed"]

#: Largest initial crank angle, rad: its rounding (2e-11 rad) stays below the integrator's
#: relative tolerance floor times the angle.
THETA1_MAX = 1e5
#: Ways the crank can be driven in a simulation.
DRIVES: tuple[str, ...] = ("free", "constant-speed")
#: Least relative tolerance of a simulation: 100 ε, below which SciPy's integrators raise it.
RTOL_MIN = 100 * 2.220446049250313e-16
#: Least absolute tolerance: errors over it are squared, which must not overflow (1e-150²).
ATOL_MIN = 1e-150


@dataclass(frozen=True, kw_only=True)
class Link:
    """Mass properties of one moving link and the constant loads on it.

    Attributes
    ----------
    mass
        Mass ``m``, kg.
    inertia
        Moment of inertia about the centre of mass ``I``, kg·m².
    e
        Centre of mass along the line from the first joint to the second, m.
    f
        Centre of mass perpendicular to that line, positive to its left, m.
    force
        Constant applied force at the centre of mass ``(Fx, Fy)`` in global axes, N.
    moment
        Constant applied moment ``M``, N·m (counter-clockwise positive).
    counter_rotor
        Inertia of a counter-rotor coaxial with the link's ground pivot, kg·m² (0: none).
    """

    mass: float
    inertia: float
    e: float
    f: float
    force: tuple[float, float] = (0.0, 0.0)
    moment: float = 0.0
    counter_rotor: float = 0.0

    def __post_init__(self) -> None:
        """Check the values (keys are the spec's names within the link's table)."""
        _set(self, "mass", v.positive(self.mass, "mass"))
        _set(self, "inertia", v.nonnegative(self.inertia, "inertia"))
        _set(self, "e", v.number(self.e, "com.e"))
        _set(self, "f", v.number(self.f, "com.f"))
        _set(self, "force", v.vector2(self.force, "force"))
        _set(self, "moment", v.number(self.moment, "moment"))
        _set(self, "counter_rotor", v.nonnegative(self.counter_rotor, "counter_rotor"))

    @property
    def com(self) -> complex:
        """Centre of mass ``s̄ = e + i·f`` in the link frame, m."""
        return complex(self.e, self.f)

    @property
    def s(self) -> float:
        """Distance of the centre of mass from the first joint, m."""
        return math.hypot(self.e, self.f)

    @property
    def sigma(self) -> float:
        """Angle of the centre of mass from the link line, rad."""
        return math.atan2(self.f, self.e)

    @property
    def force_complex(self) -> complex:
        """Applied force ``F̄ = Fx + i·Fy``, N."""
        return complex(*self.force)

    @property
    def has_loads(self) -> bool:
        """Whether any applied force or moment acts on the link."""
        return self.force != (0.0, 0.0) or self.moment != 0.0

    def inertia_about_joint(self) -> float:
        """Moment of inertia about the first joint ``I + m·s²``, kg·m²."""
        return self.inertia + self.mass * (self.e**2 + self.f**2)

    def with_com_polar(self, s: float, sigma: float) -> Link:
        """Return a copy with the centre of mass at distance ``s`` (m) and angle ``sigma`` (rad)."""
        c = cmath.rect(s, sigma)
        return replace(self, e=c.real, f=c.imag)

    def without_loads(self) -> Link:
        """Return a copy with no applied force or moment."""
        return replace(self, force=(0.0, 0.0), moment=0.0)


@dataclass(frozen=True, kw_only=True)
class FourBar:
    """A planar 4R four-bar linkage A0 A1 A2 A3 (Meijaard & van der Wijk 2020, Fig. 1).

    Ground pivots A0 at the origin and A3 at ``(l4, 0)``. Link 1 (crank) A0→A1, link 2 (coupler)
    A1→A2, link 3 (rocker) A2→A3, link 4 the frame A3→A0 (θ4 = π).

    Attributes
    ----------
    lengths
        ``(l1, l2, l3, l4)``: crank, coupler, rocker and frame lengths, m.
    crank, coupler, rocker
        The three moving links.
    branch
        ``"+"``: A2 to the left of the directed line A1→A3 (the paper's Fig. 1); ``"-"``: the
        other assembly.
    """

    type: ClassVar[str] = "four-bar"
    link_names: ClassVar[tuple[str, str, str]] = ("crank", "coupler", "rocker")
    length_names: ClassVar[tuple[str, ...]] = ("crank", "coupler", "rocker", "frame")
    #: Links whose pivot is on the ground, where a counter-rotor can sit.
    grounded_links: ClassVar[tuple[str, ...]] = ("crank", "rocker")

    lengths: tuple[float, float, float, float]
    crank: Link
    coupler: Link
    rocker: Link
    branch: Branch = "+"

    def __post_init__(self) -> None:
        """Check lengths, links and branch; raise :class:`AssemblyError` if it never assembles.

        Keys are the spec's, from its root (``mechanism.lengths.crank``).
        """
        lengths = _check_mechanism(self)
        from .kinematics import assembly_range

        if assembly_range(lengths).empty:
            l1, l2, l3, l4 = lengths
            raise AssemblyError(
                "the linkage cannot be assembled at any crank angle: the coupler and rocker "
                f"(|l2 − l3| = {abs(l2 - l3):.6g} m to l2 + l3 = {l2 + l3:.6g} m) cannot "
                f"bridge A1 to A3 (|l4 − l1| = {abs(l4 - l1):.6g} m to l1 + l4 = "
                f"{l1 + l4:.6g} m)",
                key="mechanism.lengths",
                value=dict(zip(self.length_names, lengths, strict=True)),
            )

    @property
    def links(self) -> tuple[Link, Link, Link]:
        """The moving links in order (crank, coupler, rocker)."""
        return (self.crank, self.coupler, self.rocker)

    @property
    def total_mass(self) -> float:
        """Mass of the moving links ``m_tot = m1 + m2 + m3``, kg."""
        return self.crank.mass + self.coupler.mass + self.rocker.mass

    @property
    def has_loads(self) -> bool:
        """Whether any link carries an applied force or moment."""
        return any(link.has_loads for link in self.links)

    @property
    def sizes(self) -> dict[str, float]:
        """The geometry's sizes by spec key, m: the lengths (see :func:`check_scales`)."""
        return _length_sizes(self)

    @property
    def gas_forces(self) -> tuple[tuple[str, GasForce], ...]:
        """Forces on sliders along their guides, by spec key: none on a four-bar."""
        return ()

    @property
    def springs(self) -> tuple:
        """Linear springs: none on a four-bar."""
        return ()

    def link(self, name: str) -> Link:
        """Return the link called ``name`` (``"crank"``, ``"coupler"`` or ``"rocker"``)."""
        if name not in self.link_names:
            raise KeyError(name)
        return getattr(self, name)

    def with_link(self, name: str, link: Link) -> FourBar:
        """Return a copy with link ``name`` replaced."""
        if name not in self.link_names:
            raise KeyError(name)
        return replace(self, **{name: link})

    def with_links(self, links: dict[str, Link]) -> FourBar:
        """Return a copy with several links replaced."""
        return replace(self, **links)

    def without_loads(self) -> FourBar:
        """Return a copy with every applied force and moment removed."""
        return replace(self, **{n: self.link(n).without_loads() for n in self.link_names})


@dataclass(frozen=True, kw_only=True)
class GasForce:
    """A force on the slider along its guide that depends on the crank angle (a gas force).

    It acts between the slider (piston, along +x) and the frame (cylinder head, along −x), on the
    guide line: it drives the crank but, being internal to the machine, does not shake the frame
    except through the reaction of what holds the crank.

    Attributes
    ----------
    angles
        Crank angles of the table, rad, increasing within one period starting at 0.
    values
        Force along +x at those angles, N, interpolated by a periodic cubic spline (a pressure
        table samples a smooth curve; the spline is twice continuously differentiable, which
        an integrator of the motion needs to keep its accuracy).
    period
        Period in crank angle, rad (2π; 4π for a four-stroke cycle).
    """

    angles: tuple[float, ...] = (0.0,)
    values: tuple[float, ...] = (0.0,)
    period: float = 2 * math.pi

    def __post_init__(self) -> None:
        """Check the table (keys within ``gas_force``)."""
        period = v.positive(self.period, "period")
        angles, values = (_numbers(x, k) for x, k in ((self.angles, "crank_angle"),
                                                       (self.values, "force")))
        if len(angles) != len(values):
            raise SpecError(f"crank_angle and force must have the same length ({len(angles)} "
                            f"and {len(values)})", key="force")
        if (any(b <= a for a, b in zip(angles, angles[1:], strict=False)) or angles[0] < 0
                or angles[-1] >= period):
            raise SpecError("crank angles must increase within one period, from 0",
                            key="crank_angle", value=list(angles))
        _set(self, "period", period)
        _set(self, "angles", angles)
        _set(self, "values", values)

    @classmethod
    def constant(cls, value: float) -> GasForce:
        """A constant force along +x, N."""
        return cls(angles=(0.0,), values=(float(value),))

    @property
    def is_zero(self) -> bool:
        """Whether the force vanishes everywhere."""
        return all(v == 0.0 for v in self.values)

    @cached_property
    def _spline(self):
        return _PeriodicCubic(self.angles, self.values, self.period)

    def at(self, theta1):
        """The force (N) at crank angle(s) ``theta1`` (rad): a float for a float."""
        if len(self.values) == 1:
            return self.values[0] + 0.0 * theta1
        start = self.angles[0]
        if isinstance(theta1, float):  # one state of an integration: no arrays
            return self._spline.at(start + (theta1 - start) % self.period)
        import numpy as np

        t = np.asarray(theta1, dtype=float)
        return self._spline(start + np.mod(t - start, self.period))


class _PeriodicCubic:
    """The periodic cubic spline through ``(x_i, y_i)``, ``i < n``, of period ``P``.

    Its second derivatives ``M_i`` at the knots solve the cyclic tridiagonal system
    ``h_{i−1}·M_{i−1} + 2(h_{i−1} + h_i)·M_i + h_i·M_{i+1} = 6(Δ_i − Δ_{i−1})`` with
    ``h_i = x_{i+1} − x_i`` and ``Δ_i = (y_{i+1} − y_i)/h_i`` (indices modulo ``n``, de Boor,
    *A Practical Guide to Splines*, ch. IV): strictly diagonally dominant, solved densely
    (tables are short). The same spline as SciPy's ``CubicSpline(bc_type="periodic")`` (the
    tests compare them), without importing ``scipy.interpolate`` (0.6 s) for a short table.
    """

    def __init__(self, x, y, period: float) -> None:
        import numpy as np

        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        n = x.size
        self.knots = np.append(x, x[0] + period)
        h = np.diff(self.knots)
        slope = (np.roll(y, -1) - y) / h
        i = np.arange(n)
        a = np.zeros((n, n))
        a[i, i] = 2 * (np.roll(h, 1) + h)
        a[i, (i - 1) % n] += np.roll(h, 1)
        a[i, (i + 1) % n] += h
        m = np.linalg.solve(a, 6 * (slope - np.roll(slope, 1)))
        self.h, self.y, self.m = h, np.append(y, y[0]), np.append(m, m[0])
        self._knots = self.knots.tolist()

    def __call__(self, t):
        """The spline at ``t`` (within one period from the first knot)."""
        import numpy as np

        t = np.asarray(t, dtype=float)
        i = np.clip(np.searchsorted(self.knots, t, side="right") - 1, 0, self.h.size - 1)
        return self._piece(i, t, np)

    def at(self, t: float) -> float:
        """:meth:`__call__` at one time, in plain floats (an integrator's single state)."""
        import bisect

        i = min(max(bisect.bisect_right(self._knots, t) - 1, 0), len(self._knots) - 2)
        return float(self._piece(i, t, None))

    def _piece(self, i, t, np):
        """The cubic of interval ``i`` at ``t`` (indices and times arrays, or numbers)."""
        h = self.h[i]
        a = (self.knots[i + 1] - t) / h
        b = 1.0 - a
        return (a * self.y[i] + b * self.y[i + 1]
                + ((a**3 - a) * self.m[i] + (b**3 - b) * self.m[i + 1]) * (h * h / 6.0))


@dataclass(frozen=True, kw_only=True)
class SliderCrank:
    """A slider-crank A0 A1 A2 with the slider's pin A2 on a straight guide.

    Wunderlich (1964), Sect. 3.

    A0 at the origin; link 1 (crank) A0→A1, link 2 (connecting rod) A1→A2; the slider's pin A2
    moves on the guide line ``y = offset`` along x. θ1, θ2 are the angles of A0→A1 and A1→A2.

    Attributes
    ----------
    lengths
        ``(r, L, e)``: crank and rod lengths (m, positive) and the signed offset of the guide
        from A0 (m).
    crank, rod
        The rotating links (centre of mass in the link frame, as for the four-bar).
    slider
        The slider: its centre of mass relative to the pin is in global axes; its inertia does
        not matter (it does not turn).
    branch
        ``"+"``: the slider on the +x side of the crank pin; ``"-"``: the other assembly.
    gas_force
        Force on the slider along the guide, from the frame (see :class:`GasForce`).
    """

    type: ClassVar[str] = "slider-crank"
    link_names: ClassVar[tuple[str, str, str]] = ("crank", "rod", "slider")
    length_names: ClassVar[tuple[str, ...]] = ("crank", "rod", "offset")
    grounded_links: ClassVar[tuple[str, ...]] = ("crank",)

    lengths: tuple[float, float, float]
    crank: Link
    rod: Link
    slider: Link
    branch: Branch = "+"
    gas_force: GasForce = field(default_factory=GasForce)

    def __post_init__(self) -> None:
        """Check lengths, links and branch; raise :class:`AssemblyError` if it never assembles.

        Keys are the spec's, from its root (``mechanism.lengths.offset``).
        """
        if not isinstance(self.gas_force, GasForce):
            raise SpecError("must be a GasForce", key="links.slider.gas_force",
                            value=self.gas_force)
        r, big_l, e = _check_mechanism(self)
        if abs(e) > r + big_l:
            raise AssemblyError(
                f"the slider-crank cannot be assembled at any crank angle: the guide is "
                f"{abs(e):.6g} m from A0, beyond the reach of crank and rod "
                f"({r + big_l:.6g} m)",
                key="mechanism.lengths.offset",
                value=e,
            )

    @property
    def links(self) -> tuple[Link, Link, Link]:
        """The moving links in order (crank, rod, slider)."""
        return (self.crank, self.rod, self.slider)

    @property
    def total_mass(self) -> float:
        """Mass of the moving parts, kg."""
        return self.crank.mass + self.rod.mass + self.slider.mass

    @property
    def has_loads(self) -> bool:
        """Whether any link carries an applied force or moment, or a gas force acts."""
        return any(link.has_loads for link in self.links) or not self.gas_force.is_zero

    @property
    def sizes(self) -> dict[str, float]:
        """The geometry's sizes by spec key, m: the lengths, the offset's magnitude."""
        return _length_sizes(self)

    @property
    def gas_forces(self) -> tuple[tuple[str, GasForce], ...]:
        """Forces on sliders along their guides, by spec key: the gas force."""
        return (("links.slider.gas_force", self.gas_force),)

    @property
    def springs(self) -> tuple:
        """Linear springs: none on a slider-crank."""
        return ()

    def link(self, name: str) -> Link:
        """Return the link called ``name`` (``"crank"``, ``"rod"`` or ``"slider"``)."""
        if name not in self.link_names:
            raise KeyError(name)
        return getattr(self, name)

    def with_link(self, name: str, link: Link) -> SliderCrank:
        """Return a copy with link ``name`` replaced."""
        if name not in self.link_names:
            raise KeyError(name)
        return replace(self, **{name: link})

    def with_links(self, links: dict[str, Link]) -> SliderCrank:
        """Return a copy with several links replaced."""
        return replace(self, **links)

    def without_loads(self) -> SliderCrank:
        """Return a copy with every applied force, moment and gas force removed."""
        return replace(self, gas_force=GasForce(),
                       **{n: self.link(n).without_loads() for n in self.link_names})


#: The name of the general linkage's frame: a link without mass whose points do not move.
GROUND = "ground"
#: Names a moving link may not have: the keys of ``[balance]`` beside the links' tables.
RESERVED_LINK_NAMES = ("objective", "force_balance")


@dataclass(frozen=True, kw_only=True)
class Body:
    """One link of a general :class:`Linkage`: the points it carries and its mass properties.

    Its frame has its origin at its first point and its x-axis towards its second, at the
    reference pose; a one-point link's x-axis is the direction of the slider it runs in.

    Attributes
    ----------
    name
        The link's name (``"ground"`` for the frame).
    points
        Names of its points, first the frame's origin.
    props
        Mass properties and loads in that frame (:class:`Link`); ``None`` for the ground.
    """

    name: str
    points: tuple[str, ...]
    props: Link | None = None


@dataclass(frozen=True, kw_only=True)
class Slider:
    """A prismatic pair: a point of ``link`` runs on a line fixed in ``guide``.

    The pair also keeps the two links' relative angle. The line passes through the point's
    reference position with the given direction (at the reference pose).

    Attributes
    ----------
    link, guide
        The sliding link and the link that carries the guide (``"ground"`` for the frame).
    point
        The point of ``link`` on the line.
    direction
        The line's direction at the reference pose (any length but zero).
    force
        A force on ``link`` along ``direction`` from ``guide``, a function of the input's angle
        (a gas force between piston and cylinder); internal to the machine.
    """

    link: str
    guide: str
    point: str
    direction: tuple[float, float]
    force: GasForce = field(default_factory=GasForce)


@dataclass(frozen=True, kw_only=True)
class Spring:
    """A linear spring between two points (of one or two links, or the ground).

    Attributes
    ----------
    points
        The two anchor points.
    stiffness
        N/m.
    free_length
        Length at which it carries no force, m.
    """

    points: tuple[str, str]
    stiffness: float
    free_length: float

    def __post_init__(self) -> None:
        """Check the values (keys within the spring's table)."""
        if (isinstance(self.points, str) or not hasattr(self.points, "__len__")
                or len(self.points) != 2 or not all(isinstance(p, str) for p in self.points)):
            raise SpecError("must be a list of two point names", key="points",
                            value=self.points)
        if self.points[0] == self.points[1]:
            raise SpecError("must be two different points", key="points",
                            value=list(self.points))
        _set(self, "points", tuple(self.points))
        _set(self, "stiffness", v.nonnegative(self.stiffness, "stiffness"))
        _set(self, "free_length", v.nonnegative(self.free_length, "free_length"))


@dataclass(frozen=True, kw_only=True)
class Linkage:
    """A planar linkage with one degree of freedom, driven by a crank on a ground pivot.

    See DESIGN.md, "General planar linkages". A point named by two or more links is a revolute
    joint between them; a point of one link only is a marker. The reference pose (the
    points' positions) fixes the assembly: every other pose is the one reached from it
    continuously as the input turns. Mobility, a regular reference pose and a drivable input
    are checked when the linkage's equations are built
    (:func:`balancer.linkage.structure.Structure`); this object checks what its data alone
    can show.

    Attributes
    ----------
    points
        ``(name, (x, y))`` of every point at the reference pose, m.
    bodies
        The links, the ground (named ``"ground"``) among them.
    input
        The name of the driven link; its first point is its ground pivot.
    sliders
        Prismatic pairs.
    springs
        Linear springs.
    """

    type: ClassVar[str] = "linkage"

    points: tuple[tuple[str, tuple[float, float]], ...]
    bodies: tuple[Body, ...]
    input: str
    sliders: tuple[Slider, ...] = ()
    springs: tuple[Spring, ...] = ()

    def __post_init__(self) -> None:
        """Check names and references (keys are the spec's, from its root)."""
        points = {}
        for item in self.points:
            if not (isinstance(item, tuple | list) and len(item) == 2
                    and isinstance(item[0], str)):
                raise SpecError("must be (name, (x, y)) pairs", key="mechanism.points",
                                value=item)
            name, xy = item
            if name in points:
                raise SpecError("is given twice", key=f"mechanism.points.{name}")
            x, y = v.vector2(xy, f"mechanism.points.{name}")
            for coord in (x, y):
                if abs(coord) > v.LENGTH_RANGE[1]:
                    raise SpecError(f"must be within {v.LENGTH_RANGE[1]:g} m of the origin",
                                    key=f"mechanism.points.{name}", value=list(xy))
            points[name] = (x, y)
        if not points:
            raise SpecError("a linkage needs points", key="mechanism.points")
        _set(self, "points", tuple(points.items()))
        names: dict[str, Body] = {}
        for body in self.bodies:
            if not isinstance(body, Body):
                raise SpecError("must be a Body", key="links", value=body)
            key = f"links.{body.name}"
            if not isinstance(body.name, str) or not body.name:
                raise SpecError("a link needs a name", key="links", value=body.name)
            if body.name in names:
                raise SpecError("is given twice", key=key)
            if body.name in RESERVED_LINK_NAMES:
                raise SpecError(f"is a name the spec reserves ([balance.{body.name}] means "
                                "something else); call the link otherwise", key=key)
            if (isinstance(body.points, str) or not hasattr(body.points, "__len__")
                    or not body.points or not all(isinstance(p, str) for p in body.points)):
                raise SpecError("must be a non-empty list of point names", key=f"{key}.points",
                                value=body.points)
            for p in body.points:
                if p not in points:
                    raise SpecError(f"names an unknown point '{p}' (the points are "
                                    f"{', '.join(points)})", key=f"{key}.points", value=p)
            if len(set(body.points)) != len(body.points):
                raise SpecError("names a point twice", key=f"{key}.points",
                                value=list(body.points))
            if body.name == GROUND:
                if body.props is not None:
                    raise SpecError("the ground has no mass properties", key=key)
            elif not isinstance(body.props, Link):
                raise SpecError("a moving link needs its mass properties (a Link)", key=key)
            _set(body, "points", tuple(body.points))
            names[body.name] = body
        if GROUND not in names:
            raise SpecError("a linkage needs a ground link", key=f"links.{GROUND}")
        if len(names) < 2:
            raise SpecError("a linkage needs a moving link", key="links")
        on_links = {p for b in names.values() for p in b.points}
        for p in points:
            if p not in on_links:
                raise SpecError("is on no link", key=f"mechanism.points.{p}")
        for i, slider in enumerate(self.sliders):
            self._check_slider(i, slider, names, points)
        for i, spring in enumerate(self.springs):
            if not isinstance(spring, Spring):
                raise SpecError("must be a Spring", key=f"springs[{i}]", value=spring)
            for p in spring.points:
                if p not in points:
                    raise SpecError(f"names an unknown point '{p}' (the points are "
                                    f"{', '.join(points)})", key=f"springs[{i}].points",
                                    value=list(spring.points))
        for name, body in names.items():
            if name == GROUND or len(body.points) > 1:
                continue
            count = sum(s.link == name for s in self.sliders)
            if count != 1:
                raise SpecError(
                    "a one-point link must be the link of exactly one slider (its frame's "
                    f"x-axis is that slider's direction); it is the link of {count}",
                    key=f"links.{name}.points", value=list(body.points))
        self._check_frames(names, points)
        ground = set(names[GROUND].points)
        key = "mechanism.input"
        if not isinstance(self.input, str) or self.input not in names or self.input == GROUND:
            raise SpecError(f"must name a moving link ({_link_list(names)})", key=key,
                            value=self.input)
        if names[self.input].points[0] not in ground:
            raise SpecError(f"the input's first point ({names[self.input].points[0]}) must be "
                            "a ground point: the crank turns about it", key=key,
                            value=self.input)
        for name, body in names.items():
            if name != GROUND and body.props.counter_rotor and not ground & set(body.points):
                raise SpecError("a counter-rotor sits on a ground pivot: this link has none",
                                key=f"links.{name}.counter_rotor",
                                value=body.props.counter_rotor)
        _set(self, "bodies", tuple(self.bodies))
        _set(self, "sliders", tuple(self.sliders))
        _set(self, "springs", tuple(self.springs))

    @staticmethod
    def _check_slider(i: int, slider, names, points) -> None:
        key = f"mechanism.sliders[{i}]"
        if not isinstance(slider, Slider):
            raise SpecError("must be a Slider", key=key, value=slider)
        for attr in ("link", "guide"):
            value = getattr(slider, attr)
            if value not in names:
                raise SpecError(f"names an unknown link ({_link_list(names)})",
                                key=f"{key}.{attr}", value=value)
        if slider.link == GROUND:
            raise SpecError("the sliding link must move (put the guide on the ground)",
                            key=f"{key}.link", value=slider.link)
        if slider.link == slider.guide:
            raise SpecError("a link cannot slide on itself", key=f"{key}.guide",
                            value=slider.guide)
        if slider.point not in names[slider.link].points:
            raise SpecError(f"must be a point of {slider.link} "
                            f"({', '.join(names[slider.link].points)})", key=f"{key}.point",
                            value=slider.point)
        dx, dy = v.vector2(slider.direction, f"{key}.direction")
        if dx == 0 and dy == 0:
            raise SpecError("must not be zero", key=f"{key}.direction", value=[dx, dy])
        if not isinstance(slider.force, GasForce):
            raise SpecError("must be a GasForce", key=f"{key}.force", value=slider.force)
        object.__setattr__(slider, "direction", (dx, dy))

    @staticmethod
    def _check_frames(names, points) -> None:
        """A link's first two points must be apart: they fix its frame."""
        scale = max(math.hypot(*xy) for xy in points.values()) or 1.0
        for name, body in names.items():
            if len(body.points) < 2 or name == GROUND:
                continue
            (x0, y0), (x1, y1) = points[body.points[0]], points[body.points[1]]
            if math.hypot(x1 - x0, y1 - y0) <= v.RELATIVE_LENGTH * scale:
                raise SpecError(
                    f"its first two points ({body.points[0]}, {body.points[1]}) coincide: they "
                    "fix the link's frame", key=f"links.{name}.points",
                    value=list(body.points))

    # -- what every mechanism model offers ----------------------------------------------------

    @property
    def point_positions(self) -> dict[str, complex]:
        """Each point's position at the reference pose, m."""
        return {name: complex(*xy) for name, xy in self.points}

    @property
    def ground(self) -> Body:
        """The ground link."""
        return next(b for b in self.bodies if b.name == GROUND)

    @property
    def moving(self) -> tuple[Body, ...]:
        """The moving links, in the spec's order."""
        return tuple(b for b in self.bodies if b.name != GROUND)

    @property
    def link_names(self) -> tuple[str, ...]:
        """Names of the moving links."""
        return tuple(b.name for b in self.moving)

    @property
    def links(self) -> tuple[Link, ...]:
        """Mass properties of the moving links."""
        return tuple(b.props for b in self.moving)  # type: ignore[misc]

    @property
    def grounded_links(self) -> tuple[str, ...]:
        """Moving links that share a point with the ground (where a counter-rotor can sit)."""
        ground = set(self.ground.points)
        return tuple(b.name for b in self.moving if ground & set(b.points))

    @property
    def total_mass(self) -> float:
        """Mass of the moving links, kg."""
        return math.fsum(link.mass for link in self.links)

    @property
    def has_loads(self) -> bool:
        """Whether any link carries an applied force or moment, or a slider a force."""
        return (any(link.has_loads for link in self.links)
                or any(not s.force.is_zero for s in self.sliders))

    @property
    def sizes(self) -> dict[str, float]:
        """The geometry's sizes by spec key, m: each point's distance from the origin."""
        return {f"mechanism.points.{p}": math.hypot(*xy) for p, xy in self.points}

    @property
    def gas_forces(self) -> tuple[tuple[str, GasForce], ...]:
        """Forces on sliders along their guides, by the sliding link's key."""
        return tuple((f"links.{s.link}.gas_force", s.force) for s in self.sliders)

    def link(self, name: str) -> Link:
        """The mass properties of the moving link called ``name``."""
        for b in self.moving:
            if b.name == name:
                return b.props  # type: ignore[return-value]
        raise KeyError(name)

    def with_link(self, name: str, link: Link) -> Linkage:
        """Return a copy with link ``name``'s mass properties replaced."""
        return self.with_links({name: link})

    def with_links(self, links: dict[str, Link]) -> Linkage:
        """Return a copy with several links' mass properties replaced."""
        unknown = set(links) - set(self.link_names)
        if unknown:
            raise KeyError(sorted(unknown)[0])
        bodies = tuple(replace(b, props=links[b.name]) if b.name in links else b
                       for b in self.bodies)
        return replace(self, bodies=bodies)

    def without_loads(self) -> Linkage:
        """Return a copy with every applied force and moment and slider force removed."""
        bodies = tuple(b if b.props is None else replace(b, props=b.props.without_loads())
                       for b in self.bodies)
        sliders = tuple(replace(s, force=GasForce()) for s in self.sliders)
        return replace(self, bodies=bodies, sliders=sliders)


#: A mechanism the package knows.
Mechanism = FourBar | SliderCrank | Linkage


def _set(obj, name: str, value) -> None:
    """Store a checked (normalised) value on a frozen dataclass."""
    object.__setattr__(obj, name, value)


def _numbers(values, key: str) -> tuple[float, ...]:
    if isinstance(values, str | bytes) or not hasattr(values, "__iter__"):
        raise SpecError("must be a non-empty list of numbers", key=key, value=values)
    out = tuple(v.number(x, key) for x in values)
    if not out:
        raise SpecError("must be a non-empty list of numbers", key=key, value=list(values))
    return out


def _length_sizes(mech) -> dict[str, float]:
    """A four-bar's or slider-crank's lengths by spec key (magnitudes), m."""
    return {f"mechanism.lengths.{n}": abs(x)
            for n, x in zip(mech.length_names, mech.lengths, strict=True)}


def _check_mechanism(mech) -> tuple[float, ...]:
    """Lengths, links and branch of a mechanism; store the lengths as floats and return them.

    A slider-crank's offset (its last length) is signed; every other length is positive. Link
    keys are ``links.<name>``, lengths ``mechanism.lengths.<name>``.
    """
    names = mech.length_names
    raw = mech.lengths
    if isinstance(raw, str) or not hasattr(raw, "__len__") or len(raw) != len(names):
        raise SpecError(f"must be {len(names)} lengths ({', '.join(names)})",
                        key="mechanism.lengths", value=raw)
    lengths = []
    for name, value in zip(names, raw, strict=True):
        key = f"mechanism.lengths.{name}"
        if name == "offset":
            x = v.number(value, key)
            if x != 0:
                v.length(abs(x), key)
            lengths.append(x)
        else:
            lengths.append(v.length(value, key))
    v.relative_lengths(dict(zip(names, lengths, strict=True)), "mechanism.lengths")
    _set(mech, "lengths", tuple(lengths))
    _set(mech, "branch", v.choice(mech.branch, "mechanism.branch", ("+", "-")))
    for name in mech.link_names:
        link = getattr(mech, name)
        if not isinstance(link, Link):
            raise SpecError("must be a Link", key=f"links.{name}", value=link)
        if link.counter_rotor and name not in mech.grounded_links:
            where = " and ".join(mech.grounded_links)
            raise SpecError(
                f"a counter-rotor sits on a ground pivot: only the {where} can have one",
                key=f"links.{name}.counter_rotor", value=link.counter_rotor,
            )
    return tuple(lengths)


@dataclass(frozen=True, kw_only=True)
class Operation:
    """The operating condition a cycle analysis and a balancing refer to.

    Attributes
    ----------
    speed
        Constant crank speed, rad/s (counter-clockwise positive).
    samples
        Number of equally spaced crank angles over one revolution, starting at θ1 = 0.
    gravity
        Gravitational acceleration ``(gx, gy)`` the cycle analysis includes, m/s² (``(0, 0)``:
        none): the frame then carries the links' weights too.
    """

    speed: float
    samples: int = 360
    gravity: tuple[float, float] = (0.0, 0.0)

    #: Memory a cycle analysis or a balancing takes per sampled angle, bytes (the regressors'
    #: complex (N, 14) arrays and the motion's, with room for temporaries).
    BYTES_PER_SAMPLE: ClassVar[int] = 4096

    def __post_init__(self) -> None:
        """Check the values (keys within ``[operation]``)."""
        _set(self, "speed", v.nonzero(self.speed, "speed", "the crank must turn"))
        samples = v.integer(self.samples, "samples", minimum=8)
        v.require_memory(samples, self.BYTES_PER_SAMPLE, "samples", "samples of a revolution")
        _set(self, "samples", samples)
        _set(self, "gravity", v.vector2(self.gravity, "gravity"))


@dataclass(frozen=True, kw_only=True)
class SimulationSettings:
    """How ``simulate`` and ``verify`` run the forward dynamics.

    Attributes
    ----------
    duration
        Simulated time, s.
    theta1
        Initial crank angle, rad; ``None``: the mechanism's start (a general linkage's
        reference pose, θ1 = 0 for the four-bar and slider-crank).
    omega1
        Initial crank speed, rad/s; when ``drive`` is ``"constant-speed"``, the constant speed
        (where it is zero, a design's simulation takes the operating speed ``[operation] speed``:
        :func:`balancer.simulation.simulate_design`).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s² (``(0, 0)``: none).
    drive
        ``"free"``: the crank moves under the loads alone; ``"constant-speed"``: a motor on the
        ground holds the crank at ``omega1`` (or at the operating speed, see ``omega1``).
    method
        Formulation of the equations of motion (see :mod:`balancer.formulations`); ``None``:
        the mechanism's default.
    rtol, atol
        Relative and absolute tolerances of the integrator.
    outputs
        Number of equally spaced output times, including both ends.
    """

    duration: float = 5.0
    theta1: float | None = None
    omega1: float = 0.0
    gravity: tuple[float, float] = (0.0, 0.0)
    drive: Drive = "free"
    method: str | None = None
    rtol: float = 1e-10
    atol: float = 1e-12
    outputs: int = 501

    #: Memory a simulation takes per output time, bytes (state, evaluation, CSV text).
    BYTES_PER_OUTPUT: ClassVar[int] = 4096

    def __post_init__(self) -> None:
        """Check the values (keys within ``[simulation]``)."""
        _set(self, "duration", v.positive(self.duration, "duration"))
        if self.theta1 is not None:
            _set(self, "theta1", v.number(self.theta1, "theta1"))
            if abs(self.theta1) > THETA1_MAX:
                raise SpecError(f"must be within ±{THETA1_MAX:g} rad: beyond, the integration's "
                                "steps of the crank angle lose their digits to its size "
                                "(give it modulo 2π)", key="theta1", value=self.theta1)
        _set(self, "omega1", v.number(self.omega1, "omega1"))
        _set(self, "gravity", v.vector2(self.gravity, "gravity"))
        _set(self, "drive", v.choice(self.drive, "drive", DRIVES))
        if self.method is not None:
            # which formulations apply depends on the mechanism: simulate checks the name
            if not isinstance(self.method, str) or not self.method:
                raise SpecError("must be the name of a formulation", key="method",
                                value=self.method)
        rtol = v.number(self.rtol, "rtol")
        if not RTOL_MIN <= rtol < 1:
            raise SpecError(f"must be at least {RTOL_MIN:.3g} (100 ε: the integrator's floor) "
                            "and below 1", key="rtol", value=self.rtol)
        _set(self, "rtol", rtol)
        atol = v.positive(self.atol, "atol")
        if atol < ATOL_MIN:
            raise SpecError(f"must be at least {ATOL_MIN:g} (the integrator squares errors "
                            "over it)", key="atol", value=self.atol)
        _set(self, "atol", atol)
        outputs = v.integer(self.outputs, "outputs", minimum=2)
        v.require_memory(outputs, self.BYTES_PER_OUTPUT, "outputs", "output times")
        _set(self, "outputs", outputs)


@dataclass(frozen=True, kw_only=True)
class Design:
    """A complete design spec: the mechanism and what to do with it.

    Attributes
    ----------
    mechanism
        The linkage and its links.
    operation
        The operating speed for cycle analysis and balancing (``None`` if the spec has none).
    simulation
        Settings for forward dynamics.
    balance
        The redesign problem (``None`` if the spec has none); see :mod:`balancer.balance.problem`.
    original
        The unbalanced design this one was derived from, if any (written by ``optimize``).
    title
        A free-text name for reports.
    """

    mechanism: Mechanism
    operation: Operation | None = None
    simulation: SimulationSettings = field(default_factory=SimulationSettings)
    balance: object | None = None
    original: Mechanism | None = None
    title: str = ""

    def __post_init__(self) -> None:
        """Check the parts' types and that the figures stay within double precision.

        Keys are the spec's, from its root.
        """
        if not isinstance(self.mechanism, Mechanism):
            raise SpecError("must be a FourBar, a SliderCrank or a Linkage", key="mechanism",
                            value=type(self.mechanism).__name__)
        for name, cls in (("operation", Operation), ("simulation", SimulationSettings)):
            value = getattr(self, name)
            if value is not None and not isinstance(value, cls):
                raise SpecError(f"must be an {cls.__name__}", key=name,
                                value=type(value).__name__)
        if self.original is not None and type(self.original) is not type(self.mechanism):
            raise SpecError("must be the same kind of mechanism as the design",
                            key="original", value=type(self.original).__name__)
        if not isinstance(self.title, str):
            raise SpecError("must be a string", key="title", value=self.title)
        speeds = {"simulation.omega1": self.simulation.omega1}
        gravity = {"simulation.gravity": self.simulation.gravity}
        if self.operation is not None:
            speeds["operation.speed"] = self.operation.speed
            gravity["operation.gravity"] = self.operation.gravity
        for mech in (self.mechanism, self.original):
            if mech is not None:
                check_scales(mech, speeds, gravity)


def _link_list(names) -> str:
    """The links of a spec by name, for a message: the moving ones, and the frame's name."""
    moving = [n for n in names if n != GROUND]
    return f"the moving links are {', '.join(moving)}; the frame is called {GROUND}"


def check_scales(mechanism, speeds: dict[str, float],
                 gravity: dict[str, tuple[float, float]] | None = None) -> None:
    """Raise :class:`SpecError` if a force, moment or energy of the motion leaves double precision.

    The scales (:func:`balancer.validate.check_magnitudes`): a reach ``R`` (the model's
    ``sizes`` and the centres of mass' distances from their links' origins, summed); forces
    ``m·R·ω²``, ``m·|g|``, the applied forces, the model's ``gas_forces`` and its springs'
    ``k·R`` and ``k·|l0|``; moments ``R`` times those, ``I·ω²``, ``J_c·ω²`` and the applied
    moments; energies ``I·ω²``, ``J_c·ω²``, ``m·R²·ω²``, ``k·R²`` and ``k·l0²``. Each
    input that enters a scale is a term of its own, so that the one at fault is named.
    ``speeds`` and ``gravity`` are keyed by their spec keys (the largest of each counts).
    """
    links = dict(zip(mechanism.link_names, mechanism.links, strict=True))
    reach_terms = dict(mechanism.sizes)
    for name, link in links.items():
        reach_terms[f"links.{name}.com"] = math.hypot(link.e, link.f)
    reach_key = max(reach_terms, key=reach_terms.__getitem__)
    r = [(reach_key, math.fsum(reach_terms.values()))]  # the reach R, m
    speed_key = max(speeds, key=lambda k: abs(speeds[k]))
    w2 = [(speed_key, speeds[speed_key])] * 2  # ω², as two factors
    gravity = gravity or {"gravity": (0.0, 0.0)}
    g_key = max(gravity, key=lambda k: math.hypot(*gravity[k]))
    g = gravity[g_key]
    g_abs = [(g_key, math.hypot(*g))]
    forces, moments, energies = [], [], []
    for name, link in links.items():
        mass = [(f"links.{name}.mass", link.mass)]
        inertia = [(f"links.{name}.inertia", link.inertia)]
        rotor = [(f"links.{name}.counter_rotor", link.counter_rotor)]
        force = [(f"links.{name}.force", math.hypot(*link.force))]
        forces += [mass + r + w2, mass + g_abs, force]
        moments += [mass + r + r + w2, mass + g_abs + r, force + r, inertia + w2, rotor + w2,
                    [(f"links.{name}.moment", link.moment)]]
        energies += [inertia + w2, rotor + w2, mass + r + r + w2]
    for key, g in mechanism.gas_forces:
        if not g.is_zero:
            gas = [(key, max(abs(x) for x in g.values))]
            forces.append(gas)
            moments.append(gas + r)
    for i, spring in enumerate(mechanism.springs):
        # Its force k·(R + |l0|) at most, moment R times that, energy k·(R + |l0|)²/2: the
        # reach's and the free length's terms apart, each named by its own key.
        stiffness = [(f"springs[{i}].stiffness", spring.stiffness)]
        free = [(f"springs[{i}].free_length", spring.free_length)]
        for stretch in (r, free):
            forces.append(stiffness + stretch)
            moments.append(stiffness + stretch + r)
            energies.append(stiffness + stretch + stretch)
    v.check_magnitudes(forces, "the forces", "N")
    v.check_magnitudes(moments, "the moments", "N·m")
    v.check_magnitudes(energies, "the kinetic energy", "J")
