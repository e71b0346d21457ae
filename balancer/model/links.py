"""A link's mass properties and loads, a slider's gas force, and the parts of a general linkage.

Notation (Meijaard & van der Wijk 2020, Sect. 2–3, Fig. 1): link ``k``'s centre of mass relative
to its first joint, in the frame along the link, is ``s̄k = sk·exp(iσk) = ek + i·fk``; ``Ik`` is
its moment of inertia about that centre of mass. Applied loads are a constant force ``F̄k``
(global axes) at the centre of mass and a moment ``Mk``. SI units throughout.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from types import ModuleType
from typing import TYPE_CHECKING, Any, TypeVar, overload

from .. import validate as v
from ..errors import SpecError

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike, NDArray


#: A number, a numpy array or a CasADi symbol: what the inertial-parameter map works on.
N = TypeVar("N", bound=Any)


def inertial_parameters(mass: N, e: N, f: N, inertia: N) -> tuple[N, N, N, N]:
    """A link's inertial parameters ``(m, m·e, m·f, J)`` from ``m``, ``e``, ``f``, ``I``.

    ``J = I + m·(e² + f²)`` is the inertia about the link frame's origin (its first joint); the
    shaking force, moment and driving torque are linear in these four (Meijaard & van der Wijk
    2020, Eq. 55–56). Works on floats, numpy arrays and CasADi symbols alike. The one map from
    a link's mass properties to its inertial parameters; :func:`physical_parameters` inverts it.
    """
    return mass, mass * e, mass * f, inertia + mass * (e * e + f * f)


def physical_parameters(params: Iterable[float]) -> tuple[float, float, float, float]:
    """``(m, e, f, I)`` from inertial parameters ``(m, m·e, m·f, J)`` (:func:`inertial_parameters`).

    ``m`` must not be zero.
    """
    m, me, mf, j = (float(p) for p in params)
    e, f = me / m, mf / m
    return m, e, f, j - m * (e * e + f * f)


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
    z
        The plane the link moves in, along the crank's axis, m (0: the crank's plane): a
        lamina there. Links in several planes rock the frame (the rocking couple).
    """

    mass: float
    inertia: float
    e: float
    f: float
    force: tuple[float, float] = (0.0, 0.0)
    moment: float = 0.0
    counter_rotor: float = 0.0
    z: float = 0.0

    def __post_init__(self) -> None:
        """Check the values (keys are the spec's names within the link's table)."""
        v.store(self, "mass", v.positive(self.mass, "mass"))
        v.store(self, "inertia", v.nonnegative(self.inertia, "inertia"))
        v.store(self, "e", v.number(self.e, "com.e"))
        v.store(self, "f", v.number(self.f, "com.f"))
        v.store(self, "force", v.vector2(self.force, "force"))
        v.store(self, "moment", v.number(self.moment, "moment"))
        v.store(self, "counter_rotor", v.nonnegative(self.counter_rotor, "counter_rotor"))
        v.store(self, "z", v.number(self.z, "z"))

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
        """Angle of the centre of mass from the link line, rad, in (−π, π].

        (A centre on the link line behind its first joint is at π whatever the sign of its
        zero ``f``: ``+ 0.0`` turns −0.0 into 0.0.)
        """
        return math.atan2(self.f + 0.0, self.e)

    @property
    def force_complex(self) -> complex:
        """Applied force ``F̄ = Fx + i·Fy``, N."""
        return complex(*self.force)

    @property
    def has_loads(self) -> bool:
        """Whether any applied force or moment acts on the link."""
        return self.force != (0.0, 0.0) or self.moment != 0.0

    @property
    def inertial_parameters(self) -> tuple[float, float, float, float]:
        """Inertial parameters ``(m, m·e, m·f, J)``, ``J = I + m·s²`` about the first joint.

        See :func:`inertial_parameters`.
        """
        return inertial_parameters(self.mass, self.e, self.f, self.inertia)

    def inertia_about_joint(self) -> float:
        """Moment of inertia about the first joint ``I + m·s²``, kg·m²."""
        return self.inertial_parameters[3]

    def with_com_polar(self, s: float, sigma: float) -> Link:
        """Return a copy with the centre of mass at distance ``s`` (m) and angle ``sigma`` (rad)."""
        c = cmath.rect(s, sigma)
        return replace(self, e=c.real, f=c.imag)

    def without_loads(self) -> Link:
        """Return a copy with no applied force or moment."""
        return replace(self, force=(0.0, 0.0), moment=0.0)


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
        angles, values = (v.numbers(x, k) for x, k in ((self.angles, "crank_angle"),
                                                       (self.values, "force")))
        if len(angles) != len(values):
            raise SpecError(f"crank_angle and force must have the same length ({len(angles)} "
                            f"and {len(values)})", key="force")
        if (any(b <= a for a, b in zip(angles, angles[1:], strict=False)) or angles[0] < 0
                or angles[-1] >= period):
            raise SpecError("crank angles must increase within one period, from 0",
                            key="crank_angle", value=list(angles))
        v.store(self, "period", period)
        v.store(self, "angles", angles)
        v.store(self, "values", values)

    @classmethod
    def constant(cls, value: float) -> GasForce:
        """A constant force along +x, N."""
        return cls(angles=(0.0,), values=(float(value),))

    @property
    def is_zero(self) -> bool:
        """Whether the force vanishes everywhere."""
        return all(v == 0.0 for v in self.values)

    @cached_property
    def _spline(self) -> _PeriodicCubic:
        return _PeriodicCubic(self.angles, self.values, self.period)

    @overload
    def at(self, theta1: float) -> float: ...
    @overload
    def at(self, theta1: NDArray[np.float64]) -> NDArray[np.float64]: ...

    def at(self, theta1: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
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

    def __init__(self, x: Sequence[float], y: Sequence[float], period: float) -> None:
        import numpy as np

        xs = np.asarray(x, dtype=float)
        ys = np.asarray(y, dtype=float)
        n = xs.size
        self.knots = np.append(xs, xs[0] + period)
        h = np.diff(self.knots)
        slope = (np.roll(ys, -1) - ys) / h
        i = np.arange(n)
        a = np.zeros((n, n))
        a[i, i] = 2 * (np.roll(h, 1) + h)
        a[i, (i - 1) % n] += np.roll(h, 1)
        a[i, (i + 1) % n] += h
        m = np.linalg.solve(a, 6 * (slope - np.roll(slope, 1)))
        self.h, self.y, self.m = h, np.append(ys, ys[0]), np.append(m, m[0])
        self._knots = self.knots.tolist()

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        """The spline at ``t`` (within one period from the first knot)."""
        import numpy as np

        ts = np.asarray(t, dtype=float)
        i = np.clip(np.searchsorted(self.knots, ts, side="right") - 1, 0, self.h.size - 1)
        return self._piece(i, ts, np)

    def at(self, t: float) -> float:
        """:meth:`__call__` at one time, in plain floats (an integrator's single state)."""
        import bisect

        i = min(max(bisect.bisect_right(self._knots, t) - 1, 0), len(self._knots) - 2)
        return float(self._piece(i, t, None))

    @overload
    def _piece(self, i: int, t: float, np: None) -> np.float64: ...
    @overload
    def _piece(self, i: NDArray[np.intp], t: NDArray[np.float64],
               np: ModuleType) -> NDArray[np.float64]: ...

    def _piece(self, i: int | NDArray[np.intp], t: float | NDArray[np.float64],
               np: ModuleType | None) -> np.float64 | NDArray[np.float64]:
        """The cubic of interval ``i`` at ``t`` (indices and times arrays, or numbers)."""
        h = self.h[i]
        a = (self.knots[i + 1] - t) / h
        b = 1.0 - a
        return (a * self.y[i] + b * self.y[i + 1]
                + ((a**3 - a) * self.m[i] + (b**3 - b) * self.m[i + 1]) * (h * h / 6.0))


#: The name of the general linkage's frame: a link without mass whose points do not move.
GROUND = "ground"
#: Names a moving link may not have: the keys of ``[balance]`` beside the links' tables.
RESERVED_LINK_NAMES = ("objective", "force_balance", "motions")


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
class Gear:
    """A pair of spur gears on two links, each turned about its ground pivot.

    The driven link turns at ``ratio`` times the driver's rate (``ω_driven = ratio·ω_driver``):
    negative for two gears in mesh (they turn opposite ways), above 1 for a pinion inside a
    ring gear. Their pitch circles touch at the pitch point on the line of their pivots (the
    links' first points), where ``ω_a·ρ_a = ω_b·ρ_b`` for the signed radii ``ρ`` along that
    line; the teeth push along the common tangent there (the pitch-line force: the separating
    force of a pressure angle is left out). A ratio of 1 has no pitch point (two shafts at one
    speed mesh through an idler).

    Attributes
    ----------
    name
        The pair's name, as outputs call its tooth load.
    driver, driven
        The two links' names.
    ratio
        ``ω_driven / ω_driver``; not 0 nor 1.
    """

    name: str
    driver: str
    driven: str
    ratio: float


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
        v.store(self, "points", tuple(self.points))
        v.store(self, "stiffness", v.nonnegative(self.stiffness, "stiffness"))
        v.store(self, "free_length", v.nonnegative(self.free_length, "free_length"))
