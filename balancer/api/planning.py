"""A motion's time law planned to shake the frame least (``balancer plan``)."""

from __future__ import annotations

from dataclasses import replace

from .. import validate as v
from ..errors import SpecError
from ..mechanisms import mechanism_of
from ..model import Design
from ..model.motions import REVOLUTION
from ..model.plan import PlanSpec
from ..planning import Plan, check_plan, path_of, plan_motion
from ..planning.codesign import CoDesign
from ..planning.codesign import codesign as run_codesign
from ..spec import schema
from .analysis import spec_gravity


def plan(design: Design, motion: str | None = None, *, settings: PlanSpec | None = None
         ) -> Plan:
    """The time law of a motion's path that shakes the frame least (:mod:`balancer.planning`).

    Parameters
    ----------
    design
        The design (a linkage whose spec takes ``[plan]``: four-bar, slider-crank, general).
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
    _check_type(design)
    spec = _for_motion(design, settings or design.plan or PlanSpec(), motion)
    mech = mechanism_of(design.mechanism)
    name = motion if motion is not None else spec.motion
    path = path_of(design, name, key="--motion" if motion is not None else "plan.motion")
    check_plan(mech, path, spec)  # (its keys the spec's, not under the motion's)
    index = next((i for i, m in enumerate(design.motions) if m is path), None)
    with v.under("plan" if index is None else v.item("motion", index)):
        return plan_motion(mech, path, spec, gravity=spec_gravity(design))


def codesign(design: Design, motion: str | None = None, *, settings: PlanSpec | None = None
             ) -> CoDesign:
    """The masses of ``[balance]`` and a motion's time law chosen together.

    Each lever's certified problem in turn until neither improves the plan's objective
    (:mod:`balancer.planning.codesign`); with what each alone buys from the spec.

    Raises
    ------
    SpecError
        If the spec has no ``[balance]``, its linkage has one input, or the motion is unknown.
    SolverError
        If a step fails.
    """
    _check_type(design)
    spec = _for_motion(design, settings or design.plan or PlanSpec(), motion)
    return run_codesign(design, spec, motion, gravity=spec_gravity(design))


def _check_type(design: Design) -> None:
    """Refuse a mechanism whose spec takes no plan (an engine's crank turns at its speed)."""
    if "plan" not in schema.known("", design.mechanism.type):
        raise SpecError(f"plans a linkage's motion; a spec of type \"{design.mechanism.type}\" "
                        "has no [plan] and no [[motion]]", key="mechanism.type")


def _for_motion(design: Design, spec: PlanSpec, motion: str | None) -> PlanSpec:
    """The plan for another motion than its own: its planned motion's name is that motion's."""
    own = path_of(design, spec.motion).name if spec.motion is not None or design.motions \
        else REVOLUTION
    if motion is None or motion == own or spec.name is None:
        return spec
    return replace(spec, name=None)


def planned_design(design: Design, result: Plan) -> Design:
    """The design with the planned motion among its motions (replacing one of its name)."""
    motions = [m for m in design.motions if m.name != result.planned.name]
    return replace(design, motions=(*motions, result.planned))
