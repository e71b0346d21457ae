"""Where a four-bar assembles, from its lengths alone: Grashof's classes and the crank's range.

A four-bar's range follows from the triangle inequalities of its diagonal (Meijaard & van der
Wijk 2020, Eq. 2), which also tell a four-bar that assembles nowhere from one that does, as the
model checks it.
"""

from __future__ import annotations

import math
from enum import StrEnum

import numpy as np

from ...model.assembly import AssemblyRange

#: Relative tolerance within which a position at a triangle-inequality bound counts as reached
#: (rounding) rather than outside the assembly range.
BOUND_TOLERANCE = 1e-12


Lengths = tuple[float, float, float, float]


class LinkageClass(StrEnum):
    """Grashof classification of a four-bar (which links can turn fully)."""

    CRANK_ROCKER = "crank-rocker"
    """Grashof, crank shortest: the crank turns fully, the rocker oscillates."""
    DOUBLE_CRANK = "double-crank"
    """Grashof, frame shortest: crank and rocker both turn fully (drag link)."""
    ROCKER_CRANK = "rocker-crank"
    """Grashof, rocker shortest: the rocker turns fully, the crank only oscillates."""
    DOUBLE_ROCKER = "double-rocker"
    """Grashof, coupler shortest: the coupler turns fully, crank and rocker oscillate."""
    TRIPLE_ROCKER = "triple-rocker"
    """Non-Grashof: no link turns fully relative to the frame."""
    CHANGE_POINT = "change-point"
    """s + l = p + q: all joints become collinear and the assembly can switch (parallelogram,
    deltoid)."""


def classify(lengths: Lengths, rtol: float = BOUND_TOLERANCE) -> LinkageClass:
    """Grashof classification of a four-bar with lengths ``(l1, l2, l3, l4)``.

    Grashof's condition ``s + l ≤ p + q`` (shortest plus longest at most the sum of the other
    two); equality within ``rtol`` of the perimeter is a change-point linkage.
    """
    ordered = sorted(lengths)
    s, p, q, long_ = ordered
    slack = (p + q) - (s + long_)
    if abs(slack) <= rtol * sum(lengths):
        return LinkageClass.CHANGE_POINT
    if slack < 0:
        return LinkageClass.TRIPLE_ROCKER
    shortest = int(np.argmin(lengths))
    return (
        LinkageClass.CRANK_ROCKER,
        LinkageClass.DOUBLE_ROCKER,
        LinkageClass.ROCKER_CRANK,
        LinkageClass.DOUBLE_CRANK,
    )[shortest]


def cosine_bounds(lengths: Lengths) -> tuple[float, float]:
    """Bounds ``(c_lo, c_hi)`` on cos θ1 for assembly (from Eq. 2 and the triangle inequalities).

    ``|l2 − l3| ≤ l23 ≤ l2 + l3`` with ``l23² = l1² + l4² − 2·l1·l4·cos θ1`` gives
    ``c_lo ≤ cos θ1 ≤ c_hi``.
    """
    l1, l2, l3, l4 = lengths
    base = l1 * l1 + l4 * l4
    c_lo = (base - (l2 + l3) ** 2) / (2 * l1 * l4)
    c_hi = (base - (l2 - l3) ** 2) / (2 * l1 * l4)
    return c_lo, c_hi


def assembly_range(lengths: Lengths, rtol: float = BOUND_TOLERANCE) -> AssemblyRange:
    """Crank angles at which a four-bar with lengths ``(l1, l2, l3, l4)`` assembles."""
    c_lo, c_hi = cosine_bounds(lengths)
    tol = rtol * 4  # the bounds are O(1) numbers; allow a few roundings
    if c_lo > 1 + tol or c_hi < -1 - tol or c_lo > c_hi:
        return AssemblyRange(intervals=(), full=False)
    lo_free = c_lo <= -1 + tol  # no upper bound on l23 binds
    hi_free = c_hi >= 1 - tol  # no lower bound on l23 binds
    if lo_free and hi_free:
        return AssemblyRange(intervals=((-math.pi, math.pi),), full=True)
    a_lo = math.acos(min(1.0, max(-1.0, c_lo)))  # cos θ1 ≥ c_lo  ⇔  |θ1| ≤ a_lo
    a_hi = math.acos(min(1.0, max(-1.0, c_hi)))  # cos θ1 ≤ c_hi  ⇔  |θ1| ≥ a_hi
    if hi_free:
        return AssemblyRange(intervals=((-a_lo, a_lo),), full=False)
    if lo_free:
        return AssemblyRange(intervals=((a_hi, 2 * math.pi - a_hi),), full=False)
    return AssemblyRange(intervals=((-a_lo, -a_hi), (a_hi, a_lo)), full=False)


def crank_turns_fully(lengths: Lengths) -> bool:
    """Whether the crank can turn a full revolution."""
    return assembly_range(lengths).full
