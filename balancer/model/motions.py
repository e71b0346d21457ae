"""Motions of a linkage with several inputs, and the configuration space it works in.

DESIGN.md, "Mechanisms with several inputs": ``[workspace]`` gives each input's range (its
change from the reference pose, rad) and the grid that samples it; each ``[[motion]]`` a named
path — a marker point's (m, through inverse kinematics) or the inputs' own (rad) — through
waypoints at given times, run by a time law:

``"trapezoid"``
    the motion's time argument ``τ`` runs from the first waypoint's time to the last with a
    trapezoidal rate: constant acceleration for ``acc_time`` s, constant rate, constant
    deceleration for ``acc_time`` s (the Forbal controllers' law);
``"cubic"``, ``"quintic"``
    ``τ`` by the rest-to-rest polynomial ``3u² − 2u³`` or ``10u³ − 15u⁴ + 6u⁵`` of the
    normalised time ``u``;
``"spline"``
    ``τ = t``, the path a cubic spline at its waypoints' pace: periodic for a closed path,
    clamped (at rest at both ends) for an open one.

The path through the waypoints is a cubic Hermite spline of ``τ`` with zero end slopes (its
inner slopes the three-point differences), or the cubic spline for ``"spline"``
(:mod:`balancer.linkage.trajectory`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from .. import validate as v
from ..errors import SpecError

#: The time laws a motion may follow.
LAWS: tuple[str, ...] = ("trapezoid", "cubic", "quintic", "spline")


@dataclass(frozen=True, kw_only=True)
class InputRange:
    """One input's range in the workspace: its change from the reference pose, rad."""

    name: str
    low: float
    high: float


@dataclass(frozen=True, kw_only=True)
class Workspace:
    """The configuration space a force balance for every motion must hold over.

    Attributes
    ----------
    ranges
        Each input's ``[low, high]`` change from the reference pose, rad, by name.
    samples
        Grid points per input (states that do not assemble are left out).
    joints
        Limits of passive joints, by their point: the change of the angle between the
        joint's two links from the reference pose, rad.
    """

    ranges: tuple[InputRange, ...]
    samples: int = 40
    joints: tuple[InputRange, ...] = ()

    #: Least and most grid points per input.
    SAMPLES: ClassVar[tuple[int, int]] = (2, 10_000)

    def __post_init__(self) -> None:
        """Check the values (keys within ``[workspace]``)."""
        for r in (*self.ranges, *self.joints):
            key = r.name if r in self.ranges else f"joints.{r.name}"
            low, high = v.vector2((r.low, r.high), key)
            if not low < high:
                raise SpecError("must be [low, high] with low < high", key=key,
                                value=[low, high])
            if max(abs(low), abs(high)) > 1e3:
                raise SpecError("must be within 1000 rad of the reference pose", key=key,
                                value=[low, high])
            object.__setattr__(r, "low", low)
            object.__setattr__(r, "high", high)
        v.store(self, "samples", v.integer(self.samples, "samples", minimum=self.SAMPLES[0],
                                           maximum=self.SAMPLES[1]))

    def range_of(self, name: str) -> InputRange | None:
        """An input's range, if the workspace gives one."""
        return next((r for r in self.ranges if r.name == name), None)


@dataclass(frozen=True, kw_only=True)
class MotionSpec:
    """A named motion: waypoints at times, a time law, how many states to sample.

    Attributes
    ----------
    name
        Its name (``--motion NAME``).
    times
        The waypoints' times, s, increasing from the first.
    path
        The waypoints: a marker point's ``(x, y)`` in m when ``point`` is given, else each
        input's angle in rad (one entry per input, in the linkage's order).
    point
        The marker point whose path it is, or ``None`` (the inputs' own angles).
    law
        One of :data:`LAWS`.
    acc_time
        The trapezoid's acceleration time, s (``"trapezoid"`` only): more than zero, at most
        half the motion's duration.
    samples
        States along the motion for the analysis and the balancing (equally spaced in time,
        both ends included).
    """

    name: str
    times: tuple[float, ...]
    path: tuple[tuple[float, ...], ...]
    point: str | None = None
    law: str = "cubic"
    acc_time: float | None = None
    samples: int = 400

    #: Least and most states along a motion.
    SAMPLES: ClassVar[tuple[int, int]] = (8, 1_000_000)

    def __post_init__(self) -> None:
        """Check the values (keys within its ``[[motion]]`` table)."""
        if not isinstance(self.name, str) or not self.name:
            raise SpecError("a motion needs a name", key="name", value=self.name)
        times = v.numbers(self.times, "times")
        if len(times) < 2:
            raise SpecError("needs at least two waypoints' times", key="times",
                            value=list(times))
        if any(b <= a for a, b in zip(times, times[1:], strict=False)):
            raise SpecError("must increase", key="times", value=list(times))
        v.store(self, "times", tuple(times))
        rows = self.path
        if not isinstance(rows, tuple | list) or len(rows) != len(times):
            raise SpecError(f"must give one waypoint per time ({len(times)})", key="path",
                            value=rows)
        width = 2 if self.point is not None else None
        path = []
        for row in rows:
            if not isinstance(row, tuple | list) or not row:
                raise SpecError("each waypoint must be a list of numbers", key="path",
                                value=row)
            values = v.numbers(row, "path")
            if width is None:
                width = len(values)
            if len(values) != width:
                what = "(x, y) of the point" if self.point is not None else "one per input"
                raise SpecError(f"each waypoint must have {width} numbers ({what})",
                                key="path", value=list(row))
            path.append(values)
        v.store(self, "path", tuple(path))
        if self.law not in LAWS:
            raise SpecError(f"must be one of {', '.join(LAWS)}", key="law", value=self.law)
        duration = times[-1] - times[0]
        if self.law == "trapezoid":
            if self.acc_time is None:
                raise SpecError("the trapezoid law needs its acceleration time", key="acc_time")
            acc = v.number(self.acc_time, "acc_time")
            if not 0 < acc <= duration / 2:
                raise SpecError(f"must be more than 0 and at most half the duration "
                                f"({duration / 2:g} s)", key="acc_time", value=acc)
            v.store(self, "acc_time", acc)
        elif self.acc_time is not None:
            raise SpecError(f"is the trapezoid law's; this motion's law is {self.law}",
                            key="acc_time", value=self.acc_time)
        v.store(self, "samples", v.integer(self.samples, "samples", minimum=self.SAMPLES[0],
                                           maximum=self.SAMPLES[1]))

    @property
    def closed(self) -> bool:
        """Whether the path ends where it starts (to 1e-12 of its figures)."""
        return all(math.isclose(a, b, rel_tol=0.0, abs_tol=1e-12 * max(1.0, abs(a)))
                   for a, b in zip(self.path[0], self.path[-1], strict=True))

    @property
    def duration(self) -> float:
        """The motion's duration, s."""
        return self.times[-1] - self.times[0]
