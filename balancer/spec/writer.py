"""A design written back as a spec, exactly: what is read again is the same design."""

from __future__ import annotations

import os

from .. import tomltext as toml
from ..model import Design, SimulationSettings
from ..outputs import write_atomic
from . import schema
from .codecs import balance_spec_of, spec_of


def dumps_design(design: Design) -> str:
    """The design as TOML text that :func:`loads_design` reads back to an equal design."""
    codec = spec_of(design.mechanism.type)
    out: list[str] = []
    if design.title:
        out += [f"title = {toml.string(design.title)}", ""]
    out += codec.lines(design.mechanism)
    if design.operation is not None:
        op = design.operation
        out += [
            "",
            "[operation]",
            f"speed = {toml.number(op.speed)}  # rad/s",
            f"samples = {toml.number(op.samples)}",
            *([f"gravity = [{toml.number(op.gravity[0])}, {toml.number(op.gravity[1])}]  # m/s²"]
              if any(op.gravity) else []),
            *([f"speed_fluctuation = {toml.number(op.speed_fluctuation)}"]
              if op.speed_fluctuation is not None else []),
        ]
    sim, default = design.simulation, SimulationSettings()
    lines = {
        "duration": f"duration = {toml.number(sim.duration)}  # s",
        "theta1": f"theta1 = {toml.number(sim.theta1)}  # rad" if sim.theta1 is not None
        else None,
        "omega1": f"omega1 = {toml.number(sim.omega1)}  # rad/s",
        "gravity": f"gravity = [{toml.number(sim.gravity[0])}, {toml.number(sim.gravity[1])}]"
                   "  # m/s²",
        "drive": f'drive = "{sim.drive}"',
        "method": f'method = "{sim.method}"' if sim.method else None,
        "rtol": f"rtol = {toml.number(sim.rtol)}",
        "atol": f"atol = {toml.number(sim.atol)}",
        "outputs": f"outputs = {toml.number(sim.outputs)}",
    }
    # What the spec gave, or what differs from its default (a default left unsaid stays one:
    # verify sizes its runs where no duration is given).
    stated = [line for key, line in lines.items() if line is not None
              and (key in sim.given or getattr(sim, key) != getattr(default, key))]
    if stated:
        out += ["", "[simulation]", *stated]
    if design.balance is not None:
        out += ["", *balance_spec_of(design.mechanism.type).balance_lines(design.balance)]
    if design.original is not None:
        out += ["", "# The unbalanced design this one was derived from (same geometry)."]
        out += codec.original_lines(design.original)
    out += _motion_lines(design)
    return "\n".join(out) + "\n"


def _motion_lines(design: Design) -> list[str]:
    """``[workspace]`` and each ``[[motion]]``, as the reader reads them."""
    def pair(low: float, high: float) -> str:
        return f"[{toml.number(low)}, {toml.number(high)}]"

    out: list[str] = []
    w = design.workspace
    if w is not None:
        out += ["", "[workspace]  # each input's change from the reference pose, rad"]
        out += [f"{toml.key(r.name)} = {pair(r.low, r.high)}" for r in w.ranges]
        out.append(f"samples = {toml.number(w.samples)}")
        if w.joints:
            out += ["", "[workspace.joints]"]
            out += [f"{toml.key(r.name)} = {pair(r.low, r.high)}" for r in w.joints]
    for m in design.motions:
        out += ["", "[[motion]]", f"name = {toml.string(m.name)}"]
        if m.along is not None and m.pace is not None:  # a planned motion: a path and a pace
            rows = ",\n        ".join(f"[{toml.number(tau)}, {toml.number(rate)}]"
                                       for tau, rate in m.pace)
            out += [f"along = {toml.string(m.along)}",
                    f"pace = [{rows}]  # the path's argument (s) and its rate (s/s)",
                    f"samples = {toml.number(m.samples)}"]
            continue
        rows = ", ".join("[" + ", ".join(toml.number(x) for x in row) + "]" for row in m.path)
        if m.point is not None:
            out.append(f"point = {toml.string(m.point)}")
        out += [f"times = [{', '.join(toml.number(t) for t in m.times)}]  # s",
                f"path = [{rows}]  # {'m' if m.point is not None else 'rad'}",
                f"law = {toml.string(m.law)}"]
        if m.acc_time is not None:
            out.append(f"acc_time = {toml.number(m.acc_time)}  # s")
        out.append(f"samples = {toml.number(m.samples)}")
    return out + _plan_lines(design)


def _plan_lines(design: Design) -> list[str]:
    """``[plan]`` and its objective, as the reader reads them (given values only)."""
    plan = design.plan
    if plan is None:
        return []
    out = ["", "[plan]"]
    for key in ("motion", "name"):
        value = getattr(plan, key)
        if value is not None:
            out.append(f"{key} = {toml.string(value)}")
    if plan.duration is not None:
        out.append(f"duration = {toml.number(plan.duration)}  # s")
    out.append(f"measure = {toml.string(plan.measure)}")
    if plan.intervals is not None:
        out.append(f"intervals = {toml.number(plan.intervals)}")
    section = schema.section("plan")
    assert section is not None
    for key, unit in ((k.name, k.unit) for k in section.keys if k.name.startswith("max_")):
        limits = getattr(plan, key)
        if limits.every is not None:
            out.append(f"{key} = {toml.number(limits.every)}  # {unit}")
        elif limits.each:
            rows = ", ".join(f"{toml.key(name)} = {toml.number(x)}" for name, x in limits.each)
            out.append(f"{key} = {{ {rows} }}  # {unit}")
    out += ["", "[plan.objective]"]
    weights = {"shaking_moment": plan.objective.shaking_moment,  # (its default is 1)
               **plan.objective.terms()}
    out += [f"{name} = {toml.number(weight)}" for name, weight in weights.items()]
    return out


def save_design(design: Design, path: str | os.PathLike[str]) -> None:
    """Write the design to a TOML file, whole or not at all.

    Raises
    ------
    OutputError
        If the file cannot be written.
    """
    write_atomic(path, dumps_design(design))
