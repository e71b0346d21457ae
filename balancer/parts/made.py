"""The parts of a balancing: each counterweight sized in its room, and the design as built.

``optimize`` tells per link the body to add (:mod:`balancer.balance.counterweights`). Here each
such body becomes a part: the family and room of the spec's ``[balance.<link>] counterweight
= { …, part = { … } }`` (:mod:`balancer.model.parts`), or where none is given a steel disc (a
ring with no hole and no limit: the disc the report has always proposed), dimensioned by
:func:`balancer.parts.sizing.size_part`. The original link plus the part as made is the link as
built; where every part is exact it is the balanced link, and the analysis of the design as
built (:func:`as_built`) gives back the balanced analysis.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace

from ..balance.counterweights import Counterweight
from ..balance.result import BalanceResult
from ..cycle import CycleAnalysis, cycle_analysis
from ..errors import SpecError
from ..mechanisms import mechanism_of
from ..model import Design, Link
from ..model import MechanismModel as Model
from ..model.balance import BalanceProblem
from ..model.parts import STEEL, Part, Ring
from .planes import PlanePart, make_webs, webs_as_built
from .shapes import MassProperties, union
from .sizing import SizedPart, size_part

#: The part of a counterweight whose spec names none: a steel disc, sized freely.
DISC = Ring(inner_radius=0.0, outer_radius=math.inf, thickness=math.inf, material=STEEL)


@dataclass(frozen=True, kw_only=True)
class LinkPart:
    """One link's counterweight as a part.

    Attributes
    ----------
    link
        The link's name.
    counterweight
        What the optimiser asked (:class:`~balancer.balance.counterweights.Counterweight`).
    sized
        The part, sized in its room (:class:`~balancer.parts.sizing.SizedPart`).
    given
        Whether the spec gave the part (else :data:`DISC`).
    pivot
        The link's ``com_about`` point in its frame, m (a sector's arcs are centred there).
    points
        The link's points in its frame, m, by name (for the drawing).
    original
        The original link's mass properties.
    balanced
        The balanced link's.
    built
        The original link plus the part as made (``None`` without a part).
    """

    link: str
    counterweight: Counterweight
    sized: SizedPart
    given: bool
    pivot: complex
    points: tuple[tuple[str, complex], ...]
    original: MassProperties
    balanced: MassProperties
    built: MassProperties | None

    @property
    def moves(self) -> tuple[float, complex, float] | None:
        """How the link as built differs from the balanced link.

        Its mass (kg), first moment in its frame (kg·m) and inertia about its frame's origin
        (kg·m²); ``None`` without a part.
        """
        if self.built is None:
            return None
        m1, me1, mf1, j1 = self.built.inertial_parameters
        m0, me0, mf0, j0 = self.balanced.inertial_parameters
        return m1 - m0, complex(me1 - me0, mf1 - mf0), j1 - j0


def _props(link: Link) -> MassProperties:
    return MassProperties(link.mass, link.com, link.inertia)


def _room(problem: BalanceProblem | object, name: str) -> Part | None:
    """The part the spec gives link ``name``'s counterweight, if any."""
    if not isinstance(problem, BalanceProblem):
        return None
    freedom = problem.link(name)
    if freedom is None or freedom.counterweight is None:
        return None
    return freedom.counterweight.part


def _about(problem: BalanceProblem | object, name: str, first: str) -> str:
    """The link's ``com_about`` for its counterweight (default: its first point)."""
    if isinstance(problem, BalanceProblem):
        freedom = problem.link(name)
        if freedom is not None and freedom.com_about is not None:
            return freedom.com_about
    return first


def make_parts(design: Design, result: BalanceResult) -> dict[str, LinkPart]:
    """Each counterweight to add of ``result`` (balancing ``design``) as a part, by link.

    Links whose counterweight is no body to add (unchanged, material to remove, a rebuild)
    have none. An engine's balancing (its masses on shafts) has none here.
    """
    if result.rotor_masses is not None:
        return {}
    mech = mechanism_of(result.original)
    structure = mech.structure
    out: dict[str, LinkPart] = {}
    for name, weight in result.counterweights.items():
        if weight.kind != "add" or weight.mass <= 0:
            continue
        k = structure.index(name)
        body_points = next(b.points for b in mech.linkage.moving if b.name == name)
        points = tuple((p, structure.local[(k, p)].complex()) for p in body_points)
        pivot = dict(points)[_about(design.balance, name, body_points[0])]
        room = _room(design.balance, name)
        target = MassProperties(weight.mass, complex(weight.e, weight.f), weight.inertia)
        sized = size_part(room or DISC, target, pivot)
        original = _props(result.original.link(name))
        built = None if sized.made is None else union(original, sized.made)
        out[name] = LinkPart(link=name, counterweight=weight, sized=sized,
                             given=room is not None, pivot=pivot, points=points,
                             original=original, balanced=_props(result.linkage.link(name)),
                             built=built)
    return out


def built_model(result: BalanceResult, parts: Mapping[str, LinkPart]) -> Model:
    """The balanced mechanism with each link that has a part as built: original + part.

    Every other figure (the other links, counter-rotors, loads) is the balanced design's.
    """
    links = {}
    for name, part in parts.items():
        if part.built is None:
            continue
        link = result.linkage.link(name)
        b = part.built
        links[name] = replace(link, mass=b.mass, e=b.centre.real, f=b.centre.imag,
                              inertia=max(b.inertia, 0.0))
    return result.linkage.with_links(links) if links else result.linkage


def as_built(result: BalanceResult, parts: Mapping[str, LinkPart]) -> CycleAnalysis:
    """The analysis at the operating speed of the design as built.

    Loads and gravity included, as :attr:`BalanceResult.operating`'s.
    """
    before = result.before
    if not isinstance(before, CycleAnalysis):
        raise SpecError("counterweights as parts are made for a linkage turned by one crank so "
                        "far", key="balance")
    return cycle_analysis(built_model(result, parts), before.speed, before.samples,
                          gravity=result.gravity)


def parts_of(design: Design, result: BalanceResult, *, always: bool = False
             ) -> tuple[dict[str, LinkPart] | dict[str, PlanePart], CycleAnalysis | None]:
    """The counterweights of ``result`` as parts, and the analysis of the design as built.

    Where the spec gives a counterweight a part, or ``always`` (``optimize --cad``: a steel
    disc for a counterweight the spec gives none); else none: ``({}, None)``. An engine's:
    each plane's crank-web sector where ``[balance.counterweights]`` gives a part
    (:mod:`balancer.parts.planes`).
    """
    if result.rotor_masses is not None:
        webs = make_webs(design, result)
        return webs, (webs_as_built(result, webs) if webs else None)
    given = any(_room(design.balance, name) is not None for name in result.counterweights)
    if not (given or always):
        return {}, None
    parts = make_parts(design, result)
    return parts, (as_built(result, parts) if parts else None)

