"""A design written back as a spec, exactly: what is read again is the same design."""

from __future__ import annotations

import os

from .. import tomltext as toml
from ..mechanisms.engine.model import Engine
from ..mechanisms.slidercrank.model import SliderCrank
from ..model import ChainModel, Design, GasForce, Link, Linkage, MechanismModel
from ..model.balance import RotorBalanceProblem
from ..outputs import write_atomic
from .balance import balance_lines
from .engine import engine_balance_lines, engine_lines


def _link_lines(link: Link, frame: str = "link") -> list[str]:
    lines = [
        f"mass = {toml.number(link.mass)}  # kg",
        f"inertia = {toml.number(link.inertia)}  # kg·m² about the centre of mass",
        f"com = {{ e = {toml.number(link.e)}, f = {toml.number(link.f)} }}  "
        + (f"# m (s = {link.s:.6g} m, sigma = {link.sigma:.6g} rad)" if frame == "link"
           else "# m from the pin, in global axes"),
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


def _gas_lines(gas: GasForce) -> list[str]:
    if gas.is_zero:
        return []
    if len(gas.values) == 1:
        return [f"gas_force = {toml.number(gas.values[0])}  # N along the guide"]
    angles = ", ".join(toml.number(a) for a in gas.angles)
    values = ", ".join(toml.number(v) for v in gas.values)
    return [f"gas_force = {{ crank_angle = [{angles}], force = [{values}], "
            f"period = {toml.number(gas.period)} }}  # rad, N"]


def _links_lines(mech: MechanismModel, prefix: str) -> list[str]:
    out: list[str] = []
    for name in mech.link_names:
        slider = isinstance(mech, SliderCrank) and name == "slider"  # (in global axes)
        out += ["", f"[{prefix}.{toml.key(name)}]",
                *_link_lines(mech.link(name), "global" if slider else "link")]
        if prefix == "links" and slider:
            assert isinstance(mech, SliderCrank)
            out += _gas_lines(mech.gas_force)
    return out


def _linkage_lines(mech: Linkage) -> list[str]:
    """A general linkage's ``[mechanism]``, ``[links]`` and ``[[springs]]``."""
    out = ["[mechanism]", 'type = "linkage"', f"input = {toml.string(mech.input)}", "",
           "[mechanism.points]  # m, at the reference pose"]
    out += [f"{toml.key(p)} = [{toml.number(x)}, {toml.number(y)}]" for p, (x, y) in mech.points]
    for s in mech.sliders:
        out += ["", "[[mechanism.sliders]]", f"link = {toml.string(s.link)}",
                f"guide = {toml.string(s.guide)}", f"point = {toml.string(s.point)}",
                f"direction = [{toml.number(s.direction[0])}, {toml.number(s.direction[1])}]"]
    for body in mech.bodies:
        names = ", ".join(map(toml.string, body.points))
        out += ["", f"[links.{toml.key(body.name)}]", f"points = [{names}]"]
        if body.props is not None:
            out += _link_lines(body.props)
    for spring in mech.springs:
        out += ["", "[[springs]]", f"points = [{', '.join(map(toml.string, spring.points))}]",
                f"stiffness = {toml.number(spring.stiffness)}  # N/m",
                f"free_length = {toml.number(spring.free_length)}  # m"]
    return out


def dumps_design(design: Design) -> str:
    """The design as TOML text that :func:`loads_design` reads back to an equal design."""
    mech = design.mechanism
    out: list[str] = []
    if design.title:
        out += [f"title = {toml.string(design.title)}", ""]
    if isinstance(mech, Linkage):
        out += _linkage_lines(mech)
    elif isinstance(mech, Engine):
        out += engine_lines(mech)
    else:
        assert isinstance(mech, ChainModel)
        out += ["[mechanism]", f'type = "{mech.type}"', f'branch = "{mech.branch}"', ""]
        out.append("[mechanism.lengths]  # m")
        for name, length in zip(mech.length_names, mech.lengths, strict=True):
            out.append(f"{name} = {toml.number(length)}")
        out += _links_lines(mech, "links")
    if design.operation is not None:
        op = design.operation
        out += [
            "",
            "[operation]",
            f"speed = {toml.number(op.speed)}  # rad/s",
            f"samples = {toml.number(op.samples)}",
            *([f"gravity = [{toml.number(op.gravity[0])}, {toml.number(op.gravity[1])}]  # m/s²"]
              if any(op.gravity) else []),
        ]
    sim = design.simulation
    out += [
        "",
        "[simulation]",
        f"duration = {toml.number(sim.duration)}  # s",
        *([f"theta1 = {toml.number(sim.theta1)}  # rad"] if sim.theta1 is not None else []),
        f"omega1 = {toml.number(sim.omega1)}  # rad/s",
        f"gravity = [{toml.number(sim.gravity[0])}, {toml.number(sim.gravity[1])}]  # m/s²",
        f'drive = "{sim.drive}"',
        *([f'method = "{sim.method}"'] if sim.method else []),
        f"rtol = {toml.number(sim.rtol)}",
        f"atol = {toml.number(sim.atol)}",
        f"outputs = {toml.number(sim.outputs)}",
    ]
    if design.balance is not None:
        out += ["", *(engine_balance_lines(design.balance)
                      if isinstance(design.balance, RotorBalanceProblem)
                      else balance_lines(design.balance))]
    if design.original is not None:
        out += ["", "# The unbalanced design this one was derived from (same geometry)."]
        out += _links_lines(design.original, "original")
    return "\n".join(out) + "\n"


def save_design(design: Design, path: str | os.PathLike[str]) -> None:
    """Write the design to a TOML file, whole or not at all.

    Raises
    ------
    OutputError
        If the file cannot be written.
    """
    write_atomic(path, dumps_design(design))
