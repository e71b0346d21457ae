"""A motion's time law planned to shake the frame least (``balancer plan``)."""

from __future__ import annotations

from dataclasses import replace

from .. import validate as v
from ..errors import SpecError
from ..mechanisms import mechanism_of
from ..model import Design
from ..model.motions import REVOLUTION, MotionSpec
from ..model.plan import PlanSpec
from ..planning import Plan, plan_motion, revolution
from .analysis import spec_gravity


def plan(design: Design, motion: str | None = None, *, settings: PlanSpec | None = None
         ) -> Plan:
    """The time law of a motion's path that shakes the frame least (:mod:`balancer.planning`).

    Parameters
    ----------
    design
        The design (a general linkage, ``type = "linkage"``).
    motion
        The motion whose path is run (its name, or ``"revolution"``), instead of the plan's.
    settings
        The plan, instead of the spec's ``[plan]`` (default: its, or the defaults).

    Raises
    ------
    SpecError
        If the motion is unknown, or a limit names no input.
    AssemblyError
        If the path leaves the workspace.
    SolverError
        If the limits cannot be met in the duration, or IPOPT fails.
    """
    if design.mechanism.type != "linkage":
        raise SpecError(f"plans a general linkage's motion (type = \"linkage\"; this spec's is "
                        f"\"{design.mechanism.type}\")", key="mechanism.type")
    spec = settings or design.plan or PlanSpec()
    mech = mechanism_of(design.mechanism)
    name = motion if motion is not None else spec.motion
    path = path_of(design, name, key="--motion" if motion is not None else "plan.motion")
    index = next((i for i, m in enumerate(design.motions) if m is path), None)
    with v.under("plan" if index is None else v.item("motion", index)):
        return plan_motion(mech, path, spec, gravity=spec_gravity(design))


def path_of(design: Design, name: str | None, *, key: str = "plan.motion") -> MotionSpec:
    """The motion whose path a plan runs: by name, the first, or a one-input revolution."""
    inputs = mechanism_of(design.mechanism).linkage.inputs
    if name == REVOLUTION or (name is None and not design.motions):
        if len(inputs) != 1 or design.operation is None:
            raise SpecError("a revolution is a one-input linkage's at its [operation] speed; "
                            "name a [[motion]]" if design.motions or len(inputs) != 1 else
                            "a one-input linkage's revolution needs its [operation] speed",
                            key=key, value=name)
        return revolution(design.operation.speed)
    if name is None:
        return design.motions[0]
    found = next((m for m in design.motions if m.name == name), None)
    if found is None:
        known = [m.name for m in design.motions] + ([REVOLUTION] if len(inputs) == 1 else [])
        raise SpecError(f"names no motion of the spec ({', '.join(known)})", key=key,
                        value=name)
    return found


def planned_design(design: Design, result: Plan) -> Design:
    """The design with the planned motion among its motions (replacing one of its name)."""
    motions = [m for m in design.motions if m.name != result.planned.name]
    return replace(design, motions=(*motions, result.planned))
