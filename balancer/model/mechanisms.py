"""What every mechanism's data offers (:class:`MechanismModel`), and the general linkage.

A mechanism's data is frozen and checks itself when made (:mod:`balancer.validate`, the same
checks as the spec loader's). The general linkage (:class:`Linkage`) is the core's: a general
linkage's points at a reference pose that fix its assembly branch (DESIGN.md, "General planar
linkages"). A mechanism given by its lengths and named links in a chain, with an assembly
branch (the four-bar, the slider-crank: :mod:`balancer.mechanisms`), shares
:class:`ChainModel`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Iterable
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any, ClassVar, Literal, Protocol, Self

from .. import validate as v
from ..errors import SpecError
from .links import GROUND, RESERVED_LINK_NAMES, Body, GasForce, Gear, Link, Slider, Spring

#: An assembly branch of a mechanism given by its lengths.
Branch = Literal["+", "-"]


class ThrowBalance(Protocol):
    """One crank throw's balance as engine designers quote it (an engine's ``Throw``)."""

    @property
    def cylinders(self) -> tuple[int, ...]: ...
    @property
    def phase_deg(self) -> float: ...
    @property
    def rotating_mr(self) -> float: ...
    @property
    def reciprocating_mr(self) -> float: ...
    @property
    def counterweight_mr(self) -> float: ...
    @property
    def factor(self) -> float: ...
    def as_dict(self) -> dict[str, object]: ...


class MechanismModel(ABC):
    """What every mechanism's data offers the rest of the package: its links and loads.

    The spec's ``mechanism.type`` is :attr:`type`; the mechanisms' registry
    (:func:`balancer.mechanisms.mechanism_of`) turns the data into the mechanism that moves.
    """

    #: The spec's ``mechanism.type``.
    type: ClassVar[str]
    #: What its spec's ``[balance]`` holds, for the error of a verb that must balance it
    #: without one (:func:`balancer.model.balance.missing_balance`).
    balance_tables: ClassVar[str] = "the redesign problem ([balance])"

    @property
    @abstractmethod
    def link_names(self) -> tuple[str, ...]:
        """Names of the moving links, in order."""

    @property
    @abstractmethod
    def links(self) -> tuple[Link, ...]:
        """Mass properties of the moving links, in order."""

    @property
    @abstractmethod
    def grounded_links(self) -> tuple[str, ...]:
        """Links pivoted to the frame (where a counter-rotor can sit)."""

    @property
    @abstractmethod
    def sizes(self) -> dict[str, float]:
        """The geometry's sizes by spec key, m (see :func:`balancer.model.check_scales`)."""

    @property
    def gas_forces(self) -> tuple[tuple[str, GasForce], ...]:
        """Forces on sliders along their guides, by spec key (none unless it has sliders)."""
        return ()

    @property
    def springs(self) -> tuple[Spring, ...]:
        """Linear springs (none unless it has some)."""
        return ()

    @property
    def cycle_revolutions(self) -> int:
        """Crank revolutions of the mechanism's cycle: 2 where a load repeats every two.

        A slider force given as a table of period 4π (a four-stroke engine's gas force); else
        1 (the motion and every other load repeat every revolution).
        """
        for _, gas in self.gas_forces:
            if not gas.is_zero and math.isclose(gas.period, 4 * math.pi, rel_tol=1e-12):
                return 2
        return 1

    @property
    def total_mass(self) -> float:
        """Mass of the moving links, kg."""
        return math.fsum(link.mass for link in self.links)

    @property
    def has_loads(self) -> bool:
        """Whether any link carries an applied force or moment, or a slider a force."""
        return (any(link.has_loads for link in self.links)
                or any(not gas.is_zero for _, gas in self.gas_forces))

    def link(self, name: str) -> Link:
        """The mass properties of the moving link called ``name``."""
        try:
            return self.links[self.link_names.index(name)]
        except ValueError:
            raise KeyError(name) from None

    def with_link(self, name: str, link: Link) -> Self:
        """Return a copy with link ``name``'s mass properties replaced."""
        return self.with_links({name: link})

    @abstractmethod
    def with_links(self, links: dict[str, Link]) -> Self:
        """Return a copy with several links' mass properties replaced."""

    @abstractmethod
    def without_loads(self) -> Self:
        """Return a copy with every applied force, moment and slider force removed."""

    def balance_factors(self, balanced: MechanismModel
                        ) -> tuple[tuple[ThrowBalance, ...], tuple[ThrowBalance, ...]] | None:
        """Each crank throw's balance before (this design) and after (``balanced``).

        ``None``: a mechanism without crank throws (an engine's are its own).
        """
        return None


class ChainModel(MechanismModel):
    """A mechanism given by its lengths, its links by name (fields of its own) and a branch.

    Subclasses are frozen dataclasses with the fields ``lengths``, ``branch`` and one
    :class:`Link` per name of :attr:`link_names`; :meth:`check_chain` checks them.
    """

    #: The spec's names of the lengths (``mechanism.lengths.<name>``), in order; a length
    #: called ``offset`` is signed and may be zero.
    length_names: ClassVar[tuple[str, ...]]
    #: The moving links' names (fields of the dataclass), in order.
    chain_links: ClassVar[tuple[str, ...]]
    #: Links pivoted to the frame.
    ground_pivoted: ClassVar[tuple[str, ...]]

    lengths: tuple[float, ...]
    branch: Branch

    @property
    def link_names(self) -> tuple[str, ...]:
        return self.chain_links

    @property
    def links(self) -> tuple[Link, ...]:
        return tuple(getattr(self, name) for name in self.chain_links)

    @property
    def grounded_links(self) -> tuple[str, ...]:
        return self.ground_pivoted

    @property
    def sizes(self) -> dict[str, float]:
        """The geometry's sizes by spec key, m: the lengths (an offset's magnitude)."""
        return {f"mechanism.lengths.{n}": abs(x)
                for n, x in zip(self.length_names, self.lengths, strict=True)}

    def with_links(self, links: dict[str, Link]) -> Self:
        unknown = set(links) - set(self.chain_links)
        if unknown:
            raise KeyError(sorted(unknown)[0])
        changes: dict[str, Any] = dict(links)
        return replace(self, **changes)  # type: ignore[type-var]  # a dataclass (see above)

    def without_loads(self) -> Self:
        changes: dict[str, Any] = {n: self.link(n).without_loads() for n in self.chain_links}
        changes.update(self.unloaded_fields())
        return replace(self, **changes)  # type: ignore[type-var]  # a dataclass (see above)

    def unloaded_fields(self) -> dict[str, Any]:
        """The fields other than the links that :meth:`without_loads` sets (a gas force)."""
        return {}

    def check_chain(self) -> tuple[float, ...]:
        """Check lengths, links and branch; store the lengths as floats and return them.

        An ``offset`` (a slider-crank's last length) is signed; every other length is
        positive. Link keys are ``links.<name>``, lengths ``mechanism.lengths.<name>``.
        """
        names = self.length_names
        raw = self.lengths
        if isinstance(raw, str) or not hasattr(raw, "__len__") or len(raw) != len(names):
            raise SpecError(f"must be {len(names)} lengths ({', '.join(names)})",
                            key="mechanism.lengths", value=raw)
        lengths: list[float] = []
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
        v.store(self, "lengths", tuple(lengths))
        v.store(self, "branch", v.choice(self.branch, "mechanism.branch", ("+", "-")))
        for name in self.chain_links:
            link = getattr(self, name)
            if not isinstance(link, Link):
                raise SpecError("must be a Link", key=f"links.{name}", value=link)
            if link.counter_rotor and name not in self.ground_pivoted:
                where = " and ".join(self.ground_pivoted)
                raise SpecError(
                    f"a counter-rotor sits on a ground pivot: only the {where} can have one",
                    key=f"links.{name}.counter_rotor", value=link.counter_rotor,
                )
        return tuple(lengths)






@dataclass(frozen=True, kw_only=True)
class Linkage(MechanismModel):
    """A planar linkage driven at one or several links, each turned about a ground pivot.

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
    inputs
        The names of the driven links, in the order of their positions in an input state
        (:class:`balancer.linkage.inputs.InputState`); each one's first point is its ground
        pivot. A one-input linkage's is its crank (:attr:`input`).
    sliders
        Prismatic pairs.
    springs
        Linear springs.
    gears
        Gear pairs: each driven link turned by its driver's gear about its own ground pivot.
    """

    type: ClassVar[str] = "linkage"

    points: tuple[tuple[str, tuple[float, float]], ...]
    bodies: tuple[Body, ...]
    inputs: tuple[str, ...]
    sliders: tuple[Slider, ...] = ()
    springs: tuple[Spring, ...] = ()
    gears: tuple[Gear, ...] = ()

    def __post_init__(self) -> None:
        """Check names and references (keys are the spec's, from its root)."""
        points: dict[str, tuple[float, float]] = {}
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
        v.store(self, "points", tuple(points.items()))
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
            v.store(body, "points", tuple(body.points))
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
                raise SpecError("must be a Spring", key=v.item("springs", i), value=spring)
            for p in spring.points:
                if p not in points:
                    raise SpecError(f"names an unknown point '{p}' (the points are "
                                    f"{', '.join(points)})", key=f"{v.item('springs', i)}.points",
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
        self._check_inputs(names, ground)
        self._check_gears(names, ground, points)
        if len(self.inputs) > 1:  # (a slider force is a table of the crank angle)
            for key, gas in self.gas_forces:
                if not gas.is_zero:
                    raise SpecError("is a table of the crank's angle: a linkage with several "
                                    "inputs has no crank", key=key,
                                    value=list(self.inputs))
        for name, body in names.items():
            if (name != GROUND and body.props is not None and body.props.counter_rotor
                    and not ground & set(body.points)):
                raise SpecError("a counter-rotor sits on a ground pivot: this link has none",
                                key=f"links.{name}.counter_rotor",
                                value=body.props.counter_rotor)
        v.store(self, "bodies", tuple(self.bodies))
        v.store(self, "sliders", tuple(self.sliders))
        v.store(self, "springs", tuple(self.springs))

    @property
    def input(self) -> str:
        """A one-input linkage's driven link (its crank); ``ValueError`` for several."""
        if len(self.inputs) != 1:
            raise ValueError(f"the linkage has {len(self.inputs)} inputs, not one")
        return self.inputs[0]

    def _check_inputs(self, names: dict[str, Body], ground: set[str]) -> None:
        """Each input a moving link turned about a ground point, none named twice.

        With several inputs, a link may be driven along a ground guide instead.
        """
        inputs = self.inputs
        several = not (isinstance(inputs, tuple | list) and len(inputs) == 1)
        key = "mechanism.inputs" if several else "mechanism.input"
        if isinstance(inputs, str) or not isinstance(inputs, tuple | list) or not inputs:
            raise SpecError("must name the driven links", key=key, value=inputs)
        for name in inputs:
            shown = list(inputs) if several else name
            if not isinstance(name, str) or name not in names or name == GROUND:
                raise SpecError(f"must name a moving link ({_link_list(names)})", key=key,
                                value=shown)
            sliding = several and any(s.link == name and s.guide == GROUND
                                      for s in self.sliders)
            if names[name].points[0] not in ground and not sliding:
                turned = ("an input turns about it, or slides on a ground guide"
                          if several else "the crank turns about it")
                raise SpecError(f"the input's first point ({names[name].points[0]}) must be "
                                f"a ground point: {turned}", key=key, value=shown)
        if len(set(inputs)) != len(inputs):
            raise SpecError("names a link twice", key=key, value=list(inputs))
        v.store(self, "inputs", tuple(inputs))

    def _check_gears(self, names: dict[str, Body], ground: set[str],
                     points: dict[str, tuple[float, float]]) -> None:
        """Each gear pair between two moving links turned about ground pivots apart.

        Its driver an input or a driven gear found before it (their angles run on, unwrapped),
        its driven link no input and driven once, its ratio neither 0 nor 1; turned by one crank,
        each geared link at a whole number of the crank's speed (every motion then repeats each
        revolution, as a cycle analysis and a balancing sample it).
        """
        driven: set[str] = set()
        overall = {name: 1.0 for name in self.inputs}
        for i, gear in enumerate(self.gears):
            key = v.item("mechanism.gears", i)
            if not isinstance(gear, Gear):
                raise SpecError("must be a Gear", key=key, value=gear)
            if (not isinstance(gear.name, str) or not gear.name
                    or not all(ch.isalnum() or ch in "_-." for ch in gear.name)):
                raise SpecError("must be a name of letters, digits, '_', '-' and '.' (the "
                                "outputs' columns are named by it)", key=f"{key}.name",
                                value=gear.name)
            for attr in ("driver", "driven"):
                name = getattr(gear, attr)
                if name not in names or name == GROUND:
                    raise SpecError(f"must name a moving link ({_link_list(names)})",
                                    key=f"{key}.{attr}", value=name)
                if names[name].points[0] not in ground:
                    raise SpecError(f"the link's first point ({names[name].points[0]}) must "
                                    "be a ground point: its gear turns about it",
                                    key=f"{key}.{attr}", value=name)
            if gear.driver not in self.inputs and gear.driver not in driven:
                raise SpecError("must be an input or a link driven by a gear named before",
                                key=f"{key}.driver", value=gear.driver)
            if gear.driven in self.inputs or gear.driven in driven:
                raise SpecError("is turned already (an input, or driven by another gear)",
                                key=f"{key}.driven", value=gear.driven)
            ratio = v.number(gear.ratio, f"{key}.ratio")
            if ratio == 0 or ratio == 1:
                raise SpecError("must be neither 0 nor 1 (two shafts at one speed mesh "
                                "through an idler)", key=f"{key}.ratio", value=gear.ratio)
            a = points[names[gear.driver].points[0]]
            b = points[names[gear.driven].points[0]]
            scale = max(math.hypot(*xy) for xy in points.values()) or 1.0
            if math.hypot(b[0] - a[0], b[1] - a[1]) <= v.RELATIVE_LENGTH * scale:
                raise SpecError("the two gears' pivots coincide: they must be apart",
                                key=f"{key}.driven", value=gear.driven)
            object.__setattr__(gear, "ratio", ratio)
            driven.add(gear.driven)
            overall[gear.driven] = speed = overall[gear.driver] * ratio
            if len(self.inputs) == 1 and abs(speed - round(speed)) > 1e-12 * abs(speed):
                raise SpecError(f"turns {gear.driven} at {speed:.6g} times the crank's speed: "
                                "a linkage turned by one crank must repeat every revolution, "
                                "each geared link at a whole number of the crank's speed",
                                key=f"{key}.ratio", value=gear.ratio)
        v.store(self, "gears", tuple(self.gears))

    @staticmethod
    def _check_slider(i: int, slider: Slider, names: dict[str, Body],
                      points: dict[str, tuple[float, float]]) -> None:
        key = v.item("mechanism.sliders", i)
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
    def _check_frames(names: dict[str, Body], points: dict[str, tuple[float, float]]) -> None:
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

    @cached_property
    def ground(self) -> Body:
        """The ground link."""
        return next(b for b in self.bodies if b.name == GROUND)

    @cached_property
    def moving(self) -> tuple[Body, ...]:
        """The moving links, in the spec's order."""
        return tuple(b for b in self.bodies if b.name != GROUND)

    @cached_property
    def link_names(self) -> tuple[str, ...]:
        """Names of the moving links."""
        return tuple(b.name for b in self.moving)

    @cached_property
    def links(self) -> tuple[Link, ...]:
        """Mass properties of the moving links."""
        return tuple(b.props for b in self.moving if b.props is not None)  # all of them

    @cached_property
    def grounded_links(self) -> tuple[str, ...]:
        """Moving links that share a point with the ground (where a counter-rotor can sit)."""
        ground = set(self.ground.points)
        return tuple(b.name for b in self.moving if ground & set(b.points))

    @property
    def ground_sliders(self) -> tuple[str, ...]:
        """Links that slide on a guide of the frame (their normal force and couple act)."""
        return tuple(s.link for s in self.sliders if s.guide == GROUND)

    def guide_normals(self) -> dict[str, complex]:
        """Unit normal of each ground guide (its direction turned by +90°), by sliding link.

        The direction in which a positive normal force acts.
        """
        out: dict[str, complex] = {}
        for s in self.sliders:
            if s.guide == GROUND:
                d = complex(*s.direction)
                out[s.link] = 1j * d / abs(d)
        return out

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
            if b.name == name and b.props is not None:  # a moving link's always is
                return b.props
        raise KeyError(name)

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


def _link_list(names: Iterable[str]) -> str:
    """The links of a spec by name, for a message: the moving ones, and the frame's name."""
    moving = [n for n in names if n != GROUND]
    return f"the moving links are {', '.join(moving)}; the frame is called {GROUND}"
