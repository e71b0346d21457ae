"""A general linkage's tables of a spec.

``[mechanism]`` (input, points, sliders), its links' tables (each with its points) and
``[[springs]]``.

Reached through the registry (:func:`balancer.mechanisms.folder_module`) by the
spec reader and writer (:mod:`balancer.spec`); ``[balance]`` is the linkages' own.
"""

from __future__ import annotations

import math
from typing import Any

from ... import tomltext as toml
from ... import validate as v
from ...errors import SpecError
from ...model import GROUND, Body, Gear, Linkage, Slider, Spring
from ...model import MechanismModel as Model
from ...spec import schema
from ...spec.links import link_lines, links_lines, read_link, read_links
from ...spec.tables import Table


def _names(table: Table, name: str) -> tuple[str, ...]:
    """A required list of names (strings)."""
    if not table.has(name):
        raise table._missing(name)
    raw = table.raw(name)
    if not isinstance(raw, list) or not all(isinstance(x, str) for x in raw):
        raise SpecError("must be a list of names", key=table.key(name), value=raw)
    return tuple(raw)


def _inputs(mech: Table) -> tuple[str, ...]:
    """The driven links: ``input = "crank"`` (one) or ``inputs = ["left", "right"]``."""
    if mech.has("input") and mech.has("inputs"):
        raise SpecError("give either input (one driven link) or inputs (several), not both",
                        key=mech.key("inputs"), value=mech.raw("inputs"))
    if mech.has("inputs"):
        names = _names(mech, "inputs")
        if not names:
            raise SpecError("must name at least one driven link", key=mech.key("inputs"),
                            value=[])
        return names
    if not mech.has("input"):
        raise mech._missing("input")
    input_name = mech.raw("input")
    if not isinstance(input_name, str):
        raise SpecError("must be the name of a link", key=mech.key("input"), value=input_name)
    return (input_name,)


def read(root: Table, mech: Table) -> Linkage:
    """A general linkage (``type = "linkage"``; DESIGN.md, "General planar linkages").

    Its ``[mechanism]``, ``[links]`` and ``[[springs]]``.
    """
    mech.expect(schema.known("mechanism", schema.LINKAGE))
    inputs = _inputs(mech)
    points_table = mech.table("points")
    assert points_table is not None
    points_table.known = tuple(points_table.data)
    points = {p: points_table.vector2(p, default=(0.0, 0.0)) for p in points_table.data}
    points_table.finish()
    sliders: list[dict[str, Any]] = []  # each a Slider's fields
    for sub in mech.tables("sliders"):
        sub.expect(schema.known("mechanism.sliders[]", schema.LINKAGE))
        fields: dict[str, Any] = {}
        for attr in ("link", "guide", "point"):
            if not sub.has(attr):
                raise sub._missing(attr)
            value = sub.raw(attr)
            if not isinstance(value, str):
                raise SpecError("must be a name", key=sub.key(attr), value=value)
            fields[attr] = value
        if not sub.has("direction"):
            raise sub._missing("direction")
        fields["direction"] = sub.vector2("direction", default=(1.0, 0.0))
        sub.finish()
        sliders.append(fields)
    gears = []
    for sub in mech.tables("gears"):
        sub.expect(schema.known("mechanism.gears[]", schema.LINKAGE))
        names: dict[str, str] = {}
        for attr in ("name", "driver", "driven", "ratio"):
            if not sub.has(attr):
                raise sub._missing(attr)
        for attr in ("name", "driver", "driven"):
            value = sub.raw(attr)
            if not isinstance(value, str) or not value:
                raise SpecError("must be a name", key=sub.key(attr), value=value)
            names[attr] = value
        gears.append(Gear(**names, ratio=sub.value("ratio", 0.0)))
        sub.finish()
    if len({g.name for g in gears}) != len(gears):
        raise SpecError("names a gear pair twice", key=mech.key("gears"),
                        value=[g.name for g in gears])
    mech.finish()
    links_table = root.table("links")
    assert links_table is not None
    links_table.known = tuple(links_table.data)
    positions = {p: complex(*xy) for p, xy in points.items()}
    bodies = []
    for name in links_table.data:
        link = links_table.table(name)
        if name == GROUND:
            link.expect(schema.known("links.ground", schema.LINKAGE))
            bodies.append(Body(name=name, points=_names(link, "points")))
            link.finish()
            continue
        link.expect(schema.known("links.<link>", schema.LINKAGE))
        link_points = _names(link, "points")
        frame = _frame(name, link_points, positions, sliders)
        props = read_link(link, positions=True, frame=frame)
        link.finish()
        bodies.append(Body(name=name, points=link_points, props=props))
    links_table.finish()
    springs = []
    for sub in root.tables("springs"):
        sub.expect(schema.known("springs[]", schema.LINKAGE))
        for k in ("stiffness", "free_length"):
            if not sub.has(k):
                raise sub._missing(k)
        ends: Any = _names(sub, "points")  # names as written: the spring checks there are two
        with v.under(sub.path):
            springs.append(Spring(points=ends, stiffness=sub.raw("stiffness"),
                                  free_length=sub.raw("free_length")))
        sub.finish()
    return Linkage(points=tuple(points.items()), bodies=tuple(bodies), inputs=inputs,
                   sliders=tuple(Slider(**f) for f in sliders), springs=tuple(springs),
                   gears=tuple(gears))


def _frame(name: str, link_points: tuple[str, ...], positions: dict[str, complex],
           sliders: list[dict[str, Any]]) -> tuple[complex, float] | None:
    """A general linkage's link frame at the reference pose: origin and x-axis angle.

    ``None`` if its points are not all known yet (the model then reports what is wrong).
    """
    if not link_points or any(p not in positions for p in link_points):
        return None
    origin = positions[link_points[0]]
    if len(link_points) > 1:
        axis = positions[link_points[1]] - origin
    else:
        mine = [s for s in sliders if s.get("link") == name]
        if len(mine) != 1:
            return None
        axis = complex(*mine[0]["direction"])
    if axis == 0:
        return None
    return origin, math.atan2(axis.imag, axis.real)


def lines(model: Model) -> list[str]:
    """Its ``[mechanism]``, ``[links]`` and ``[[springs]]``, as :func:`read` reads them."""
    assert isinstance(model, Linkage)
    mech = model
    driven = (f"input = {toml.string(mech.inputs[0])}" if len(mech.inputs) == 1 else
              f"inputs = [{', '.join(toml.string(name) for name in mech.inputs)}]")
    out = ["[mechanism]", 'type = "linkage"', driven, "",
           "[mechanism.points]  # m, at the reference pose"]
    out += [f"{toml.key(p)} = [{toml.number(x)}, {toml.number(y)}]" for p, (x, y) in mech.points]
    for s in mech.sliders:
        out += ["", "[[mechanism.sliders]]", f"link = {toml.string(s.link)}",
                f"guide = {toml.string(s.guide)}", f"point = {toml.string(s.point)}",
                f"direction = [{toml.number(s.direction[0])}, {toml.number(s.direction[1])}]"]
    for g in mech.gears:
        out += ["", "[[mechanism.gears]]", f"name = {toml.string(g.name)}",
                f"driver = {toml.string(g.driver)}", f"driven = {toml.string(g.driven)}",
                f"ratio = {toml.number(g.ratio)}"]
    for body in mech.bodies:
        names = ", ".join(map(toml.string, body.points))
        out += ["", f"[links.{toml.key(body.name)}]", f"points = [{names}]"]
        if body.props is not None:
            out += link_lines(body.props)
    for spring in mech.springs:
        out += ["", "[[springs]]", f"points = [{', '.join(map(toml.string, spring.points))}]",
                f"stiffness = {toml.number(spring.stiffness)}  # N/m",
                f"free_length = {toml.number(spring.free_length)}  # m"]
    return out


def read_original(table: Table, model: Model) -> Model:
    """``[original]``: the same linkage with the links given there.

    Each centre of mass as ``{e, f}`` or ``{s, sigma}`` in its link's frame.
    """
    return model.with_links(read_links(table, model.link_names, Linkage.type,
                                       positions=True))


def original_lines(model: Model) -> list[str]:
    """``[original.<link>]`` tables of ``model``."""
    return links_lines(model, "original")


#: Its ``[balance]``: the linkages' own, read and written by this module (loaded only for a
#: spec that has the table).
BALANCE = "balancer.spec.balance"

__all__ = ["BALANCE", "lines", "original_lines", "read", "read_original"]
