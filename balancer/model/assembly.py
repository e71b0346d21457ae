"""The crank angles at which a mechanism assembles (:class:`AssemblyRange`).

The general core finds a linkage's by sampling (:mod:`balancer.mechanisms.base`); the four-bar
and the slider-crank have theirs in closed form (:mod:`balancer.mechanisms.fourbar.assembly`,
:mod:`balancer.mechanisms.slidercrank.kinematics`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: |sin(θ3 − θ2)| (a slider-crank's |cos θ2|) below which a closed form flags a position as
#: (near) a dead or change point, where the dependent rates are ill-determined.
SINGULAR_TOLERANCE = 1e-6


@dataclass(frozen=True)
class AssemblyRange:
    """The crank angles at which the linkage can be assembled.

    Attributes
    ----------
    intervals
        Closed intervals ``(start, end)`` of θ1 in rad, ``start < end ≤ start + 2π``, starting
        within ``[-π, π]``; empty if the linkage cannot be assembled at all.
    full
        Whether the crank can turn a full revolution.
    """

    intervals: tuple[tuple[float, float], ...]
    full: bool

    @property
    def empty(self) -> bool:
        """Whether no crank angle assembles."""
        return not self.intervals

    def contains(self, theta1: ArrayLike, atol: float = 1e-12) -> NDArray[np.bool_]:
        """Whether each crank angle (rad) lies in the range."""
        t = np.asarray(theta1, dtype=float)
        if self.full:
            return np.ones(t.shape, dtype=bool)
        inside = np.zeros(t.shape, dtype=bool)
        for a, b in self.intervals:
            # Bring the angle into [a, a + 2π).
            w = a + np.mod(t - a, 2 * math.pi)
            inside |= (w <= b + atol) | (w >= a + 2 * math.pi - atol)
        return inside

    def describe(self) -> str:
        """Human-readable form, in degrees."""
        if self.full:
            return "full revolution"
        if self.empty:
            return "none"
        return ", ".join(
            f"[{math.degrees(a):.4g}°, {math.degrees(b):.4g}°]" for a, b in self.intervals
        )
