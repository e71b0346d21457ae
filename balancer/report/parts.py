"""The parts of a balancing as ``optimize`` reports them: a table for the workshop, and JSON.

Computes nothing: the parts (:func:`balancer.parts.made.make_parts`) and the analysis as built
(:func:`balancer.parts.made.as_built`) are given.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, cast

from ..cycle import CycleAnalysis
from ..model.parts import Insert, Washers
from ..parts.made import LinkPart
from ..parts.planes import PlanePart
from ..parts.shapes import AnnularSector, Annulus, Profile, Rectangle
from ..rounding import Scales
from .text import table


def dimensions(profile: Profile) -> dict[str, float]:
    """A profile's dimensions by name, m (the sector's angle and bisector in degrees)."""
    if isinstance(profile, Annulus):
        return {"inner_radius": profile.inner, "outer_radius": profile.outer,
                "thickness": profile.thickness}
    if isinstance(profile, AnnularSector):
        return {"inner_radius": profile.inner, "outer_radius": profile.outer,
                "angle_deg": math.degrees(profile.angle),
                "direction_deg": math.degrees(profile.direction),
                "thickness": profile.thickness}
    return {"length": profile.length, "width": profile.width, "thickness": profile.thickness}


def dimensions_text(part: LinkPart | PlanePart) -> str:
    """The part's dimensions as a workshop reads them, mm and degrees."""
    sized, profile = part.sized, part.sized.profile
    if profile is None:
        return "—"
    if isinstance(sized.room, Washers):
        return f"{sized.count} × ISO 7089 {sized.room.size} ({1e3 * profile.thickness:.4g} high)"
    if isinstance(profile, Annulus):
        if isinstance(sized.room, Insert):
            return f"pocket Ø {2e3 * profile.outer:.4g} × {1e3 * profile.thickness:.4g} deep"
        hole = f" bore Ø {2e3 * profile.inner:.4g}" if profile.inner else ""
        return f"Ø {2e3 * profile.outer:.4g}{hole} × {1e3 * profile.thickness:.4g}"
    if isinstance(profile, AnnularSector):
        direction = math.degrees(profile.direction)
        if isinstance(part, PlanePart):  # (as the counterweights' angles, in [0, 360))
            direction %= 360.0
        return (f"R {1e3 * profile.inner:.4g}–{1e3 * profile.outer:.4g}, "
                f"{math.degrees(profile.angle):.4g}° at {direction:.4g}°, "
                f"× {1e3 * profile.thickness:.4g}")
    assert isinstance(profile, Rectangle)
    return (f"{1e3 * profile.length:.4g} × {1e3 * profile.width:.4g} × "
            f"{1e3 * profile.thickness:.4g}")


def _material(part: LinkPart | PlanePart) -> str:
    room = part.sized.room
    if isinstance(room, Insert):
        return f"{room.material.name} in {room.host.name}"
    return room.material.name


def parts_text(parts: Mapping[str, LinkPart] | Mapping[str, PlanePart],
               before: CycleAnalysis | None = None, balanced: CycleAnalysis | None = None,
               built: CycleAnalysis | None = None) -> str:
    """The parts as a table (mm, kg), and how the design as built differs from the optimum.

    How each link as built moves from the balanced one, and the shaking of the design as
    built beside the optimum's (a figure that is rounding of the original's as 0). An
    engine's crank-web sectors: :func:`webs_text`.
    """
    if any(isinstance(p, PlanePart) for p in parts.values()):
        return webs_text(cast("Mapping[str, PlanePart]", parts), before, balanced, built)
    return _links_text(cast("Mapping[str, LinkPart]", parts), before, balanced, built)


def _links_text(parts: Mapping[str, LinkPart], before: CycleAnalysis | None,
                balanced: CycleAnalysis | None, built: CycleAnalysis | None) -> str:
    rows = []
    notes = []
    for name, part in parts.items():
        sized = part.sized
        made = sized.made
        state = "exact" if sized.exact else "nearest" if made is not None else "none"
        rows.append([name, sized.room.shape + ("" if part.given else " (default)"),
                     _material(part), dimensions_text(part),
                     "" if made is None else f"{made.mass:.6g}", state])
        moves = part.moves
        if made is None:
            notes.append(f"{name}: no part ({sized.note})")
        elif not sized.exact and moves is not None:
            dm, dfirst, dj = moves
            at = ", ".join(sized.limits) or "its room"
            notes.append(f"{name}: the nearest part stands at its room's {at}; the link as "
                         f"built differs from the balanced one by {dm:+.4g} kg of mass, "
                         f"{1e3 * abs(dfirst):.4g} kg·mm of first moment and {dj:+.4g} kg·m² "
                         "of inertia about its first point")
    lines = [table(rows, ["part", "shape", "material", "dimensions mm", "mass kg", "meets"])]
    lines += notes
    if before is not None and balanced is not None and built is not None:
        o, b, a = before.summary, balanced.summary, built.summary
        scales = Scales([("N", o.shaking_force.rms), ("N·m", o.shaking_moment.rms)])
        lines.append(
            f"as built: RMS shaking force {scales.number(a.shaking_force.rms, 'N')} N "
            f"(optimum {scales.number(b.shaking_force.rms, 'N')}), RMS shaking moment "
            f"{scales.number(a.shaking_moment.rms, 'N·m')} N·m (optimum "
            f"{scales.number(b.shaking_moment.rms, 'N·m')})")
    return "\n".join(lines)


def _body(props: Any) -> dict[str, float]:
    return {"mass": props.mass, "e": props.centre.real, "f": props.centre.imag,
            "inertia": props.inertia}


def parts_json(parts: Mapping[str, LinkPart] | Mapping[str, PlanePart]
               ) -> dict[str, dict[str, Any]]:
    """``optimize --json``'s ``parts``: per link its part (docs/outputs.md).

    An engine's crank-web sectors: :func:`webs_json`.
    """
    if any(isinstance(p, PlanePart) for p in parts.values()):
        return webs_json(cast("Mapping[str, PlanePart]", parts))
    return _links_json(cast("Mapping[str, LinkPart]", parts))


def _links_json(parts: Mapping[str, LinkPart]) -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name, part in parts.items():
        sized = part.sized
        room = sized.room
        moves = part.moves
        out[name] = {
            "shape": room.shape,
            "given": part.given,
            "material": room.material.name,
            "density": room.material.density,
            "dimensions": None if sized.profile is None else dimensions(sized.profile),
            "count": sized.count,
            "exact": sized.exact,
            "limits": list(sized.limits),
            "made": None if sized.made is None else _body(sized.made),
            "built": None if part.built is None else _body(part.built),
            "moves": None if moves is None else {
                "mass": moves[0], "first_moment": [moves[1].real, moves[1].imag],
                "inertia": moves[2]},
            "note": sized.note or None,
        }
    return out


# -- an engine's crank-web sectors ---------------------------------------------------------------

def webs_text(parts: Mapping[str, PlanePart], before: CycleAnalysis | None = None,
              balanced: CycleAnalysis | None = None,
              built: CycleAnalysis | None = None) -> str:
    """The crankshaft's counterweights as sectors (mm, kg, kg·m), and the engine as built.

    Each plane's sector, its mass·radius and angle; where its room caps the plane's bound or
    cannot hold what was asked, what it holds; the shaking of the engine as built beside the
    optimum's (a figure that is rounding of the original's as 0).
    """
    rows, notes = [], []
    for name, part in parts.items():
        sized, made = part.sized, part.built
        state = "exact" if sized.exact else "nearest" if made is not None else "none"
        rows.append([name, f"{1e3 * part.z:.6g}", sized.room.shape, _material(part),
                     dimensions_text(part),
                     "" if sized.made is None else f"{sized.made.mass:.6g}",
                     "" if made is None else f"{made.mr:.6g}",
                     "" if made is None else f"{made.phase_deg:.6g}", state])
        moves = part.moves
        if made is None:
            notes.append(f"{name}: no part ({sized.note})")
        elif not sized.exact and moves is not None:
            at = ", ".join(sized.limits) or "its room"
            notes.append(f"{name}: the room holds at most {part.most:.6g} kg·m (its sector at "
                         f"its {at}): the nearest part has {made.mr:.6g} kg·m of the "
                         f"{part.placed.mr:.6g} asked; the crankshaft as built differs from "
                         f"the balanced one by {abs(moves):.4g} kg·m in this plane")
    capped = sorted({(p.most, p.max_mr) for p in parts.values() if p.most < p.max_mr})
    for most, max_mr in capped:
        notes.append(f"the sector's room holds at most {most:.6g} kg·m (at its full outer "
                     "radius and thickness, its angle at most 180°): the optimiser's bound in "
                     f"each plane, below max_mr = {max_mr:.6g}")
    lines = [table(rows, ["part", "plane z mm", "shape", "material", "dimensions mm",
                          "mass kg", "mr kg·m", "angle °", "meets"])]
    lines.append("the sectors' arcs about the crank's axis, their angles at θ1 = 0 from +x "
                 "towards +y (as the counterweights'), each centred on its plane")
    lines += notes
    if before is not None and balanced is not None and built is not None:
        o, b, a = before.summary, balanced.summary, built.summary
        scales = Scales([("N", o.shaking_force.rms), ("N·m", o.rocking_couple.rms),
                         ("N·m", o.shaking_moment.rms)])
        figures = [(f"RMS {words}", getattr(a, key).rms, getattr(b, key).rms, unit)
                   for key, words, unit in (("shaking_force", "shaking force", "N"),
                                            ("rocking_couple", "rocking couple", "N·m"),
                                            ("shaking_moment", "shaking moment", "N·m"))]
        lines.append("as built: " + ", ".join(
            f"{words} {scales.number(after, unit)} {unit} (optimum "
            f"{scales.number(optimum, unit)})" for words, after, optimum, unit in figures))
    return "\n".join(lines)


def webs_json(parts: Mapping[str, PlanePart]) -> dict[str, dict[str, Any]]:
    """``optimize --json``'s ``parts`` of an engine: per plane its sector (docs/outputs.md)."""
    out: dict[str, dict[str, Any]] = {}
    for name, part in parts.items():
        sized, built, moves = part.sized, part.built, part.moves
        out[name] = {
            "link": part.link,
            "z": part.z,
            "shape": sized.room.shape,
            "given": part.given,
            "material": sized.room.material.name,
            "density": sized.room.material.density,
            "dimensions": None if sized.profile is None else {
                k: x % 360.0 if k == "direction_deg" else x
                for k, x in dimensions(sized.profile).items()},
            "count": None,
            "exact": sized.exact,
            "limits": list(sized.limits),
            "asked": {"mr": part.placed.mr, "phase_deg": part.placed.phase_deg},
            "most_mr": part.most,
            "made": None if sized.made is None else _body(sized.made),
            "built": None if built is None else {"z": built.z, "mr": built.mr,
                                                 "phase_deg": built.phase_deg},
            "moves": None if moves is None else {"first_moment": [moves.real, moves.imag]},
            "note": sized.note or None,
        }
    return out
