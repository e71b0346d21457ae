"""A motion's time law to be planned: ``[plan]`` (``balancer plan``).

The path of one of the spec's motions stays; the planner chooses how fast it is run — the
path's argument ``τ(t)`` — to shake the frame least, within the inputs' speed, acceleration and
load limits, in the same duration (or the one given). The objective is the mean square over
time (``measure = "rms"``) or the largest value (``"peak"``) of the weighted sum

``Σ w·q²``  over the shaking force (and its x, y parts), the shaking moment, the rocking couple
and the inputs' torques (``torque``: their squares summed),

weighted as ``[balance.objective]``'s terms are (:class:`balancer.model.balance.Objective`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from .. import validate as v
from ..errors import SpecError

#: What a plan minimises: the objective's mean square over time, or its largest value.
MEASURES = ("rms", "peak")

#: The terms of ``[plan.objective]``: frame loads and the inputs' torques.
PLAN_OBJECTIVE_KEYS = ("shaking_moment", "shaking_force", "shaking_force_x", "shaking_force_y",
                       "rocking_couple", "torque")

#: A transcription's intervals where ``[plan] intervals`` is not given (at least one per
#: segment of the path).
DEFAULT_INTERVALS = 200

#: The limits a plan keeps each input within (``[plan]``), with their units for an input
#: turned about a pivot (a slide's: m/s, m/s², N).
LIMIT_KEYS = {"max_speed": "rad/s", "max_acceleration": "rad/s²", "max_torque": "N·m"}


@dataclass(frozen=True, kw_only=True)
class PlanWeights:
    """The objective's weights (``[plan.objective]``), each at least 0, not all 0.

    Its errors' keys are within ``[plan.objective]``.
    Units as ``[balance.objective]``'s: the shaking moment's and the torques' dimensionless,
    the forces' (N·m)²/N².
    """

    shaking_moment: float = 0.0
    shaking_force: float = 0.0
    shaking_force_x: float = 0.0
    shaking_force_y: float = 0.0
    rocking_couple: float = 0.0
    torque: float = 0.0

    def __post_init__(self) -> None:
        """Check the weights (keys within ``[plan.objective]``)."""
        for name in PLAN_OBJECTIVE_KEYS:
            value = v.number(getattr(self, name), name)
            if value < 0:
                raise SpecError("must be at least 0", key=name, value=value)
            v.store(self, name, value)
        if not any(getattr(self, name) for name in PLAN_OBJECTIVE_KEYS):
            raise SpecError(f"needs a weight above 0 ({', '.join(PLAN_OBJECTIVE_KEYS)})")

    def terms(self) -> dict[str, float]:
        """The weights above 0, by key."""
        return {name: getattr(self, name) for name in PLAN_OBJECTIVE_KEYS
                if getattr(self, name) > 0}


@dataclass(frozen=True, kw_only=True)
class InputLimits:
    """One kind of limit on the inputs: one value for all, or one per input (by name)."""

    every: float | None = None
    each: tuple[tuple[str, float], ...] = ()

    def of(self, name: str) -> float | None:
        """The limit on input ``name`` (``None``: none)."""
        return dict(self.each).get(name, self.every)


@dataclass(frozen=True, kw_only=True)
class PlanSpec:
    """``[plan]``: which motion's time law to plan, for what, within which limits.

    Attributes
    ----------
    motion
        The motion whose path is run (its name), or ``"revolution"`` (a one-input linkage's
        input turning once at the operating speed); ``None``: the spec's first motion (a
        one-input linkage without motions: its revolution).
    name
        The planned motion's name (default: the motion's, followed by ``" planned"``).
    duration
        The planned motion's duration, s (default: the motion's own — a revolution's at the
        operating speed, so the mean speed stays).
    measure
        ``"rms"`` or ``"peak"`` (:data:`MEASURES`).
    objective
        The weights.
    intervals
        Intervals of the path's argument in the transcription (the pace's rows less one);
        ``None``: :data:`DEFAULT_INTERVALS`, or the path's segments where it has more.
    max_speed, max_acceleration, max_torque
        Limits on each input's rate, acceleration and load.
    """

    motion: str | None = None
    name: str | None = None
    duration: float | None = None
    measure: str = "rms"
    objective: PlanWeights = field(default_factory=lambda: PlanWeights(shaking_moment=1.0))
    intervals: int | None = None
    max_speed: InputLimits = field(default_factory=InputLimits)
    max_acceleration: InputLimits = field(default_factory=InputLimits)
    max_torque: InputLimits = field(default_factory=InputLimits)

    #: Least and most intervals (setting up a transcription with limits or a peak grows with
    #: the square of its rows: 2000 take some 20 s).
    INTERVALS: ClassVar[tuple[int, int]] = (4, 2_000)

    def __post_init__(self) -> None:
        """Check the values (keys within ``[plan]``)."""
        for name in ("motion", "name"):
            value = getattr(self, name)
            if value is not None and (not isinstance(value, str) or not value):
                raise SpecError("must be a name", key=name, value=value)
        if self.duration is not None:
            v.store(self, "duration", v.positive(self.duration, "duration"))
        if self.measure not in MEASURES:
            raise SpecError(f"must be one of {', '.join(MEASURES)}", key="measure",
                            value=self.measure)
        if self.intervals is not None:
            v.store(self, "intervals", v.integer(self.intervals, "intervals",
                                                 minimum=self.INTERVALS[0],
                                                 maximum=self.INTERVALS[1]))

    def intervals_for(self, segments: int) -> int:
        """The transcription's intervals on a path of ``segments`` waypoint segments."""
        if self.intervals is not None:
            return self.intervals
        return max(DEFAULT_INTERVALS, segments)
        for key in LIMIT_KEYS:
            limits: InputLimits = getattr(self, key)
            given: list[tuple[str, float | None]] = [(key, limits.every)]
            given += [(f"{key}.{name}", value) for name, value in limits.each]
            for where, value in given:
                if value is not None:
                    v.positive(value, where)
