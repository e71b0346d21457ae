"""Where a general linkage assembles: the crank angles its groups can be placed at.

Sampled over a revolution from the reference pose, the sampled minima of the groups' least
assembly gap refined (a dip between samples must not hide a dead point), and the ends of a
partial range found by bisection. The four-bar and the slider-crank have theirs in closed form
as well (:mod:`balancer.mechanisms.fourbar.assembly`, :mod:`balancer.mechanisms.slidercrank.
kinematics`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..model.assembly import AssemblyRange
from . import kinematics
from .inputs import InputState
from .structure import Structure

#: Least normalised assembly gap of a dyad over a revolution for the crank to turn fully: at
#: or below it the dyad reaches a dead point (its links in line) within rounding.
GAP_TOLERANCE = 1e-12
#: Crank angles sampled to find where a linkage assembles (then refined).
RANGE_SAMPLES = 1440
#: Points per bracket, and rounds, of the refinement of the sampled minima of the gap.
ZOOM_POINTS = 33
ZOOM_ROUNDS = 5
def assembly_gaps(structure: Structure, theta1: NDArray[np.float64]) -> NDArray[np.float64]:
    """The least assembly gap of the groups at each angle.

    Where a link cannot be placed (a numeric group's Newton fails) the gap is −1.
    """
    gaps: list[NDArray[np.float64]] = []
    with np.errstate(all="ignore"):
        pose = kinematics.positions(structure, InputState.crank(theta1), gaps=gaps)
    least = np.ones_like(theta1)
    for g in gaps:
        least = np.minimum(least, np.where(np.isnan(g), -1.0, g))
    for k in range(structure.size):
        least = np.where(np.isfinite(pose.angles[k]), least, -1.0)
    return least


def _refined_minimum(structure: Structure, lo: NDArray[np.float64],
                     hi: NDArray[np.float64]) -> float:
    """The least gap within brackets ``[lo, hi]`` of crank angles, each around one minimum.

    All brackets at once: :data:`ZOOM_POINTS` equally spaced angles in each, then the bracket
    narrowed to the two spacings around the least, :data:`ZOOM_ROUNDS` times — a factor 16
    each, from two sampling steps to ~1e-7 rad, where the gap (quadratic about its minimum)
    is within ~1e-15 of it.
    """
    if not lo.size:
        return math.inf
    rows = np.arange(lo.size)
    least = math.inf
    for _ in range(ZOOM_ROUNDS):
        grid = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, ZOOM_POINTS)[None, :]
        gap = assembly_gaps(structure, grid.ravel()).reshape(grid.shape)
        k = np.argmin(gap, axis=1)
        least = min(least, float(np.min(gap[rows, k])))
        width = (hi - lo) / (ZOOM_POINTS - 1)
        lo, hi = grid[rows, k] - width, grid[rows, k] + width
    return least


def assembly_range(structure: Structure) -> AssemblyRange:
    """Where the linkage assembles on the reference branch.

    Sampled, the sampled minima refined, the ends found by bisection (see
    :data:`GAP_TOLERANCE`).
    """
    start = structure.ref_angle[structure.input]
    step = 2 * math.pi / RANGE_SAMPLES
    theta = start + step * np.arange(RANGE_SAMPLES + 1, dtype=float)
    gap = assembly_gaps(structure, theta)

    def at(t: float) -> float:
        return float(assembly_gaps(structure, np.array([t]))[0])

    # Refine each sampled minimum: a dip between samples must not hide a dead point.
    # (strict on one side: a flat stretch, as of a group whose gap does not change, is none)
    dips = np.flatnonzero((gap[1:-1] < gap[:-2]) & (gap[1:-1] <= gap[2:])) + 1
    least = min(float(np.min(gap)), _refined_minimum(structure, theta[dips - 1],
                                                      theta[dips + 1]))
    if least > GAP_TOLERANCE:
        structure.kinematic["least gap"] = least
        return AssemblyRange(intervals=((-math.pi, math.pi),), full=True)
    from scipy.optimize import brentq

    # The range around the reference: walk out each way to the first bad sample, then bisect.
    ends: list[float] = []
    for direction in (1, -1):
        t = start
        while True:
            t_next = t + direction * step
            if abs(t_next - start) > 2 * math.pi or at(t_next) <= GAP_TOLERANCE:
                break
            t = t_next
        if abs(t - start) >= 2 * math.pi - step:
            ends.append(t)
            continue
        lo, hi = sorted((t, t + direction * step))
        good_is_lo = direction == 1
        def f(x: float) -> float:
            return at(x) - GAP_TOLERANCE

        try:
            edge = brentq(f, lo, hi, xtol=1e-12) if f(lo) * f(hi) < 0 else (
                lo if good_is_lo else hi)
        except ValueError:
            edge = lo if good_is_lo else hi
        ends.append(edge)
    hi, lo = ends
    if hi - lo <= 0:
        return AssemblyRange(intervals=(), full=False)
    shift = 2 * math.pi * math.floor((lo + math.pi) / (2 * math.pi))  # start within [−π, π)
    return AssemblyRange(intervals=((lo - shift, hi - shift),), full=False)
