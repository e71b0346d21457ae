"""The redesign problem: which links may change, within which bounds, and what to minimise.

A design spec's ``[balance]`` section describes it; any link of any mechanism may be listed::

    [balance]
    force_balance = true          # exact shaking-force balance as constraints
    [balance.objective]           # J = w_M·mean(Msh²) + w_τ·mean(τ²) + w_F·mean(|F̄sh|²)
    shaking_moment = 1.0          #     + w_m·(total mass − original total mass)
    driving_torque = 0.0          # w_τ, (N·m)²/(N·m)²
    shaking_force = 0.0           # w_F, (N·m)²/N² (useful only with force_balance = false)
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

**Inertial balancing only.** With the crank at constant speed every reaction, the shaking force,
the shaking moment and the driving torque are linear in the design vector of the mechanism's
layout (:class:`balancer.linkage.dynamics.Layout`: per link ``m``, ``m·e``, ``m·f`` and ``J``
about the frame's origin, then the counter-rotors' inertias). Applied loads are not (a force at
a centre of mass that the redesign moves), so the redesign balances the **inertial** shaking;
the loads stay on the links of the balanced design as they were.

Two halves:

- the spec side, :class:`BalanceProblem` (with :class:`Objective` and one :class:`LinkFreedom`
  per listed link), read by :func:`read_balance` and written back exactly by
  :func:`balance_lines`;
- the numeric side, :class:`NumericProblem` from :func:`numeric_problem`: the regressors over
  the revolution, per-link bounds (:class:`LinkBounds`), the force-balance conditions
  (:mod:`balancer.force_balance`), the objective, and the feasibility checks that the
  optimisers and the tests rely on.

This module imports neither CVXPY nor CasADi.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .. import tomltext as toml
from ..cycle import sample_angles
from ..errors import SpecError
from ..force_balance import SMALL_ROW, force_balance_conditions
from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism
from ..model import GROUND, Design, Link
from ..validate import LENGTH_RANGE
from .lsq import bounded_lstsq

if TYPE_CHECKING:  # pragma: no cover
    from ..spec import _Table

_OBJECTIVE_KEYS = (
    "shaking_moment",
    "driving_torque",
    "shaking_force",
    "shaking_force_x",
    "shaking_force_y",
    "added_mass",
)
_LINK_KEYS = ("mass", "com_radius", "com_about", "min_gyration", "inertia", "counter_rotor",
              "counterweight", "com_on_line")
_COUNTERWEIGHT_KEYS = ("mass", "radius", "gyration")

#: Relative tolerance of :meth:`NumericProblem.violations` for a solver's design (bounds and
#: force balance): ten times Clarabel's tolerance.
FEASIBILITY_TOLERANCE = 1e-9
#: Relative residual of a force-balance condition (against the size of its terms) that a
#: balanced design must meet: rounding, with room for the conditioning of the rows.
FORCE_BALANCE_TOLERANCE = 1e-12
#: Rounding of the objective relative to the rounding of one sum (:meth:`NumericProblem.rounding`).
ROUNDING_FACTOR = 64.0
#: The share of a row's raw terms that its size is at least: their rounding over the tolerance.
_RAW_SHARE = ROUNDING_FACTOR * float(np.finfo(float).eps) / FORCE_BALANCE_TOLERANCE
#: A bound met to this (relative, :meth:`NumericProblem.violations`) is met to rounding: the
#: physical values (:meth:`NumericProblem.physical`) then meet it exactly.
ROUNDING_TOLERANCE = 1e-12
#: A counterweight whose mass may be zero (``counterweight = { mass = [0, hi], … }``) and whose
#: own mass, first moments and inertia are all within this share of the link's scales (``m``,
#: ``m·l``, ``m·l²``) is none: the link is kept as it is (:meth:`NumericProblem.absent`). An
#: interior-point solver approaches a counterweight of no mass only as the apex of its cone, with
#: a centre of mass that the ratio of two vanishing first moments puts anywhere.
ABSENT = 1e-9
#: A design whose shaking is below this share of what its inertias can produce
#: (:attr:`NumericProblem.inertial_scale`) is balanced already; the problem's scale is then
#: that share of the inertial scale, not the (vanishing) original figures.
BALANCED_SHARE = 1e-3


# ----------------------------------------------------------------------------------------------
# The spec side


@dataclass(frozen=True, kw_only=True)
class Objective:
    """Weights of the objective ``J`` (see the module docstring).

    ``J = w_M·mean(Msh²) + w_τ·mean(τ²) + w_F·mean(|F̄sh|²) + w_m·(Σm − Σm_original)``, in
    (N·m)², over the sampled crank angles.

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
    added_mass
        ``w_m``, (N·m)²/kg: penalises mass added to the linkage.
    """

    shaking_moment: float = 1.0
    driving_torque: float = 0.0
    shaking_force: float = 0.0
    shaking_force_x: float = 0.0
    shaking_force_y: float = 0.0
    added_mass: float = 0.0

    @property
    def terms(self) -> tuple[ObjectiveTerm, ...]:
        """The quantities ``J`` weighs, each once, with their weights (non-zero ones only).

        The shaking force's components weighted alike are the shaking force (its mean-square
        magnitude); weighted apart, each component is a term of its own.
        """
        fx = self.shaking_force + self.shaking_force_x
        fy = self.shaking_force + self.shaking_force_y
        forces = ([ObjectiveTerm("shaking_force", fx, "N")] if fx == fy else
                  [ObjectiveTerm("shaking_force_x", fx, "N"),
                   ObjectiveTerm("shaking_force_y", fy, "N")])
        terms = [ObjectiveTerm("shaking_moment", self.shaking_moment, "N·m"),
                 ObjectiveTerm("driving_torque", self.driving_torque, "N·m"), *forces,
                 ObjectiveTerm("added_mass", self.added_mass, "kg")]
        return tuple(t for t in terms if t.weight > 0)

    @property
    def single(self) -> ObjectiveTerm | None:
        """The one mean-square quantity ``J`` weighs (``J = w·mean(q²)``), or ``None``."""
        terms = self.terms
        if len(terms) == 1 and terms[0].name != "added_mass":
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
    """

    mass: tuple[float, float]
    radius: float
    gyration: float = 0.0


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
    objective
        Weights of the objective.
    links
        What may change on each listed link, by name (a dict is accepted); a link not listed
        stays as it is.
    """

    force_balance: bool = True
    objective: Objective = field(default_factory=Objective)
    links: tuple[tuple[str, LinkFreedom], ...] = ()

    def __post_init__(self) -> None:
        """Store ``links`` as pairs (a dict is accepted)."""
        links = self.links.items() if isinstance(self.links, dict) else self.links
        object.__setattr__(self, "links", tuple((str(n), f) for n, f in links))

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


def _check_keys(table: _Table, known: tuple[str, ...]) -> None:
    """Reject unknown keys first, with a suggestion for a typo."""
    for name in table.data:
        if name not in known:
            import difflib  # only for a spec that is wrong

            close = difflib.get_close_matches(name, known, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise SpecError(f"unknown key '{name}'{hint}", key=table.key(name))


def _read_range(
    table: _Table, name: str, *, positive: bool, unit: str
) -> tuple[float, float] | None:
    """A number (fixes the value) or a list ``[low, high]``; ``None`` if absent."""
    if not table.has(name):
        return None
    key = table.key(name)
    value = table.raw(name)
    if isinstance(value, list):
        if len(value) != 2:
            raise SpecError(
                f"must be a number or a range [low, high] in {unit}", key=key, value=value
            )
        items = value
    else:
        items = [value, value]
    bounds = []
    for item in items:
        if isinstance(item, bool) or not isinstance(item, int | float):
            raise SpecError(
                f"must be a number or a range [low, high] in {unit}", key=key, value=value
            )
        x = float(item)
        if not math.isfinite(x):
            raise SpecError("must be finite", key=key, value=value)
        if positive and x <= 0:
            raise SpecError("bounds must be positive", key=key, value=value)
        if x < 0:
            raise SpecError("bounds must be zero or positive", key=key, value=value)
        bounds.append(x)
    lo, hi = bounds
    if lo > hi:
        raise SpecError("the lower bound exceeds the upper bound", key=key, value=value)
    return (lo, hi)


def _read_link_freedom(table: _Table, points: tuple[str, ...]) -> LinkFreedom:
    _check_keys(table, _LINK_KEYS)
    com_about = None
    if table.has("com_about"):
        com_about = table.string("com_about", choices=points)
    counterweight = None
    sub = table.table("counterweight", required=False)
    if sub is not None:
        for name in ("mass", "com_radius", "min_gyration", "inertia"):
            if table.has(name):
                raise SpecError("a link with a counterweight is kept as it is: give the "
                                "counterweight's bounds only (counterweight = {mass, radius, "
                                "gyration})", key=table.key(name), value=table.raw(name))
        _check_keys(sub, _COUNTERWEIGHT_KEYS)
        mass = _read_range(sub, "mass", positive=False, unit="kg")
        if mass is None:
            raise SpecError("missing required key (the counterweight's mass, [low, high] kg)",
                            key=sub.key("mass"))
        counterweight = CounterweightFreedom(
            mass=mass, radius=sub.nonnegative("radius"),
            gyration=sub.nonnegative("gyration", default=0.0))
        if counterweight.gyration > LENGTH_RANGE[1]:
            raise SpecError(f"must be at most {LENGTH_RANGE[1]:g} m", key=sub.key("gyration"),
                            value=counterweight.gyration)
        sub.finish()
    freedom = LinkFreedom(
        mass=_read_range(table, "mass", positive=True, unit="kg"),
        com_radius=table.nonnegative("com_radius") if table.has("com_radius") else None,
        com_about=com_about,
        min_gyration=table.nonnegative("min_gyration") if table.has("min_gyration") else None,
        inertia=_read_range(table, "inertia", positive=False, unit="kg·m²"),
        counter_rotor=_read_range(table, "counter_rotor", positive=False, unit="kg·m²"),
        counterweight=counterweight,
        com_on_line=_read_flag(table, "com_on_line"),
    )
    table.finish()
    return freedom


def _read_flag(table: _Table, name: str) -> bool:
    """A ``true``/``false`` key (absent: false)."""
    if not table.has(name):
        return False
    value = table.raw(name)
    if not isinstance(value, bool):
        raise SpecError("must be true or false", key=table.key(name), value=value)
    return value


def read_balance(table: _Table, mechanism) -> BalanceProblem:
    """Read and validate a spec's ``[balance]`` table (called by :mod:`balancer.spec`).

    Parameters
    ----------
    table
        The ``[balance]`` table being read.
    mechanism
        The spec's mechanism (a model or a :class:`Mechanism`), for the links' points and the
        values of what stays fixed.

    Raises
    ------
    SpecError
        Naming the key and value at fault (see :func:`check_problem`).
    """
    mech = mechanism_of(mechanism)
    names = mech.link_names
    for name, value in table.data.items():  # a table for a link the mechanism does not have
        if isinstance(value, dict) and name not in ("objective", *names):
            import difflib  # only for a spec that is wrong

            close = difflib.get_close_matches(name, names, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise SpecError(f"names no moving link of the {mech.kind}{hint} (its moving links "
                            f"are {', '.join(names)}; the frame stays as it is)",
                            key=table.key(name))
    _check_keys(table, ("force_balance", "objective", *names))
    force_balance = True
    if table.has("force_balance"):
        value = table.raw("force_balance")
        if not isinstance(value, bool):
            raise SpecError("must be true or false", key=table.key("force_balance"), value=value)
        force_balance = value
    objective = Objective()
    sub = table.table("objective", required=False)
    if sub is not None:
        _check_keys(sub, _OBJECTIVE_KEYS)
        objective = Objective(
            **{
                name: sub.nonnegative(name, default=getattr(objective, name))
                for name in _OBJECTIVE_KEYS
            }
        )
        sub.finish()
    points = tuple(p for p, _ in mech.linkage.points)
    links: dict[str, LinkFreedom] = {}
    for name in names:
        sub = table.table(name, required=False)
        if sub is not None:
            links[name] = _read_link_freedom(sub, points)
    table.finish()
    problem = BalanceProblem(force_balance=force_balance, objective=objective, links=links)
    check_problem(problem, mech)
    return problem


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


def check_problem(problem: BalanceProblem, mechanism) -> None:
    """Raise :class:`SpecError` on a contradictory or impossible redesign problem.

    Checks what one key alone cannot: a point that is not on the link, a counter-rotor on a
    link off the ground, a least radius of gyration that no allowed inertia meets, a zero
    objective, a problem in which nothing may change. (Whether force balance can be met within
    the bounds is the optimiser's question.)
    """
    mech = mechanism_of(mechanism)
    w = problem.objective
    weights = tuple(getattr(w, name) for name in _OBJECTIVE_KEYS)
    if any(x < 0 for x in weights):
        raise SpecError("weights must be zero or positive", key="balance.objective")
    if not any(weights):
        raise SpecError(
            "every weight is zero: there is nothing to minimise", key="balance.objective"
        )
    for name, x in zip(_OBJECTIVE_KEYS, weights, strict=True):
        if 0 < x < sys.float_info.min:  # its square root squared is lost to underflow
            raise SpecError(f"must be zero or at least {sys.float_info.min:.3g} (a subnormal "
                            "weight is too small to compute with)",
                            key=f"balance.objective.{name}", value=x)
    bodies = {b.name: b for b in mech.linkage.moving}
    for name in problem.listed:
        if name not in bodies:
            raise SpecError(f"the {mech.kind} has no moving link {name} (its moving links are "
                            f"{', '.join(bodies)})", key=f"balance.{name}")
    free = False
    for name in mech.link_names:
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
        if freedom.counter_rotor is not None and name not in mech.grounded_links:
            where = " and the ".join(mech.grounded_links)
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
    """Refuse a bound beyond :data:`BOUND_RANGE` times the link's scale, naming it."""
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


def _bracketed(bounds: tuple[float, float]) -> str:
    return f"[{toml.number(bounds[0])}, {toml.number(bounds[1])}]"


def _range_text(bounds: tuple[float, float]) -> str:
    lo, hi = bounds
    return toml.number(lo) if lo == hi else f"[{toml.number(lo)}, {toml.number(hi)}]"


def balance_lines(problem: BalanceProblem) -> list[str]:
    """The problem as TOML lines that :func:`read_balance` reads back to an equal problem."""
    w = problem.objective
    lines = [
        "[balance]",
        f"force_balance = {'true' if problem.force_balance else 'false'}",
        "",
        "[balance.objective]  # J = mean(Msh²) + w_tau·mean(tau²) + w_force·mean(|Fsh|²)"
        " + w_mass·Δmass",
        f"shaking_moment = {toml.number(w.shaking_moment)}",
        f"driving_torque = {toml.number(w.driving_torque)}  # (N·m)²/(N·m)²",
        f"shaking_force = {toml.number(w.shaking_force)}  # (N·m)²/N²",
        *([f"shaking_force_x = {toml.number(w.shaking_force_x)}  # (N·m)²/N², along x",
           f"shaking_force_y = {toml.number(w.shaking_force_y)}  # (N·m)²/N², along y"]
          if w.shaking_force_x or w.shaking_force_y else []),
        f"added_mass = {toml.number(w.added_mass)}  # (N·m)²/kg",
    ]
    for name, freedom in problem.links:
        lines += ["", f"[balance.{toml.key(name)}]"]
        if freedom.mass is not None:
            lines.append(f"mass = {_range_text(freedom.mass)}  # kg")
        if freedom.com_radius is not None:
            lines.append(f"com_radius = {toml.number(freedom.com_radius)}  # m")
        if freedom.com_about is not None:
            lines.append(f"com_about = {toml.string(freedom.com_about)}")
        if freedom.min_gyration is not None:
            lines.append(f"min_gyration = {toml.number(freedom.min_gyration)}  # m")
        if freedom.inertia is not None:
            lines.append(f"inertia = {_range_text(freedom.inertia)}  # kg·m² about the COM")
        if freedom.com_on_line:
            lines.append("com_on_line = true")
        if freedom.counterweight is not None:
            cw = freedom.counterweight
            lines.append(f"counterweight = {{ mass = {_bracketed(cw.mass)}, radius = "
                         f"{toml.number(cw.radius)}, gyration = {toml.number(cw.gyration)} }}"
                         "  # kg, m, m")
        if freedom.counter_rotor is not None:
            lines.append(f"counter_rotor = {_range_text(freedom.counter_rotor)}  # kg·m²")
    return lines


# ----------------------------------------------------------------------------------------------
# The numeric side


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

    @property
    def key(self) -> str:
        """Spec key of the link's table, ``balance.<name>``."""
        return f"balance.{self.name}"

    @property
    def line_span(self) -> tuple[float, float]:
        """Where on the link's line (``e``, m) the disc allows the centre of mass.

        With 8 units in the last place of the radius to spare, as :meth:`_onto_disc` keeps.
        """
        c, r = self.com_centre, self.com_radius * (1 - 8 * 2.0**-52)
        half = math.sqrt(max(r * r - c.imag * c.imag, 0.0))
        return c.real - half, c.real + half

    def bound_key(self, bound: str) -> str:
        """Spec key of one of its bounds (``mass``, ``com_radius``, ``min_gyration``)."""
        if self.offset is None:
            return f"{self.key}.{bound}"
        word = {"mass": "mass", "com_radius": "radius", "min_gyration": "gyration"}[bound]
        return f"{self.key}.counterweight.{word}"

    @property
    def about(self) -> str:
        """Name of the point at :attr:`com_centre`."""
        return self.com_about

    @property
    def counterweight_reach(self) -> float:
        """How far a counterweight's mass may spread from :attr:`about`, m: ``√(2R² + ρ²)``.

        Its second moment about that point is at most its mass times the square of this: as a
        body with its centre within ``R`` and its own radius of gyration within ``√(R² + ρ²)``,
        ``ρ`` its least (a bound that never binds a counterweight of the least inertia its
        gyration allows). A body of no mass has no inertia: the optimiser cannot buy a
        counter-rotor's work with a massless flywheel.
        """
        return math.sqrt(2 * self.com_radius**2 + self.gyration**2)

    @property
    def entries(self) -> slice:
        """The link's four entries in the design vector."""
        return slice(self.start, self.start + 4)

    @property
    def inertia_fixed(self) -> bool:
        """Whether the inertia about the centre of mass is fixed."""
        return self.inertia[0] == self.inertia[1]

    @property
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

    @property
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
    return link_length(mech, mech.input) if name != mech.input else structure.length_scale()


def resolve_link(mech: Mechanism, name: str, freedom: LinkFreedom | None) -> LinkBounds:
    """Apply the defaults of the module docstring to one link's freedom."""
    link = mech.linkage.link(name)
    layout = mech.layout
    k = mech.structure.index(name)
    points = next(b.points for b in mech.linkage.moving if b.name == name)
    rotor_entry = layout.rotor(name)
    rotor = (link.counter_rotor, link.counter_rotor) if rotor_entry is not None else None
    about_default = default_about(mech, name)
    common = {"name": name, "index": k, "start": layout.index(name, "m"), "rotor": rotor_entry,
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
        return LinkBounds(
            **common, listed=True, mass=cw.mass, com_fixed=None, com_about=about,
            com_centre=mech.structure.local[(k, about)].complex(), com_radius=cw.radius,
            inertia=(0.0, math.inf), gyration=cw.gyration, counter_rotor=rotor,
            offset=tuple(float(v) for v in physical_to_inertial(
                link.mass, link.com.real, link.com.imag, link.inertia)),
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


def _bounded_least_squares(a, x, entries, lower, upper, original) -> NDArray[np.float64]:
    """Values of ``x[entries]`` within bounds minimising ``‖a·x‖²``, nearest ``original``.

    A light pull towards the original (1e-6 of the problem's scale) picks one among equally
    good choices.
    """
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    original = np.asarray(original, float)
    free = lower < upper
    out = original.copy()
    if not free.any():
        return out
    x = np.array(x, dtype=float)
    x[list(entries)] = original  # the fixed ones at their value, the free ones solved for
    entries = [e for e, f in zip(entries, free, strict=True) if f]
    lower, upper, original = lower[free], upper[free], original[free]
    cols = a[:, entries]
    rest = a @ x - cols @ x[entries]
    scale = np.maximum(np.abs(original), 1.0)
    weight = 1e-6 * max(float(np.linalg.norm(cols)), 1e-300)
    lhs = np.vstack([cols * scale, weight * np.eye(len(entries))])
    rhs = np.concatenate([-rest, weight * original / scale])
    sol = bounded_lstsq(lhs, rhs, lower / scale, upper / scale, tol=1e-14)
    out[free] = np.clip(sol.x * scale, lower, upper)
    return out


def physical_to_inertial(m, e, f, inertia):
    """Inertial parameters ``(m, m·e, m·f, J)`` from ``m``, ``e``, ``f``, ``I``.

    ``J = I + m·(e² + f²)`` is the inertia about the link frame's origin. Works on floats,
    numpy arrays and CasADi symbols alike (the NLP writes its objective through it).
    """
    return m, m * e, m * f, inertia + m * (e * e + f * f)


def inertial_to_physical(params) -> tuple[float, float, float, float]:
    """``(m, e, f, I)`` from inertial parameters ``(m, m·e, m·f, J)`` (inverse of the above)."""
    m, me, mf, j = (float(p) for p in params)
    e, f = me / m, mf / m
    return m, e, f, j - m * (e * e + f * f)


@dataclass(frozen=True)
class CycleRegressors:
    """The inertial shaking over a revolution as linear maps of the design vector.

    Arrays ``(N, P)``: shaking force (complex, N), shaking moment and driving torque (N·m),
    per unit of each entry.
    """

    shaking_force: NDArray[np.complex128]
    shaking_moment: NDArray[np.float64]
    driving_torque: NDArray[np.float64]


def cycle_regressors(mech: Mechanism, angles: NDArray[np.float64], omega: float,
                     alpha: float = 0.0) -> CycleRegressors:
    """Regressors at crank states ``(θ1, ω, α)``, as the cycle analysis samples them.

    At a sample exactly at a singular pose that the smooth motion passes (a four-bar's change
    points) the rows are the limits of that motion (:meth:`Mechanism.limits`).
    """
    def evaluate(theta):
        with np.errstate(all="ignore"):
            f = mech.regressors(mech.motion(theta, omega, alpha))
        return f.shaking_force.complex(), f.shaking_moment, f.driving_torque

    force, moment, torque = evaluate(angles)
    force, moment, torque = force.copy(), moment.copy(), torque.copy()
    for limit in mech.limits(angles):
        parts = [evaluate(angles[limit.mask] + d) for d in limit.offsets]
        for i, target in enumerate((force, moment, torque)):
            target[limit.mask] = sum(w * p[i] for w, p in zip(limit.weights, parts, strict=True))
    return CycleRegressors(shaking_force=force, shaking_moment=moment, driving_torque=torque)


@dataclass(frozen=True, kw_only=True)
class NumericProblem:
    """The redesign problem in numbers, built once by :func:`numeric_problem`.

    The objective is ``J(x) = ‖K·x‖² + w_m·(Σm − Σm_original)`` with ``K`` the weighted
    regressor rows (shaking moment, driving torque, shaking force) divided by ``√N``;
    :attr:`factor` ``R`` (from a QR factorisation of ``K``) has ``‖R·x‖ = ‖K·x‖`` and only as
    many rows as the design vector has entries, which is what the optimisers use.

    Attributes
    ----------
    problem
        The spec-side problem.
    mechanism
        The original design's mechanism.
    speed
        Crank speed, rad/s.
    theta1
        Sampled crank angles, rad.
    regressors
        The inertial shaking at those angles per unit entry (:class:`CycleRegressors`).
    links
        Resolved bounds of every moving link.
    x0
        Design vector of the original.
    rows
        ``K`` above, ``(rows, P)``, N·m.
    factor
        ``R`` above, upper triangular, N·m.
    force_balance
        ``(A, b)``: ``A·x = b`` is shaking-force balance
        (:func:`balancer.force_balance.force_balance_conditions`), or ``None`` when force
        balance is not imposed.
    inert
        Entries of ``x`` (inertias about the frames' origins, counter-rotors) that change
        nothing the objective measures: their regressor columns vanish (a crank's at constant
        speed: ``α1 = 0``). The optimisers leave them out; :meth:`settle` then gives them the
        value nearest the original's that the bounds allow.
    """

    problem: BalanceProblem
    mechanism: Mechanism
    speed: float
    theta1: NDArray[np.float64]
    regressors: CycleRegressors
    links: tuple[LinkBounds, ...]
    x0: NDArray[np.float64]
    rows: NDArray[np.float64]
    factor: NDArray[np.float64]
    force_balance: tuple[NDArray[np.float64], NDArray[np.float64]] | None
    inert: tuple[bool, ...]

    def with_problem(self, problem: BalanceProblem) -> NumericProblem:
        """The same design at the same operating point under another redesign problem.

        For new bounds (or other links free, another objective) without rebuilding what does
        not depend on them: the regressors, the force-balance conditions and the rows of
        :attr:`acceleration_factor` are kept; with the same objective weights also their
        reduction (:attr:`rows`, :attr:`factor`, :attr:`inert`) and the objective's scales.
        The result equals what :func:`numeric_problem` builds for the design with ``problem``
        as its ``[balance]``.

        Raises
        ------
        SpecError
            If ``problem`` is contradictory (:func:`check_problem`).
        """
        problem = _checked_problem(problem)
        mech = self.mechanism
        check_problem(problem, mech)
        links = tuple(resolve_link(mech, name, problem.link(name)) for name in mech.link_names)
        same_objective = problem.objective == self.problem.objective
        if same_objective:
            rows, factor, inert = self.rows, self.factor, self.inert
        else:
            rows, factor, inert = _reduced(self.regressors, problem.objective, links, self.size)
        fb = None
        if problem.force_balance:
            fb = self.force_balance if self.force_balance is not None else _force_balance(mech)
        new = replace(self, problem=problem, links=links, rows=rows, factor=factor,
                      force_balance=fb, inert=inert)
        kept = ["acceleration_factor", "scales", "original_mass"]
        if same_objective:
            kept += ["objective_reference", "inertial_scale", "objective_scale",
                     "original_objective"]
        if fb is not None and fb is self.force_balance:
            kept.append("_force_balance_sizes")
        for name in kept:  # cached properties that the new problem shares (made once)
            new.__dict__[name] = getattr(self, name)
        return new

    @property
    def linkage(self):
        """The original design's model."""
        return self.mechanism.model

    @property
    def size(self) -> int:
        """Number of entries of the design vector ``P``."""
        return self.x0.size

    @property
    def samples(self) -> int:
        """Number of sampled crank angles ``N``."""
        return self.theta1.size

    @property
    def weights(self) -> Objective:
        """The objective's weights."""
        return self.problem.objective

    @cached_property
    def mass_entries(self) -> list[int]:
        """Positions of the links' masses in the design vector."""
        return [b.start for b in self.links]

    @cached_property
    def offset(self) -> NDArray[np.float64]:
        """The design vector's part that no bound concerns: the kept links' own entries.

        Zero except for a link with a counterweight, whose four entries hold the original
        link's (:attr:`LinkBounds.offset`).
        """
        out = np.zeros(self.size)
        for b in self.links:
            if b.offset is not None:
                out[b.entries] = b.offset
        return out

    def own(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The entries the bounds concern: ``x`` less :attr:`offset` (a counterweight's own)."""
        return np.asarray(x, dtype=float) - self.offset

    def absent(self, b: LinkBounds, own: NDArray[np.float64] | list[float]) -> bool:
        """Whether link ``b``'s counterweight in ``own`` (:meth:`own`) is none at all.

        Only a counterweight whose mass may be zero; its own ``m``, ``m·e``, ``m·f`` and
        (unless it is :attr:`inert`, settled afterwards) ``J`` all within :data:`ABSENT` of the
        link's scales.
        """
        if b.offset is None or b.mass[0] > 0:
            return False
        k = b.start
        m, me, mf, j = (float(v) for v in own[k : k + 4])
        return (abs(m) <= ABSENT * b.mass_ref and abs(me) <= ABSENT * b.mass_ref * b.length
                and abs(mf) <= ABSENT * b.mass_ref * b.length
                and (self.inert[k + 3] or abs(j) <= ABSENT * b.inertia_ref))

    def without_absent(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                             NDArray[np.bool_]]:
        """``x`` with every counterweight that is none (:meth:`absent`) exactly none.

        Returns the design vector and the mask of the entries so set (to be kept by what
        restores Eq. 58 afterwards).
        """
        x = np.array(x, dtype=float)
        own = self.own(x)
        mask = np.zeros(self.size, dtype=bool)
        for b in self.links:
            if self.absent(b, own):
                x[b.entries] = self.offset[b.entries]
                mask[b.entries] = True
        return x, mask

    @cached_property
    def rotor_links(self) -> list[LinkBounds]:
        """The links that have a counter-rotor entry."""
        return [b for b in self.links if b.rotor is not None]

    @cached_property
    def original_mass(self) -> float:
        """Total mass of the original moving links, kg."""
        return self.linkage.total_mass

    @cached_property
    def scales(self) -> NDArray[np.float64]:
        """Typical magnitude of each entry of ``x``, for scaling the optimisers' variables.

        ``m``, ``m·l``, ``m·l``, ``m·l²`` per link (original mass); counter-rotors like their
        link's ``m·l²``.
        """
        out = np.ones(self.size)
        for b in self.links:
            m, l = b.mass_ref, b.length
            out[b.entries] = (m, m * l, m * l, m * l * l)
            if b.rotor is not None:
                out[b.rotor] = b.inertia_ref
        return out

    def total_mass(self, x: NDArray[np.float64]) -> float:
        """``Σm`` of a design vector, kg."""
        return float(np.sum(np.asarray(x)[self.mass_entries]))

    def quadratic(self, x: NDArray[np.float64]) -> float:
        """``‖K·x‖²``: the weighted mean squares, (N·m)²."""
        r = self.rows @ x
        return float(r @ r)

    def objective(self, x: NDArray[np.float64]) -> float:
        """``J(x)`` from the full regressor matrices, (N·m)² (see the module docstring)."""
        w = self.weights
        reg = self.regressors
        total = 0.0
        if w.shaking_moment:
            total += w.shaking_moment * float(np.mean((reg.shaking_moment @ x) ** 2))
        if w.driving_torque:
            total += w.driving_torque * float(np.mean((reg.driving_torque @ x) ** 2))
        if w.shaking_force or w.shaking_force_x or w.shaking_force_y:
            force = reg.shaking_force @ x
            wx = w.shaking_force + w.shaking_force_x
            wy = w.shaking_force + w.shaking_force_y
            total += wx * float(np.mean(force.real**2)) + wy * float(np.mean(force.imag**2))
        if w.added_mass:
            total += w.added_mass * (self.total_mass(x) - self.original_mass)
        return total

    def reduced_objective(self, x: NDArray[np.float64]) -> float:
        """``J(x)`` through the factor: ``‖R·x‖² + w_m·(Σm − Σm_original)``, (N·m)².

        Equal to :meth:`objective` up to rounding, at a cost independent of the number of
        sampled angles: what the solvers' inner loops compare.
        """
        r = self.factor @ x
        total = float(r @ r)
        if self.weights.added_mass:
            total += self.weights.added_mass * (self.total_mass(x) - self.original_mass)
        return total

    @cached_property
    def original_objective(self) -> float:
        """``J`` of the original design, (N·m)²."""
        return self.objective(self.x0)

    @cached_property
    def objective_reference(self) -> float:
        """A positive scale of ``J``: ``‖K·x0‖² + w_m·Σm_original``, (N·m)²."""
        value = self.quadratic(self.x0) + self.weights.added_mass * self.original_mass
        return value if value > 0 else 1.0

    @cached_property
    def inertial_scale(self) -> float:
        """The largest RMS a change of the parameters by their own scale makes, N·m.

        ``σ_max(R·diag(scales))`` (:attr:`scales`): what the links' inertias can produce, which
        does not vanish when the original design happens to be balanced.
        """
        if not self.factor.shape[0]:
            return 0.0
        return float(np.linalg.norm(self.factor * self.scales, 2))

    @cached_property
    def objective_scale(self) -> float:
        """The problem's own scale of ``√J``, N·m: the original design's ``‖K·x0‖``.

        It is the RMS of the original's weighted shaking (its RMS shaking moment for the
        default objective); for a design that is balanced already (below
        :data:`BALANCED_SHARE` of :attr:`inertial_scale`) that share of the inertial scale.
        Solvers scale their objective by it; optimality is judged against it.
        """
        value = max(math.sqrt(self.quadratic(self.x0)), BALANCED_SHARE * self.inertial_scale)
        return value if value > 0 else 1.0

    @property
    def rms_form(self) -> bool:
        """Whether ``J`` is a mean square (no mass term): then compared through ``√J``, N·m."""
        return not self.weights.added_mass

    def gap(self, objective: float, lower_bound: float) -> float:
        """The gap of ``objective`` to ``lower_bound``, relative to :attr:`objective_scale`.

        ``(√J − √J_low)/s`` for a mean-square objective (its RMS over the problem's scale, so
        that a zero optimum is judged as finely as any other), else ``(J − J_low)/s²``.
        Dimensionless.
        """
        s = self.objective_scale
        if self.rms_form:
            return (math.sqrt(max(objective, 0.0)) - math.sqrt(max(lower_bound, 0.0))) / s
        return (objective - lower_bound) / (s * s)

    def rounding(self, x: NDArray[np.float64]) -> float:
        """How much rounding can blur the objective at ``x``, in the units of :meth:`gap`.

        The weighted mean squares ``‖K·x‖`` are sums of terms as large as ``|K|·|x|``
        (entry by entry); their rounding is ε times that, and the regressors' own rounding
        (from the kinematics) about as much again: :data:`ROUNDING_FACTOR`·ε·``‖|K|·|x|‖``.
        Tiny for most designs; for links of very different masses (whose terms cancel), large
        enough that no claim of optimality finer than it can be made.
        """
        eps = np.finfo(float).eps
        blur = ROUNDING_FACTOR * eps * float(np.linalg.norm(np.abs(self.rows) @ np.abs(x)))
        s = self.objective_scale
        if self.rms_form:
            return blur / s
        root = math.sqrt(max(self.quadratic(x), 0.0))
        mass = self.weights.added_mass * ROUNDING_FACTOR * eps * self.original_mass
        return (2 * root * blur + blur * blur + mass) / (s * s)

    def within(self, a: float, b: float, rel: float) -> bool:
        """Whether objective ``a`` exceeds ``b`` by at most ``rel`` of the problem's scale.

        In the sense of :meth:`gap`.
        """
        return self.gap(a, b) <= rel

    @cached_property
    def acceleration_factor(self) -> NDArray[np.float64]:
        """Shaking moment per unit crank acceleration at rest, reduced: ``(P, P)``, N·m/(rad/s²).

        The regressors at ``(θ1, θ̇1 = 0, θ̈1 = 1)`` on the sampled angles, divided by ``√N``
        (``A``), as their triangular factor ``R`` (``‖R·x‖ = ‖A·x‖``, the root mean square of
        that shaking moment), so that settling costs the same at any number of samples. The
        objective, at constant speed, does not see what the crank's rotary inertia does when
        the speed changes; this does.
        """
        reg = cycle_regressors(self.mechanism, self.theta1, 0.0, 1.0)
        rows = reg.shaking_moment / math.sqrt(self.theta1.size)
        return np.linalg.qr(rows, mode="r")

    def settle(self, x: NDArray[np.float64], *, for_motion: bool = True) -> NDArray[np.float64]:
        """Give the :attr:`inert` entries their values.

        With ``for_motion`` false they just take the allowed value nearest the original's (all
        that a check of the objective or the constraints needs); otherwise:

        Nothing the objective or a constraint measures depends on them. An inertia about a
        centre of mass keeps the allowed value nearest the original's (a designer's crankshaft
        or flywheel is not shrunk behind their back). A counter-rotor is chosen, within its
        bounds, to minimise the mean square of the shaking moment per unit crank acceleration
        (:attr:`acceleration_factor`): what a change of crank speed (start-up, fluctuation, free
        motion) makes the frame feel; among equally good choices the one nearest the original.
        With Berkof's conditions met this gives the crank the counter-rotor that completes the
        balance for every motion.
        """
        x = np.array(x, dtype=float)
        own = self.own(x).tolist()
        offset = self.offset.tolist()
        entries, lower, upper, original = [], [], [], []
        for b in self.links:
            k = b.start
            if not self.inert[k + 3]:
                continue
            m, me, mf = own[k], own[k + 1], own[k + 2]
            if self.absent(b, own):  # no counterweight: none of its inertia either
                x[k + 3] = self.offset[k + 3]
                continue
            if not m > 0:  # nothing to settle
                continue
            q = (me * me + mf * mf) / m
            lo = max(b.inertia[0], m * b.gyration**2)
            shift = offset[k + 3]
            # A counterweight's inertia nearest its least (it has no original).
            kept = lo if b.offset is not None else min(max(b.original.inertia, lo), b.inertia[1])
            entries.append(k + 3)
            lower.append(lo + q + shift)
            upper.append(b.inertia[1] + q + shift)
            original.append(kept + q + shift)
        for b in self.rotor_links:
            if self.inert[b.rotor] and b.counter_rotor is not None:
                lo, hi = b.counter_rotor
                entries.append(b.rotor)
                lower.append(lo)
                upper.append(hi)
                original.append(min(max(b.original.counter_rotor, lo), hi))
        if not entries:
            return x
        x[entries] = original
        if not for_motion:
            return x
        a = self.acceleration_factor
        lower_a, upper_a, original_a = (np.array(v, dtype=float) for v in (lower, upper,
                                                                             original))
        rotor_entries = {b.rotor for b in self.rotor_links}
        rotors = np.array([i in rotor_entries for i in entries])
        if rotors.any():
            idx = [e for e, r in zip(entries, rotors, strict=True) if r]
            x[idx] = _bounded_least_squares(a, x, idx, lower_a[rotors], upper_a[rotors],
                                            original_a[rotors])
        return x

    def physical(self, x: NDArray[np.float64]) -> dict[str, tuple[float, float, float, float,
                                                                   float]]:
        """Each link's ``(m, e, f, I, counter-rotor)`` of design vector ``x``, in its bounds.

        ``m``, ``e = m·e/m``, ``f = m·f/m``, ``I = J − m·(e² + f²)``; an inertia within
        rounding of the original's is the original's. Each value is then put into its bounds
        exactly (:meth:`clamp`): the conversion rounds, and a designer's spec must hold what
        the problem promised. How far that moved anything is the caller's to check
        (:meth:`clamp_distance`).
        """
        out = {}
        own_x = self.own(x)
        for b in self.links:
            rotor = float(x[b.rotor]) if b.rotor is not None else 0.0
            if self.absent(b, own_x) or (b.offset is not None and b.mass[0] == 0
                                         and not own_x[b.start] > 0):
                # no counterweight (none, or no mass where none is allowed: its mass put into
                # its bounds is 0, and a body of no mass has no centre): the link as it is
                original = b.original
                out[b.name] = (original.mass, original.e, original.f, original.inertia, rotor)
                continue
            if b.offset is not None:  # the counterweight in its bounds, added to the link
                own = inertial_to_physical(x[b.entries] - self.offset[b.entries])
                m, e, f, inertia, rotor = self.clamp(b, *own, rotor)
                if (m, e, f, inertia) == own:  # in its bounds: the link's values as they are
                    out[b.name] = (*inertial_to_physical(x[b.entries]), rotor)
                    continue
                # (Through the counterweight's own values only when a bound moved it: a
                # counterweight that nearly cancels the link's first moment loses digits of
                # the sum on the way.)
                total = np.add(physical_to_inertial(m, e, f, inertia), b.offset)
                out[b.name] = (*inertial_to_physical(total), rotor)
                continue
            m, e, f, inertia = inertial_to_physical(x[b.entries])
            if abs(inertia - b.original.inertia) <= 1e-12 * b.inertia_ref:
                inertia = b.original.inertia  # only roundoff from J − m·s²
            out[b.name] = self.clamp(b, m, e, f, inertia, rotor)
        return out

    @staticmethod
    def clamp(b: LinkBounds, m: float, e: float, f: float, inertia: float,
              rotor: float) -> tuple[float, float, float, float, float]:
        """Physical values of one link put exactly into its bounds ``b``.

        Mass into its range; the centre of mass onto the disc (radially) or to its fixed
        place; the inertia into ``[max(I_low, m·ρ²), I_high]``, a counterweight's also under
        its spread (:attr:`LinkBounds.counterweight_reach`: at most ``m·(reach² − |c̄ − p|²)``);
        the counter-rotor into its range. A bound derived by arithmetic (a distance, ``m·ρ²``)
        is met with a margin of a few units in the last place, so that it holds whichever way a
        reader rounds it.
        """
        ulps = 8 * 2.0**-52
        m = min(max(m, b.mass[0]), b.mass[1])
        if b.com_fixed is not None:
            e, f = b.com_fixed.real, b.com_fixed.imag
        elif b.on_line:
            e, f = min(max(e, b.line_span[0]), b.line_span[1]), 0.0
        else:
            e, f = NumericProblem._onto_disc(b.com_centre, b.com_radius, e, f)
        least = m * b.gyration**2 * (1 + ulps)
        most = b.inertia[1]
        if b.offset is not None:  # a counterweight's spread
            spread = m * (b.counterweight_reach**2 - abs(complex(e, f) - b.com_centre) ** 2)
            most = min(most, max(spread * (1 - ulps), least))
        if least > most:
            least = most
        inertia = min(max(inertia, b.inertia[0], least), most)
        if b.counter_rotor is not None:
            rotor = min(max(rotor, b.counter_rotor[0]), b.counter_rotor[1])
        return m, e, f, inertia, rotor

    @staticmethod
    def _onto_disc(centre: complex, radius: float, e: float, f: float) -> tuple[float, float]:
        """``(e, f)`` moved radially onto the disc ``|s̄ − centre| ≤ radius`` if outside it.

        Judged on the coordinates as stored: ``centre + d`` rounds to the spacing of the
        coordinates, which for a small disc far from the frame's origin (a ``com_about`` at the
        far joint) is far coarser than the radius's last digits, so the point is pulled in by
        that spacing until the stored coordinates are inside. The bound is met with 8 units in
        the last place of the radius to spare (a reader's subtraction ``e − c`` rounds relative
        to the distance, its ``hypot`` to a unit or so). A radius below the coordinates'
        spacing leaves the centre itself.
        """
        limit = radius * (1 - 8 * 2.0**-52)
        d = complex(e, f) - centre
        if abs(d) <= limit:
            return e, f
        target = limit
        for _ in range(8):  # one pull by twice the rounding suffices; more is a safeguard
            if target <= 0:
                break
            d *= target / abs(d)
            p = centre + d
            e, f = p.real, p.imag
            if abs(complex(e, f) - centre) <= limit:
                return e, f
            target -= 2 * float(np.spacing(max(abs(e), abs(f))))
        return centre.real, centre.imag

    def clamp_distance(self, x: NDArray[np.float64]) -> float:
        """How far :meth:`physical` moved ``x`` to put it in its bounds, relative.

        The largest change of an entry over its scale (:attr:`scales`).
        """
        return float(np.max(np.abs(self.vector_of(self.physical(x)) - x) / self.scales))

    def vector_of(self, physical) -> NDArray[np.float64]:
        """The design vector of physical values (as from :meth:`physical`)."""
        x = np.zeros(self.size)
        for b in self.links:
            m, e, f, inertia, rotor = physical[b.name]
            x[b.entries] = physical_to_inertial(m, e, f, inertia)
            if b.rotor is not None:
                x[b.rotor] = rotor
        return x

    def linkage_of(self, x: NDArray[np.float64]):
        """The mechanism's model with design vector ``x`` (loads kept from the original links).

        Physical values from :meth:`physical`, in their bounds exactly.
        """
        links = {}
        values = self.physical(x)
        for b in self.links:
            m, e, f, inertia, rotor = values[b.name]
            links[b.name] = replace(
                b.original, mass=m, e=e, f=f, inertia=inertia, counter_rotor=rotor
            )
        return self.linkage.with_links(links)

    def violations(self, x: NDArray[np.float64], tol: float = FEASIBILITY_TOLERANCE) -> list[str]:
        """The constraints that ``x`` breaks by more than ``tol`` (relative), as text.

        Bounds are compared on the scale of the link (``m``, ``l``, ``m·l²``); force balance
        per condition against the size of its terms (:meth:`force_balance_rows`), at
        ``max(tol, FORCE_BALANCE_TOLERANCE)``. An empty list means ``x`` is a feasible design.
        """
        out = []
        own = self.own(x).tolist()  # Python floats: the same arithmetic, a scalar at a time
        for b in self.links:
            k = b.start
            m, me, mf, j = own[k : k + 4]
            whose = b.name if b.offset is None else f"{b.name}'s counterweight"
            if self.absent(b, own):
                continue  # none added: the link as it is
            if not m > 0:
                out.append(f"{whose}: mass {m:.6g} kg is not positive")
                continue
            l, mref, iref = b.length, b.mass_ref, b.inertia_ref
            if m < b.mass[0] - tol * mref or m > b.mass[1] + tol * mref:
                out.append(f"{b.bound_key('mass')}: {m:.9g} kg outside [{b.mass[0]:.9g}, "
                           f"{b.mass[1]:.9g}]")
            com = complex(me, mf) / m
            if b.on_line and abs(com.imag) > tol * l:
                out.append(f"{b.key}.com_on_line: centre of mass {com.imag:.3g} m off the line")
            if b.com_fixed is not None:
                if abs(com - b.com_fixed) > tol * l:
                    out.append(f"{b.name}: centre of mass moved by {abs(com - b.com_fixed):.3g} m")
            elif abs(com - b.com_centre) > b.com_radius + tol * l:
                out.append(
                    f"{b.bound_key('com_radius')}: centre of {whose} "
                    f"{abs(com - b.com_centre):.9g} m from {b.about} (at most "
                    f"{b.com_radius:.9g})"
                )
            inertia = j - (me * me + mf * mf) / m
            lo = max(b.inertia[0], m * b.gyration**2)
            if inertia < lo - tol * iref or inertia > b.inertia[1] + tol * iref:
                out.append(
                    f"{whose}: inertia {inertia:.9g} kg·m² outside [{lo:.9g}, {b.inertia[1]:.9g}]"
                )
            if b.offset is not None:  # its spread (LinkBounds.counterweight_reach)
                p = b.com_centre
                about_p = j - 2 * (p.real * me + p.imag * mf) + m * abs(p) ** 2
                if about_p > m * b.counterweight_reach**2 + tol * iref:
                    out.append(f"{whose}: second moment {about_p:.9g} kg·m² about {b.about} "
                               f"beyond m·(2R² + ρ²) = {m * b.counterweight_reach**2:.9g}")
        for b in self.rotor_links:
            value = float(x[b.rotor])
            if b.counter_rotor is None:
                if abs(value) > tol * b.inertia_ref:
                    out.append(f"{b.name}: has no counter-rotor, got {value:.6g} kg·m²")
                continue
            lo, hi = b.counter_rotor
            scale = max(b.inertia_ref, hi)
            if value < lo - tol * scale or value > hi + tol * scale:
                out.append(
                    f"{b.key}.counter_rotor: {value:.9g} kg·m² outside [{lo:.9g}, {hi:.9g}]"
                )
        residual = self.force_balance_residual(x)
        if residual > max(tol, FORCE_BALANCE_TOLERANCE):
            out.append(f"force balance: residual {residual:.3g} of its terms")
        return out

    def force_balance_residual(self, x: NDArray[np.float64]) -> float:
        """Largest residual of the force-balance conditions relative to their terms' size.

        See :meth:`force_balance_rows`. 0 when force balance is not imposed.
        """
        return float(np.max(self.force_balance_rows(x), initial=0.0))

    @cached_property
    def _force_balance_sizes(self) -> tuple[NDArray[np.float64], ...]:
        """What :meth:`force_balance_rows` needs of ``(A, b)`` alone.

        ``|A|``, the indicator ``(P, links)`` of each link's entries (a link's terms are
        combined before their magnitude is taken), each row's :data:`SMALL_ROW` floor, and
        ``|b|``.
        """
        a, rhs = self.force_balance
        by_link = np.zeros((self.size, len(self.links)))
        for j, b in enumerate(self.links):
            by_link[b.entries, j] = 1.0
        return np.abs(a), by_link, SMALL_ROW * (np.abs(a) @ self.scales), np.abs(rhs)

    def force_balance_rows(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each condition's residual relative to the size of its terms.

        ``|A_i·x − b_i| / s_i``. The size ``s_i`` is the sum over links of the magnitude of
        each link's contribution (a link's terms combined first: a heavy link whose centre of
        mass sits on its pivot contributes nothing, exactly, and must not hide a light link's
        unbalance); it is at least :data:`ROUNDING_FACTOR`·ε/:data:`FORCE_BALANCE_TOLERANCE`
        times the raw terms ``Σ_j |A_ij·x_j|`` (their rounding, which no design can beat) and
        :data:`SMALL_ROW` of the row at the parameters' scales. Under a counterweight an entry
        is the sum of the kept link's and the counterweight's (:attr:`offset`), whose rounding
        is that of both: its raw term is ``|A_ij|·(|x_j − offset_j| + |offset_j|)`` (a
        counterweight that cancels the kept link's first moment, as a slider-crank's rod
        must have ``m·f = 0``, leaves a sum of rounding).
        """
        if self.force_balance is None:
            return np.zeros(0)
        a, rhs = self.force_balance
        x = np.asarray(x, dtype=float)
        abs_a, by_link, floor, abs_rhs = self._force_balance_sizes
        offset = self.offset
        raw = abs_a @ (np.abs(x - offset) + np.abs(offset)) + abs_rhs
        combined = np.abs((a * x) @ by_link).sum(axis=1) + abs_rhs
        size = np.maximum(np.maximum(combined, _RAW_SHARE * raw), floor)
        residual = np.abs(a @ x - rhs)
        if floor.all():  # every row has a positive size
            return residual / size
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(size > 0, residual / size, residual)


def numeric_problem(design: Design) -> NumericProblem:
    """Build the numeric redesign problem of a design spec once.

    For the same design under other bounds, :meth:`NumericProblem.with_problem` reuses what
    does not depend on them.

    Raises
    ------
    SpecError
        If the spec has no ``[balance]`` or no ``[operation]`` section, or the problem is
        contradictory (see :func:`check_problem`).
    AssemblyError
        If the crank cannot turn a full revolution.
    """
    problem = _checked_problem(design.balance)
    if design.operation is None:
        raise SpecError(
            "missing required key: the balancing objective is evaluated at the operating speed",
            key="operation.speed",
        )
    mech = mechanism_of(design.mechanism)
    check_problem(problem, mech)
    mech.require_full_revolution("balancing")
    speed = design.operation.speed
    angles = sample_angles(design.operation.samples)
    reg = cycle_regressors(mech, angles, speed)
    links = tuple(resolve_link(mech, name, problem.link(name)) for name in mech.link_names)
    rows, factor, inert = _reduced(reg, problem.objective, links, mech.layout.size)
    return NumericProblem(
        problem=problem,
        mechanism=mech,
        speed=speed,
        theta1=angles,
        regressors=reg,
        links=links,
        x0=mech.parameters(),
        rows=rows,
        factor=factor,
        force_balance=_force_balance(mech) if problem.force_balance else None,
        inert=inert,
    )


def _checked_problem(problem) -> BalanceProblem:
    """``problem`` if it is a redesign problem; :class:`SpecError` if there is none."""
    if problem is None:
        raise SpecError("missing required table: the redesign problem ([balance])",
                        key="balance")
    if not isinstance(problem, BalanceProblem):
        raise TypeError(f"design.balance must be a BalanceProblem, not {type(problem).__name__}")
    return problem


def _force_balance(mech: Mechanism) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(A, b)`` of shaking-force balance.

    From :func:`~balancer.force_balance.force_balance_conditions`.
    """
    conditions = force_balance_conditions(mech)
    return conditions.matrix, np.zeros(conditions.count)


def _reduced(reg: CycleRegressors, w: Objective, links: tuple[LinkBounds, ...], p: int
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[bool, ...]]:
    """The objective's rows ``K``, their triangular factor ``R`` and the inert entries.

    ``K`` stacks the weighted regressor rows divided by ``√N`` (see :class:`NumericProblem`);
    an entry is inert where its column of ``R`` vanishes (to ``1e-12`` of the largest).
    """
    n = reg.shaking_moment.shape[0]
    blocks = []
    if w.shaking_moment:
        blocks.append(math.sqrt(w.shaking_moment) * reg.shaking_moment)
    if w.driving_torque:
        blocks.append(math.sqrt(w.driving_torque) * reg.driving_torque)
    wx, wy = w.shaking_force + w.shaking_force_x, w.shaking_force + w.shaking_force_y
    if wx:
        blocks.append(math.sqrt(wx) * reg.shaking_force.real)
    if wy:
        blocks.append(math.sqrt(wy) * reg.shaking_force.imag)
    rows = np.vstack(blocks) / math.sqrt(n) if blocks else np.zeros((0, p))
    factor = np.linalg.qr(rows, mode="r") if blocks else np.zeros((0, p))
    norms = np.linalg.norm(factor, axis=0) if blocks else np.zeros(p)
    threshold = 1e-12 * max(float(norms.max(initial=0.0)), 1e-300)
    candidates = {b.start + 3 for b in links} | {b.rotor for b in links if b.rotor is not None}
    inert = tuple(i in candidates and norms[i] <= threshold for i in range(p))
    return rows, factor, inert


__all__ = [
    "GROUND",
    "BalanceProblem",
    "CycleRegressors",
    "LinkBounds",
    "LinkFreedom",
    "NumericProblem",
    "Objective",
    "balance_lines",
    "check_problem",
    "cycle_regressors",
    "numeric_problem",
    "read_balance",
    "resolve_link",
]
