"""A trade-off front: its points, each a certified optimum, and what a report says of them.

Made by :func:`balancer.balance.pareto.pareto_front`: for a linkage the least RMS shaking moment
against a second objective (:mod:`.pareto`), for an engine the least weighted RMS shaking of its
``[balance.objective]`` against the mass·radius it may add (:mod:`.rotor_front`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..quantities import QUANTITIES, unit_of, words_of

#: The second objectives of a front (``pareto --against``).
Against = Literal["driving-torque", "added-mass", "shaking-force"]
#: Each second objective's report name and unit.
AGAINST: dict[str, tuple[str, str]] = {
    against: (against.replace("-", "_"), unit_of(against.replace("-", "_")))
    for against in ("driving-torque", "added-mass", "shaking-force")}
#: What a front may minimise, and the figures its points report: their words and units.
FIGURES: dict[str, tuple[str, str]] = {
    "rms": ("weighted RMS shaking √J", "N·m"),
    **{key: (words_of(key) if QUANTITIES[key].largest else f"RMS {words_of(key)}",
             unit_of(key))
       for key in ("rocking_couple", "shaking_force", "shaking_moment", "main_bearing_load",
                   "largest_bearing_load")}}


@dataclass(frozen=True, eq=False)
class FrontPoint:
    """One point of a front: a design and its two objectives.

    Attributes
    ----------
    least
        The minimised objective of the design (:attr:`Front.minimised`; a linkage's RMS
        shaking moment), N·m.
    value
        Its second objective (RMS driving torque N·m, added mass kg (an engine's without a
        radius: kg·m), or RMS shaking force N).
    epsilon
        The bound on the second objective this point was solved under (same unit).
    lower_bound
        No design within the bounds with the second objective at most ``epsilon`` has a
        smaller :attr:`least`, N·m (certified).
    x
        The design vector.
    knee
        Whether this is the front's knee.
    figures
        The design's figures by name (:data:`FIGURES`): its RMS shaking moment always, an
        engine's RMS rocking couple and shaking force too.
    """

    least: float
    value: float
    epsilon: float
    lower_bound: float
    x: NDArray[np.float64] = field(repr=False)
    knee: bool = False
    figures: Mapping[str, float] = field(default_factory=dict)

    @property
    def shaking_moment(self) -> float:
        """The design's RMS shaking moment, N·m."""
        return self.figures.get("shaking_moment", self.least)


@dataclass(frozen=True)
class Front:
    """A trade-off front, its points ordered by the second objective.

    ``original`` is the original design's ``(second objective, least)``: where the designer
    starts from (it need not meet the balancing constraints), ``original_figures`` its figures.
    ``force_balance``: whether every design on the front is held to exact force balance (the
    spec's ``[balance] force_balance``); ``original_force_balanced``: whether the original
    design is. ``minimised``: what the front minimises (a key of :data:`FIGURES`);
    ``value_unit``: the second objective's unit where it is not :data:`AGAINST`'s (an
    engine's mass·radius, kg·m). ``masses``: the front of an engine's balancing, each point
    bounded masses on rotors (:mod:`.rotor_front`), not a linkage's redesign.
    """

    against: str
    points: tuple[FrontPoint, ...]
    original: tuple[float, float] = (math.nan, math.nan)
    force_balance: bool = False
    original_force_balanced: bool | None = None
    minimised: str = "shaking_moment"
    value_unit: str | None = None
    original_figures: Mapping[str, float] = field(default_factory=dict)
    masses: bool = False
    #: What the front leaves out of the spec's ``[balance]``, said with it (text and JSON).
    notes: tuple[str, ...] = ()

    def __repr__(self) -> str:
        ends = (f"{self.points[0].value:.4g}–{self.points[-1].value:.4g} {self.unit}, "
                f"{self.points[0].least:.4g}–{self.points[-1].least:.4g} N·m")
        return f"Front({self.minimised} against {self.against}, {len(self.points)} points: {ends})"

    @property
    def name(self) -> str:
        """The second objective's report name (``driving_torque``, …)."""
        return AGAINST[self.against][0]

    @property
    def unit(self) -> str:
        """The second objective's unit."""
        return self.value_unit or AGAINST[self.against][1]

    @property
    def words(self) -> str:
        """What the front minimises, in words (``RMS shaking moment``)."""
        return FIGURES[self.minimised][0]

    @property
    def figure_names(self) -> tuple[str, ...]:
        """The figures its points report besides :attr:`minimised`, in :data:`FIGURES`' order."""
        given = set(self.points[0].figures) if self.points else set()
        return tuple(n for n in FIGURES if n in given and n != self.minimised)

    def as_dict(self) -> dict[str, object]:
        """The ``pareto --json`` document's ``against`` and ``points``."""
        units = {f"{self.minimised}, lower_bound": FIGURES[self.minimised][1],
                 f"{self.name}, epsilon": self.unit}
        for n in self.figure_names:
            units[n] = FIGURES[n][1]
        return {
            "against": self.against,
            **({"minimised": self.minimised} if self.masses else {}),
            **({"notes": list(self.notes)} if self.notes else {}),
            "points": [{self.minimised: p.least, **{n: p.figures[n] for n in self.figure_names},
                        self.name: p.value, "epsilon": p.epsilon,
                        "lower_bound": p.lower_bound, "knee": p.knee}
                       for p in self.points],
            "original": {self.minimised: self.original[1],
                         **{n: self.original_figures[n] for n in self.figure_names
                            if n in self.original_figures},
                         self.name: self.original[0]},
            "units": units,
        }


def mark_knee(points: list[FrontPoint]) -> list[FrontPoint]:
    """The points, the one farthest from the chord between the ends marked as the knee.

    Each objective measured over its range (the ends at (0, 1) and (1, 0)); a convex front
    lies below the chord.
    """
    if len(points) < 3:
        return points
    xs = np.array([p.value for p in points])
    ys = np.array([p.least for p in points])
    span_x, span_y = xs[-1] - xs[0], ys[0] - ys[-1]
    if not (span_x > 0 and span_y > 0):
        return points
    u, v = (xs - xs[0]) / span_x, (ys - ys[-1]) / span_y
    distance = 1.0 - u - v  # below the chord u + v = 1
    k = int(np.argmax(distance))
    return [replace(p, knee=i == k) for i, p in enumerate(points)]
