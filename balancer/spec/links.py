"""A link's table of a spec (``[links.<name>]``): its mass properties and loads.

Read and written once.

The four-bar's, the slider-crank's, a general linkage's links and an engine's rod; and a
mechanism's named links (``[links]``, ``[original]``) table by table.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable, Sequence

from .. import tomltext as toml
from .. import validate as v
from ..errors import SpecError
from ..model import Link, Linkage
from ..model import MechanismModel as Model
from . import schema
from .tables import Table


def read_link(table: Table, *, slider: bool = False, positions: bool = False,
              frame: tuple[complex, float] | None = None) -> Link:
    """One link; its values are checked by :class:`~balancer.model.Link` (keys prefixed).

    ``slider``: a link that does not turn (its inertia may be left out) and may carry a gas
    force (read by its mechanism). ``positions``: ``com = { at = [x, y] }``, the centre of
    mass's global position, is allowed (a general linkage's links), in the link's ``frame``
    (its origin, complex, and its x-axis's angle at the reference pose).
    """
    if not table.has("mass"):
        raise table._missing("mass")
    mass = table.raw("mass")
    # A slider does not turn: its inertia does not matter and may be left out.
    if not slider and not table.has("inertia"):
        raise table._missing("inertia")
    inertia = table.value("inertia", 0.0)
    com = table.table("com")
    assert com is not None
    polar = com.has("s") or com.has("sigma")
    cartesian = com.has("e") or com.has("f")
    at = com.has("at")
    if polar + cartesian + at > 1:
        raise SpecError(
            "give the centre of mass either as {s, sigma}, {e, f} or {at = [x, y]}, not two",
            key=com.path,
        )
    if at:
        if not positions:
            raise SpecError("at = [x, y] is for the links of a general linkage (type = "
                            f'"{Linkage.type}"); give {{e, f}} or {{s, sigma}}',
                            key=com.key("at"))
        # Without a frame (unknown or coincident points, a one-point link without its one
        # slider or with a zero direction) the linkage itself names the cause when it is
        # built; until then the centre of mass stays at the origin of the link.
        origin, angle = frame if frame is not None else (complex(*com.vector2(
            "at", default=(0.0, 0.0))), 0.0)
        x, y = com.vector2("at", default=(0.0, 0.0))
        local = (complex(x, y) - origin) * cmath.exp(-1j * angle)
        e, f = local.real, local.imag
    elif polar:
        s = com.nonnegative("s")
        sigma = com.number("sigma")
        e, f = s * math.cos(sigma), s * math.sin(sigma)
    elif cartesian:
        e = com.number("e")
        f = com.number("f")
    else:
        raise SpecError("missing required key: give {s, sigma}, {e, f} or {at = [x, y]}",
                        key=com.path)
    com.finish()
    if table.has("gas_force") and not slider:
        raise SpecError("only a slider carries a gas force", key=table.key("gas_force"))
    with v.under(table.path):
        return Link(
            mass=mass,
            inertia=inertia,
            e=e,
            f=f,
            force=table.value("force", (0.0, 0.0)),
            moment=table.value("moment", 0.0),
            counter_rotor=table.value("counter_rotor", 0.0),
            z=table.value("z", 0.0),
        )


def link_lines(link: Link, global_axes: bool = False) -> list[str]:
    """A link's table as TOML lines that :func:`read_link` reads back equal.

    ``global_axes``: its centre of mass is in global axes from its pin (a slider's).
    """
    lines = [
        f"mass = {toml.number(link.mass)}  # kg",
        f"inertia = {toml.number(link.inertia)}  # kg·m² about the centre of mass",
        f"com = {{ e = {toml.number(link.e)}, f = {toml.number(link.f)} }}  "
        + ("# m from the pin, in global axes" if global_axes
           else f"# m (s = {link.s:.6g} m, sigma = {link.sigma:.6g} rad)"),
    ]
    if link.force != (0.0, 0.0):
        lines.append(f"force = [{toml.number(link.force[0])}, {toml.number(link.force[1])}]  # N")
    if link.moment != 0.0:
        lines.append(f"moment = {toml.number(link.moment)}  # N·m")
    if link.counter_rotor != 0.0:
        lines.append(f"counter_rotor = {toml.number(link.counter_rotor)}  # kg·m²")
    if link.z != 0.0:
        lines.append(f"z = {toml.number(link.z)}  # m: the link's plane along the crank's axis")
    return lines


def read_links(table: Table, names: Sequence[str], mechanism_type: str, *,
               sliders: Sequence[str] = (), positions: bool = False,
               extra: Callable[[str, Table], None] | None = None) -> dict[str, Link]:
    """A mechanism's named links (``[links]``, ``[original]``), each required.

    ``sliders``: the links that do not turn (:func:`read_link`); ``extra(name, table)`` reads
    what a mechanism's link table holds besides (a slider's gas force) before it is finished.
    """
    table.expect(schema.known(table.path, mechanism_type) or tuple(names))
    links = {}
    for name in names:
        sub = table.table(name)
        assert sub is not None
        links[name] = read_link(sub, slider=name in sliders, positions=positions)
        if extra is not None:
            extra(name, sub)
        sub.finish()
    table.finish()
    return links


def links_lines(model: Model, prefix: str, *, sliders: Sequence[str] = (),
                extra: Callable[[str], list[str]] | None = None) -> list[str]:
    """A mechanism's named links as ``[prefix.<name>]`` tables (``extra(name)``: more lines)."""
    out: list[str] = []
    for name in model.link_names:
        out += ["", f"[{prefix}.{toml.key(name)}]",
                *link_lines(model.link(name), global_axes=name in sliders)]
        if extra is not None:
            out += extra(name)
    return out
