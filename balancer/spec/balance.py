"""The ``[balance]`` table of a spec: read into the schema, checked, and written back exactly."""

from __future__ import annotations

import math

from .. import tomltext as toml
from ..balance.bounds import check_problem
from ..errors import SpecError
from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism
from ..model import MechanismModel as Model
from ..model.balance import (
    FORCE_SCOPES,
    OBJECTIVE_KEYS,
    BalanceProblem,
    CounterweightFreedom,
    LinkFreedom,
    Objective,
)
from ..quantities import unit_of
from ..validate import LENGTH_RANGE
from . import schema
from .parts import part_text, read_part
from .tables import Table, hint


def _check_keys(table: Table, known: tuple[str, ...], *, elsewhere: tuple[str, ...] = (),
                kind: str = "") -> None:
    """Reject unknown keys first, with a suggestion for a typo.

    A key of the table in another mechanism's spec (``elsewhere``: an engine's ``unbalance``
    in a linkage's objective) is said not to apply to a ``kind``, with the keys that do.
    """
    for name in table.data:
        if name in known:
            continue
        if name in elsewhere:
            raise SpecError(f"does not apply to a {kind}'s balancing (its keys here: "
                            f"{', '.join(known)})", key=table.key(name),
                            value=table.raw(name))
        raise SpecError(f"unknown key '{name}'{hint(name, known)}", key=table.key(name))


def _read_range(
    table: Table, name: str, *, positive: bool, unit: str
) -> tuple[float, float] | None:
    """A number (fixes the value) or a list ``[low, high]``; ``None`` if absent."""
    if not table.has(name):
        return None
    key = table.key(name)
    value = table.raw(name)
    if isinstance(value, list):
        if len(value) != 2:
            raise SpecError(
                f"must be a number or a range [low, high] in {unit}", key=key, value=value
            )
        items = value
    else:
        items = [value, value]
    bounds = []
    for item in items:
        if isinstance(item, bool) or not isinstance(item, int | float):
            raise SpecError(
                f"must be a number or a range [low, high] in {unit}", key=key, value=value
            )
        x = float(item)
        if not math.isfinite(x):
            raise SpecError("must be finite", key=key, value=value)
        if positive and x <= 0:
            raise SpecError("bounds must be positive", key=key, value=value)
        if x < 0:
            raise SpecError("bounds must be zero or positive", key=key, value=value)
        bounds.append(x)
    lo, hi = bounds
    if lo > hi:
        raise SpecError("the lower bound exceeds the upper bound", key=key, value=value)
    return (lo, hi)


def _read_link_freedom(table: Table, points: tuple[str, ...]) -> LinkFreedom:
    _check_keys(table, schema.known("balance.<link>"))
    com_about = None
    if table.has("com_about"):
        com_about = table.string("com_about", choices=points)
    counterweight = None
    sub = table.table("counterweight", required=False)
    if sub is not None:
        for name in ("mass", "com_radius", "min_gyration", "inertia"):
            if table.has(name):
                raise SpecError("a link with a counterweight is kept as it is: give the "
                                "counterweight's bounds only (counterweight = {mass, radius, "
                                "gyration})", key=table.key(name), value=table.raw(name))
        _check_keys(sub, schema.known("balance.<link>.counterweight"))
        mass = _read_range(sub, "mass", positive=False, unit="kg")
        if mass is None:
            raise SpecError("missing required key (the counterweight's mass, [low, high] kg)",
                            key=sub.key("mass"))
        part_table = sub.table("part", required=False)
        counterweight = CounterweightFreedom(
            mass=mass, radius=sub.nonnegative("radius"),
            gyration=sub.nonnegative("gyration", default=0.0),
            part=None if part_table is None else read_part(part_table))
        if counterweight.gyration > LENGTH_RANGE[1]:
            raise SpecError(f"must be at most {LENGTH_RANGE[1]:g} m", key=sub.key("gyration"),
                            value=counterweight.gyration)
        sub.finish()
    freedom = LinkFreedom(
        mass=_read_range(table, "mass", positive=True, unit="kg"),
        com_radius=table.nonnegative("com_radius") if table.has("com_radius") else None,
        com_about=com_about,
        min_gyration=table.nonnegative("min_gyration") if table.has("min_gyration") else None,
        inertia=_read_range(table, "inertia", positive=False, unit="kg·m²"),
        counter_rotor=_read_range(table, "counter_rotor", positive=False, unit="kg·m²"),
        counterweight=counterweight,
        com_on_line=_read_flag(table, "com_on_line"),
    )
    table.finish()
    return freedom


def _read_flag(table: Table, name: str) -> bool:
    """A ``true``/``false`` key (absent: false)."""
    if not table.has(name):
        return False
    value = table.raw(name)
    if not isinstance(value, bool):
        raise SpecError("must be true or false", key=table.key(name), value=value)
    return value


def read_balance(table: Table, mechanism: Model | Mechanism) -> BalanceProblem:
    """Read and validate a spec's ``[balance]`` table (called by :mod:`balancer.spec`).

    Parameters
    ----------
    table
        The ``[balance]`` table being read.
    mechanism
        The spec's mechanism (a model or a :class:`Mechanism`), for the links' points and the
        values of what stays fixed.

    Raises
    ------
    SpecError
        Naming the key and value at fault (see :func:`check_problem`).
    """
    mech = mechanism_of(mechanism)
    names = mech.linkage.link_names
    for name, value in table.data.items():  # a table for a link the mechanism does not have
        if isinstance(value, dict) and name not in ("objective", "motions", *names):
            raise SpecError(f"names no moving link of the {mech.model.type}{hint(name, names)} "
                            f"(its moving links are {', '.join(names)}; the frame stays as it is)",
                            key=table.key(name))
    _check_keys(table, (*schema.known("balance"), *names))
    force_balance = True
    if table.has("force_balance"):
        value = table.raw("force_balance")
        if not isinstance(value, bool):
            raise SpecError("must be true or false", key=table.key("force_balance"), value=value)
        force_balance = value
    force_scope = "every-motion"
    if table.has("force"):
        force_scope = table.raw("force")
        if force_scope not in FORCE_SCOPES:
            raise SpecError(f"must be one of {', '.join(FORCE_SCOPES)}",
                            key=table.key("force"), value=force_scope)
        if force_scope == "motion" and len(mech.linkage.inputs) < 2:
            raise SpecError("balances a linkage with several inputs along its motions only; "
                            "a one-input mechanism's balance holds over its revolution",
                            key=table.key("force"), value=force_scope)
    objective = Objective()
    sub = table.table("objective", required=False)
    if sub is not None:
        _check_keys(sub, schema.known("balance.objective", mech.model.type),
                    elsewhere=schema.known("balance.objective"), kind=mech.model.type)
        weights_of = {name: sub.nonnegative(name, default=getattr(objective, name))
                      for name in OBJECTIVE_KEYS}
        if sub.has("torque"):  # (DESIGN.md's name of the inputs' torques' term)
            if sub.has("driving_torque"):
                raise SpecError("give driving_torque or torque, not both (they are one term)",
                                key=sub.key("torque"), value=sub.raw("torque"))
            weights_of["driving_torque"] = sub.nonnegative("torque")
        objective = Objective(**weights_of)
        sub.finish()
    weights: dict[str, float] = {}
    sub = table.table("motions", required=False)
    if sub is not None:
        sub.known = tuple(sub.data)
        weights = {name: sub.nonnegative(name) for name in sub.data}
        sub.finish()
    points = tuple(p for p, _ in mech.linkage.points)
    links: dict[str, LinkFreedom] = {}
    for name in names:
        sub = table.table(name, required=False)
        if sub is not None:
            links[name] = _read_link_freedom(sub, points)
    fluctuation = table.value("max_speed_fluctuation", None)
    if fluctuation is not None and len(mech.linkage.inputs) > 1:
        raise SpecError("bounds the crank's speed fluctuation at the operating speed: a "
                        "linkage with several inputs has no one crank", key=table.key(
                            "max_speed_fluctuation"), value=fluctuation)
    table.finish()
    problem = BalanceProblem(force_balance=force_balance, force_scope=force_scope,
                             objective=objective, links=tuple(links.items()),
                             motion_weights=tuple(weights.items()),
                             max_speed_fluctuation=fluctuation)
    check_problem(problem, mech)
    return problem


def _bracketed(bounds: tuple[float, float]) -> str:
    return f"[{toml.number(bounds[0])}, {toml.number(bounds[1])}]"


def _range_text(bounds: tuple[float, float]) -> str:
    lo, hi = bounds
    return toml.number(lo) if lo == hi else f"[{toml.number(lo)}, {toml.number(hi)}]"


#: The objective's weights written whatever their value (the others where not zero; the
#: shaking force's components both where either is).
ALWAYS_WRITTEN = ("shaking_moment", "driving_torque", "shaking_force", "added_mass")


def _objective_lines(w: Objective) -> list[str]:
    """``[balance.objective]``'s lines: each weight of :data:`OBJECTIVE_KEYS` with its unit.

    The unit of a mean square's weight is ``(N·m)²`` over its quantity's unit squared (its
    unit from the quantity table), of the added mass's ``(N·m)²/kg``; the shaking moment's is
    1 and goes unsaid.
    """
    components = bool(w.shaking_force_x or w.shaking_force_y)
    out = []
    for key in OBJECTIVE_KEYS:
        weight = getattr(w, key)
        along = key.removeprefix("shaking_force_") if key.startswith("shaking_force_") else ""
        if key not in ALWAYS_WRITTEN and not weight and not (along and components):
            continue
        unit = unit_of(key)
        per = ("" if key == "shaking_moment" else
               "(N·m)²/kg" if key == "added_mass" else
               f"(N·m)²/{'(N·m)²' if unit == 'N·m' else unit + '²'}")
        note = per + (f", along {along}" if along else "")
        out.append(f"{key} = {toml.number(weight)}" + (f"  # {note}" if note else ""))
    return out


def balance_lines(problem: BalanceProblem) -> list[str]:
    """The problem as TOML lines that :func:`read_balance` reads back to an equal problem."""
    w = problem.objective
    lines = [
        "[balance]",
        f"force_balance = {'true' if problem.force_balance else 'false'}",
        *([f"force = {toml.string(problem.force_scope)}  # along the motions only"]
          if problem.force_scope != "every-motion" else []),
        *([f"max_speed_fluctuation = {toml.number(problem.max_speed_fluctuation)}  # "
           "(ω_max − ω_min)/ω_mean: the flywheel it needs goes on the crank"]
          if problem.max_speed_fluctuation is not None else []),
        "",
        "[balance.objective]  # J = mean(Msh²) + w_tau·mean(tau²) + w_force·mean(|Fsh|²)"
        " + w_mass·Δmass",
        *_objective_lines(w),
    ]
    if problem.motion_weights:
        lines += ["", "[balance.motions]  # each motion's weight in the objective"]
        lines += [f"{toml.key(name)} = {toml.number(w)}" for name, w in problem.motion_weights]
    for name, freedom in problem.links:
        lines += ["", f"[balance.{toml.key(name)}]"]
        if freedom.mass is not None:
            lines.append(f"mass = {_range_text(freedom.mass)}  # kg")
        if freedom.com_radius is not None:
            lines.append(f"com_radius = {toml.number(freedom.com_radius)}  # m")
        if freedom.com_about is not None:
            lines.append(f"com_about = {toml.string(freedom.com_about)}")
        if freedom.min_gyration is not None:
            lines.append(f"min_gyration = {toml.number(freedom.min_gyration)}  # m")
        if freedom.inertia is not None:
            lines.append(f"inertia = {_range_text(freedom.inertia)}  # kg·m² about the COM")
        if freedom.com_on_line:
            lines.append("com_on_line = true")
        if freedom.counterweight is not None:
            cw = freedom.counterweight
            part = "" if cw.part is None else f", part = {part_text(cw.part)}"
            lines.append(f"counterweight = {{ mass = {_bracketed(cw.mass)}, radius = "
                         f"{toml.number(cw.radius)}, gyration = {toml.number(cw.gyration)}"
                         f"{part} }}  # kg, m, m")
        if freedom.counter_rotor is not None:
            lines.append(f"counter_rotor = {_range_text(freedom.counter_rotor)}  # kg·m²")
    return lines
