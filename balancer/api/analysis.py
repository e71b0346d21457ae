"""The analysis of a design: one revolution at its operating speed, or along its motions."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from .. import validate as v
from ..cycle import DRAWING_TOLERANCE, CycleAnalysis, cycle_analysis, drawn_analyses
from ..errors import SpecError
from ..force_balance import force_balance_residual
from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism, Route, require_full_revolution
from ..model import Design, check_scales

if TYPE_CHECKING:  # (the loads along motions: imported when a spec asks for them)
    from ..model.motions import MotionSpec
    from ..motion_analysis import AlongMotions, MotionAnalysis
    from ..phasors import Phasors
    from ..speed_fluctuation import Flywheel


def analyze(design: Design, *, route: Route | None = None,
            gravity: tuple[float, float] | None = None) -> CycleAnalysis:
    """One crank revolution at the design's operating speed (``[operation]``).

    Parameters
    ----------
    design
        The design.
    route
        Inverse-dynamics route (default the mechanism's first).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s², instead of the spec's
        ``[operation] gravity`` (whose default is none); the figures then include the weights.

    Raises
    ------
    SpecError
        If the spec has no operating speed, the crank cannot turn a full revolution, or
        ``gravity`` is not two finite numbers.
    """
    if design.operation is None:
        raise SpecError(
            "missing required key: a cycle analysis needs the operating speed",
            key="operation.speed",
        )
    op = design.operation
    if gravity is None:
        gravity = op.gravity
    else:
        gravity = v.vector2(gravity, "gravity")
        check_scales(design.mechanism, {"operation.speed": op.speed}, {"gravity": gravity})
    return cycle_analysis(design.mechanism, op.speed, op.samples, route=route, gravity=gravity)


def flywheel(design: Design, fluctuation: float | None = None, *,
             gravity: tuple[float, float] | None = None) -> Flywheel:
    """The least flywheel on the crank for a speed fluctuation (:mod:`balancer.speed_fluctuation`).

    Over the design's cycle at its operating speed (``[operation]``, its gravity included),
    from the exact energy balance of the mechanism with its applied loads (gas, springs,
    weights) under a constant torque that takes or gives their mean work.

    Parameters
    ----------
    design
        A one-input design with ``[operation]``.
    fluctuation
        The largest ``(ω_max − ω_min)/ω_mean`` allowed (default the spec's
        ``[operation] speed_fluctuation``).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s², instead of the spec's.

    Raises
    ------
    SpecError
        Without ``[operation]``, without a fluctuation, with several inputs, or where a load
        depends on the crank's speed.
    """
    from ..speed_fluctuation import CrankEnergy
    from ..speed_fluctuation import flywheel as least_flywheel

    op = design.operation
    if op is None:
        raise SpecError("missing required key: a flywheel is sized at the operating speed",
                        key="operation.speed")
    if fluctuation is None:
        if op.speed_fluctuation is None:
            raise SpecError("missing required key: the speed fluctuation to keep",
                            key="operation.speed_fluctuation")
        fluctuation = op.speed_fluctuation
    mech = mechanism_of(design.mechanism)
    require_full_revolution(mech, "sizing a flywheel")
    g = op.gravity if gravity is None else v.vector2(gravity, "gravity")
    energy = CrankEnergy.over_cycle(mech, op.samples, g)
    return least_flywheel(energy, op.speed, fluctuation)


def phasors(design: Design, orders: Sequence[int] = (1, 2)) -> Phasors:
    """Each plane's inertial force and couple by order at the operating speed, as phasors.

    The arrows at θ1 = 0 of each plane's forward and backward whirl at each of ``orders``
    (:mod:`balancer.phasors`); drawn by :func:`balancer.phasors_figure`.

    Raises
    ------
    SpecError
        Without ``[operation]``, or for an order that is not a whole number from 1.
    AssemblyError
        If the crank cannot turn a full revolution.
    """
    from ..phasors import phasors as plane_phasors

    if design.operation is None:
        raise SpecError("missing required key: the phasors are of the operating speed",
                        key="operation.speed")
    return plane_phasors(mechanism_of(design.mechanism), design.operation.speed, tuple(orders))


def analyze_motions(design: Design, names: Sequence[str] | None = None, *,
                    gravity: tuple[float, float] | None = None) -> AlongMotions:
    """The frame's loads along the design's motions (``[[motion]]``), or those named.

    With the force balance: the conditions' residual, and the total centre of mass over the
    spec's ``[workspace]`` grid where it gives one.

    Parameters
    ----------
    design
        The design.
    names
        The motions to run (default: every one, in the spec's order).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s², instead of the spec's
        ``[operation] gravity`` (default none).

    Raises
    ------
    SpecError
        If the spec has no motion or none of that name, or a motion does not fit the linkage.
    AssemblyError
        If a point's path leaves the workspace.
    """
    gravity = spec_gravity(design) if gravity is None else v.vector2(gravity, "gravity")
    chosen = list(design.motions) if not names else [design.motion(n) for n in names]
    if not chosen:
        raise SpecError("a linkage is analysed along its motions: the spec has no [[motion]]",
                        key="motion")
    from ..motion_analysis import AlongMotions

    mech = mechanism_of(design.mechanism)
    return AlongMotions(
        motions=tuple(_along(design, mech, m, gravity) for m in chosen),
        force_balance_residual=force_balance_residual(mech),
        workspace_spec=design.workspace)


def analyze_motion(design: Design, name: str | None = None) -> MotionAnalysis:
    """The frame's loads along one of the design's motions (``None``: its first).

    As :func:`analyze_motions` gives it (the spec's gravity), without the force balance and
    the workspace's grid: what a figure of the motion draws.

    Raises
    ------
    SpecError
        If the spec has no motion or none of that name, or the motion does not fit the linkage.
    AssemblyError
        If a point's path leaves the workspace.
    """
    motion = design.motion(name)
    mech = mechanism_of(design.mechanism)  # (its errors are the mechanism's, not the motion's)
    return _along(design, mech, motion, spec_gravity(design))


def spec_gravity(design: Design) -> tuple[float, float]:
    """The spec's gravity, m/s² (``[operation] gravity``; none without ``[operation]``)."""
    return design.operation.gravity if design.operation is not None else (0.0, 0.0)


def _along(design: Design, mech: Mechanism, motion: MotionSpec,
           gravity: tuple[float, float]) -> MotionAnalysis:
    """:func:`~balancer.motion_analysis.motion_analysis`, its errors under the motion's key."""
    from ..motion_analysis import motion_analysis

    with v.under(v.item("motion", design.motions.index(motion))):
        return motion_analysis(mech, motion, gravity=gravity)


def several_inputs(design: Design) -> bool:
    """Whether the design's mechanism is driven at more than one input."""
    return len(mechanism_of(design.mechanism).linkage.inputs) > 1


def cycle_analyses(design: Design, *, samples: int | None = None,
                   tolerance: float = DRAWING_TOLERANCE) -> tuple[CycleAnalysis,
                                                                   CycleAnalysis | None]:
    """One revolution of the design and of its original, sampled finely enough to draw.

    At the operating speed with the spec's gravity, from at least the spec's ``samples``
    (:func:`balancer.cycle.drawn_analyses`, to ``tolerance`` of each panel's span); with
    ``samples``, exactly that many crank angles.

    Returns
    -------
    tuple
        ``(design's, original's or None)`` :class:`~balancer.cycle.CycleAnalysis`, both at
        the same crank angles.

    Raises
    ------
    SpecError
        If the design has no operating speed; :class:`~balancer.errors.AssemblyError` if a
        crank cannot turn a full revolution.
    """
    if design.operation is None:
        raise SpecError("missing required key: a cycle analysis needs the operating speed",
                        key="operation.speed")
    op = design.operation
    models = [design.mechanism, *([design.original] if design.original is not None else [])]
    analyses = drawn_analyses(models, op.speed, samples=samples, least=op.samples,
                              gravity=op.gravity, tolerance=tolerance)
    return analyses[0], (analyses[1] if len(analyses) > 1 else None)
