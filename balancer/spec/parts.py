"""A counterweight's ``part`` table: read into :mod:`balancer.model.parts`, and written back.

``[balance.<link>] counterweight = { …, part = { shape = "ring", … } }`` (or the table
``[balance.<link>.counterweight.part]``). Every family takes ``shape``, ``material`` (a name of
:data:`~balancer.model.parts.MATERIALS`, default steel; with ``density``, any name) and
``density`` (kg/m³); its room in its own keys (:func:`own`), lengths in m, the angle in
degrees. A key of another family is refused, naming it and the family's keys.
"""

from __future__ import annotations

from dataclasses import fields

from .. import tomltext as toml
from ..errors import SpecError
from ..model.parts import (
    MATERIALS,
    SHAPES,
    STEEL,
    Block,
    Insert,
    Material,
    Part,
    Ring,
    Sector,
    Washers,
)
from .tables import Table

#: The model's class of each family (:data:`balancer.model.parts.SHAPES`).
FAMILIES: dict[str, type] = {"ring": Ring, "washers": Washers, "sector": Sector,
                             "block": Block, "insert": Insert}


def own(shape: str) -> tuple[str, ...]:
    """A family's own keys of a ``part`` table.

    Its model's fields (``host`` with ``host_density``), beside ``shape``, ``material`` and
    ``density``, which every family takes.
    """
    names = [f.name for f in fields(FAMILIES[shape]) if f.name != "material"]
    return tuple(n for name in names for n in ((name, "host_density") if name == "host"
                                                 else (name,)))


def _material(table: Table, name_key: str, density_key: str, default: Material | None
              ) -> Material:
    """A material by name, or a name and a density (any name then)."""
    name = table.text(name_key, default="") if table.has(name_key) else None
    if table.has(density_key):
        density = table.positive(density_key)
        return Material(name=name or "custom", density=density)
    if name is None:
        if default is None:
            raise SpecError("missing required key (a material denser than the link's: "
                            f"one of {', '.join(MATERIALS)}, or give {density_key})",
                            key=table.key(name_key))
        return default
    if name not in MATERIALS:
        raise SpecError(f"must be one of {', '.join(MATERIALS)} (or give {density_key} in "
                        "kg/m³ beside it)", key=table.key(name_key), value=name)
    return Material(name=name, density=MATERIALS[name])


def read_part(table: Table) -> Part:
    """The part of a counterweight's ``part`` table (:class:`SpecError` naming key and value)."""
    shape = table.string("shape", choices=SHAPES)
    keys = own(shape)
    for name in table.data:
        if name not in ("shape", "material", "density", *keys):
            raise SpecError(f"does not apply to a {shape} part (its keys: "
                            f"{', '.join(keys)})", key=table.key(name), value=table.raw(name))
    material = _material(table, "material", "density", None if shape == "insert" else STEEL)
    try:
        part: Part
        if shape == "ring":
            part = Ring(inner_radius=table.nonnegative("inner_radius", default=0.0),
                        outer_radius=table.positive("outer_radius"),
                        thickness=table.positive("thickness"), material=material)
        elif shape == "washers":
            size = table.raw("size") if table.has("size") else None
            if size is None:
                raise SpecError("missing required key (an ISO 7089 size such as \"M12\")",
                                key=table.key("size"))
            part = Washers(size=size, thickness=table.positive("thickness"),
                           material=material)
        elif shape == "sector":
            part = Sector(inner_radius=table.nonnegative("inner_radius", default=0.0),
                          outer_radius=table.positive("outer_radius"),
                          angle_deg=table.positive("angle_deg"),
                          thickness=table.positive("thickness"),
                          material=material)
        elif shape == "block":
            part = Block(length=table.positive("length"), width=table.positive("width"),
                         thickness=table.positive("thickness"), material=material)
        else:
            host = _material(table, "host", "host_density", STEEL)
            part = Insert(radius=table.positive("radius"),
                          thickness=table.positive("thickness"), material=material, host=host)
    except SpecError as exc:
        if exc.key is not None and "." not in exc.key:  # the model's own key, in this table
            raise SpecError(exc.detail, key=table.key(exc.key), value=exc.value) from None
        raise
    table.finish()
    return part


def _material_items(material: Material, name_key: str, density_key: str,
                    default: Material | None) -> list[str]:
    if material == default:
        return []
    if MATERIALS.get(material.name) == material.density:
        return [f"{name_key} = {toml.string(material.name)}"]
    return [f"{name_key} = {toml.string(material.name)}",
            f"{density_key} = {toml.number(material.density)}"]


def part_text(part: Part) -> str:
    """The part as a TOML inline table that :func:`read_part` reads back equal."""
    items = [f"shape = {toml.string(part.shape)}"]
    if isinstance(part, Insert):
        items += _material_items(part.material, "material", "density", None)
    else:
        items += _material_items(part.material, "material", "density", STEEL)
    if isinstance(part, Ring | Sector) and part.inner_radius:
        items.append(f"inner_radius = {toml.number(part.inner_radius)}")
    if isinstance(part, Ring | Sector):
        items.append(f"outer_radius = {toml.number(part.outer_radius)}")
    if isinstance(part, Sector):
        items.append(f"angle_deg = {toml.number(part.angle_deg)}")
    if isinstance(part, Washers):
        items.append(f"size = {toml.string(part.size)}")
    if isinstance(part, Block):
        items += [f"length = {toml.number(part.length)}", f"width = {toml.number(part.width)}"]
    if isinstance(part, Insert):
        items.append(f"radius = {toml.number(part.radius)}")
    items.append(f"thickness = {toml.number(part.thickness)}")
    if isinstance(part, Insert):
        items += _material_items(part.host, "host", "host_density", STEEL)
    return "{ " + ", ".join(items) + " }"
