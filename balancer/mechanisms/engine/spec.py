"""An engine's tables of a spec (``type = "engine"``; DESIGN.md, "Engines"): read and written.

``[mechanism]`` (strokes, firing order, every cylinder's lengths and ``[[mechanism.cylinders]]``),
``[links.crankshaft]``, ``[links.rod]``, ``[links.piston]``, ``[[crankshafts]]``,
``[[balance_shafts]]`` and ``[gas]``.
Angles are in degrees, as the spec writes them: what is written reads back exactly. Reached
through the registry (:func:`balancer.mechanisms.folder_module`) by the spec
reader and writer (:mod:`balancer.spec`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, cast

from ... import tomltext as toml
from ... import validate as v
from ...errors import SpecError
from ...model import Link
from ...model import MechanismModel as Model
from ...model.balance import (
    ENGINE_OBJECTIVE_KEYS,
    CounterweightPlanes,
    RotorBalanceProblem,
    ShaftFreedom,
)
from ...model.parts import SHAPES, Sector
from ...spec import schema
from ...spec.links import read_link
from ...spec.parts import part_text, read_part
from ...spec.tables import Table
from .model import BalanceShaft, Crankshaft, Cylinder, Engine, GasCycle, GearedCrankshaft, Mass

#: The cylinder's lengths, in ``[mechanism.lengths]`` and each ``[[mechanism.cylinders]]``.
LENGTHS = ("crank", "rod", "offset", "bore")


def _masses(table: Table, name: str) -> tuple[Mass, ...]:
    out = []
    for sub in table.tables(name):
        sub.expect(schema.known(sub.path, schema.ENGINE))
        if not sub.has("mr"):
            raise sub._missing("mr")
        with v.under(sub.path):
            out.append(Mass(mr=sub.raw("mr"), phase_deg=sub.value("phase_deg", 0.0),
                            z=sub.value("z", 0.0), label=sub.value("label", "")))
        sub.finish()
    return tuple(out)


def _cylinders(mech: Table) -> tuple[Cylinder, ...]:
    lengths = mech.table("lengths")
    lengths.expect(schema.known(lengths.path, schema.ENGINE))
    common = {k: lengths.raw(k) for k in LENGTHS if lengths.has(k)}
    lengths.finish()
    tables = mech.tables("cylinders")
    if not tables:
        raise SpecError("an engine needs at least one cylinder ([[mechanism.cylinders]])",
                        key=mech.key("cylinders"))
    out = []
    for sub in tables:
        sub.expect(schema.known(sub.path, schema.ENGINE))
        own = {k: sub.raw(k) for k in LENGTHS if sub.has(k)}
        fields: dict[str, Any] = {**common, **own}
        for k in ("crank", "rod"):
            if k not in fields:
                raise SpecError("missing required key (here or in [mechanism.lengths])",
                                key=sub.key(k))
        try:
            cylinder = Cylinder(z=sub.value("z", 0.0), phase_deg=sub.value("phase_deg", 0.0),
                                bank_deg=sub.value("bank_deg", 0.0),
                                crankshaft=sub.raw("crankshaft") if sub.has("crankshaft") else 1,
                                **fields)
        except SpecError as exc:  # named where the value was given: here, or for every cylinder
            name = (exc.key or "").split(".")[-1]
            mine = [k for k in ("offset", "crank") if k in own]
            if name == "rod" and "rod" not in own and mine:  # (this cylinder's own length)
                raise SpecError(exc.detail, key=sub.key(mine[0]),
                                value=own[mine[0]]) from None
            raise exc.under(lengths.path if name in common and name not in own
                            else sub.path) from None
        out.append(cylinder)
        sub.finish()
    return tuple(out)


def _link(links: Table, name: str) -> Table:
    """``[links.<name>]`` of an engine, with only the keys that link takes."""
    table = links.table(name)
    table.expect(schema.known("links.<link>", schema.ENGINE))
    for key in table.data:
        if key not in schema.ENGINE_LINKS[name]:
            raise SpecError(f"is not a key of an engine's {name} (it takes "
                            f"{', '.join(schema.ENGINE_LINKS[name])})", key=table.key(key))
    return table


def _rod(links: Table) -> Link:
    table = _link(links, "rod")
    rod = read_link(table)
    table.finish()
    return rod


def _crankshaft(links: Table) -> Crankshaft:
    table = _link(links, "crankshaft")
    masses = _masses(table, "masses")  # (each under its own path, not under the shaft's too)
    with v.under(table.path):
        shaft = Crankshaft(inertia=table.value("inertia", 0.0), mass=table.value("mass", 0.0),
                           masses=masses)
    table.finish()
    return shaft


def _piston(links: Table) -> Any:
    """The piston's mass as written (the engine checks it)."""
    table = _link(links, "piston")
    if not table.has("mass"):
        raise table._missing("mass")
    mass = table.raw("mass")
    table.finish()
    return mass


def _shafts(root: Table) -> tuple[BalanceShaft, ...]:
    out = []
    for sub in root.tables("balance_shafts"):
        sub.expect(schema.known(sub.path, schema.ENGINE))
        if not sub.has("ratio"):
            raise sub._missing("ratio")
        eccentrics = _masses(sub, "eccentrics")  # (each under its own path)
        with v.under(sub.path):
            out.append(BalanceShaft(ratio=sub.raw("ratio"), at=sub.value("at", (0.0, 0.0)),
                                    inertia=sub.value("inertia", 0.0), eccentrics=eccentrics))
        sub.finish()
    return tuple(out)


def _geared(root: Table) -> tuple[GearedCrankshaft, ...]:
    """``[[crankshafts]]``: the crankshafts geared to the first."""
    out = []
    for sub in root.tables("crankshafts"):
        sub.expect(schema.known(sub.path, schema.ENGINE))
        if not sub.has("at"):
            raise sub._missing("at")
        masses = _masses(sub, "masses")  # (each under its own path)
        bearings = sub.value("main_bearings", ())
        if not isinstance(bearings, list | tuple):
            raise SpecError("must be a list of planes (m)", key=sub.key("main_bearings"),
                            value=bearings)
        with v.under(sub.path):
            out.append(GearedCrankshaft(at=sub.raw("at"), ratio=sub.value("ratio", -1),
                                        inertia=sub.value("inertia", 0.0),
                                        mass=sub.value("mass", 0.0), masses=masses,
                                        idler_inertia=sub.value("idler_inertia", 0.0),
                                        main_bearings=tuple(bearings),
                                        gear_z=sub.value("gear_z", 0.0)))
        sub.finish()
    return tuple(out)


def _gas(root: Table) -> GasCycle | None:
    table = root.table("gas", required=False)
    if table is None:
        return None
    table.expect(schema.known("gas", schema.ENGINE))
    for name in ("crank_angle_deg", "pressure"):
        if not table.has(name):
            raise table._missing(name)
        if not isinstance(table.data[name], list) or not table.data[name]:
            raise SpecError("must be a non-empty list of numbers", key=table.key(name),
                            value=table.data[name])
    with v.under("gas"):
        gas = GasCycle(crank_angle_deg=table.raw("crank_angle_deg"),
                       pressure=table.raw("pressure"),
                       crankcase=table.value("crankcase", 1.0e5))
    table.finish()
    return gas


def read(root: Table, mech: Table) -> Engine:
    """An engine from a spec's root table and its ``[mechanism]`` (its ``type`` read)."""
    mech.expect(schema.known("mechanism", schema.ENGINE))
    strokes = mech.value("strokes", 4)
    order = mech.value("firing_order", None)
    if order is not None and not isinstance(order, list):
        raise SpecError("must be a list of cylinder numbers", key=mech.key("firing_order"),
                        value=order)
    bearings = mech.value("main_bearings", ())
    if not isinstance(bearings, list | tuple):
        raise SpecError("must be a list of planes (m)", key=mech.key("main_bearings"),
                        value=bearings)
    cylinders = _cylinders(mech)
    mech.finish()
    links = root.table("links")
    links.expect(schema.known("links", schema.ENGINE))
    crankshaft, rod, piston = _crankshaft(links), _rod(links), _piston(links)
    links.finish()
    return Engine(cylinders=cylinders, crankshaft=crankshaft, rod=rod, piston=piston,
                  balance_shafts=_shafts(root), strokes=strokes,
                  firing_order=None if order is None else tuple(order), gas=_gas(root),
                  main_bearings=tuple(bearings), crankshafts=_geared(root))


def _mass_text(m: Mass) -> str:
    label = f", label = {toml.string(m.label)}" if m.label else ""
    return (f"{{ mr = {toml.number(m.mr)}, phase_deg = {toml.number(m.phase_deg)}, "
            f"z = {toml.number(m.z)}{label} }}")


def _masses_lines(key: str, masses: tuple[Mass, ...]) -> list[str]:
    if not masses:
        return []
    return [f"{key} = [", *(f"  {_mass_text(m)}," for m in masses), "]  # kg·m, °, m"]


def _links_lines(model: Engine, prefix: str) -> list[str]:
    """``[<prefix>.crankshaft]``, ``[<prefix>.rod]`` and ``[<prefix>.piston]``."""
    shaft, rod = model.crankshaft, model.rod
    out = ["", f"[{prefix}.crankshaft]", f"inertia = {toml.number(shaft.inertia)}  # kg·m²"]
    if shaft.mass:
        out.append(f"mass = {toml.number(shaft.mass)}  # kg")
    out += _masses_lines("masses", shaft.masses)
    out += ["", f"[{prefix}.rod]", f"mass = {toml.number(rod.mass)}  # kg",
            f"inertia = {toml.number(rod.inertia)}  # kg·m² about its centre of mass",
            f"com = {{ e = {toml.number(rod.e)}, f = {toml.number(rod.f)} }}  # m from the big "
            "end",
            "", f"[{prefix}.piston]", f"mass = {toml.number(model.piston)}  # kg"]
    return out


def _geared_lines(model: Engine, key: str) -> list[str]:
    """Each geared crankshaft as ``[[<key>]]``."""
    out: list[str] = []
    for g in model.crankshafts:
        out += ["", f"[[{key}]]", f"at = [{toml.number(g.at[0])}, {toml.number(g.at[1])}]  # m",
                f"ratio = {g.ratio}", f"inertia = {toml.number(g.inertia)}  # kg·m²"]
        if g.mass:
            out.append(f"mass = {toml.number(g.mass)}  # kg")
        if g.ratio == 1:
            out.append(f"idler_inertia = {toml.number(g.idler_inertia)}  # kg·m²")
        if g.main_bearings:
            out.append(f"main_bearings = [{', '.join(toml.number(z) for z in g.main_bearings)}]"
                       "  # m")
        if g.gear_z or g.main_bearings or model.main_bearings:
            out.append(f"gear_z = {toml.number(g.gear_z)}  # m: its gears' plane")
        out += _masses_lines("masses", g.masses)
    return out


def _shafts_lines(model: Engine, key: str) -> list[str]:
    """Each balance shaft as ``[[<key>]]``."""
    out: list[str] = []
    for s in model.balance_shafts:
        out += ["", f"[[{key}]]", f"ratio = {s.ratio}",
                f"at = [{toml.number(s.at[0])}, {toml.number(s.at[1])}]  # m",
                f"inertia = {toml.number(s.inertia)}  # kg·m²",
                *_masses_lines("eccentrics", s.eccentrics)]
    return out


def lines(model: Model) -> list[str]:
    """The engine's ``[mechanism]``, ``[links]``, ``[[balance_shafts]]`` and ``[gas]``."""
    assert isinstance(model, Engine)
    out = ["[mechanism]", 'type = "engine"', f"strokes = {model.strokes}"]
    if model.firing_order is not None:
        out.append(f"firing_order = [{', '.join(str(k) for k in model.firing_order)}]")
    if model.main_bearings:
        out.append(f"main_bearings = [{', '.join(toml.number(z) for z in model.main_bearings)}]"
                   "  # m")
    first = model.cylinders[0]
    out += ["", "[mechanism.lengths]  # m, every cylinder's",
            f"crank = {toml.number(first.crank)}", f"rod = {toml.number(first.rod)}",
            f"offset = {toml.number(first.offset)}"]
    shared_bore = all(c.bore == first.bore for c in model.cylinders)
    if shared_bore and first.bore is not None:
        out.append(f"bore = {toml.number(first.bore)}")
    for c in model.cylinders:
        out += ["", "[[mechanism.cylinders]]", f"z = {toml.number(c.z)}  # m",
                f"phase_deg = {toml.number(c.phase_deg)}",
                f"bank_deg = {toml.number(c.bank_deg)}"]
        out += [f"{k} = {toml.number(getattr(c, k))}  # m" for k in LENGTHS
                if getattr(c, k) is not None
                and (getattr(c, k) != getattr(first, k) or (k == "bore" and not shared_bore))]
        if c.crankshaft != 1:
            out.append(f"crankshaft = {c.crankshaft}")
    out += (_links_lines(model, "links") + _geared_lines(model, "crankshafts")
            + _shafts_lines(model, "balance_shafts"))
    if model.gas is not None:
        g = model.gas
        out += ["", "[gas]",
                f"crank_angle_deg = [{', '.join(toml.number(a) for a in g.crank_angle_deg)}]",
                f"pressure = [{', '.join(toml.number(p) for p in g.pressure)}]  # Pa",
                f"crankcase = {toml.number(g.crankcase)}  # Pa"]
    return out


# -- [balance]: counterweights and new shafts (DESIGN.md, "Balancing an engine") -------------


def read_balance(table: Table, engine: Model) -> RotorBalanceProblem:
    """An engine's ``[balance]``: the objective, the counterweights' planes, the new shafts."""
    if table.has("force_balance"):
        raise SpecError("does not apply to an engine: its balancing chooses counterweights and "
                        "shafts ([balance.counterweights], [[balance.shafts]])",
                        key=table.key("force_balance"), value=table.raw("force_balance"))
    if table.has("max_speed_fluctuation"):
        raise SpecError("does not apply to an engine's balancing (its counterweights leave "
                        "the crankshaft's inertia as it is): [operation] speed_fluctuation "
                        "gives the flywheel it needs", key=table.key("max_speed_fluctuation"),
                        value=table.raw("max_speed_fluctuation"))
    table.expect(schema.known("balance", schema.ENGINE))
    defaults = RotorBalanceProblem().objective
    objective = defaults
    sub = table.table("objective", required=False)
    if sub is not None:
        weights = schema.known("balance.objective", schema.ENGINE)
        for name in sub.data:  # a linkage's weight (driving_torque, added_mass, …)
            if name not in weights and name in schema.known("balance.objective"):
                raise SpecError("does not apply to an engine's balancing (its keys here: "
                                f"{', '.join(weights)})", key=sub.key(name),
                                value=sub.raw(name))
        sub.expect(weights)
        objective = replace(defaults, **{name: sub.nonnegative(name, default=getattr(
            defaults, name)) for name in ENGINE_OBJECTIVE_KEYS})
        sub.finish()
    counterweights = None
    sub = table.table("counterweights", required=False)
    if sub is not None:
        sub.expect(schema.known("balance.counterweights", schema.ENGINE))
        if not sub.has("max_mr"):
            raise sub._missing("max_mr")
        part = _sector(sub.table("part", required=False))
        every = cast("Engine", engine).shafts
        with v.under(sub.path):
            counterweights = CounterweightPlanes(
                planes=sub.value("planes", list(cast("Engine", engine).counterweight_planes)),
                max_mr=sub.raw("max_mr"), radius=sub.value("radius", None), part=part,
                crankshafts=sub.raw("crankshafts") if sub.has("crankshafts") else None)
        if part is not None and (counterweights.crankshafts or every) != (1,):
            raise SpecError("sizes the first crankshaft's crank webs: with a part, the "
                            "counterweights go on it alone (crankshafts = [1])",
                            key=sub.key("part"))
        sub.finish()
    shafts = []
    for sub in table.tables("shafts"):
        sub.expect(schema.known(sub.path, schema.ENGINE))
        for name in ("ratio", "planes", "max_mr"):
            if not sub.has(name):
                raise sub._missing(name)
        with v.under(sub.path):
            shafts.append(ShaftFreedom(ratio=sub.raw("ratio"), at=sub.value("at", (0.0, 0.0)),
                                       planes=sub.raw("planes"), max_mr=sub.raw("max_mr")))
        sub.finish()
    bound = table.value("max_bearing_load", None)
    weighted = [name for name in ("main_bearing_load", "largest_bearing_load")
                if getattr(objective, name)]
    if bound is not None or weighted:
        key = (table.key("max_bearing_load") if bound is not None
               else f"balance.objective.{weighted[0]}")
        model = cast("Engine", engine)
        if not any(model.shaft_bearings(k) for k in model.shafts):
            raise SpecError("needs the main bearings' planes: [mechanism] main_bearings",
                            key=key)
    table.finish()
    with v.under(table.path):
        return RotorBalanceProblem(objective=objective, counterweights=counterweights,
                                   shafts=tuple(shafts), max_bearing_load=bound)


def _sector(table: Table | None) -> Sector | None:
    """``[balance.counterweights] part``: a crank-web sector (another shape refused first)."""
    if table is None:
        return None
    shape = table.data.get("shape")
    if shape is not None and shape != "sector" and shape in SHAPES:
        raise SpecError('an engine\'s crankshaft counterweights are crank-web sectors about the '
                        'crank\'s axis: must be "sector"', key=table.key("shape"), value=shape)
    part = read_part(table)
    assert isinstance(part, Sector)
    return part


def _numbers(values: tuple[float, ...]) -> str:
    return f"[{', '.join(toml.number(x) for x in values)}]"


def balance_lines(problem: object) -> list[str]:
    """The problem as TOML lines that :func:`read_balance` reads back equal."""
    assert isinstance(problem, RotorBalanceProblem)
    w = problem.objective
    out = ["[balance.objective]  # weights of the mean squares over the cycle"
           + (" (largest_bearing_load: of the largest load's square)"
              if w.largest_bearing_load else ""),
           *(f"{name} = {toml.number(getattr(w, name))}" for name in ENGINE_OBJECTIVE_KEYS
             if name not in ("main_bearing_load", "largest_bearing_load") or getattr(w, name))]
    if problem.max_bearing_load is not None:
        out = ["[balance]", f"max_bearing_load = {toml.number(problem.max_bearing_load)}  # N",
               "", *out]
    cws = problem.counterweights
    if cws is not None:
        out += ["", "[balance.counterweights]  # on the crankshaft",
                f"planes = {_numbers(cws.planes)}  # m",
                f"max_mr = {_numbers(cws.max_mr)}  # kg·m"]
        if cws.radius is not None:
            out.append(f"radius = {toml.number(cws.radius)}  # m")
        if cws.part is not None:
            out.append(f"part = {part_text(cws.part)}  # m, °: each plane's crank-web sector")
        if cws.crankshafts is not None:
            out.append(f"crankshafts = [{', '.join(str(k) for k in cws.crankshafts)}]")
    for s in problem.shafts:
        out += ["", "[[balance.shafts]]  # a new shaft, sized by the optimiser",
                f"ratio = {s.ratio}", f"at = {_numbers(s.at)}  # m",
                f"planes = {_numbers(s.planes)}  # m", f"max_mr = {_numbers(s.max_mr)}  # kg·m"]
    return out


def read_original(table: Table, model: Model) -> Model:
    """``[original]``: the same engine with the links and balance shafts given there.

    Its cylinders, firing order and gas are the design's; its crankshaft (with every mass it
    carried), rod and piston are required, its balance shafts (``[[original.balance_shafts]]``)
    none where there are none.
    """
    assert isinstance(model, Engine)
    table.expect(schema.known("original", schema.ENGINE))
    crankshaft, rod, piston = _crankshaft(table), _rod(table), _piston(table)
    shafts = _shafts(table)
    geared = _geared(table)
    if len(geared) != len(model.crankshafts):
        raise SpecError(f"must be the design's geared crankshafts ({len(model.crankshafts)}), "
                        "each with the masses it had: [[original.crankshafts]]",
                        key=table.key("crankshafts"), value=len(geared))
    for j, (old, new) in enumerate(zip(geared, model.crankshafts, strict=True)):
        if (old.at, old.ratio) != (new.at, new.ratio):
            raise SpecError(f"must be the design's axis {list(new.at)} and ratio {new.ratio}: the "
                            "original differs in its masses only",
                            key=f"{v.item(table.key('crankshafts'), j)}.at", value=list(old.at))
    table.finish()
    piston = v.positive(piston, table.key("piston.mass"))  # (named here, not as [links]')
    return replace(model, crankshaft=crankshaft, rod=rod, piston=piston, balance_shafts=shafts,
                   crankshafts=geared)


def original_lines(model: Model) -> list[str]:
    """``model``'s links and balance shafts as ``[original.…]`` tables (:func:`read_original`).

    ``[original.crankshaft]``, ``[original.rod]``, ``[original.piston]`` and
    ``[[original.balance_shafts]]``.
    """
    assert isinstance(model, Engine)
    return (_links_lines(model, "original") + _geared_lines(model, "original.crankshafts")
            + _shafts_lines(model, "original.balance_shafts"))


#: Its ``[balance]``: read and written by this module (:func:`read_balance`,
#: :func:`balance_lines`).
BALANCE = __name__

__all__ = ["BALANCE", "balance_lines", "lines", "original_lines", "read", "read_balance",
           "read_original"]
