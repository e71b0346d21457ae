"""Kinematics of the slider-crank, vectorised over arrays of crank states.

The loop ``l̄1 + l̄2 = r̄A2 = x + i·e`` (Wunderlich 1964, Eq. 11 with the guide at height e):
its imaginary part fixes the rod, ``sin θ2 = (e − r·sin θ1)/L``, its real part gives the slider.
Differentiating: ``θ̇2 = Θ2·θ̇1`` with ``Θ2 = −r·cos θ1/(L·cos θ2)``, and

    θ̈2 = [−r·(cos θ1·θ̈1 − sin θ1·θ̇1²) + L·sin θ2·θ̇2²]/(L·cos θ2)
    ẍ  = −r·(sin θ1·θ̈1 + cos θ1·θ̇1²) − L·(sin θ2·θ̈2 + cos θ2·θ̇2²)

``cos θ2 = 0`` (rod square to the guide) is the dead point of a crank that cannot turn fully.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import AssemblyError
from ...linkage.vectors import as_1d
from ...model.assembly import SINGULAR_TOLERANCE, AssemblyRange
from .model import SliderCrank

Lengths = tuple[float, float, float]


def assembly_range(lengths: Lengths) -> AssemblyRange:
    """Crank angles at which the slider-crank assembles: ``|e − r·sin θ1| ≤ L``.

    The crank turns fully when ``r + |e| < L``. When ``r + |e| = L`` it assembles at every
    angle but the rod stands square to the guide at ``θ1 = −π/2`` (``e > 0``), ``+π/2``
    (``e < 0``) or both (``e = 0``): a dead point that the smooth motion cannot be driven
    through. The range is then reported from that dead point round to itself, not full.
    """
    r, big_l, e = lengths
    s_lo, s_hi = (e - big_l) / r, (e + big_l) / r
    if s_lo > 1 or s_hi < -1:
        return AssemblyRange(intervals=(), full=False)
    lo_free, hi_free = s_lo <= -1, s_hi >= 1
    if lo_free and hi_free:
        if s_lo < -1 and s_hi > 1:
            return AssemblyRange(intervals=((-math.pi, math.pi),), full=True)
        half = math.pi / 2
        if s_lo == -1 and s_hi == 1:  # dead points at both θ1 = ±π/2
            return AssemblyRange(intervals=((-half, half), (half, 3 * half)), full=False)
        dead = -half if s_lo == -1 else half  # sin θ1 = −1 or +1 reaches the rod's length
        return AssemblyRange(intervals=((dead, dead + 2 * math.pi),), full=False)
    if lo_free:  # sin θ1 ≤ s_hi: the arc around θ1 = π/2 is excluded
        a = math.asin(s_hi)
        return AssemblyRange(intervals=((math.pi - a, 2 * math.pi + a),), full=False)
    if hi_free:  # sin θ1 ≥ s_lo: the arc around −π/2 is excluded
        a = math.asin(s_lo)
        return AssemblyRange(intervals=((a, math.pi - a),), full=False)
    a, b = math.asin(s_lo), math.asin(s_hi)
    return AssemblyRange(intervals=((a, b), (math.pi - b, math.pi - a)), full=False)


def _sign(branch: str | ArrayLike) -> float | NDArray[np.float64]:
    if isinstance(branch, str):
        if branch not in ("+", "-"):
            raise ValueError(f"branch must be '+' or '-', got {branch!r}")
        return 1.0 if branch == "+" else -1.0
    return np.asarray(branch, dtype=float)


@dataclass(frozen=True, eq=False)
class SliderMotion:
    """Positions, rates and accelerations of a slider-crank at arrays of crank states.

    Attributes
    ----------
    lengths
        ``(r, L, e)``, m.
    theta1
        Crank angles, rad.
    l1, l2
        Crank and rod vectors, complex, m.
    omega, alpha
        ``(θ̇1, θ̇2)`` (rad/s) and ``(θ̈1, θ̈2)`` (rad/s²).
    x, v, a
        Slider pin position along the guide (m), its velocity (m/s) and acceleration (m/s²).
    transfer
        ``Θ2 = dθ2/dθ1`` and ``X = dx/dθ1`` (m/rad).
    singular
        At or near a dead point (|cos θ2| < :data:`~balancer.model.assembly.SINGULAR_TOLERANCE`).
    """

    lengths: Lengths
    theta1: NDArray[np.float64]
    l1: NDArray[np.complex128]
    l2: NDArray[np.complex128]
    omega: tuple[NDArray[np.float64], NDArray[np.float64]]
    alpha: tuple[NDArray[np.float64], NDArray[np.float64]]
    x: NDArray[np.float64]
    v: NDArray[np.float64]
    a: NDArray[np.float64]
    transfer: tuple[NDArray[np.float64], NDArray[np.float64]]
    singular: NDArray[np.bool_]

    @property
    def size(self) -> int:
        """Number of states."""
        return self.theta1.size

    @property
    def A1(self) -> NDArray[np.complex128]:
        """Crank pin, m."""
        return self.l1

    @cached_property
    def A2(self) -> NDArray[np.complex128]:
        """Slider pin ``x + i·e``, m."""
        return np.asarray(self.x + 1j * self.lengths[2], dtype=complex)

    @cached_property
    def theta2(self) -> NDArray[np.float64]:
        """Rod angle, rad in (−π, π]."""
        return np.angle(self.l2)

    @property
    def vectors(self) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """``(l̄1, l̄2)``, m."""
        return (self.l1, self.l2)

    def vector_rate(self, k: int) -> NDArray[np.complex128]:
        """``i·ωk·l̄k`` for the crank (0) or the rod (1), m/s."""
        return 1j * self.omega[k] * self.vectors[k]

    def vector_acceleration(self, k: int) -> NDArray[np.complex128]:
        """``(i·αk − ωk²)·l̄k`` for the crank (0) or the rod (1), m/s²."""
        return (1j * self.alpha[k] - self.omega[k] ** 2) * self.vectors[k]


def motion(
    lengths: Lengths,
    theta1: ArrayLike,
    omega1: ArrayLike = 0.0,
    alpha1: ArrayLike = 0.0,
    branch: str | ArrayLike = "+",
    *,
    check: bool = True,
) -> SliderMotion:
    """Full kinematics of the slider-crank at crank states ``(θ1, θ̇1, θ̈1)``.

    Parameters
    ----------
    lengths
        ``(r, L, e)``: crank, rod (m) and guide offset (m, signed).
    theta1, omega1, alpha1
        Crank angle (rad), rate (rad/s) and acceleration (rad/s²); broadcast together.
    branch
        ``"+"`` (slider on the +x side of the crank pin) or ``"-"``, or ±1 per state.
    check
        Raise :class:`~balancer.errors.AssemblyError` for an angle where it cannot assemble.
    """
    r, big_l, e = lengths
    t, w1, a1 = np.broadcast_arrays(as_1d(theta1), as_1d(omega1), as_1d(alpha1))
    sign = _sign(branch)
    c1, s1 = np.cos(t), np.sin(t)
    s2 = (e - r * s1) / big_l
    # 1 − sin²θ2 as a product, accurate near the dead points.
    c2_sq = (big_l - e + r * s1) * (big_l + e - r * s1) / (big_l * big_l)
    bad = c2_sq < -1e-12
    if check and bad.any():
        k = int(np.argmax(bad))
        rng = assembly_range(lengths)
        raise AssemblyError(
            f"the slider-crank cannot be assembled at crank angle θ1 = {t[k]:.6g} rad "
            f"({math.degrees(t[k]):.6g}°); it assembles for θ1 in {rng.describe()}",
            key="theta1",
            value=float(t[k]),
        )
    c2 = sign * np.sqrt(np.maximum(c2_sq, 0.0))
    c2 = np.where(bad, np.nan, c2)
    l1 = r * (c1 + 1j * s1)
    l2 = big_l * (c2 + 1j * s2)
    with np.errstate(divide="ignore", invalid="ignore"):
        big2 = -r * c1 / (big_l * c2)
        w2 = big2 * w1
        a2 = (-r * (c1 * a1 - s1 * w1 * w1) + big_l * s2 * w2 * w2) / (big_l * c2)
    x = r * c1 + big_l * c2
    v = -r * s1 * w1 - big_l * s2 * w2
    acc = -r * (s1 * a1 + c1 * w1 * w1) - big_l * (s2 * a2 + c2 * w2 * w2)
    big_x = -r * s1 - big_l * s2 * big2
    return SliderMotion(
        lengths=lengths,
        theta1=np.array(t, dtype=float),
        l1=l1,
        l2=l2,
        omega=(np.array(w1, dtype=float), w2),
        alpha=(np.array(a1, dtype=float), a2),
        x=x,
        v=v,
        a=acc,
        transfer=(big2, big_x),
        singular=bad | (np.abs(c2) < SINGULAR_TOLERANCE),
    )


def motion_of(mechanism: SliderCrank, theta1: ArrayLike, omega1: ArrayLike = 0.0,
              alpha1: ArrayLike = 0.0, *, check: bool = True) -> SliderMotion:
    """:func:`motion` for a :class:`~balancer.SliderCrank` on its own branch."""
    return motion(mechanism.lengths, theta1, omega1, alpha1, mechanism.branch, check=check)


def classify(lengths: Lengths) -> str:
    """Whether the crank turns fully (``r + |e| ≤ L``): ``"rotating crank"`` or not."""
    return "rotating crank" if assembly_range(lengths).full else "oscillating crank"
