"""Each link's bounds as the optimisers see them: the ``[balance]`` schema resolved and checked.

A link's :class:`~balancer.model.balance.LinkFreedom` (or none: the link fixed) becomes a
:class:`LinkBounds` by the defaults of :mod:`balancer.model.balance` (:func:`resolve_link`);
:func:`check_problem` refuses a problem that contradicts itself or its mechanism, naming the key.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Any

from ..errors import SpecError
from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism
from ..model import Link
from ..model import MechanismModel as Model
from ..model.balance import OBJECTIVE_KEYS, BalanceProblem, LinkFreedom
from ..model.links import inertial_parameters
from ..parts.sizing import counterweight_bounds
from ..validate import LENGTH_RANGE


def default_about(mech: Mechanism, name: str) -> str:
    """The point a link's ``com_radius`` is measured from by default.

    Its ground pivot if it has one, else its first point.
    """
    points = next(b.points for b in mech.linkage.moving if b.name == name)
    ground = set(mech.linkage.ground.points)
    return next((p for p in points if p in ground), points[0])


def _link_is_free(b: LinkBounds) -> bool:
    """Whether anything about the link may vary (not just be set to another fixed value)."""
    return (
        b.mass[0] < b.mass[1]
        or b.com_radius is not None
        or b.inertia[0] < b.inertia[1]
        or (b.counter_rotor is not None and b.counter_rotor[0] < b.counter_rotor[1])
    )


def check_problem(problem: BalanceProblem, mechanism: Model | Mechanism) -> None:
    """Raise :class:`SpecError` on a contradictory or impossible redesign problem.

    Checks what one key alone cannot: a point that is not on the link, a counter-rotor on a
    link off the ground, a least radius of gyration that no allowed inertia meets, a zero
    objective, a problem in which nothing may change. (Whether force balance can be met within
    the bounds is the optimiser's question.)
    """
    mech = mechanism_of(mechanism)
    try:
        _checked(problem, mech)  # once per problem and mechanism: the reader and the optimiser
    except TypeError:  # unhashable: checked every time
        _check_problem(problem, mech)


@lru_cache(maxsize=256)
def _checked(problem: BalanceProblem, mech: Mechanism) -> None:
    """:func:`_check_problem`, remembered where it passed (a refusal is raised again)."""
    _check_problem(problem, mech)


def _check_problem(problem: BalanceProblem, mech: Mechanism) -> None:
    """:func:`check_problem` of a problem not yet checked on ``mech``."""
    w = problem.objective
    weights = tuple(getattr(w, name) for name in OBJECTIVE_KEYS)
    if any(x < 0 for x in weights):
        raise SpecError("weights must be zero or positive", key="balance.objective")
    if not any(weights):
        raise SpecError(
            "every weight is zero: there is nothing to minimise", key="balance.objective"
        )
    for name, x in zip(OBJECTIVE_KEYS, weights, strict=True):
        if 0 < x < sys.float_info.min:  # its square root squared is lost to underflow
            raise SpecError(f"must be zero or at least {sys.float_info.min:.3g} (a subnormal "
                            "weight is too small to compute with)",
                            key=f"balance.objective.{name}", value=x)
    bodies = {b.name: b for b in mech.linkage.moving}
    for name in problem.listed:
        if name not in bodies:
            raise SpecError(f"the {mech.model.type} has no moving link {name} (its moving "
                            f"links are {', '.join(bodies)})", key=f"balance.{name}")
    free = False
    for name in mech.linkage.link_names:
        freedom = problem.link(name)
        if freedom is None:
            continue
        key = f"balance.{name}"
        if freedom.com_about is not None:
            points = bodies[name].points
            if freedom.com_about not in points:
                raise SpecError(
                    f"must be a joint of the {name} ({' or '.join(points)})",
                    key=f"{key}.com_about",
                    value=freedom.com_about,
                )
            if freedom.com_radius is None and freedom.counterweight is None:
                raise SpecError(
                    "com_about needs com_radius (without it the centre of mass is fixed)",
                    key=f"{key}.com_about",
                    value=freedom.com_about,
                )
        if freedom.com_on_line:
            if freedom.counterweight is not None or freedom.com_radius is None:
                raise SpecError("keeps a centre of mass that may move on the link's line: give "
                                "com_radius (and no counterweight)", key=f"{key}.com_on_line",
                                value=True)
            bounds = resolve_link(mech, name, freedom)
            if abs(bounds.com_centre.imag) > freedom.com_radius:
                raise SpecError(
                    f"the disc of com_radius {freedom.com_radius:.6g} m about "
                    f"{bounds.com_about} does not reach the {name}'s line (it lies "
                    f"{abs(bounds.com_centre.imag):.6g} m off it)", key=f"{key}.com_on_line",
                    value=True)
        if freedom.counter_rotor is not None and name not in mech.linkage.grounded_links:
            where = " and the ".join(mech.linkage.grounded_links)
            raise SpecError(
                f"a counter-rotor sits on a ground pivot: only the {where} can have one",
                key=f"{key}.counter_rotor",
                value=list(freedom.counter_rotor),
            )
        if freedom.min_gyration is not None and freedom.min_gyration > LENGTH_RANGE[1]:
            raise SpecError(f"must be at most {LENGTH_RANGE[1]:g} m (m·ρ² would leave double "
                            "precision)", key=f"{key}.min_gyration", value=freedom.min_gyration)
        bounds = resolve_link(mech, name, freedom)
        _check_widths(freedom, bounds, key)
        rho = bounds.gyration
        least = bounds.mass[0] * rho * rho
        if least > bounds.inertia[1]:
            raise SpecError(
                f"needs an inertia about the centre of mass of at least m·ρ² = {least:.6g} "
                f"kg·m² at the least mass, more than the {bounds.inertia[1]:.6g} kg·m² "
                f"allowed" + (f" by {key}.inertia" if freedom.inertia is not None else ""),
                key=f"{key}.min_gyration",
                value=freedom.min_gyration,
            )
        free = free or _link_is_free(bounds)
    if not free:
        raise SpecError(
            "nothing may change: give a link a mass range, com_radius, min_gyration, an "
            "inertia range or a counter_rotor range",
            key="balance",
        )


#: Least scale of a link's parameters (kg, kg·m, kg·m²): far above the least normal double,
#: so that products and squares of scales stay normal.
LEAST_SCALE = 1e-150


#: Widest bound the optimiser is given, as a multiple of the link's own scale (its mass, its
#: length, its inertia plus ``m·l²`` for inertias). Interior-point iterates span the bounds:
#: on PB1, a mass, radius or counter-rotor bound 1e9 times the scale still solved, 1e12 lost
#: the proof of optimality and 1e15 failed. (A flywheel on a short crank has an inertia many
#: times ``m·l²``: the limit is the solver's, not a judgment of what is physical.)
BOUND_RANGE = 1e9


def _check_widths(freedom: LinkFreedom, bounds: LinkBounds, key: str) -> None:
    """Refuse a bound beyond :data:`BOUND_RANGE` times the link's scale, naming it.

    A link's mass range, too, may span at most :data:`BOUND_RANGE` (its upper end over its
    lower): the optimum may take the link to its lower end, and the balanced spec, whose link
    has that mass, must load again with the same bounds.
    """
    mass = max(bounds.original.mass, bounds.mass[0])
    length = bounds.length
    inertia = bounds.original.inertia + mass * length * length
    checks = [("mass", freedom.mass, mass, "kg", "mass"),
              ("com_radius", freedom.com_radius, length, "m", "length"),
              ("inertia", freedom.inertia, inertia, "kg·m²", "inertia scale m·l²"),
              ("counter_rotor", freedom.counter_rotor, inertia, "kg·m²",
               "inertia scale m·l²")]
    if freedom.counterweight is not None:
        checks += [("counterweight.mass", freedom.counterweight.mass, mass, "kg", "mass"),
                   ("counterweight.radius", freedom.counterweight.radius, length, "m",
                    "length")]
    for name, value, scale, unit, what in checks:
        if value is None:
            continue
        top = value[1] if isinstance(value, tuple) else value
        if top > BOUND_RANGE * scale:
            raise SpecError(
                f"must be at most {BOUND_RANGE:g} times the link's {what} "
                f"({BOUND_RANGE * scale:.6g} {unit}): a wider bound leaves the optimiser's "
                "precision", key=f"{key}.{name}", value=list(value) if isinstance(
                    value, tuple) else value)
    if freedom.mass is not None and freedom.mass[1] > BOUND_RANGE * freedom.mass[0]:
        raise SpecError(
            f"must span at most {BOUND_RANGE:g} (its upper end over its lower): the optimum may "
            "take the link to its lower end, where a wider bound leaves the optimiser's "
            "precision", key=f"{key}.mass", value=list(freedom.mass))


@dataclass(frozen=True, kw_only=True)
class LinkBounds:
    """The resolved bounds of one link (every default applied).

    Attributes
    ----------
    name
        The link's name.
    index
        Its index among the moving links.
    start
        Position of its four entries (``m``, ``m·e``, ``m·f``, ``J``) in the design vector.
    rotor
        Position of its counter-rotor's entry, or ``None`` (not pivoted to the ground).
    length
        The length that scales its parameters (its largest extent; a one-point link's: the
        input's), m.
    original
        The link as the spec has it.
    points
        Its points.
    listed
        Whether the link appears in ``[balance]``.
    mass
        ``(low, high)``, kg; ``high`` already includes the cap ``I_high/ρ²`` implied by the
        inertia bounds.
    com_fixed
        ``s̄ = e + i·f`` when the centre of mass cannot move, m; else ``None``.
    com_about
        The point the radius is measured from.
    com_centre
        Its position in the link's frame, complex, m.
    com_radius
        Radius of the disc the centre of mass must stay in, m (``None``: fixed).
    inertia
        ``(low, high)`` inertia about the centre of mass, kg·m² (``high`` may be ``inf``).
    gyration
        Least radius of gyration ``ρ``, m.
    counter_rotor
        ``(low, high)``, kg·m², or ``None`` (no counter-rotor can sit on it).
    default_about
        The point ``com_radius`` is measured from by default.
    offset
        With a counterweight: the original link's four entries ``(m, m·e, m·f, J)``, which
        the design vector's entries exceed by the counterweight's; every bound above is then
        the counterweight's (:meth:`NumericProblem.own`). ``None`` for a link that is free or
        fixed.
    on_line
        The centre of mass stays on the link's line: ``f = 0`` (``m·f`` is no variable).
    room
        The counterweight's bounds its part's room narrowed (``mass``, ``com_radius``,
        ``min_gyration``), each with the value the spec wrote (kg, m): the diagnosis then
        names the part (:meth:`room_written`).
    """

    name: str
    index: int
    start: int
    rotor: int | None
    length: float
    original: Link
    points: tuple[str, ...]
    listed: bool
    mass: tuple[float, float]
    com_fixed: complex | None
    com_about: str
    com_centre: complex
    com_radius: float | None
    inertia: tuple[float, float]
    gyration: float
    counter_rotor: tuple[float, float] | None
    default_about: str
    offset: tuple[float, float, float, float] | None = None
    on_line: bool = False
    room: tuple[tuple[str, float], ...] = ()

    @property
    def key(self) -> str:
        """Spec key of the link's table, ``balance.<name>``."""
        return f"balance.{self.name}"

    @property
    def part_key(self) -> str:
        """Spec key of its counterweight's part, ``balance.<name>.counterweight.part``."""
        return f"{self.key}.counterweight.part"

    def room_written(self, bound: str) -> float | None:
        """The value the spec wrote for ``bound`` where the part's room narrowed it, else None."""
        return dict(self.room).get(bound)

    @cached_property
    def line_span(self) -> tuple[float, float]:
        """Where on the link's line (``e``, m) the disc allows the centre of mass.

        With 8 units in the last place of the radius to spare, as :meth:`_onto_disc` keeps.
        """
        c, r = self.com_centre, self.radius * (1 - 8 * 2.0**-52)
        half = math.sqrt(max(r * r - c.imag * c.imag, 0.0))
        return c.real - half, c.real + half

    def bound_key(self, bound: str) -> str:
        """Spec key of one of its bounds (``mass``, ``com_radius``, ``min_gyration``)."""
        if self.offset is None:
            return f"{self.key}.{bound}"
        word = {"mass": "mass", "com_radius": "radius", "min_gyration": "gyration"}[bound]
        return f"{self.key}.counterweight.{word}"

    @cached_property
    def radius(self) -> float:
        """:attr:`com_radius` of a link whose centre of mass may move (no :attr:`com_fixed`), m.

        Every such link has one (a disc; :func:`resolve_link`).
        """
        assert self.com_radius is not None, "a fixed centre of mass has no disc"
        return self.com_radius

    @property
    def rotor_entry(self) -> int:
        """:attr:`rotor` of a link that has a counter-rotor entry (``rotor_links``)."""
        assert self.rotor is not None, "a link with a counter-rotor entry"
        return self.rotor

    @property
    def about(self) -> str:
        """Name of the point at :attr:`com_centre`."""
        return self.com_about

    @cached_property
    def counterweight_reach(self) -> float:
        """How far a counterweight's mass may spread from :attr:`about`, m: ``√(2R² + ρ²)``.

        Its second moment about that point is at most its mass times the square of this: as a
        body with its centre within ``R`` and its own radius of gyration within ``√(R² + ρ²)``,
        ``ρ`` its least (a bound that never binds a counterweight of the least inertia its
        gyration allows). A body of no mass has no inertia: the optimiser cannot buy a
        counter-rotor's work with a massless flywheel.
        """
        return math.sqrt(2 * self.radius**2 + self.gyration**2)

    @cached_property
    def entries(self) -> slice:
        """The link's four entries in the design vector."""
        return slice(self.start, self.start + 4)

    @cached_property
    def inertia_fixed(self) -> bool:
        """Whether the inertia about the centre of mass is fixed."""
        return self.inertia[0] == self.inertia[1]

    @cached_property
    def mass_ref(self) -> float:
        """Mass scale, kg: the link's mass.

        Where that is so small that its ``m·l²`` would fall below :data:`LEAST_SCALE` (a
        subnormal mass: valid input, as good as none, whose scales underflow to zero), its
        largest allowed mass, or what makes ``m·l²`` that least scale.
        """
        m, reach = self.original.mass, min(self.length**2, 1.0)
        if m * reach >= LEAST_SCALE:
            return m
        return max(self.mass[1], LEAST_SCALE / reach)

    @cached_property
    def inertia_ref(self) -> float:
        """Inertia scale ``m·l²``, kg·m² (with :attr:`mass_ref`)."""
        return max(self.mass_ref * self.length**2, LEAST_SCALE)


def link_length(mech: Mechanism, name: str) -> float:
    """The length that scales link ``name``'s parameters, m.

    Its largest distance between two of its points; a one-point link takes the input's.
    """
    structure = mech.structure
    k = structure.index(name)
    points = [structure.local[(k, p)] for p in next(b.points for b in mech.linkage.moving
                                                    if b.name == name)]
    extent = max((abs(a.complex() - b.complex()) for a in points for b in points), default=0.0)
    if extent > 0:
        return extent
    first = mech.linkage.inputs[0]
    return link_length(mech, first) if name != first else structure.length_scale()


def resolve_link(mech: Mechanism, name: str, freedom: LinkFreedom | None) -> LinkBounds:
    """Apply the defaults of the module docstring to one link's freedom.

    Resolved once per mechanism and freedom (the spec's reader checks what the optimiser then
    solves): the bounds are immutable.
    """
    try:
        return _resolved(mech, name, freedom)
    except TypeError:  # unhashable: resolved every time
        return _resolve_link(mech, name, freedom)


@lru_cache(maxsize=1024)
def _resolved(mech: Mechanism, name: str, freedom: LinkFreedom | None) -> LinkBounds:
    """:func:`_resolve_link`, remembered (the bounds are immutable)."""
    return _resolve_link(mech, name, freedom)


def _resolve_link(mech: Mechanism, name: str, freedom: LinkFreedom | None) -> LinkBounds:
    """:func:`resolve_link`, computed."""
    link = mech.linkage.link(name)
    layout = mech.layout
    k = mech.structure.index(name)
    points = next(b.points for b in mech.linkage.moving if b.name == name)
    rotor_entry = layout.rotor(name)
    rotor = (link.counter_rotor, link.counter_rotor) if rotor_entry is not None else None
    about_default = default_about(mech, name)
    common: dict[str, Any] = {
        "name": name, "index": k, "start": layout.index(name, "m"), "rotor": rotor_entry,
        "length": link_length(mech, name), "original": link, "points": points,
        "default_about": about_default}
    if freedom is None:
        return LinkBounds(
            **common, listed=False, mass=(link.mass, link.mass), com_fixed=link.com,
            com_about=about_default,
            com_centre=mech.structure.local[(k, about_default)].complex(), com_radius=None,
            inertia=(link.inertia, link.inertia), gyration=0.0, counter_rotor=rotor,
        )  # fmt: skip
    if rotor_entry is not None and freedom.counter_rotor is not None:
        rotor = freedom.counter_rotor
    if freedom.counterweight is not None:
        cw = freedom.counterweight
        about = freedom.com_about or points[0]
        m, me, mf, j = (float(v) for v in inertial_parameters(
            link.mass, link.com.real, link.com.imag, link.inertia))
        # A part's room narrows the bounds to what the part can be (balancer.parts.sizing).
        cw_mass, cw_radius, cw_gyration = counterweight_bounds(cw.mass, cw.radius,
                                                               cw.gyration, cw.part)
        if cw_mass[0] > cw_mass[1]:
            raise SpecError(f"the part's room holds at most {cw_mass[1]:.6g} kg, less than the "
                            "counterweight's least mass", key=f"balance.{name}.counterweight."
                            "part", value=cw.part.shape if cw.part is not None else None)
        room = tuple((bound, written) for bound, written, now in (
            ("mass", cw.mass[1], cw_mass[1]), ("com_radius", cw.radius, cw_radius),
            ("min_gyration", cw.gyration, cw_gyration)) if now != written)
        return LinkBounds(
            **common, listed=True, mass=cw_mass, com_fixed=None, com_about=about,
            com_centre=mech.structure.local[(k, about)].complex(), com_radius=cw_radius,
            inertia=(0.0, math.inf), gyration=cw_gyration, counter_rotor=rotor,
            offset=(m, me, mf, j), room=room,
        )  # fmt: skip
    mass = freedom.mass if freedom.mass is not None else (link.mass, link.mass)
    about = freedom.com_about or about_default
    centre = mech.structure.local[(k, about)].complex()
    com_fixed: complex | None = None
    radius = freedom.com_radius
    if radius is None:
        com_fixed = link.com
    elif radius == 0.0:
        com_fixed = centre
        radius = None
    rho = freedom.min_gyration or 0.0
    if freedom.inertia is not None:
        inertia = freedom.inertia
    elif mass[0] < mass[1] or freedom.com_radius is not None or freedom.min_gyration is not None:
        inertia = (0.0, math.inf)
    else:
        inertia = (link.inertia, link.inertia)
    if rho * rho > 0 and math.isfinite(inertia[1]):  # (a radius of 1e-300 squares to 0)
        mass = (mass[0], min(mass[1], inertia[1] / (rho * rho)))
    return LinkBounds(
        **common, listed=True, mass=mass, com_fixed=com_fixed, com_about=about,
        com_centre=centre, com_radius=radius, inertia=inertia, gyration=rho,
        counter_rotor=rotor, on_line=freedom.com_on_line and com_fixed is None,
    )  # fmt: skip
