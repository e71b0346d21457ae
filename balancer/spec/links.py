"""A link's table of a spec (``[links.<name>]``): its mass properties and loads, read once.

The four-bar's, the slider-crank's, a general linkage's links and an engine's rod.
"""

from __future__ import annotations

import cmath
import math

from .. import validate as v
from ..errors import SpecError
from ..mechanisms.slidercrank.model import SliderCrank
from ..model import Link, Linkage
from ..model import MechanismModel as Model
from .tables import Table


def read_link(table: Table, name: str,
               mechanism_class: type[Model],
               frame: tuple[complex, float] | None = None) -> Link:
    """One link; its values are checked by :class:`~balancer.model.Link` (keys prefixed).

    ``frame`` (a general linkage's link: its origin, complex, and its x-axis's angle at the
    reference pose) allows ``com = { at = [x, y] }``, the centre of mass's global position.
    """
    slider = mechanism_class is SliderCrank and name == "slider"
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
        if mechanism_class is not Linkage:
            raise SpecError("at = [x, y] is for the links of a general linkage (type = "
                            '"linkage"); give {e, f} or {s, sigma}', key=com.key("at"))
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
