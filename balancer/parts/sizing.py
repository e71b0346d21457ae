"""Dimension a part within its room so that it has the mass properties asked of it.

The optimiser asks of a counterweight a mass ``m`` (kg), a centre ``c̄`` in the link's frame (m)
and an inertia ``I`` about that centre (kg·m²); write ``k² = I/m`` (its radius of gyration,
squared). Each family of :mod:`balancer.model.parts` has a room and solves its free dimensions
(closed forms, and one root of ``sin α/α`` for a sector) for:

``ring`` (inner radius ``Ri`` given)
    ``I = m·(Ro² + Ri²)/2`` gives ``Ro = √(2k² − Ri²)``; ``m = ρ·t·π·(Ro² − Ri²)`` gives ``t``.
``washers`` (one washer of mass ``m_w``)
    The count ``n = round(m/m_w)`` (at least 1, as many as the room holds): exact only where
    ``m`` is a whole number of washers and ``k`` the washer's.
``sector`` (about the pivot, inner radius ``Ri`` given, at distance ``D = |c̄ − pivot|``)
    The polar inertia about the pivot ``I + m·D² = m·(Ro² + Ri²)/2`` gives ``Ro``; the centroid
    ``D = g(Ri, Ro)·sin α/α`` (:func:`~balancer.parts.shapes.sector_reach`) gives the half
    angle ``α`` (a root, ``sin α/α`` falling on (0, π]); ``m = ρ·t·α·(Ro² − Ri²)`` gives ``t``.
``block`` (length ``a`` given)
    ``I = m·(a² + b²)/12`` gives the width ``b = √(12k² − a²)``; ``m = ρ·t·a·b`` gives ``t``.
``insert`` (a pocket, net density ``ρ − ρ_host``)
    ``I = m·r²/2`` gives the radius ``r = √2·k``; ``m = (ρ − ρ_host)·h·π·r²`` gives the depth.

Where the solution leaves the room, the part is the **nearest** the room allows, in this
order: the mass and the centre kept (the shaking-force balance rests on them), the inertia
brought as near as the room allows (it moves the shaking moment only); where even the mass
does not fit, the largest part the room holds at that centre. :attr:`SizedPart.exact` says
whether the part meets what was asked (to :data:`EXACT` of its scale).

:func:`envelope` gives what any part of a room can be: at most a mass, at least a radius of
gyration, its centre at most some distance from the pivot. The balancing problem takes these as
bounds on the counterweight (:func:`counterweight_bounds`).
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable
from dataclasses import dataclass

from ..model.parts import Block, Insert, Part, Ring, Sector, Washers
from .shapes import (
    AnnularSector,
    Annulus,
    MassProperties,
    Profile,
    Rectangle,
    sector_reach,
    sinc,
)

#: A part meets its target when its mass, centre and inertia agree to this share of their
#: scales (the mass; the part's reach from the pivot and its radius of gyration; its inertia
#: about the pivot).
EXACT = 1e-9


@dataclass(frozen=True, kw_only=True)
class SizedPart:
    """A part dimensioned within its room.

    Attributes
    ----------
    room
        The family and room it was sized in (:data:`balancer.model.parts.Part`).
    profile
        Its dimensions (:data:`~balancer.parts.shapes.Profile`, m), in the link's frame;
        ``None`` where no part of the room can be made (:attr:`note` says why).
    density
        The density its profile is made of, kg/m³ (an insert's: net of the pocket's material).
    count
        A washer stack's number of washers (``None`` for the other families).
    target
        What the optimiser asked of the counterweight.
    made
        The part's own mass properties (``target``'s where it is exact; ``None`` with no part).
    exact
        Whether ``made`` equals ``target`` to :data:`EXACT`.
    limits
        The room's keys whose limits the part stands at, where it is not exact (``thickness``,
        ``outer_radius``, …).
    note
        Why there is no part, or nothing.
    """

    room: Part
    profile: Profile | None
    density: float
    target: MassProperties
    made: MassProperties | None
    exact: bool
    count: int | None = None
    limits: tuple[str, ...] = ()
    note: str = ""


@dataclass(frozen=True)
class Envelope:
    """What any part of a room can be.

    Attributes
    ----------
    mass
        Its largest mass, kg (``inf``: no limit).
    gyration
        Its least radius of gyration about its centre, m.
    reach
        Its centre's largest distance from the pivot, m (``inf``: no limit; a sector's only).
    """

    mass: float
    gyration: float
    reach: float = math.inf


def washer_mass(room: Washers) -> float:
    """One washer's mass, ``ρ·h·π·(d2² − d1²)/4``, kg."""
    d1, d2, h = room.washer
    return room.material.density * h * math.pi * (d2 * d2 - d1 * d1) / 4


def envelope(room: Part) -> Envelope:
    """The largest mass, least radius of gyration and largest reach of a part of ``room``.

    ``ring``: ``ρ·T·π·(Ro² − Ri²)``; gyration ``Ri`` (``k² = (Ro² + Ri²)/2 > Ri²``).
    ``washers``: as many as fit ``T``; gyration a washer's, ``√((d1² + d2²)/8)``.
    ``sector``: ``ρ·T·(φ/2)·(Ro² − Ri²)``; reach ``g(Ri, Ro)`` (a thin sector's).
    ``block``: ``ρ·T·a·b``; gyration ``a/√12``. ``insert``: ``(ρ − ρ_host)·T·π·r²``.
    """
    if isinstance(room, Ring):
        rho, ri = room.material.density, room.inner_radius
        return Envelope(rho * room.thickness * math.pi * (room.outer_radius**2 - ri * ri), ri)
    if isinstance(room, Washers):
        d1, d2, h = room.washer
        return Envelope(_most_washers(room) * washer_mass(room), math.sqrt((d1**2 + d2**2) / 8))
    if isinstance(room, Sector):
        rho, ri, ro = room.material.density, room.inner_radius, room.outer_radius
        return Envelope(rho * room.thickness * room.angle / 2 * (ro * ro - ri * ri), 0.0,
                        sector_reach(ri, ro))
    if isinstance(room, Block):
        return Envelope(room.material.density * room.thickness * room.length * room.width,
                        room.length / math.sqrt(12))
    return Envelope(room.net_density * room.thickness * math.pi * room.radius**2, 0.0)


def counterweight_bounds(mass: tuple[float, float], radius: float, gyration: float,
                         room: Part | None) -> tuple[tuple[float, float], float, float]:
    """A counterweight's bounds ``(mass, radius, gyration)`` narrowed to what ``room`` holds.

    The mass's upper bound at most the room's largest mass, the radius (of the centre from
    the pivot) at most the room's reach, the least gyration at least the room's. A sector's
    reach is that of its heaviest part at the full outer radius and thickness,
    ``g(Ri, Ro)·sin a/a`` with ``a = m_max/(ρ·T·(Ro² − Ri²))``: every lighter part with its
    centre within it has a sector of that radius and no thicker than ``T``. (The lower bound
    of the mass may then exceed its upper bound: the caller says so.)
    """
    if room is None:
        return mass, radius, gyration
    env = envelope(room)
    most = min(mass[1], env.mass)
    reach = env.reach
    if isinstance(room, Sector) and most > 0:
        # The heaviest part's least half angle (at the full radius and thickness) bounds the
        # reach of every lighter one: each then has a sector of ``Ro`` and at most ``T``.
        ri, ro = room.inner_radius, room.outer_radius
        least = most / (room.material.density * room.thickness * (ro * ro - ri * ri))
        reach = sector_reach(ri, ro) * sinc(min(least, room.angle / 2))
    return (mass[0], most), min(radius, reach), max(gyration, env.gyration)


def _most_washers(room: Washers) -> int:
    """How many washers the room's thickness holds.

    (``inf`` thickness: no limit, as a count far above any stack.)
    """
    h = room.washer[2]
    if math.isinf(room.thickness):
        return 10**9
    return max(1, math.floor(room.thickness / h * (1 + 1e-12)))


def _meets(made: MassProperties, target: MassProperties, pivot: complex) -> bool:
    """Whether ``made`` equals ``target`` to :data:`EXACT` of their scales."""
    m = target.mass
    reach = max(abs(target.centre - pivot), math.sqrt(max(target.inertia, 0.0) / m))
    polar = target.inertia + m * abs(target.centre - pivot) ** 2
    return (abs(made.mass - m) <= EXACT * m
            and abs(made.centre - target.centre) <= EXACT * max(reach, 1e-300)
            and abs(made.inertia - target.inertia) <= EXACT * max(polar, 1e-300))


def size_part(room: Part, target: MassProperties, pivot: complex = 0j) -> SizedPart:
    """The part of ``room`` nearest to ``target`` (module docstring).

    Parameters
    ----------
    room
        The family and its room.
    target
        The counterweight's mass (kg, positive), centre in the link's frame (m) and inertia
        about it (kg·m², at least 0).
    pivot
        The point a sector's arcs are centred on (the link's ``com_about``), m in the link's
        frame; the other families ignore it.
    """
    if not (target.mass > 0 and target.inertia >= 0):
        raise ValueError(f"a part is a body: mass {target.mass!r} kg must be positive and "
                         f"inertia {target.inertia!r} kg·m² at least 0")
    count = None
    profile: Profile | None
    if isinstance(room, Ring):
        profile, density, limits = _ring(room, target)
    elif isinstance(room, Washers):
        profile, density, limits, count = _washers(room, target)
    elif isinstance(room, Sector):
        profile, density, limits = _sector(room, target, pivot)
    elif isinstance(room, Block):
        profile, density, limits = _block(room, target)
    else:
        profile, density, limits = _insert(room, target)
    if profile is None:
        return SizedPart(room=room, profile=None, density=density, target=target, made=None,
                         exact=False, count=count, limits=limits,
                         note="no part of finite thickness has so little inertia: give the "
                              "room a thickness or the counterweight a gyration")
    made = profile.mass_properties(density)
    exact = _meets(made, target, pivot)
    return SizedPart(room=room, profile=profile, density=density, target=target, made=made,
                     exact=exact, count=count, limits=() if exact else limits)


def _annulus(centre: complex, density: float, ri: float, most: float, thickness: float,
             target: MassProperties) -> tuple[Annulus | None, tuple[str, ...]]:
    """An annulus of inner radius ``ri`` about ``centre`` for ``target``, and its limits.

    Its outer radius (at most ``most``) and thickness (at most ``thickness``) for ``target``
    (module docstring); the room's limits it stands at.
    """
    m, k2 = target.mass, target.inertia / target.mass
    want = 2 * k2 - ri * ri  # Ro² for the inertia
    lo = ri * ri + m / (density * math.pi * thickness)  # thinnest at the thickness limit
    hi = most * most
    if lo > hi:  # not even the mass fits: the whole room
        return Annulus(centre=centre, inner=ri, outer=most, thickness=thickness), (
            "outer_radius", "thickness")
    ro2 = min(max(want, lo), hi)
    if ro2 <= ri * ri:  # no thickness limit and too little inertia
        return None, ()
    limits = ("thickness",) if want < lo else ("outer_radius",) if want > hi else ()
    t = m / (density * math.pi * (ro2 - ri * ri))
    return Annulus(centre=centre, inner=ri, outer=math.sqrt(ro2), thickness=t), limits


def _ring(room: Ring, target: MassProperties
          ) -> tuple[Annulus | None, float, tuple[str, ...]]:
    rho = room.material.density
    profile, limits = _annulus(target.centre, rho, room.inner_radius, room.outer_radius,
                               room.thickness, target)
    return profile, rho, limits


def _insert(room: Insert, target: MassProperties
            ) -> tuple[Annulus | None, float, tuple[str, ...]]:
    rho = room.net_density
    profile, limits = _annulus(target.centre, rho, 0.0, room.radius, room.thickness, target)
    return profile, rho, tuple("radius" if k == "outer_radius" else k for k in limits)


def _washers(room: Washers, target: MassProperties
             ) -> tuple[Annulus, float, tuple[str, ...], int]:
    d1, d2, h = room.washer
    most = _most_washers(room)
    n = min(max(round(target.mass / washer_mass(room)), 1), most)
    limits = ("size", "thickness") if n == most else ("size",)
    return (Annulus(centre=target.centre, inner=d1 / 2, outer=d2 / 2, thickness=n * h),
            room.material.density, limits, n)


def _block(room: Block, target: MassProperties
           ) -> tuple[Rectangle | None, float, tuple[str, ...]]:
    rho, a = room.material.density, room.length
    m, k2 = target.mass, target.inertia / target.mass
    want = math.sqrt(max(12 * k2 - a * a, 0.0))
    lo, hi = m / (rho * a * room.thickness), room.width
    if lo > hi:
        return Rectangle(centre=target.centre, length=a, width=hi, direction=0.0,
                         thickness=room.thickness), rho, ("width", "thickness")
    b = min(max(want, lo), hi)
    if b <= 0:
        return None, rho, ()
    limits = ("thickness", "length") if want < lo else ("width",) if want > hi else ()
    return Rectangle(centre=target.centre, length=a, width=b, direction=0.0,
                     thickness=m / (rho * a * b)), rho, limits


def half_angle(ratio: float) -> float:
    """``α`` in (0, π] with ``sin α/α = ratio`` (for ``ratio`` in [0, 1)), rad."""
    if not 0 <= ratio < 1:
        raise ValueError(f"sin α/α = {ratio!r} has no root in (0, π]")
    if ratio <= sinc(math.pi):  # 0, or below sin π/π's rounding
        return math.pi
    from scipy.optimize import brentq  # here: reading a spec needs no SciPy

    # sin α/α falls from 1 to 0 on (0, π]; near 0 it is 1 − α²/6: the root is above
    # √(6·(1 − ratio))/2, where sin α/α > ratio still.
    lo = min(math.sqrt(6 * (1 - ratio)) / 2, math.pi / 2)
    while sinc(lo) <= ratio:
        lo /= 2
    return float(brentq(lambda a: sinc(a) - ratio, lo, math.pi, xtol=1e-15, rtol=1e-15))


def _sector(room: Sector, target: MassProperties, pivot: complex
            ) -> tuple[AnnularSector | None, float, tuple[str, ...]]:
    """A sector about ``pivot`` through the target's centre (module docstring).

    The outer radius ``Ro`` is the one unknown: the centroid fixes the half angle
    ``α(Ro) = (sin α/α)⁻¹(D/g(Ri, Ro))`` and the mass the thickness; ``g``, ``α`` and the
    area ``α·(Ro² − Ri²)`` grow with ``Ro``. So the room bounds ``Ro`` from below (``g > D``:
    the centroid within reach; the thickness at most ``T``: the area at least ``m/(ρ·T)``)
    and from above (``Ro`` itself; the angle at most ``φ``: ``g ≤ D/(sin(φ/2)/(φ/2))``), and
    the inertia asks for one ``Ro``, kept within those bounds.
    """
    from scipy.optimize import brentq  # here: reading a spec needs no SciPy

    rho, ri, most, t_most = (room.material.density, room.inner_radius, room.outer_radius,
                             room.thickness)
    m = target.mass
    offset = target.centre - pivot
    d = abs(offset)
    direction = cmath.phase(offset) if d > 0 else 0.0

    def g(ro: float) -> float:
        return sector_reach(ri, ro)

    def alpha(ro: float) -> float:
        reach = g(ro)
        return half_angle(min(d / reach if reach > 0 else float(d > 0), 1 - 1e-16))

    def area(ro: float) -> float:
        return alpha(ro) * (ro * ro - ri * ri)

    def root(f: Callable[[float], float], a: float, b: float) -> float:
        return float(brentq(f, a, b, xtol=1e-15 * b, rtol=1e-15))

    # From below: the centroid within reach.
    low_limit = "inner_radius"
    if g(most) <= d:
        lo = math.inf
    elif d <= ri:  # g(Ri, Ro) > Ri ≥ D for every Ro > Ri
        lo = ri
    else:
        lo = root(lambda r: g(r) - d, ri, most)
    # From above: the room, and the angle.
    whole = room.angle_deg == 360
    hi = most
    if not whole:
        cap = d / sinc(room.angle / 2)
        if ri >= cap:
            hi = -math.inf
        elif g(most) > cap:
            hi = root(lambda r: g(r) - cap, ri, most)
    # From below: the thickness.
    if math.isfinite(t_most) and lo < hi:
        need = m / (rho * t_most)
        if area(hi) < need:
            lo = math.inf
        else:
            start = max(lo, ri) + 1e-12 * most
            if area(start) < need:
                lo, low_limit = root(lambda r: area(r) - need, start, hi), "thickness"
    want2 = 2 * (target.inertia / m + d * d) - ri * ri
    want = math.sqrt(want2) if want2 > ri * ri else ri
    if lo <= hi:
        ro = min(max(want, lo), hi)
        if ro <= ri:  # no thickness limit and too little inertia
            return None, rho, ()
        a = alpha(ro)
        limits = ((low_limit,) if want < lo else ("outer_radius", "angle_deg")
                  if want > hi else ())
        # (At the thickness limit by construction; a thin sector's α, from 1 − sin α/α, is
        # known only to about ε/α², which would put it that far beyond.)
        t = min(m / (rho * a * (ro * ro - ri * ri)), t_most)
        return AnnularSector(pivot=pivot, inner=ri, outer=ro, angle=2 * a, direction=direction,
                             thickness=t), rho, limits
    # Not both the mass and the centre fit: the widest the room holds toward the centre, of
    # the mass where that fits (a centre nearer the pivot than a partial sector reaches: the
    # mass kept, the centre as near as the room lets it), else the largest the room holds.
    a = min(alpha(most), room.angle / 2) if g(most) > d else room.angle / 2
    t = min(m / (rho * a * (most * most - ri * ri)), t_most)
    at = ("outer_radius", "angle_deg", "thickness") if t == t_most else ("outer_radius",
                                                                          "angle_deg")
    return AnnularSector(pivot=pivot, inner=ri, outer=most, angle=2 * a, direction=direction,
                         thickness=t), rho, at


# -- a crank web's counterweight: a mass·radius about the crank's axis ---------------------------

def sector_mr(inner: float, outer: float, half: float, thickness: float, density: float
              ) -> float:
    """An annular sector's mass times its centroid's reach from its pivot, kg·m.

    ``m·d = ρ·t·α·(Ro² − Ri²)·g(Ri, Ro)·sin α/α = (2/3)·ρ·t·sin α·(Ro³ − Ri³)`` for the half
    angle ``α`` (rad).
    """
    return 2.0 / 3.0 * density * thickness * math.sin(half) * (outer**3 - inner**3)


def most_mr(room: Sector) -> float:
    """The largest mass·radius about its pivot of a sector of ``room``, kg·m.

    :func:`sector_mr` is largest at the full outer radius and thickness and at the half angle
    nearest π/2 the room allows, ``min(φ/2, π/2)`` (a crescent wider than a half turn puts
    material back on the other side); ``inf`` for an unlimited thickness.
    """
    return sector_mr(room.inner_radius, room.outer_radius, min(room.angle / 2, math.pi / 2),
                     room.thickness, room.material.density)


def web_target(room: Sector, mr: float, phase: float) -> MassProperties:
    """The crank-web sector a mass·radius ``mr`` (kg·m) at ``phase`` (rad) asks of ``room``.

    The lightest sector of the room with that mass·radius: the full outer radius and thickness
    (a sector's mass over its mass·radius, ``α/sin α·…``, falls as it narrows and as its radius
    and thickness grow), its half angle ``α = asin(mr/((2/3)·ρ·T·(Ro³ − Ri³)))``. Where that
    angle is beyond the room's (or the thickness unlimited), the angle is the room's best,
    ``min(φ/2, π/2)``, and the thickness is solved, beyond the room's where it cannot hold
    ``mr``. Its bisector points at ``phase``, its arcs about the crank's axis (the origin).
    Returns the sector's mass properties (:func:`size_part` then sizes it in ``room``).
    """
    if not (mr > 0 and math.isfinite(mr)):
        raise ValueError(f"a crank web's counterweight has a positive mass·radius, not {mr!r}")
    rho, ri, ro = room.material.density, room.inner_radius, room.outer_radius
    best = min(room.angle / 2, math.pi / 2)
    share = mr / sector_mr(ri, ro, math.pi / 2, room.thickness, rho)  # 0 for inf thickness
    if 0 < share <= math.sin(best):
        half, thickness = math.asin(share), room.thickness
    else:
        half, thickness = best, mr / sector_mr(ri, ro, best, 1.0, rho)
    return AnnularSector(pivot=0j, inner=ri, outer=ro, angle=2 * half, direction=phase,
                         thickness=thickness).mass_properties(rho)


def size_web(room: Sector, mr: float, phase: float) -> SizedPart:
    """The sector of ``room`` for a mass·radius ``mr`` (kg·m) at ``phase`` (rad) on a crank.

    :func:`size_part` of :func:`web_target` about the crank's axis: exact where the room holds
    ``mr`` (:func:`most_mr`), else the room's largest, nearest in direction and size.
    """
    return size_part(room, web_target(room, mr, phase), 0j)
