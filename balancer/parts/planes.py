"""An engine's crank-web sectors: each plane's counterweight on the crankshaft as a part.

An engine's balancing (:mod:`balancer.balance.sites`) chooses per plane of
``[balance.counterweights]`` a mass·radius ``mr`` (kg·m) at an angle: a point mass on the
crankshaft. Where the spec gives those counterweights a ``part`` (a
:class:`~balancer.model.parts.Sector`: a crank web's crescent about the crank's axis), each
plane's is sized by :func:`balancer.parts.sizing.size_web`: the lightest sector of the room
whose mass times its centroid's reach is ``mr`` and whose bisector points at the angle (the
full outer radius and thickness, its angle solved), or where the room cannot hold ``mr`` the
largest it holds. The crankshaft as built carries each part's own mass·radius in its plane
(:func:`built_engine`); where every part is exact its analysis is the balanced one.

The sector lies in the crankshaft's frame at θ1 = 0 (x–y as the drawing's, its arcs about the
axis O), centred on its plane; its files are named :func:`plane_name` (``crankshaft_z-113.5mm``).
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from typing import cast

from ..balance.result import BalanceResult
from ..cycle import CycleAnalysis, cycle_analysis
from ..errors import SpecError
from ..model import Design
from ..model import MechanismModel as Model
from ..model.balance import PlacedMass, RotorBalanced, RotorBalanceProblem
from ..model.parts import Sector
from ..rounding import direction_deg
from .sizing import SizedPart, most_mr, size_web

#: The link the parts are on (the drawing's title, the files' names).
CRANKSHAFT = "crankshaft"


@dataclass(frozen=True, kw_only=True)
class PlanePart:
    """One plane's counterweight on the crankshaft as a crank-web sector.

    Attributes
    ----------
    name
        Its name in the report, the JSON and the files (:func:`plane_name`).
    placed
        What the optimiser chose: the plane ``z`` (m), ``mr`` (kg·m) and angle (degrees).
    sized
        The sector, sized in its room about the crank's axis (its ``made`` mass, centre in the
        crankshaft's frame at θ1 = 0, and inertia about its centre).
    points
        The crank's axis ``O`` and the pins of the throws nearest the plane, m at θ1 = 0 (for
        the drawing and the DXF).
    most
        The largest mass·radius the room holds (:func:`~balancer.parts.sizing.most_mr`), kg·m.
    max_mr
        The plane's bound as the spec writes it, kg·m (the optimiser's is the least of the
        two).
    """

    name: str
    placed: PlacedMass
    sized: SizedPart
    points: tuple[tuple[str, complex], ...]
    most: float
    max_mr: float
    given: bool = True
    link: str = CRANKSHAFT

    @property
    def z(self) -> float:
        """Its plane, m."""
        return self.placed.z

    @property
    def asked(self) -> complex:
        """The optimiser's mass·radius vector ``mr·e^{iφ}``, kg·m."""
        return cmath.rect(self.placed.mr, math.radians(self.placed.phase_deg))

    @property
    def made_mr(self) -> complex | None:
        """The part's mass·radius vector, its mass times its centre, kg·m (``None``: no part)."""
        made = self.sized.made
        return None if made is None else made.mass * made.centre

    @property
    def built(self) -> PlacedMass | None:
        """The part as the crankshaft's mass in its plane (``None`` without a part)."""
        v = self.made_mr
        if v is None:
            return None
        return PlacedMass(z=self.z, mr=abs(v), phase_deg=direction_deg(v))

    @property
    def moves(self) -> complex | None:
        """How the crankshaft as built differs from the balanced one in this plane, kg·m."""
        v = self.made_mr
        return None if v is None else v - self.asked


def plane_name(z: float) -> str:
    """A plane's part's name: ``crankshaft_z<z in mm>mm`` (``crankshaft_z-113.5mm``)."""
    return f"{CRANKSHAFT}_z{1e3 * z:.10g}mm"


def web_room(design: Design) -> Sector | None:
    """The sector ``[balance.counterweights] part`` gives an engine's counterweights, if any."""
    problem = design.balance
    if not isinstance(problem, RotorBalanceProblem) or problem.counterweights is None:
        return None
    return problem.counterweights.part


def require_webs(design: Design) -> None:
    """:class:`SpecError` (exit 2) for ``--cad`` on an engine whose counterweights have no part.

    (A crank web's sector needs its room; without counterweight planes there is nothing to
    make, which the command says.)
    """
    problem = design.balance
    if (isinstance(problem, RotorBalanceProblem) and problem.counterweights is not None
            and problem.counterweights.part is None):
        raise SpecError("--cad makes the crankshaft's counterweights as crank-web sectors: give "
                        'their room, part = { shape = "sector", inner_radius, outer_radius, '
                        "angle_deg, thickness }", key="balance.counterweights.part")


def _pins(model: Model, z: float) -> tuple[tuple[str, complex], ...]:
    """The pins of the cylinders whose planes are nearest ``z``, named ``pin <k>``, m."""
    cylinders = getattr(model, "cylinders", ())
    if not cylinders:
        return ()
    near = min(abs(c.z - z) for c in cylinders)
    return tuple((f"pin {k}", cmath.rect(c.crank, c.phase)) for k, c in
                 enumerate(cylinders, start=1) if abs(c.z - z) == near)


def make_webs(design: Design, result: BalanceResult) -> dict[str, PlanePart]:
    """Each plane's counterweight of ``result`` as its sector, by :func:`plane_name`.

    Planes where the optimiser put none (``mr`` 0) have none; without a part, none at all.
    """
    room = web_room(design)
    masses = result.rotor_masses
    if room is None or masses is None:
        return {}
    assert isinstance(design.balance, RotorBalanceProblem)
    assert design.balance.counterweights is not None  # (it has a part)
    bounds = dict(zip(design.balance.counterweights.planes,
                      design.balance.counterweights.max_mr, strict=True))
    out: dict[str, PlanePart] = {}
    for c in masses.counterweights:
        if c.mr <= 0:
            continue
        name = plane_name(c.z)
        if name in out:  # (planes closer than the name's digits)
            name = f"{name}_{len(out) + 1}"
        sized = size_web(room, c.mr, math.radians(c.phase_deg))
        out[name] = PlanePart(name=name, placed=c, sized=sized,
                              points=(("O", 0j), *_pins(result.linkage, c.z)),
                              most=most_mr(room), max_mr=bounds[c.z])
    return out


def built_engine(result: BalanceResult, parts: dict[str, PlanePart]) -> Model:
    """The balanced engine with each chosen plane's counterweight as its part makes it.

    The new counterweights (labelled ``"counterweight"`` in the chosen planes) are replaced by
    the parts' mass·radius vectors; everything else (the new shafts) is the balanced design's.
    """
    masses = result.rotor_masses
    assert masses is not None, "an engine's balancing"
    model = cast("RotorBalanced", result.linkage)
    built = [p.built for p in parts.values() if p.built is not None]
    return model.with_rotor_masses(built, (), masses.replaced)


def webs_as_built(result: BalanceResult, parts: dict[str, PlanePart]) -> CycleAnalysis:
    """The analysis at the operating speed of the engine as built (loads and gravity)."""
    before = result.before
    assert isinstance(before, CycleAnalysis)  # (an engine: over its revolution)
    return cycle_analysis(built_engine(result, parts), before.speed, before.samples,
                          gravity=result.gravity)
