"""Proof by simulation that a linkage with several inputs is balanced along its motions.

The counterpart of :mod:`balancer.verification` for a linkage driven at several joints
(DESIGN.md, "Mechanisms with several inputs"). Along each of the spec's motions, every input
is driven (:func:`balancer.simulation.motions.simulate_along`) in the check's formulation —
by default ``multibody``, whose multipliers are a route the balancing never used — and in the
other one (the inputs' coordinates, the linkage core's inverse dynamics): their loads must
agree, and each run's motors' work must match its kinetic energy and the configuration's work.
The design's largest shaking force, moment and input torques are compared with the unbalanced
original's where the spec names one (``[original]``). One free run (no motor) starts from the
first motion's state where its inputs turn fastest and lasts :data:`FREE_SHARE` of it
(:func:`balancer.simulation.motions.simulate_free`): a force-balanced design's shaking force is
then the frame's share of gravity alone, whatever the motion.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import validate as v
from .errors import SpecError
from .linkage import trajectory
from .linkage.inputs import InputState
from .mechanisms import Mechanism, mechanism_of
from .model import Design
from .model.motions import MotionSpec
from .simulation.motions import METHODS, MotionRun, simulate_along, simulate_free

#: The free run lasts this share of the first motion's duration (short enough that a robot
#: coasting from the middle of its motion does not reach a singular pose).
FREE_SHARE = 0.1
#: Most wall-clock time a free run may take, s (the one-input check's): a run that creeps
#: past a singular pose, or a motion far faster than its duration, is refused, not waited on.
FREE_SECONDS = 20.0
#: Quadrature and integration tolerances of the runs (those of the one-input check).
RTOL = 1e-9
ATOL = 1e-11


def _other(method: str) -> str:
    """The formulation a run is checked against."""
    return next(m for m in METHODS if m != method)


def natural_scales(run: MotionRun) -> tuple[float, float]:
    """The run's scale of a force (N) and of a moment (N·m).

    A force's: the largest force at one ground point or guide, or where they are larger the
    largest input torque over the linkage's size (robots whose motors share one pivot, whose
    balanced pivot carries almost nothing) or twice the largest kinetic energy over the size
    (a free run, no motor); a moment's: that force times the size, or the largest moment on
    the frame or input torque.
    """
    size = run.mechanism.structure.length_scale()
    r = run.reactions
    moments = [r.shaking_moment, *r.torques, *r.slider_couple.values()]
    largest_moment = max(_largest(m) for m in moments)
    force = max(r.largest_force(), _largest(r.shaking_force),
                max(_largest(t) for t in r.torques) / size,
                2 * _largest(run.kinetic_energy) / size, 1e-300)
    return force, max(force * size, largest_moment, 1e-300)


def _agreement(a: MotionRun, b: MotionRun) -> float:
    """The largest difference of the two runs' loads, relative to their natural scales.

    Forces (the ground points', the sliders', the shaking force) against the force's scale,
    moments (the shaking moment, the sliders' couples, the inputs' torques) against the
    moment's (:func:`natural_scales`).
    """
    ra, rb = a.reactions, b.reactions
    force, moment = natural_scales(a)
    worst = 0.0
    for p in ra.ground:
        worst = max(worst, float(np.max(np.abs(ra.ground[p] - rb.ground[p]))) / force)
    for k in ra.slider_normal:
        worst = max(worst, float(np.max(np.abs(ra.slider_normal[k] - rb.slider_normal[k])))
                    / force)
        worst = max(worst, float(np.max(np.abs(ra.slider_couple[k] - rb.slider_couple[k])))
                    / moment)
    worst = max(worst, float(np.max(np.abs(ra.shaking_force - rb.shaking_force))) / force,
                float(np.max(np.abs(ra.shaking_moment - rb.shaking_moment))) / moment)
    for ta, tb in zip(ra.torques, rb.torques, strict=True):
        worst = max(worst, float(np.max(np.abs(ta - tb))) / moment)
    return worst


def _largest(values: Any) -> float:
    return float(np.max(np.abs(np.asarray(values))))


@dataclass(frozen=True)
class MotionCheck:
    """One run of the design (and of the original), and its figures.

    Attributes
    ----------
    name
        The motion's name, or ``"free"``.
    run, original
        The design's run and the original's (or ``None``).
    other
        The design's run in the other formulation (driven runs), or ``None``.
    """

    name: str
    run: MotionRun
    original: MotionRun | None
    other: MotionRun | None

    @property
    def max_shaking_force(self) -> float:
        """Largest shaking force over the run, N."""
        return _largest(self.run.reactions.shaking_force)

    @property
    def max_shaking_moment(self) -> float:
        """Largest magnitude of the shaking moment over the run, N·m."""
        return _largest(self.run.reactions.shaking_moment)

    @property
    def max_torques(self) -> dict[str, float]:
        """Each input's largest magnitude of torque over the run, N·m."""
        return {name: _largest(t) for name, t in
                zip(self.run.inputs, self.run.reactions.torques, strict=True)}

    @property
    def original_max_shaking_force(self) -> float | None:
        """The original's largest shaking force, N."""
        return None if self.original is None else _largest(self.original.reactions.shaking_force)

    @property
    def original_max_shaking_moment(self) -> float | None:
        """The original's largest magnitude of the shaking moment, N·m."""
        return (None if self.original is None
                else _largest(self.original.reactions.shaking_moment))

    @property
    def force_level(self) -> float | None:
        """Largest shaking force relative to the run's force scale (:func:`natural_scales`).

        ``None`` for a run that exerts no force at all.
        """
        scale = natural_scales(self.run)[0]
        return self.max_shaking_force / scale if scale > 1e-300 else None

    @property
    def agreement(self) -> float | None:
        """The two formulations' largest difference of loads, relative (driven runs)."""
        return None if self.other is None else _agreement(self.run, self.other)

    def as_dict(self) -> dict[str, Any]:
        """Plain dictionary for JSON."""
        def ratio(a: float, b: float | None) -> float | None:
            return None if b is None or b == 0 else a / b

        return {
            "drive": self.run.drive,
            "duration": float(self.run.t[-1] - self.run.t[0]),
            "max_shaking_force": self.max_shaking_force,
            "max_shaking_moment": self.max_shaking_moment,
            "max_torques": self.max_torques,
            "original_max_shaking_force": self.original_max_shaking_force,
            "original_max_shaking_moment": self.original_max_shaking_moment,
            "force_ratio": ratio(self.max_shaking_force, self.original_max_shaking_force),
            "moment_ratio": ratio(self.max_shaking_moment, self.original_max_shaking_moment),
            "force_level": self.force_level,
            "energy_error": self.run.energy_error,
            "other_energy_error": None if self.other is None else self.other.energy_error,
            "formulations_agree_to": self.agreement,
            "constraint_drift": {"position": self.run.drift[0],
                                 "velocity": self.run.drift[1]},
            "steps": self.run.steps,
            "rtol": self.run.rtol,
        }


@dataclass(frozen=True)
class MotionVerification:
    """The result of :func:`verify_motions`: a check per motion and the free run."""

    method: str
    motions: tuple[MotionCheck, ...]
    free: MotionCheck

    @property
    def checks(self) -> tuple[MotionCheck, ...]:
        """Every run: the motions', then the free one."""
        return (*self.motions, self.free)

    @property
    def max_shaking_force(self) -> float:
        """Largest shaking force over the runs, N."""
        return max(c.max_shaking_force for c in self.checks)

    @property
    def max_shaking_moment(self) -> float:
        """Largest magnitude of the shaking moment over the runs, N·m."""
        return max(c.max_shaking_moment for c in self.checks)

    def as_dict(self) -> dict[str, Any]:
        """Plain dictionary for JSON.

        ``max_shaking_force``, ``max_shaking_moment`` as the one-input check's; the runs under
        ``motions.<name>`` and ``free``.
        """
        return {"method": self.method, "max_shaking_force": self.max_shaking_force,
                "max_shaking_moment": self.max_shaking_moment,
                "motions": {c.name: c.as_dict() for c in self.motions},
                "free": self.free.as_dict()}


def fastest_state(mech: Mechanism, motion: MotionSpec) -> InputState:
    """The inputs' positions and rates at the motion's sample where they turn fastest.

    One state: the sample with the largest norm of the inputs' rates (a motion that rests at
    its waypoints rests halfway too).
    """
    state = trajectory.input_state(mech.structure, motion)
    speed = np.sum([np.asarray(r, dtype=float) ** 2 for r in state.rates], axis=0)
    # (the first of those within rounding of the fastest: a symmetric motion has two)
    at = int(np.argmax(speed >= (1.0 - 1e-9) * float(np.max(speed))))
    return InputState.of([p[at] for p in state.positions], [r[at] for r in state.rates])


def verify_motions(design: Design, names: Sequence[str] | None = None, *,
                   method: str | None = None, gravity: tuple[float, float] = (0.0, 0.0),
                   duration: float | None = None, rtol: float = RTOL, atol: float = ATOL
                   ) -> MotionVerification:
    """Simulate the design (and its original) driven along its motions, and free.

    ``names``: the motions (default every one); ``method``: the check's formulation (default
    ``multibody``); ``duration``: the free run's, s (default :data:`FREE_SHARE` of the first
    motion's).

    Raises
    ------
    SpecError
        If the spec has no motion, or names an unknown one or formulation.
    AssemblyError, SolverError
        If a motion leaves the workspace, or a formulation is singular along it.
    """
    method = method or METHODS[0]
    if method not in METHODS:
        raise SpecError(f"a linkage with several inputs has no such formulation; choose from "
                        f"{', '.join(METHODS)}", key="method", value=method)
    chosen = list(design.motions) if not names else [design.motion(n) for n in names]
    if not chosen:
        raise SpecError("a linkage with several inputs is verified along its motions: the "
                        "spec has no [[motion]]", key="motion")
    mech = mechanism_of(design.mechanism)
    original = None if design.original is None else mechanism_of(design.original)
    def along(m: Mechanism, motion: MotionSpec, how: str) -> MotionRun:
        with v.under(v.item("motion", design.motions.index(motion))):  # (its keys' errors)
            return simulate_along(m, motion, method=how, gravity=gravity, rtol=rtol,
                                  atol=atol)

    def free_run(m: Mechanism, motion: MotionSpec, span: float) -> MotionRun:
        with v.under(v.item("motion", design.motions.index(motion))):
            start = fastest_state(m, motion)
        return simulate_free(m, start, span, method=method, gravity=gravity, rtol=rtol,
                             atol=atol, max_seconds=FREE_SECONDS)

    checks = []
    for motion in chosen:
        checks.append(MotionCheck(
            name=motion.name, run=along(mech, motion, method),
            original=None if original is None else along(original, motion, method),
            other=along(mech, motion, _other(method))))
    first = chosen[0]
    span = FREE_SHARE * first.duration if duration is None else duration
    free = free_run(mech, first, span)
    free_before = None if original is None else free_run(original, first, span)
    return MotionVerification(method=method, motions=tuple(checks),
                              free=MotionCheck(name="free", run=free, original=free_before,
                                               other=None))
