"""Forward dynamics of a design, and the proof by simulation that it is balanced."""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

from .. import validate as v
from ..formulations import Method
from ..mechanisms import mechanism_of
from ..mechanisms.base import require_one_input
from ..model import Design, Drive
from ..motion_verification import (
    FREE_SECONDS,
    FREE_SHARE,
    MotionVerification,
    fastest_state,
    verify_motions,
)
from ..simulation import Trajectory, simulate_design
from ..simulation.motions import MotionRun, simulate_along, simulate_free
from ..verification import Verification
from ..verification import verify as run_verification


def simulate(design: Design, *, method: Method | None = None, drive: Drive | None = None,
             duration: float | None = None, rtol: float | None = None,
             atol: float | None = None, outputs: int | None = None,
             progress: Callable[[float, float], None] | None = None) -> Trajectory:
    """Forward dynamics from the spec's ``[simulation]``, each keyword overriding it.

    ``method`` a formulation of the mechanism (:func:`balancer.formulations.formulation_names`);
    ``drive`` ``"free"`` or ``"constant-speed"``; ``duration`` s; ``progress`` called as
    ``progress(done, total)`` in simulated seconds. See
    :func:`balancer.simulation.simulate_design`.
    """
    require_one_input(mechanism_of(design.mechanism), "a simulation (simulate_motion drives "
                                                      "every input along a motion)")
    return simulate_design(design, method=method, drive=drive, duration=duration, rtol=rtol,
                           atol=atol, outputs=outputs, progress=progress)


def simulate_motion(design: Design, name: str | None = None, *, method: str | None = None,
                    drive: Literal["motion", "free"] = "motion", duration: float | None = None,
                    rtol: float | None = None, atol: float | None = None,
                    outputs: int | None = None) -> MotionRun:
    """A linkage driven along one of its motions (``[[motion]]``, default the first), or free.

    ``drive="motion"``: every input prescribed along the motion, at its samples
    (:func:`balancer.simulation.motions.simulate_along`); ``"free"``: no motor, from the state
    where the motion's inputs turn fastest, for ``duration`` s (default the spec's
    ``[simulation] duration`` where it gives one, else a tenth of the motion's), ``outputs``
    times (:func:`balancer.simulation.motions.simulate_free`). ``method``: ``"multibody"``
    (default) or ``"input-coordinates"``; ``rtol``, ``atol`` default to ``[simulation]``'s.
    Gravity is the spec's ``[simulation] gravity`` where it gives one, else ``[operation]
    gravity``, as ``analyze`` along a motion takes it.
    """
    motion = design.motion(name)
    mech = mechanism_of(design.mechanism)
    settings = design.simulation
    gravity = _gravity(design)
    method = method or settings.method or "multibody"
    rtol = settings.rtol if rtol is None else rtol
    atol = settings.atol if atol is None else atol
    with v.under(v.item("motion", design.motions.index(motion))):  # (its keys' errors)
        if drive == "motion":
            return simulate_along(mech, motion, method=method, gravity=gravity, rtol=rtol,
                                  atol=atol)
        start = fastest_state(mech, motion)
    if duration is None:
        duration = (settings.duration if "duration" in settings.given
                    else FREE_SHARE * motion.duration)
    return simulate_free(mech, start, duration, method=method, gravity=gravity, rtol=rtol,
                         atol=atol, outputs=settings.outputs if outputs is None else outputs,
                         max_seconds=FREE_SECONDS)


def _gravity(design: Design) -> tuple[float, float]:
    """A run along a motion's gravity: ``[simulation]``'s if given, else ``[operation]``'s."""
    if "gravity" in design.simulation.given or design.operation is None:
        return design.simulation.gravity
    return design.operation.gravity


def verify(design: Design, *, method: Method | str | None = None,
           duration: float | None = None,
           progress: Callable[[float, float], None] | None = None
           ) -> Verification | MotionVerification:
    """Proof by simulation (driven and free) that a design is balanced.

    See :func:`balancer.verification.verify`; a linkage with several inputs is driven along
    each of its motions instead (:func:`balancer.motion_verification.verify_motions`, its
    ``duration`` the free run's).
    """
    if len(mechanism_of(design.mechanism).linkage.inputs) > 1:
        return verify_motions(design, method=method, gravity=_gravity(design),
                              duration=duration)
    return run_verification(design, method=method, duration=duration, progress=progress)
