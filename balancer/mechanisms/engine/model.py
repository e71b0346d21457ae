"""An engine's data: cylinders on one crankshaft, rods, pistons, balance shafts and gas.

DESIGN.md, "Engines and multi-plane machines". z is the crankshaft's axis, the origin O on it;
the crank turns about +z and every angle is from +x towards +y, in degrees as engine data sheets
give them (fields that end in ``_deg``; a spec reads back exactly). Cylinder ``k`` (from 1) has
its crank pin at ``θ1 + phase`` at radius ``crank``; its axis points at ``bank`` from the crank
towards the head, its piston pin's line shifted by ``offset`` along the axis turned +90°; its
rod (big end at the crank pin, x to the small end) and piston move in its plane ``z``. The
crankshaft carries mass·radius at angles and planes; balance shafts turn at integer ratios of
the crank's speed about axes parallel to it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import ClassVar

from ... import validate as v
from ...errors import AssemblyError, SpecError
from ...linkage.rotors import Eccentric, Rotor
from ...model.balance import PlacedMass, ShaftDesign
from ...model.links import GasForce, Link
from ...model.mechanisms import MechanismModel
from .throws import COUNTERWEIGHT, Throw, shaft_throws

#: A four-stroke cycle's crank angle, rad; a two-stroke's is half of it.
TWO_TURNS = 4 * math.pi
#: The crankcase's pressure when the spec gives none, Pa (DESIGN.md).
ATMOSPHERE = 1.0e5
#: Tolerance of two firings at the same crank angle, rad (cylinders with the same dead centre).
SAME_ANGLE = 1e-9


@dataclass(frozen=True, kw_only=True)
class Cylinder:
    """One cylinder: its plane, its crank pin's phase, its axis and its lengths.

    Attributes
    ----------
    z
        Its plane along the crankshaft, m.
    phase_deg
        Its crank pin's angle at θ1 = 0, degrees.
    bank_deg
        Its axis' angle, from the crank towards the head, degrees.
    crank
        Crank radius (half the stroke), m; positive.
    rod
        Rod length between the pin centres, m; longer than ``crank + |offset|``.
    offset
        The piston pin's line from the crank's axis, along the axis turned +90°, m (signed).
    bore
        The bore, m, positive (needed with gas; ``None``: not given).
    crankshaft
        The crankshaft its pin is on: 1 the first (``[links.crankshaft]``, turning at θ1
        about the origin), 2 and on the engine's geared ones (:class:`GearedCrankshaft`).
    """

    z: float = 0.0
    phase_deg: float = 0.0
    bank_deg: float = 0.0
    crank: float
    rod: float
    offset: float = 0.0
    bore: float | None = None
    crankshaft: int = 1

    def __post_init__(self) -> None:
        if (isinstance(self.crankshaft, bool) or not isinstance(self.crankshaft, int)
                or self.crankshaft < 1):
            raise SpecError("must be a crankshaft's number: 1 the first, 2 and on those of "
                            "[[crankshafts]]", key="crankshaft", value=self.crankshaft)
        for name in ("z", "phase_deg", "bank_deg", "offset"):
            v.store(self, name, v.number(getattr(self, name), name))
        v.store(self, "crank", v.length(self.crank, "crank"))
        v.store(self, "rod", v.length(self.rod, "rod"))
        if self.bore is not None:
            v.store(self, "bore", v.positive(self.bore, "bore"))
        if self.crank < SHORTEST_CRANK * self.rod:  # (the crank's marker would meet its axis)
            raise SpecError(f"must be at least {SHORTEST_CRANK:g} of the rod "
                            f"({SHORTEST_CRANK * self.rod:.3g} m)", key="crank",
                            value=self.crank)
        if not self.rod > self.crank + abs(self.offset):
            raise AssemblyError(
                f"the crank cannot turn: the rod ({self.rod:.6g} m) must be longer than the "
                f"crank and the offset's size together ({self.crank + abs(self.offset):.6g} m)",
                key="rod", value=self.rod)

    @property
    def phase(self) -> float:
        """Its crank pin's angle at θ1 = 0, rad."""
        return math.radians(self.phase_deg)

    @property
    def bank(self) -> float:
        """Its axis' angle, rad."""
        return math.radians(self.bank_deg)

    @property
    def axis(self) -> complex:
        """The unit vector of its axis, towards the head."""
        return complex(math.cos(self.bank), math.sin(self.bank))

    @property
    def piston_area(self) -> float:
        """``π·bore²/4``, m² (0 without a bore)."""
        return 0.0 if self.bore is None else math.pi * self.bore * self.bore / 4

    def top_dead_centre(self, ratio: int = 1) -> float:
        """The crank angle θ1 in [0, 2π) where its crank pin points along its axis, rad.

        Its crankshaft turning at ``ratio`` (±1) times θ1: its pin at ``ratio·θ1 + phase``.
        """
        return ((self.bank - self.phase) / ratio) % (2 * math.pi)


#: The shortest crank, a share of its rod: below, the crank's points meet within rounding.
SHORTEST_CRANK = 1e-6

def idler_name(k: int) -> str:
    """The idler gear that turns crankshaft ``k`` (at ratio +1) from the first: ``idler2``…."""
    return f"idler{k}"


def crankshaft_name(k: int) -> str:
    """Crankshaft ``k``'s link name: ``crankshaft`` for the first, ``crankshaft2`` and on."""
    return "crankshaft" if k == 1 else f"crankshaft{k}"


@dataclass(frozen=True, kw_only=True)
class Mass:
    """A mass·radius on a shaft: the crankshaft's (pin, web, counterweight), a shaft's eccentric.

    Attributes
    ----------
    mr
        Its mass times the distance of its centre from the axis, kg·m; at least 0.
    phase_deg
        Its direction from the axis at θ1 = 0, degrees from +x towards +y.
    z
        Its plane along the crankshaft, m.
    label
        What it is (``"counterweight"``: one that balancing may replace).
    """

    mr: float
    phase_deg: float = 0.0
    z: float = 0.0
    label: str = ""

    def __post_init__(self) -> None:
        v.store(self, "mr", v.nonnegative(self.mr, "mr"))
        v.store(self, "phase_deg", v.number(self.phase_deg, "phase_deg"))
        v.store(self, "z", v.number(self.z, "z"))
        if not isinstance(self.label, str):
            raise SpecError("must be a string", key="label", value=self.label)

    @property
    def eccentric(self) -> Eccentric:
        """As a rotor's eccentric (angle in radians)."""
        return Eccentric(mr=self.mr, angle=math.radians(self.phase_deg), z=self.z)


@dataclass(frozen=True, kw_only=True)
class ShaftLink(Link):
    """The crankshaft as a link of the engine's linkage: on its axis, its mass maybe not given.

    Its centre of mass on its axis (``e = f = 0``: the mass·radius it carries is its rotor's);
    its mass 0 where the spec gives none (then only its inertia counts, and its weight is left
    out).
    """

    def __post_init__(self) -> None:
        mass = self.mass
        object.__setattr__(self, "mass", 1.0)  # (checked here: it may be 0)
        super().__post_init__()
        v.store(self, "mass", v.nonnegative(mass, "mass"))


@dataclass(frozen=True, kw_only=True)
class Crankshaft:
    """The crankshaft: its inertia, its mass and the mass·radius it carries.

    Attributes
    ----------
    inertia
        About its axis, kg·m² (its masses' included).
    mass
        Its mass, kg, for its weight under gravity (0: not given).
    masses
        Every mass·radius it carries (pins, webs, counterweights): each at its angle at θ1 = 0
        and in its plane; a counterweight labelled ``"counterweight"``.
    """

    inertia: float = 0.0
    mass: float = 0.0
    masses: tuple[Mass, ...] = ()

    def __post_init__(self) -> None:
        v.store(self, "inertia", v.nonnegative(self.inertia, "inertia"))
        v.store(self, "mass", v.nonnegative(self.mass, "mass"))
        v.store(self, "masses", _masses(self.masses, "masses"))

    @property
    def rotor(self) -> Rotor:
        """Its masses as a rotor at ratio 1 on its axis (its inertia is the link's)."""
        return Rotor(ratio=1.0, inertia=0.0, eccentrics=tuple(m.eccentric for m in self.masses))


@dataclass(frozen=True, kw_only=True)
class BalanceShaft:
    """A shaft geared to the crank at an integer ratio, with eccentrics.

    Attributes
    ----------
    ratio
        Its speed over the crank's, a non-zero integer (negative: the other way).
    at
        Its axis in the x–y plane, m.
    inertia
        About its axis, kg·m².
    eccentrics
        Its masses off the axis, at their angles at θ1 = 0.
    """

    ratio: int
    at: tuple[float, float] = (0.0, 0.0)
    inertia: float = 0.0
    eccentrics: tuple[Mass, ...] = ()

    def __post_init__(self) -> None:
        v.store(self, "ratio", v.ratio(self.ratio, "ratio"))
        v.store(self, "at", v.vector2(self.at, "at"))
        v.store(self, "inertia", v.nonnegative(self.inertia, "inertia"))
        v.store(self, "eccentrics", _masses(self.eccentrics, "eccentrics"))

    @property
    def rotor(self) -> Rotor:
        """The shaft as a rotor geared to the crank."""
        return Rotor(ratio=float(self.ratio), inertia=self.inertia, axis=complex(*self.at),
                     eccentrics=tuple(m.eccentric for m in self.eccentrics))


@dataclass(frozen=True, kw_only=True)
class GearedCrankshaft:
    """A further crankshaft geared to the first: twin-crank, U and opposed-piston engines.

    It turns at ``ratio`` times the first crankshaft's angle about its own axis, parallel to
    the first; the cylinders that name it (``crankshaft = 2``, …) have their pins on it, at
    ``ratio·θ1 + phase``. At ratio −1 the two are coupled by a pair of equal spur gears whose
    pitch circles touch midway between the axes; at +1 through an idler gear midway between
    them, the three gears' pitch radii a quarter of the axes' distance
    (:class:`balancer.model.Gear`: each pair's tooth load is reported).

    Attributes
    ----------
    at
        Its axis in the x–y plane, m (away from the first's, at the origin).
    ratio
        Its speed over the first crankshaft's: -1 (two gears in mesh) or +1 (through an idler).
    inertia
        About its axis, kg·m² (its masses' included).
    mass
        Its mass, kg, for its weight under gravity (0: not given).
    masses
        Every mass·radius it carries (pins, webs, counterweights), at its angles at θ1 = 0.
    idler_inertia
        At ratio +1, the idler gear's inertia about its axis, kg·m² (its centre of mass on it).
    main_bearings
        Its main bearings' planes, m, increasing (none: its loads are reported summed at its
        axis), as the first crankshaft's ``[mechanism] main_bearings``.
    gear_z
        The plane of the gear pair (and idler) that turns it, m: where the teeth push on it and
        on the first crankshaft, for their main bearings' shares.
    """

    at: tuple[float, float]
    ratio: int = -1
    inertia: float = 0.0
    mass: float = 0.0
    masses: tuple[Mass, ...] = ()
    idler_inertia: float = 0.0
    main_bearings: tuple[float, ...] = ()
    gear_z: float = 0.0

    def __post_init__(self) -> None:
        v.store(self, "at", v.vector2(self.at, "at"))
        if self.at == (0.0, 0.0):
            raise SpecError("must be away from the first crankshaft's axis (the origin)",
                            key="at", value=list(self.at))
        ratio = v.number(self.ratio, "ratio")
        if ratio not in (-1, 1):
            raise SpecError("must be -1 (two gears in mesh: the crankshafts turn opposite ways) "
                            "or 1 (through an idler gear: the same way)", key="ratio",
                            value=self.ratio)
        v.store(self, "ratio", int(ratio))
        v.store(self, "idler_inertia", v.nonnegative(self.idler_inertia, "idler_inertia"))
        if self.idler_inertia and self.ratio == -1:
            raise SpecError("is an idler's: a crankshaft at ratio -1 meshes with the first "
                            "directly", key="idler_inertia", value=self.idler_inertia)
        v.store(self, "main_bearings", _bearings(self.main_bearings, "main_bearings"))
        v.store(self, "gear_z", v.number(self.gear_z, "gear_z"))
        v.store(self, "inertia", v.nonnegative(self.inertia, "inertia"))
        v.store(self, "mass", v.nonnegative(self.mass, "mass"))
        v.store(self, "masses", _masses(self.masses, "masses"))

    @property
    def rotor(self) -> Rotor:
        """Its masses as a rotor at its ratio on its axis (its inertia is its link's)."""
        return Rotor(ratio=float(self.ratio), inertia=0.0, axis=complex(*self.at),
                     eccentrics=tuple(m.eccentric for m in self.masses))


@dataclass(frozen=True, kw_only=True)
class GasCycle:
    """Cylinder 1's absolute pressure over its working cycle, from its firing top dead centre.

    Attributes
    ----------
    crank_angle_deg
        Crank angles from the firing top dead centre, degrees, increasing within the working
        cycle from 0.
    pressure
        Absolute pressure there, Pa (a periodic cubic spline through the points).
    crankcase
        The pressure under the piston, Pa.
    """

    crank_angle_deg: tuple[float, ...]
    pressure: tuple[float, ...]
    crankcase: float = ATMOSPHERE

    def __post_init__(self) -> None:
        v.store(self, "crank_angle_deg", v.numbers(self.crank_angle_deg, "crank_angle_deg"))
        v.store(self, "pressure", v.numbers(self.pressure, "pressure"))
        v.store(self, "crankcase", v.nonnegative(self.crankcase, "crankcase"))
        if len(self.crank_angle_deg) != len(self.pressure):
            raise SpecError(f"crank_angle_deg and pressure must have the same length "
                            f"({len(self.crank_angle_deg)} and {len(self.pressure)})",
                            key="pressure")
        if any(p < 0 for p in self.pressure):
            raise SpecError("absolute pressures must be zero or positive", key="pressure",
                            value=list(self.pressure))

    def force(self, cylinder: Cylinder, firing: float, period: float) -> GasForce:
        """The gas force on a cylinder's piston along its axis (+: towards the head), N.

        ``−(p − crankcase)·π·bore²/4`` over the crank angle θ1, the pressure curve started at
        the cylinder's ``firing`` angle (rad) and repeating every ``period``. The spline through
        the shifted points is the shifted spline (a periodic spline is the same curve whatever
        its start).
        """
        area = cylinder.piston_area
        pairs = sorted(((math.radians(a) + firing) % period, -(p - self.crankcase) * area)
                       for a, p in zip(self.crank_angle_deg, self.pressure, strict=True))
        with v.under("gas"):
            return GasForce(angles=tuple(a for a, _ in pairs),
                            values=tuple(f for _, f in pairs), period=period)


def _bearings(planes: object, key: str) -> tuple[float, ...]:
    """Main bearings' planes: none, or two or more increasing along the crankshaft (m)."""
    if planes == ():
        return ()
    out = v.numbers(planes, key)
    if len(out) < 2 or any(b <= a for a, b in zip(out, out[1:], strict=False)):
        raise SpecError("must be two planes or more, increasing along the crankshaft (m)",
                        key=key, value=list(out))
    return out


def _masses(items: Sequence[Mass], key: str) -> tuple[Mass, ...]:
    out = tuple(items)
    for i, m in enumerate(out):
        if not isinstance(m, Mass):
            raise SpecError("must be a Mass", key=v.item(key, i), value=m)
    return out


@dataclass(frozen=True, kw_only=True)
class Engine(MechanismModel):
    """A piston engine: cylinders on one crankshaft (DESIGN.md, "Engines").

    Attributes
    ----------
    cylinders
        Cylinder 1 first.
    crankshaft
        Its inertia, mass and mass·radius.
    rod
        Every cylinder's connecting rod: mass, inertia about its centre of mass, centre of mass
        ``(e, f)`` in its frame (big end, x to the small end); it moves in its cylinder's plane.
    piston
        Every cylinder's reciprocating group, a point mass at the piston pin, kg.
    balance_shafts
        Shafts geared to the crank.
    strokes
        4 (a working cycle of 720°) or 2 (360°).
    firing_order
        The cylinders (numbered from 1) in the order they fire; needed with ``gas``.
    gas
        Cylinder 1's pressure over its working cycle (``None``: no gas forces).
    main_bearings
        The main bearings' planes along the crankshaft, m, increasing (none: their loads are
        reported summed as ``O``); each throw's loads are shared by the two bearings around it
        by the lever rule (:mod:`.bearings`). An engine of one crankshaft's.
    crankshafts
        Further crankshafts geared to the first (crankshaft 2, 3, …): twin-crank engines.
    """

    type: ClassVar[str] = "engine"
    balance_tables: ClassVar[str] = (
        "an engine is balanced by counterweights on its crankshaft and new balance shafts; "
        "name where they may go: [balance.counterweights] with max_mr (kg·m; planes, m, default "
        "each cylinder's; radius, m, for their masses), and/or [[balance.shafts]] with ratio, "
        "at, planes and max_mr (docs/engines.md, \"Balancing an engine\")")

    cylinders: tuple[Cylinder, ...]
    crankshaft: Crankshaft = field(default_factory=Crankshaft)
    rod: Link
    piston: float
    balance_shafts: tuple[BalanceShaft, ...] = ()
    strokes: int = 4
    firing_order: tuple[int, ...] | None = None
    gas: GasCycle | None = None
    main_bearings: tuple[float, ...] = ()
    crankshafts: tuple[GearedCrankshaft, ...] = ()

    def __post_init__(self) -> None:
        """Check the fields (keys are the spec's, from its root)."""
        cylinders = tuple(self.cylinders) if isinstance(self.cylinders, Sequence) else ()
        if not cylinders:
            raise SpecError("an engine needs at least one cylinder",
                            key="mechanism.cylinders", value=self.cylinders)
        for i, c in enumerate(cylinders):
            if not isinstance(c, Cylinder):
                raise SpecError("must be a Cylinder", key=v.item("mechanism.cylinders", i), value=c)
        v.store(self, "cylinders", cylinders)
        if not isinstance(self.crankshaft, Crankshaft):
            raise SpecError("must be a Crankshaft", key="links.crankshaft",
                            value=self.crankshaft)
        if not isinstance(self.rod, Link):
            raise SpecError("must be a Link", key="links.rod", value=self.rod)
        v.store(self, "piston", v.positive(self.piston, "links.piston.mass"))
        shafts = tuple(self.balance_shafts)
        for j, s in enumerate(shafts):
            if not isinstance(s, BalanceShaft):
                raise SpecError("must be a BalanceShaft", key=v.item("balance_shafts", j), value=s)
        v.store(self, "balance_shafts", shafts)
        geared = tuple(self.crankshafts)
        for j, g in enumerate(geared):
            if not isinstance(g, GearedCrankshaft):
                raise SpecError("must be a GearedCrankshaft", key=v.item("crankshafts", j),
                                value=g)
            if any(g.at == h.at for h in geared[:j]):
                raise SpecError("is another crankshaft's axis: each turns about its own",
                                key=f"{v.item('crankshafts', j)}.at", value=list(g.at))
        size = max(c.rod + c.crank + abs(c.offset) for c in cylinders)
        for j, g in enumerate(geared):
            reach = math.hypot(*g.at)  # (the frame's points must stay apart, to rounding)
            if not v.RELATIVE_LENGTH * size < reach < size / v.RELATIVE_LENGTH:
                raise SpecError(f"must be apart from the first crankshaft's axis by more than "
                                f"{v.RELATIVE_LENGTH * size:.3g} m and less than "
                                f"{size / v.RELATIVE_LENGTH:.3g} m (the engine's size, "
                                f"{size:.3g} m, over and times {1 / v.RELATIVE_LENGTH:.3g})",
                                key=f"{v.item('crankshafts', j)}.at", value=list(g.at))
        v.store(self, "crankshafts", geared)
        for i, c in enumerate(cylinders):
            if c.crankshaft > 1 + len(geared):
                raise SpecError(f"names no crankshaft: there are {1 + len(geared)} (1 the "
                                "first, 2 and on those of [[crankshafts]])",
                                key=f"{v.item('mechanism.cylinders', i)}.crankshaft",
                                value=c.crankshaft)
        strokes = v.number(self.strokes, "mechanism.strokes")
        if strokes not in (2, 4):
            raise SpecError("must be 4 or 2", key="mechanism.strokes", value=self.strokes)
        v.store(self, "strokes", int(strokes))
        n = len(cylinders)
        if self.firing_order is not None:
            order = tuple(self.firing_order)
            if (sorted(x for x in order if isinstance(x, int) and not isinstance(x, bool))
                    != list(range(1, n + 1))):
                raise SpecError(f"must be a permutation of the cylinders 1 … {n}",
                                key="mechanism.firing_order", value=list(order))
            v.store(self, "firing_order", order)
        if self.gas is not None:
            if not isinstance(self.gas, GasCycle):
                raise SpecError("must be a GasCycle", key="gas", value=self.gas)
            if self.firing_order is None:
                raise SpecError("an engine with gas needs its firing order",
                                key="mechanism.firing_order")
            for i, c in enumerate(cylinders):
                if c.bore is None:
                    raise SpecError("an engine with gas needs each cylinder's bore",
                                    key=f"{v.item('mechanism.cylinders', i)}.bore", value=c.bore)
            angles = self.gas.crank_angle_deg
            if angles[0] < 0 or angles[-1] >= 180 * self.strokes or any(
                    b <= a for a, b in zip(angles, angles[1:], strict=False)):
                raise SpecError(
                    f"crank angles must increase within one working cycle "
                    f"({180 * self.strokes}°), from 0", key="gas.crank_angle_deg",
                    value=list(angles))
            self.firing_angles()  # (checks that the order fits in the cycle)
        v.store(self, "main_bearings",
                _bearings(self.main_bearings, "mechanism.main_bearings"))

    # -- its crankshafts ---------------------------------------------------------------------

    def shaft_ratio(self, shaft: int) -> int:
        """Crankshaft ``shaft``'s speed over the first's (1 for the first)."""
        return 1 if shaft == 1 else self.crankshafts[shaft - 2].ratio

    def shaft_axis(self, shaft: int) -> complex:
        """Crankshaft ``shaft``'s axis, ``x + i·y``, m (the origin for the first)."""
        return 0j if shaft == 1 else complex(*self.crankshafts[shaft - 2].at)

    def shaft_bearings(self, shaft: int) -> tuple[float, ...]:
        """Crankshaft ``shaft``'s main bearings' planes, m (none: not placed)."""
        return (self.main_bearings if shaft == 1
                else self.crankshafts[shaft - 2].main_bearings)

    def shaft_masses(self, shaft: int) -> tuple[Mass, ...]:
        """The masses crankshaft ``shaft`` carries."""
        return (self.crankshaft.masses if shaft == 1
                else self.crankshafts[shaft - 2].masses)

    @property
    def shafts(self) -> tuple[int, ...]:
        """The crankshafts' numbers, 1 the first."""
        return tuple(range(1, 2 + len(self.crankshafts)))

    # -- the working cycle -------------------------------------------------------------------

    @property
    def cycle_angle(self) -> float:
        """The working cycle's crank angle: 4π for a four-stroke, 2π for a two-stroke, rad."""
        return TWO_TURNS if self.strokes == 4 else TWO_TURNS / 2

    def firing_angles(self) -> tuple[float, ...]:
        """Each cylinder's firing crank angle, rad, by cylinder (DESIGN.md).

        The first of ``firing_order`` at its first top dead centre at or after θ1 = 0, each next
        one at its own first top dead centre after the previous firing; all within one working
        cycle of the first.

        Raises
        ------
        SpecError
            Without a firing order, or one that does not fit in the working cycle.
        """
        if self.firing_order is None:
            raise SpecError("needed to place the firings", key="mechanism.firing_order")
        out = [0.0] * len(self.cylinders)
        turn = 2 * math.pi
        previous: float | None = None
        for k in self.firing_order:
            c = self.cylinders[k - 1]
            tdc = c.top_dead_centre(self.shaft_ratio(c.crankshaft))
            if previous is None:
                angle = tdc
            else:
                angle = tdc + turn * math.floor((previous - tdc) / turn)
                while angle <= previous + SAME_ANGLE:
                    angle += turn
            out[k - 1] = angle
            previous = angle
        first = out[self.firing_order[0] - 1]
        if previous is not None and previous - first >= self.cycle_angle - SAME_ANGLE:
            raise SpecError(
                f"the firings do not fit in one working cycle of "
                f"{math.degrees(self.cycle_angle):g}° (each cylinder fires at its own next top "
                f"dead centre: cylinder {self.firing_order[-1]} would fire "
                f"{math.degrees(previous - first):.6g}° after cylinder {self.firing_order[0]})",
                key="mechanism.firing_order", value=list(self.firing_order))
        return tuple(out)

    def gas_force(self, k: int) -> GasForce:
        """The gas force on cylinder ``k``'s piston (from 1) along its axis (zero without gas)."""
        if self.gas is None:
            return GasForce()
        return self.gas.force(self.cylinders[k - 1], self.firing_angles()[k - 1],
                              self.cycle_angle)

    def balance_factors(self, balanced: MechanismModel
                        ) -> tuple[tuple[Throw, ...], tuple[Throw, ...]] | None:
        """Each throw's balance before (this engine) and after (``balanced``: its redesign).

        The same throws for both: each design's counterweight planes separate the other's too.
        """
        if not isinstance(balanced, Engine):  # (a redesign is the same kind of mechanism)
            return None

        def webs(engine: Engine) -> list[tuple[int, float]]:
            return [(shaft, m.z) for shaft in engine.shafts for m in engine.shaft_masses(shaft)
                    if m.label == COUNTERWEIGHT and m.mr > 0]

        return self.throws(webs(balanced)), balanced.throws(webs(self))

    def throws(self, webs: Sequence[tuple[int, float]] = ()) -> tuple[Throw, ...]:
        """The crank throws and their balance factors (:class:`Throw`), along each crankshaft.

        Cylinders share a crank pin where they are on one crankshaft, their pins have the same
        phase and they are next to each other along it with no web between them: no plane of a
        labelled counterweight of that shaft (nor of ``webs``, ``(shaft, z)``: another
        design's counterweights, so that two designs' throws are the same) lies between their
        planes. Each of a crankshaft's masses belongs to its throw nearest the mass's plane
        (shared evenly between two at the same distance). The first crankshaft's throws first.
        """
        out: list[Throw] = []
        for shaft in self.shafts:
            on = [i for i, c in enumerate(self.cylinders) if c.crankshaft == shaft]
            if on:
                walls = [z for k, z in webs if k == shaft]
                out += shaft_throws([self.cylinders[i] for i in on], [i + 1 for i in on],
                                    self.shaft_masses(shaft), walls, self.rod, self.piston)
        return tuple(out)

    # -- what every mechanism model offers ---------------------------------------------------

    @property
    def link_names(self) -> tuple[str, ...]:
        n = len(self.cylinders)
        return ("crankshaft", *(crankshaft_name(k) for k in self.shafts[1:]),
                *(idler_name(k) for k in self.idled),
                *(f"rod{k}" for k in range(1, n + 1)), *(f"piston{k}" for k in range(1, n + 1)))

    @property
    def idled(self) -> tuple[int, ...]:
        """The geared crankshafts turned through an idler (at ratio +1)."""
        return tuple(k for k, g in zip(self.shafts[1:], self.crankshafts, strict=True)
                     if g.ratio == 1)

    @property
    def links(self) -> tuple[Link, ...]:
        """Each crankshaft (its mass on its axis, its inertia), each rod, each piston."""
        first = self.crankshaft
        shafts = (ShaftLink(mass=first.mass, inertia=first.inertia, e=0.0, f=0.0),
                  *(ShaftLink(mass=g.mass, inertia=g.inertia, e=0.0, f=0.0)
                    for g in self.crankshafts),
                  *(ShaftLink(mass=0.0, inertia=self.crankshafts[k - 2].idler_inertia, e=0.0,
                              f=0.0) for k in self.idled))
        rods = tuple(replace(self.rod, z=c.z) for c in self.cylinders)
        pistons = tuple(Link(mass=self.piston, inertia=0.0, e=0.0, f=0.0, z=c.z)
                        for c in self.cylinders)
        return (*shafts, *rods, *pistons)

    @property
    def grounded_links(self) -> tuple[str, ...]:
        return ("crankshaft", *(crankshaft_name(k) for k in self.shafts[1:]))

    @property
    def sizes(self) -> dict[str, float]:
        """The geometry's sizes by spec key, m.

        Each cylinder's crank, rod, offset and plane, each shaft's distance from the axis and
        each main bearing's plane (a plane's distance from the origin).
        """
        out: dict[str, float] = {}
        for i, c in enumerate(self.cylinders):
            key = v.item("mechanism.cylinders", i)
            out.update({f"{key}.crank": c.crank, f"{key}.rod": c.rod,
                        f"{key}.offset": abs(c.offset), f"{key}.z": abs(c.z)})
        for j, s in enumerate(self.balance_shafts):
            out[f"{v.item('balance_shafts', j)}.at"] = math.hypot(*s.at)
        for j, z in enumerate(self.main_bearings):
            out[v.item("mechanism.main_bearings", j)] = abs(z)
        for j, g in enumerate(self.crankshafts):
            out[f"{v.item('crankshafts', j)}.at"] = math.hypot(*g.at)
        return out

    @property
    def gas_forces(self) -> tuple[tuple[str, GasForce], ...]:
        return tuple(("gas", self.gas_force(k)) for k in range(1, len(self.cylinders) + 1))

    def with_links(self, links: dict[str, Link]) -> Engine:
        """A copy with crankshafts' masses and inertias replaced (``"crankshaft"``, …).

        An engine's rods and pistons are one spec for every cylinder: they are replaced through
        the fields ``rod`` and ``piston`` (``dataclasses.replace``).
        """
        names = {crankshaft_name(k): k for k in self.shafts}
        idlers = {idler_name(k): k for k in self.idled}
        unknown = set(links) - set(names) - set(idlers)
        if unknown:
            raise KeyError(sorted(unknown)[0])
        first = self.crankshaft
        geared = list(self.crankshafts)
        for name, link in links.items():
            if name in idlers:
                k = idlers[name]
                geared[k - 2] = replace(geared[k - 2], idler_inertia=link.inertia)
                continue
            k = names[name]
            if k == 1:
                first = replace(first, mass=link.mass, inertia=link.inertia)
            else:
                geared[k - 2] = replace(geared[k - 2], mass=link.mass, inertia=link.inertia)
        return replace(self, crankshaft=first, crankshafts=tuple(geared))

    def without_loads(self) -> Engine:
        """A copy without gas."""
        return replace(self, gas=None)

    # -- balancing by counterweights and shafts (model.balance.RotorBalanced) ---------------

    @property
    def counterweight_planes(self) -> tuple[float, ...]:
        """The cylinders' planes, each once, in the cylinders' order, m."""
        return tuple(dict.fromkeys(c.z for c in self.cylinders))

    def counterweights_in(self, places: Sequence[tuple[int, float]]
                          ) -> tuple[tuple[int, Mass], ...]:
        """The masses labelled ``"counterweight"`` at ``places`` (crankshaft, plane z)."""
        return tuple((k, m) for k in self.shafts for m in self.shaft_masses(k)
                     if m.label == COUNTERWEIGHT and (k, m.z) in set(places))

    def with_rotor_masses(self, counterweights: Sequence[PlacedMass],
                          shafts: Sequence[ShaftDesign],
                          replacing: Sequence[tuple[int, float]]) -> Engine:
        """The engine with new counterweights and shafts (DESIGN.md, "Balancing an engine").

        The labelled counterweights at ``replacing`` (crankshaft, plane) go; each of
        ``counterweights`` with a mass·radius is added to its crankshaft, labelled
        ``"counterweight"``; each of ``shafts`` is added after the engine's own (no inertia),
        with its eccentrics that have a mass·radius.
        """
        gone = set(self.counterweights_in(replacing))
        masses = {k: [m for m in self.shaft_masses(k) if (k, m) not in gone]
                  for k in self.shafts}
        for c in counterweights:
            if c.mr > 0:
                masses[c.crankshaft].append(Mass(mr=c.mr, phase_deg=c.phase_deg, z=c.z,
                                                 label=COUNTERWEIGHT))
        new_shafts = tuple(
            BalanceShaft(ratio=s.ratio, at=s.at, eccentrics=tuple(
                Mass(mr=e.mr, phase_deg=e.phase_deg, z=e.z) for e in s.eccentrics if e.mr > 0))
            for s in shafts)
        geared = tuple(replace(g, masses=tuple(masses[k]))
                       for k, g in zip(self.shafts[1:], self.crankshafts, strict=True))
        return replace(self, crankshaft=replace(self.crankshaft, masses=tuple(masses[1])),
                       crankshafts=geared, balance_shafts=self.balance_shafts + new_shafts)
