"""Immutable model objects: links, mechanisms, operating conditions and a whole design.

Notation (Meijaard & van der Wijk 2020, Sect. 2–3, Fig. 1): link ``k`` runs from its first joint
to its second; its centre of mass relative to the first joint, in the frame along the link, is
``s̄k = sk·exp(iσk) = ek + i·fk``; ``Ik`` is its moment of inertia about that centre of mass.
Applied loads are a constant force ``F̄k`` (global axes) at the centre of mass and a moment ``Mk``.
A counter-rotor is a disc coaxial with the link's ground pivot geared to turn at −1 times the
link's angular velocity; only its inertia counts.

All quantities are SI: m, kg, kg·m², rad, s, N, N·m. Objects are frozen; make variants with
:func:`dataclasses.replace` or the ``with_*`` helpers.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import ClassVar, Literal

Branch = Literal["+", "-"]
Drive = Literal["free", "constant-speed"]

#: Names of the formulations of the equations of motion (see :mod:`balancer.formulations`).
METHODS: tuple[str, ...] = ("opened-loop", "complex-masses", "mass-matrix", "lie-group")
#: The formulations of each mechanism type; the first is its default.
METHODS_BY_TYPE: dict[str, tuple[str, ...]] = {
    "four-bar": METHODS,
    "slider-crank": ("mass-matrix", "complex-masses"),
}
#: Ways the crank can be driven in a simulation.
DRIVES: tuple[str, ...] = ("free", "constant-speed")


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
        from scipy.interpolate import CubicSpline

        angles = list(self.angles) + [self.angles[0] + self.period]
        values = list(self.values) + [self.values[0]]
        return CubicSpline(angles, values, bc_type="periodic")

    def at(self, theta1):
        """The force (N) at crank angle(s) ``theta1`` (rad)."""
        import numpy as np

        t = np.asarray(theta1, dtype=float)
        if len(self.values) == 1:
            return self.values[0] + 0.0 * t
        start = self.angles[0]
        return self._spline(start + np.mod(t - start, self.period))


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


#: A mechanism the package knows.
Mechanism = FourBar | SliderCrank


@dataclass(frozen=True, kw_only=True)
class Operation:
    """The operating condition a cycle analysis and a balancing refer to.

    Attributes
    ----------
    speed
        Constant crank speed, rad/s (counter-clockwise positive).
    samples
        Number of equally spaced crank angles over one revolution, starting at θ1 = 0.
    """

    speed: float
    samples: int = 360


@dataclass(frozen=True, kw_only=True)
class SimulationSettings:
    """How ``simulate`` and ``verify`` run the forward dynamics.

    Attributes
    ----------
    duration
        Simulated time, s.
    theta1
        Initial crank angle, rad.
    omega1
        Initial crank speed, rad/s (the constant speed when ``drive`` is ``"constant-speed"``).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s² (``(0, 0)``: none).
    drive
        ``"free"``: the crank moves under the loads alone; ``"constant-speed"``: a motor on the
        ground holds the crank at ``omega1``.
    method
        Formulation of the equations of motion (see :mod:`balancer.formulations`); ``None``:
        the mechanism's default.
    rtol, atol
        Relative and absolute tolerances of the integrator.
    outputs
        Number of equally spaced output times, including both ends.
    """

    duration: float = 5.0
    theta1: float = 0.0
    omega1: float = 0.0
    gravity: tuple[float, float] = (0.0, 0.0)
    drive: Drive = "free"
    method: str | None = None
    rtol: float = 1e-10
    atol: float = 1e-12
    outputs: int = 501


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
        The redesign problem (``None`` if the spec has none); see :mod:`balancer.problem`.
    original
        The unbalanced design this one was derived from, if any (written by ``optimize``).
    title
        A free-text name for reports.
    """

    mechanism: FourBar | SliderCrank
    operation: Operation | None = None
    simulation: SimulationSettings = field(default_factory=SimulationSettings)
    balance: object | None = None
    original: FourBar | SliderCrank | None = None
    title: str = ""
