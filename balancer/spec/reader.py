"""Design specs in TOML: load and validate them into model objects.

The key names are fixed (see the project's DESIGN.md)::

    title = "optional free text"

    [mechanism]
    type = "four-bar"
    branch = "+"                      # or "-"
    [mechanism.lengths]
    crank = 1.0                       # m
    coupler = 3.0
    rocker = 2.0
    frame = 3.2

    [links.crank]                     # also [links.coupler], [links.rocker]
    mass = 2.1                        # kg
    inertia = 1.1                     # kg·m² about the centre of mass
    com = { s = 0.6, sigma = 0.3 }    # or { e = .., f = .. }, m and rad
    force = [1.1, 1.2]                # N, at the centre of mass (optional)
    moment = 0.37                     # N·m (optional)
    counter_rotor = 0.0               # kg·m², crank and rocker only (optional)

    [operation]
    speed = 10.0                      # rad/s
    samples = 360
    gravity = [0.0, -9.81]            # m/s², in the cycle analysis (optional)

    [simulation]
    duration = 5.0                    # s
    theta1 = 1.0                      # rad
    omega1 = 0.0                      # rad/s
    gravity = [0.0, -9.81]            # m/s² (optional)
    drive = "free"                    # or "constant-speed"

Every error names the file, the key and the value; unknown keys are errors (a typo such as
``mas`` must not be silently ignored).
"""

from __future__ import annotations

import math
import os
import tomllib
from pathlib import Path
from typing import Any

from .. import validate as v
from ..errors import SpecError
from ..mechanisms import mechanism_of
from ..mechanisms.engine.model import Engine
from ..mechanisms.fourbar.model import FourBar
from ..mechanisms.slidercrank.model import SliderCrank
from ..model import (
    GROUND,
    Body,
    ChainModel,
    Design,
    GasForce,
    Link,
    Linkage,
    Operation,
    SimulationSettings,
    Slider,
    Spring,
)
from ..model import MechanismModel as Model
from . import schema
from .balance import read_balance
from .engine import read_engine, read_engine_balance
from .links import read_link
from .tables import Table

MECHANISMS: dict[str, type[Model]] = {
    "four-bar": FourBar, "slider-crank": SliderCrank, "linkage": Linkage, "engine": Engine}


MECHANISM_TYPES = tuple(MECHANISMS)


def _read_gas_force(table: Table) -> GasForce:
    """``gas_force = 1500.0`` or ``gas_force = {crank_angle = [...], force = [...], period}``."""
    key = table.key("gas_force")
    if not table.has("gas_force"):
        return GasForce()
    raw = table.raw("gas_force")
    if not isinstance(raw, dict):
        return GasForce.constant(v.number(raw, key))
    sub = Table(raw, key)
    sub.expect(schema.known("links.<link>.gas_force", schema.SLIDER_CRANK))
    for name in ("crank_angle", "force"):
        if not sub.has(name):
            raise sub._missing(name)
        if not isinstance(sub.data[name], list):
            raise SpecError("must be a non-empty list of numbers", key=sub.key(name),
                            value=sub.data[name])
    with v.under(key):
        gas = GasForce(angles=sub.raw("crank_angle"), values=sub.raw("force"),
                       period=sub.value("period", 2 * math.pi))
    sub.finish()
    return gas


def _read_links(table: Table, mechanism_class: type[Model],
                names: tuple[str, ...] | None = None) -> tuple[dict[str, Link], GasForce]:
    """The links of a mechanism, and the gas force on its slider (if it has one).

    ``names``: the links to read (by default the mechanism class's own).
    """
    if names is None:
        assert issubclass(mechanism_class, ChainModel)  # (a general linkage's are named)
        names = mechanism_class.chain_links
    table.expect(schema.known(table.path, mechanism_class.type) or names)
    links = {}
    gas = GasForce()
    for name in names:
        sub = table.table(name)
        assert sub is not None
        links[name] = read_link(sub, name, mechanism_class)
        if mechanism_class is SliderCrank and name == "slider":
            gas = _read_gas_force(sub)
        sub.finish()
    table.finish()
    return links, gas


def _read_mechanism(root: Table) -> Model:
    mech = root.table("mechanism")
    assert mech is not None
    kind = mech.string("type", choices=MECHANISM_TYPES)
    cls = MECHANISMS[kind]
    if issubclass(cls, Linkage):  # (it is Linkage)
        return _read_linkage(root, mech)
    if issubclass(cls, Engine):
        return read_engine(root, mech)
    assert issubclass(cls, ChainModel)
    mech.expect(schema.known("mechanism", kind))
    branch = mech.string("branch", choices=("+", "-"), default="+")
    lengths_table = mech.table("lengths")
    assert lengths_table is not None
    lengths_table.expect(schema.known("mechanism.lengths", kind))
    lengths: list[Any] = []  # as written: the mechanism checks them
    for name in cls.length_names:
        if name == "offset":
            lengths.append(lengths_table.value(name, 0.0))
        elif not lengths_table.has(name):
            raise lengths_table._missing(name)
        else:
            lengths.append(lengths_table.raw(name))
    lengths_table.finish()
    mech.finish()
    links_table = root.table("links")
    assert links_table is not None
    links, gas = _read_links(links_table, cls)
    # The mechanism checks its lengths (keys from the root: mechanism.lengths.crank), that it
    # assembles, and its links.
    fields: dict[str, Any] = {"lengths": tuple(lengths), "branch": branch, **links}
    if cls is SliderCrank:
        return SliderCrank(gas_force=gas, **fields)
    return FourBar(**fields)


def _names(table: Table, name: str) -> tuple[str, ...]:
    """A required list of names (strings)."""
    if not table.has(name):
        raise table._missing(name)
    raw = table.raw(name)
    if not isinstance(raw, list) or not all(isinstance(x, str) for x in raw):
        raise SpecError("must be a list of names", key=table.key(name), value=raw)
    return tuple(raw)


def _read_linkage(root: Table, mech: Table) -> Linkage:
    """A general linkage (``type = "linkage"``; DESIGN.md, "General planar linkages")."""
    mech.expect(schema.known("mechanism", schema.LINKAGE))
    if not mech.has("input"):
        raise mech._missing("input")
    input_name = mech.raw("input")
    if not isinstance(input_name, str):
        raise SpecError("must be the name of a link", key=mech.key("input"), value=input_name)
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
        props = read_link(link, name, Linkage, frame)
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
    return Linkage(points=tuple(points.items()), bodies=tuple(bodies), input=input_name,
                   sliders=tuple(Slider(**f) for f in sliders), springs=tuple(springs))


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


def _read_operation(root: Table) -> Operation | None:
    table = root.table("operation", required=False)
    if table is None:
        return None
    if not table.has("speed"):
        raise table._missing("speed")
    with v.under("operation"):
        operation = Operation(speed=table.raw("speed"), samples=table.value("samples", 360),
                              gravity=table.value("gravity", (0.0, 0.0)))
    table.finish()
    return operation


def _read_simulation(root: Table, mechanism: Model) -> SimulationSettings:
    table = root.table("simulation", required=False)
    defaults = SimulationSettings()
    if table is None:
        return defaults
    method = table.string("method", choices=mechanism_of(mechanism).formulation_names,
                          default="") or None
    with v.under("simulation"):
        settings = SimulationSettings(
            **{name: table.value(name, getattr(defaults, name))
               for name in ("duration", "theta1", "omega1", "gravity", "drive", "rtol", "atol",
                            "outputs")},
            method=method,
        )
    table.finish()
    return settings


def _read_original(root: Table, mechanism: Model) -> Model | None:
    table = root.table("original", required=False)
    if table is None:
        return None
    links, _ = _read_links(table, type(mechanism), tuple(mechanism.link_names))
    return mechanism.with_links(links)


def design_from_dict(data: dict[str, Any], source: str | None = None) -> Design:
    """Validate a parsed TOML document and build the :class:`~balancer.model.Design`.

    Raises
    ------
    SpecError
        With the key and value at fault and ``source`` as the file name.
    """
    try:
        root = Table(data, "")
        title = root.text("title", default="")
        mechanism = _read_mechanism(root)
        root.expect(schema.known("", mechanism.type))  # the top-level tables of its type
        operation = _read_operation(root)
        simulation = _read_simulation(root, mechanism)
        balance = None
        if root.has("balance"):
            table = root.table("balance")
            balance = (read_engine_balance(table, mechanism) if isinstance(mechanism, Engine)
                       else read_balance(table, mechanism))
        original = _read_original(root, mechanism)
        root.finish()
        return Design(
            mechanism=mechanism,
            operation=operation,
            simulation=simulation,
            balance=balance,
            original=original,
            title=title,
        )
    except SpecError as exc:
        if source is not None and exc.source is None:
            raise exc.with_source(source) from None
        raise


def load_design(path: str | os.PathLike[str]) -> Design:
    """Read and validate a design spec from a TOML file.

    Raises
    ------
    SpecError
        If the file cannot be read, is not valid TOML, or fails validation.
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise SpecError("no such file", source=str(p)) from None
    except OSError as exc:
        raise SpecError(f"cannot read the file ({exc.strerror})", source=str(p)) from None
    try:
        # "utf-8-sig": a byte-order mark, as some Windows editors write, is not content
        data = tomllib.loads(raw.decode("utf-8-sig"))
    except UnicodeDecodeError:
        raise SpecError("not a UTF-8 text file", source=str(p)) from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"not valid TOML: {exc}", source=str(p)) from None
    return design_from_dict(data, source=str(p))


def loads_design(text: str, source: str = "<string>") -> Design:
    """Read and validate a design spec from TOML text."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"not valid TOML: {exc}", source=source) from None
    return design_from_dict(data, source=source)
