"""The ``[balance]`` schema: which links may change, within which bounds, and what to minimise.

A design spec's ``[balance]`` section describes it; any link of any mechanism may be listed::

    [balance]
    force_balance = true          # exact shaking-force balance as constraints
    [balance.objective]           # J = w_M·mean(Msh²) + w_τ·mean(τ²) + w_F·mean(|F̄sh|²)
    shaking_moment = 1.0          #     + w_m·(total mass − original total mass)
    driving_torque = 0.0          # w_τ, (N·m)²/(N·m)²
    shaking_force = 0.0           # w_F, (N·m)²/N² (useful only with force_balance = false)
    rocking_couple = 0.0          # w_R, of mean(|M̄rock|²) (links in several planes)
    added_mass = 0.0              # w_m, (N·m)²/kg
    [balance.crank]               # a link listed here may change; links not listed stay fixed
    mass = [2.1, 8.4]             # kg: a range, or one number that fixes the mass;
                                  #     absent: fixed at the spec's value
    com_radius = 1.0              # m: centre of mass anywhere within this distance of
                                  #     com_about; absent: the centre of mass stays where it is
    com_about = "A0"              # a point of this link; default its ground pivot if it has
                                  #     one, else its first point
    min_gyration = 0.1            # m: inertia about the centre of mass I ≥ m·ρ²
    inertia = [0.5, 2.0]          # kg·m² about the centre of mass: a range, or one number that
                                  #     fixes it (see below)
    counter_rotor = [0.0, 20.0]   # kg·m²: a range or one number (links on a ground pivot);
                                  #     absent: fixed at the spec's counter_rotor
    [balance.rocker]
    counterweight = { mass = [0.1, 3.0], radius = 0.5, gyration = 0.02 }
                                  # keep the link as it is and add one counterweight: its mass
                                  #     within [lo, hi] kg, its centre within `radius` m of
                                  #     com_about (default: the link's first point), its own
                                  #     radius of gyration at least `gyration` m (default 0)

The inertia about the centre of mass ``I`` is free (``I ≥ m·ρ²``, ``ρ`` = ``min_gyration``,
default 0) when the mass or the centre of mass may change or ``min_gyration`` is given; when the
mass and the centre of mass are fixed and ``min_gyration`` is absent it stays at the spec's
value. ``inertia`` bounds or fixes it explicitly. The objective is evaluated at ``[operation]
speed`` over ``[operation] samples`` equally spaced crank angles ``θ1 = 2π·j/N``.

**Counterweights.** A link with ``counterweight`` keeps its own body; the redesign adds one
rigid body to it, and the bounds (mass, centre in a disc about ``com_about``, least radius of
gyration) are those of that body: the same cone constraints as a free link's, on the design
vector minus the original link's entries (:attr:`LinkBounds.offset`; the original link and the
added body together are then realisable whatever the added body is). ``mass``, ``com_radius``,
``min_gyration`` and ``inertia`` describe a free link and are refused beside it.

The spec reader and writer (:mod:`balancer.spec.balance`) turn the TOML into these objects and
back; :mod:`balancer.balance` solves the problem they describe.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import ClassVar, Protocol

from .. import validate as v
from ..errors import SpecError
from ..quantities import unit_of
from .mechanisms import MechanismModel
from .parts import Part, Sector

#: Where a linkage with several inputs is force-balanced (``[balance] force``): over its whole
#: configuration space, or along its motions only.
FORCE_SCOPES = ("every-motion", "motion")

#: The least ``[balance] max_speed_fluctuation``: finer than the energy balance's root finding
#: (1e-13 of the flywheel) can tell.
LEAST_FLUCTUATION = 1e-12
#: The keys of ``[balance.objective]``, ``[balance.<link>]`` and a counterweight's table.
OBJECTIVE_KEYS = (
    "shaking_moment",
    "driving_torque",
    "shaking_force",
    "shaking_force_x",
    "shaking_force_y",
    "rocking_couple",
    "added_mass",
)

#: The keys of an engine's ``[balance.objective]`` (DESIGN.md, "Balancing an engine").
ENGINE_OBJECTIVE_KEYS = ("rocking_couple", "shaking_force", "shaking_moment", "unbalance",
                         "main_bearing_load", "largest_bearing_load")


LINK_KEYS = ("mass", "com_radius", "com_about", "min_gyration", "inertia", "counter_rotor",
              "counterweight", "com_on_line")


COUNTERWEIGHT_KEYS = ("mass", "radius", "gyration", "part")


@dataclass(frozen=True, kw_only=True)
class Objective:
    """Weights of the objective ``J`` (see the module docstring).

    ``J = w_M·mean(Msh²) + w_τ·mean(τ²) + w_F·mean(|F̄sh|²) + w_R·mean(|M̄rock|²)
    + w_m·(Σm − Σm_original)``, in (N·m)², over the sampled crank angles.

    Attributes
    ----------
    shaking_moment
        ``w_M``, dimensionless.
    driving_torque
        ``w_τ``, (N·m)²/(N·m)².
    shaking_force
        ``w_F``, (N·m)²/N² (zero at every design when force balance is imposed).
    shaking_force_x, shaking_force_y
        Weights of the shaking force's components along x and y (for a slider-crank: along
        and across the guide), (N·m)²/N²; they add to ``w_F``.
    rocking_couple
        ``w_R``, dimensionless: of the rocking couple's mean-square magnitude (links in several
        planes along the crank's axis; zero at every design of a mechanism in one plane).
    added_mass
        ``w_m``, (N·m)²/kg: penalises mass added to the linkage.
    unbalance
        ``w_U``, m²: of ``Σ (mr·ω²)²`` over an engine's chosen counterweights and eccentrics
        (``ω`` the crank's speed), the centrifugal load they put on their bearings.
    main_bearing_load
        ``w_B``, m²: of an engine's main-bearing loads' mean-square magnitude, over its bearings
        and the samples (``[mechanism] main_bearings``).
    largest_bearing_load
        ``w_L``, m²: of the square of the largest main-bearing load, ``max |R_b(θ)|`` over the
        bearings and the samples, N (the min–max objective; ``[mechanism] main_bearings``).
    """

    shaking_moment: float = 1.0
    driving_torque: float = 0.0
    shaking_force: float = 0.0
    shaking_force_x: float = 0.0
    shaking_force_y: float = 0.0
    rocking_couple: float = 0.0
    added_mass: float = 0.0
    unbalance: float = 0.0
    main_bearing_load: float = 0.0
    largest_bearing_load: float = 0.0

    @property
    def terms(self) -> tuple[ObjectiveTerm, ...]:
        """The quantities ``J`` weighs, each once, with their weights (non-zero ones only).

        The shaking force's components weighted alike are the shaking force (its mean-square
        magnitude); weighted apart, each component is a term of its own.
        """
        fx = self.shaking_force + self.shaking_force_x
        fy = self.shaking_force + self.shaking_force_y
        forces = ([("shaking_force", fx)] if fx == fy else
                  [("shaking_force_x", fx), ("shaking_force_y", fy)])
        weights = [("shaking_moment", self.shaking_moment),
                   ("driving_torque", self.driving_torque), *forces,
                   ("rocking_couple", self.rocking_couple), ("added_mass", self.added_mass),
                   ("unbalance", self.unbalance), ("main_bearing_load", self.main_bearing_load),
                   ("largest_bearing_load", self.largest_bearing_load)]
        return tuple(ObjectiveTerm(name, weight, unit_of(name)) for name, weight in weights
                     if weight > 0)

    @property
    def single(self) -> ObjectiveTerm | None:
        """The one mean-square quantity ``J`` weighs (``J = w·mean(q²)``), or ``None``."""
        terms = self.terms
        if len(terms) == 1 and terms[0].name not in ("added_mass", "unbalance"):
            return terms[0]
        return None


@dataclass(frozen=True)
class ObjectiveTerm:
    """One quantity of the objective: its JSON name, weight and unit.

    ``added_mass`` enters ``J`` as ``w·Δm`` (``w`` in (N·m)²/kg); every other term as
    ``w·mean(q²)`` over the cycle, ``q`` in ``unit`` (``w`` in (N·m)²/unit²).
    """

    name: str
    weight: float
    unit: str


@dataclass(frozen=True, kw_only=True)
class CounterweightFreedom:
    """The one counterweight a kept link may get (``[balance.<link>] counterweight``).

    Attributes
    ----------
    mass
        ``(low, high)``, kg (``low ≥ 0``: with ``low = 0`` none may be the answer; equal ends
        fix it).
    radius
        Its centre lies within this distance of the link's ``com_about`` point, m.
    gyration
        Least radius of gyration about its own centre, m.
    part
        The part that makes it (:mod:`balancer.model.parts`: a shape family, its room and
        material), or ``None``. Its room narrows the bounds above to what the part can be
        (:func:`balancer.parts.sizing.counterweight_bounds`).
    """

    mass: tuple[float, float]
    radius: float
    gyration: float = 0.0
    part: Part | None = None


@dataclass(frozen=True, kw_only=True)
class LinkFreedom:
    """What may change on one link, as written in ``[balance.<link>]``.

    Attributes
    ----------
    mass
        ``(low, high)`` mass range, kg (equal ends fix the mass); ``None``: fixed at the spec's.
    com_radius
        The centre of mass may lie anywhere within this distance of ``com_about``, m;
        ``None``: the centre of mass stays where the spec has it.
    com_about
        Point of this link the radius is measured from (``None``: its ground pivot if it has
        one, else its first point).
    min_gyration
        Least radius of gyration about the centre of mass ``ρ`` (``I ≥ m·ρ²``), m.
    inertia
        ``(low, high)`` range of the inertia about the centre of mass, kg·m² (equal ends fix
        it); ``None``: the default rule of the module docstring.
    counter_rotor
        ``(low, high)`` range of the counter-rotor inertia, kg·m² (links on a ground pivot);
        ``None``: fixed at the spec's ``counter_rotor``.
    counterweight
        The link is kept and one counterweight added (:class:`CounterweightFreedom`); then
        ``mass``, ``com_radius``, ``min_gyration`` and ``inertia`` are ``None``.
    com_on_line
        The centre of mass stays on the link's line (its frame's x-axis, through its first
        two points: ``f = 0``), within ``com_radius`` of ``com_about``.
    """

    mass: tuple[float, float] | None = None
    com_radius: float | None = None
    com_about: str | None = None
    min_gyration: float | None = None
    inertia: tuple[float, float] | None = None
    counter_rotor: tuple[float, float] | None = None
    counterweight: CounterweightFreedom | None = None
    com_on_line: bool = False


@dataclass(frozen=True, kw_only=True)
class BalanceProblem:
    """The redesign problem of a spec's ``[balance]`` section.

    Attributes
    ----------
    force_balance
        Impose exact shaking-force balance as equality constraints.
    force_scope
        A linkage with several inputs: ``"every-motion"`` (the total centre of mass still over
        the whole configuration space) or ``"motion"`` (still along each of the spec's motions
        only: fewer conditions, more freedom for the objective).
    objective
        Weights of the objective.
    links
        What may change on each listed link, by name (a dict is accepted); a link not listed
        stays as it is.
    motion_weights
        A linkage with several inputs: each named motion's weight in the objective (one not
        named weighs 1), by name (a dict is accepted).
    max_speed_fluctuation
        A one-input mechanism's: the largest ``(ω_max − ω_min)/ω_mean`` of its crank at the
        operating speed that the balanced design may have, in ``(0, 2)``; the balancing puts
        the least flywheel that keeps it on the crank (:mod:`balancer.balance.flywheel`).
        ``None``: no bound.
    """

    force_balance: bool = True
    force_scope: str = "every-motion"
    objective: Objective = field(default_factory=Objective)
    links: tuple[tuple[str, LinkFreedom], ...] = ()
    motion_weights: tuple[tuple[str, float], ...] = ()
    max_speed_fluctuation: float | None = None
    #: The figure a balancing of this kind is about, as a sweep's atlas shows it.
    headline: ClassVar[str] = "shaking_moment"

    def __post_init__(self) -> None:
        """Store ``links`` as pairs (a dict is accepted)."""
        links = self.links.items() if isinstance(self.links, dict) else self.links
        object.__setattr__(self, "links", tuple((str(n), f) for n, f in links))
        weights = (self.motion_weights.items() if isinstance(self.motion_weights, dict)
                   else self.motion_weights)
        checked = tuple((str(n), v.nonnegative(w, f"balance.motions.{n}")) for n, w in weights)
        object.__setattr__(self, "motion_weights", checked)
        if self.force_scope not in FORCE_SCOPES:
            raise SpecError(f"must be one of {', '.join(FORCE_SCOPES)}", key="balance.force",
                            value=self.force_scope)
        if self.max_speed_fluctuation is not None:
            key = "balance.max_speed_fluctuation"
            delta = v.positive(self.max_speed_fluctuation, key)
            if not LEAST_FLUCTUATION <= delta < 2:
                raise SpecError(f"must be from {LEAST_FLUCTUATION:g} to below 2: "
                                "(ω_max − ω_min)/ω_mean", key=key, value=delta)
            v.store(self, "max_speed_fluctuation", delta)

    def weights_of(self, names: Sequence[str]) -> tuple[float, ...]:
        """The weights of the motions called ``names`` (1 where none is given)."""
        given = dict(self.motion_weights)
        return tuple(given.get(name, 1.0) for name in names)

    def link(self, name: str) -> LinkFreedom | None:
        """The freedom of link ``name``, or ``None`` if it is not listed."""
        return dict(self.links).get(name)

    def with_link(self, name: str, freedom: LinkFreedom | None) -> BalanceProblem:
        """The problem with link ``name``'s freedom replaced (listed anew; ``None``: fixed)."""
        links = [(n, f) for n, f in self.links if n != name]
        if freedom is not None:
            links.append((name, freedom))
        return replace(self, links=tuple(links))

    @property
    def listed(self) -> tuple[str, ...]:
        """Names of the listed links."""
        return tuple(n for n, _ in self.links)

    def check_scales(self, speeds: dict[str, float]) -> None:
        """Check nothing: a linkage's redesign bounds no load beyond its links' own.

        (Those are checked with the mechanism; :meth:`RotorBalanceProblem.check_scales` is an
        engine's.)
        """


# -- an engine's: counterweights on its crankshaft and eccentrics of new shafts ----------------


def _planes(planes: object) -> tuple[float, ...]:
    """A non-empty list of planes (z, m), each once."""
    out = v.numbers(planes, "planes")
    if len(set(out)) != len(out):
        raise SpecError("must name each plane once", key="planes", value=list(out))
    return out


def _bounds(max_mr: object, count: int) -> tuple[float, ...]:
    """``max_mr``: one positive number for every plane, or one per plane (kg·m)."""
    if isinstance(max_mr, list | tuple):
        out = tuple(v.positive(x, "max_mr") for x in max_mr)
        if len(out) != count:
            raise SpecError(f"must be one number or one per plane ({count})", key="max_mr",
                            value=list(max_mr))
        return out
    return (v.positive(max_mr, "max_mr"),) * count


@dataclass(frozen=True)
class CounterweightPlanes:
    """Where ``optimize`` may put counterweights on the crankshaft (``[balance.counterweights]``).

    Attributes
    ----------
    planes
        Each plane's z, m (in the order given).
    max_mr
        Each plane's bound on the counterweight's mass·radius, kg·m (positive).
    radius
        The counterweights' radius, m, for their masses in the report (``None``: not given).
    part
        The crank-web sector that makes each plane's counterweight (its room and material:
        :class:`~balancer.model.parts.Sector`, about the crank's axis), or ``None``. The room
        bounds each plane's mass·radius (:func:`balancer.parts.sizing.most_mr`) and
        ``optimize`` sizes each plane's sector (:mod:`balancer.parts.planes`).
    crankshafts
        The crankshafts that carry them (1 the first; an engine's geared ones 2 and on): in
        each of these planes on each; ``None`` (the spec names none): every crankshaft.
    """

    planes: tuple[float, ...]
    max_mr: tuple[float, ...]
    radius: float | None = None
    part: Sector | None = None
    crankshafts: tuple[int, ...] | None = None

    def __post_init__(self) -> None:
        v.store(self, "planes", _planes(self.planes))
        v.store(self, "max_mr", _bounds(self.max_mr, len(self.planes)))
        if self.radius is not None:
            v.store(self, "radius", v.positive(self.radius, "radius"))
        if self.part is not None and not isinstance(self.part, Sector):
            raise SpecError('an engine\'s crankshaft counterweights are crank-web sectors: '
                            'must be "sector"', key="part.shape",
                            value=getattr(self.part, "shape", self.part))
        shafts = self.crankshafts
        if shafts is None:
            return
        if (isinstance(shafts, str) or not isinstance(shafts, tuple | list) or not shafts
                or any(isinstance(k, bool) or not isinstance(k, int) or k < 1 for k in shafts)
                or len(set(shafts)) != len(shafts)):
            raise SpecError("must be crankshafts' numbers, each once (1 the first)",
                            key="crankshafts", value=shafts)
        v.store(self, "crankshafts", tuple(shafts))


@dataclass(frozen=True)
class ShaftFreedom:
    """A new balance shaft sized by ``optimize`` (``[[balance.shafts]]``).

    Attributes
    ----------
    ratio
        Its speed over the crank's, a non-zero integer (negative: the other way).
    at
        Its axis in the x–y plane, m.
    planes
        The z of each of its eccentrics, m.
    max_mr
        Each eccentric's bound on its mass·radius, kg·m (positive).
    """

    ratio: int
    at: tuple[float, float]
    planes: tuple[float, ...]
    max_mr: tuple[float, ...]

    def __post_init__(self) -> None:
        v.store(self, "ratio", v.ratio(self.ratio, "ratio"))
        v.store(self, "at", v.vector2(self.at, "at"))
        v.store(self, "planes", _planes(self.planes))
        v.store(self, "max_mr", _bounds(self.max_mr, len(self.planes)))


@dataclass(frozen=True, kw_only=True)
class RotorBalanceProblem:
    """An engine's redesign problem: counterweights and new shafts, each mass·radius bounded.

    The loads are linear in each counterweight's and eccentric's mass·radius vector and each
    bound is a cone, so the problem is convex (:mod:`balancer.balance.sites`).

    Attributes
    ----------
    objective
        Weights of the objective (``rocking_couple``, ``shaking_force``, ``shaking_moment``,
        ``unbalance``).
    counterweights
        The crankshaft's planes, or ``None``.
    shafts
        The new shafts.
    """

    objective: Objective = field(default_factory=lambda: Objective(shaking_moment=0.0,
                                                                  rocking_couple=1.0))
    counterweights: CounterweightPlanes | None = None
    shafts: tuple[ShaftFreedom, ...] = ()
    #: The largest load any main bearing may carry over the cycle, N (``None``: no bound).
    max_bearing_load: float | None = None
    #: The figure a balancing of this kind is about, as a sweep's atlas shows it.
    headline: ClassVar[str] = "rocking_couple"

    def __post_init__(self) -> None:
        """Check the bound (key ``max_bearing_load``)."""
        if self.max_bearing_load is not None:
            v.store(self, "max_bearing_load",
                    v.positive(self.max_bearing_load, "max_bearing_load"))

    def check_scales(self, speeds: dict[str, float]) -> None:
        """Raise :class:`SpecError` if balancing could make a load beyond double precision.

        Each bound's centrifugal force ``max_mr·(k·ω)²`` and its moments about the origin (its
        plane ``z``, its axis ``|ā|``) as :func:`balancer.validate.check_magnitudes` scales,
        each named by its spec key; ``speeds`` the design's speeds by their keys, rad/s.
        """
        speed_key = max(speeds, key=lambda k: abs(speeds[k]))
        w2 = [(speed_key, speeds[speed_key])] * 2
        forces, moments = [], []
        # (table, bound, ratio, z, |ā|) of each mass·radius the optimiser may choose
        sites: list[tuple[str, float, float, float, float]] = []
        if self.counterweights is not None:
            cws = self.counterweights
            sites += [("balance.counterweights", b, 1.0, z, 0.0)
                      for b, z in zip(cws.max_mr, cws.planes, strict=True)]
        for j, shaft in enumerate(self.shafts):
            sites += [(v.item("balance.shafts", j), b, float(shaft.ratio), z,
                       math.hypot(*shaft.at))
                      for b, z in zip(shaft.max_mr, shaft.planes, strict=True)]
        for table, bound, ratio, z, arm in sites:
            force = [(f"{table}.max_mr", bound), (f"{table}.ratio", ratio),
                     (f"{table}.ratio", ratio), *w2]
            forces.append(force)
            moments += [force + [(f"{table}.planes", z)], force + [(f"{table}.at", arm)]]
        v.check_magnitudes(forces, "the balancing's forces", "N")
        v.check_magnitudes(moments, "the balancing's moments", "N·m")


@dataclass(frozen=True)
class PlacedMass:
    """A mass·radius on a rotor: its plane, size and angle at θ1 = 0 (a design's answer).

    Attributes
    ----------
    z
        Its plane, m.
    mr
        Mass times radius, kg·m (at least 0).
    phase_deg
        Its angle at θ1 = 0 from +x towards +y, degrees.
    crankshaft
        A counterweight's crankshaft: 1 the first, 2 and on an engine's geared ones.
    """

    z: float
    mr: float
    phase_deg: float
    crankshaft: int = 1


@dataclass(frozen=True)
class ShaftDesign:
    """A new balance shaft as ``optimize`` sizes it: ratio, axis and eccentrics."""

    ratio: int
    at: tuple[float, float]
    eccentrics: tuple[PlacedMass, ...]


class RotorBalanced(Protocol):
    """A mechanism model that counterweights on its crank's rotor and new shafts can balance.

    (An engine: :class:`balancer.mechanisms.engine.model.Engine`.)
    """

    @property
    def counterweight_planes(self) -> tuple[float, ...]:
        """The planes counterweights go in where the spec names none, m."""

    @property
    def shafts(self) -> tuple[int, ...]:
        """The crankshafts' numbers, 1 the first."""

    def shaft_ratio(self, shaft: int) -> int:
        """A crankshaft's speed over the first's."""

    def shaft_axis(self, shaft: int) -> complex:
        """A crankshaft's axis, ``x + i·y``, m."""

    def counterweights_in(self, places: Sequence[tuple[int, float]]
                          ) -> tuple[tuple[int, PlacedMassLike], ...]:
        """The counterweights that balancing replaces at ``places`` (crankshaft, plane)."""

    def with_rotor_masses(self, counterweights: Sequence[PlacedMass],
                          shafts: Sequence[ShaftDesign],
                          replacing: Sequence[tuple[int, float]]) -> MechanismModel:
        """The model with the counterweights at ``replacing`` replaced and the shafts added."""


class PlacedMassLike(Protocol):
    """A mass·radius at an angle in a plane (``mr`` kg·m, ``phase_deg``, ``z`` m)."""

    @property
    def mr(self) -> float:
        """Mass times radius, kg·m."""

    @property
    def phase_deg(self) -> float:
        """Angle at θ1 = 0, degrees."""

    @property
    def z(self) -> float:
        """Plane, m."""


def missing_balance(mechanism: MechanismModel) -> SpecError:
    """The error for a spec without ``[balance]`` that a verb must balance (exit code 2).

    It says what the mechanism's ``[balance]`` holds (:attr:`MechanismModel.balance_tables`):
    an engine's, where counterweights may go and which shafts there may be; a linkage's, which
    links may change.
    """
    return SpecError(f"missing required table: {mechanism.balance_tables}", key="balance")
