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

A planned motion (``balancer plan``) runs another motion's path ``along`` it — or a one-input
linkage's revolution at constant speed, :data:`REVOLUTION` — at a ``pace``: rows ``(τ, τ̇)`` of
the path's argument (s) and its rate (s/s), ``τ̈`` constant between rows; its duration is
what the pace makes it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from .. import validate as v
from ..errors import SpecError

#: The time laws a motion may follow.
LAWS: tuple[str, ...] = ("trapezoid", "cubic", "quintic", "spline")

#: The path a planned motion of a one-input linkage runs ``along``: its input turning one
#: revolution from the reference pose at the operating speed (a straight path of the input,
#: periodic).
REVOLUTION = "revolution"


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
    along
        A planned motion's: the motion whose path (its ``times``, ``path``, ``point``,
        ``law``) it runs, or :data:`REVOLUTION`; ``None`` for a motion of its own.
    pace
        A planned motion's time law: rows ``(τ, τ̇)``, the path's argument (s, from the
        first waypoint's time to the last, increasing) and its rate (s/s, at least 0, no two
        rows in a row at rest); the argument's acceleration is constant between rows.
    """

    name: str
    times: tuple[float, ...]
    path: tuple[tuple[float, ...], ...]
    point: str | None = None
    law: str = "cubic"
    acc_time: float | None = None
    samples: int = 400
    along: str | None = None
    pace: tuple[tuple[float, float], ...] | None = None

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
        if self.pace is not None:
            v.store(self, "pace", _checked_pace(self.pace, times))

    @property
    def closed(self) -> bool:
        """Whether the path ends where it starts (to 1e-12 of its figures)."""
        return all(math.isclose(a, b, rel_tol=0.0, abs_tol=1e-12 * max(1.0, abs(a)))
                   for a, b in zip(self.path[0], self.path[-1], strict=True))

    @property
    def start(self) -> float:
        """The motion's first time, s (its first waypoint's)."""
        return self.times[0]

    @property
    def end(self) -> float:
        """The motion's last time, s."""
        return self.start + self.duration

    @property
    def duration(self) -> float:
        """The motion's duration, s: its waypoints' span, or what its pace makes it."""
        if self.pace is None:
            return self.times[-1] - self.times[0]
        return float(self.pace_times[-1] - self.pace_times[0])

    @property
    def periodic(self) -> bool:
        """Whether the motion repeats: a closed spline path, or a revolution."""
        return self.along == REVOLUTION or (self.law == "spline" and self.closed)

    @cached_property
    def pace_times(self) -> NDArray[np.float64]:
        """The times (s) of the pace's rows, from the motion's start.

        Between rows the argument's acceleration is constant, so a row's interval lasts
        ``2·Δτ/(τ̇₀ + τ̇₁)``.
        """
        if self.pace is None:
            raise ValueError(f"motion {self.name} has no pace")
        rows = np.asarray(self.pace, dtype=float)
        spans = 2.0 * np.diff(rows[:, 0]) / (rows[:-1, 1] + rows[1:, 1])
        return np.concatenate([[self.times[0]], self.times[0] + np.cumsum(spans)])


#: How near a pace's first and last arguments must be to the path's ends (a share of its span).
PACE_ENDS = 1e-9
#: A pace's rates (s/s): 0 (at rest) or within this factor of 1, either way.
PACE_RATES = 1e9


def _checked_pace(rows: object, times: Sequence[float]) -> tuple[tuple[float, float], ...]:
    """A pace's rows ``(τ, τ̇)`` checked (key ``pace``); its ends made the path's exactly."""
    if not isinstance(rows, tuple | list) or len(rows) < 2:
        raise SpecError("must be at least two rows [argument s, rate]", key="pace", value=rows)
    out: list[tuple[float, float]] = []
    for row in rows:
        if not isinstance(row, tuple | list) or len(row) != 2:
            raise SpecError("each row must be [argument s, rate]", key="pace", value=row)
        tau, rate = v.numbers(row, "pace")
        if not rate >= 0:
            raise SpecError("a rate must be at least 0", key="pace", value=list(row))
        if rate != 0.0 and not 1 / PACE_RATES <= rate <= PACE_RATES:
            raise SpecError(f"a rate must be 0 or within {1 / PACE_RATES:g} to {PACE_RATES:g}",
                            key="pace", value=list(row))
        if out and not tau > out[-1][0]:
            raise SpecError("its arguments must increase", key="pace", value=list(row))
        if out and rate == 0.0 and out[-1][1] == 0.0:
            raise SpecError("two rows in a row at rest never move on", key="pace",
                            value=list(row))
        out.append((tau, rate))
    span = times[-1] - times[0]
    for at, end in ((0, times[0]), (-1, times[-1])):
        if abs(out[at][0] - end) > PACE_ENDS * span:
            raise SpecError(f"must run the path's argument from {times[0]:g} s to "
                            f"{times[-1]:g} s", key="pace", value=list(out[at]))
    out[0], out[-1] = (times[0], out[0][1]), (times[-1], out[-1][1])
    return tuple(out)
