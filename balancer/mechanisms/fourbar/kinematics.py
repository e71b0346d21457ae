"""Kinematics of the 4R four-bar, vectorised over arrays of crank angles.

Implements Meijaard & van der Wijk (2020), Sect. 2: dependent angles for either assembly
(Eq. 2–4), first-order transfer functions and angular velocities (Eq. 5–7), angular
accelerations (Eq. 8–10) and the θ2-free form of the coupler's rate and acceleration (Eq. 11),
which serves as a cross-check. The Grashof classification and the crank angles at which the
linkage can be assembled are the model's (:mod:`balancer.model.assembly`).

Vectors in the plane are complex numbers, as in the paper: ``l̄k = lk·exp(iθk)``. Two helpers
give the scalar and the cross product of such vectors: ``inner(x, y) = Re(x*·y)`` (the paper's
``⟨x̄, ȳ⟩``) and ``cross(x, y) = Im(x*·y)``, the z-component of ``x × y``; note
``⟨x̄, iȳ⟩ = −cross(x, y)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import AssemblyError
from ...linkage.vectors import as_1d, cross, inner
from ...model.assembly import SINGULAR_TOLERANCE
from .assembly import BOUND_TOLERANCE, Lengths, assembly_range, cosine_bounds
from .model import FourBar


def _sign(branch: str) -> float:
    if branch == "+":
        return 1.0
    if branch == "-":
        return -1.0
    raise ValueError(f"branch must be '+' or '-', got {branch!r}")


@dataclass(frozen=True, eq=False)
class Position:
    """Configuration of a four-bar at an array of crank angles (Eq. 2–4).

    Attributes
    ----------
    lengths
        ``(l1, l2, l3, l4)``, m.
    theta1
        Crank angles, rad, shape ``(N,)``.
    l1, l2, l3
        Link vectors ``l̄k = lk·exp(iθk)`` as complex arrays, m.
    singular
        Flag for positions at or near a dead or change point (|sin(θ3 − θ2)| <
        :data:`SINGULAR_TOLERANCE`), where the dependent rates are ill-determined.
    """

    lengths: Lengths
    theta1: NDArray[np.float64]
    l1: NDArray[np.complex128]
    l2: NDArray[np.complex128]
    l3: NDArray[np.complex128]
    singular: NDArray[np.bool_]

    @property
    def A1(self) -> NDArray[np.complex128]:
        """Position of joint A1 (crank–coupler), m."""
        return self.l1

    @cached_property
    def A2(self) -> NDArray[np.complex128]:
        """Position of joint A2 (coupler–rocker), m."""
        return self.l1 + self.l2

    @property
    def A3(self) -> complex:
        """Position of the ground pivot A3, m."""
        return complex(self.lengths[3], 0.0)

    @cached_property
    def theta2(self) -> NDArray[np.float64]:
        """Coupler angle θ2, rad in (−π, π]."""
        return np.angle(self.l2)

    @cached_property
    def theta3(self) -> NDArray[np.float64]:
        """Rocker angle θ3 (direction A2→A3), rad in (−π, π]."""
        return np.angle(self.l3)

    @cached_property
    def sin_transmission(self) -> NDArray[np.float64]:
        """``sin(θ3 − θ2)``: zero at dead and change points."""
        return cross(self.l2, self.l3) / (self.lengths[1] * self.lengths[2])




@lru_cache(maxsize=256)
def _heron_constants(lengths: Lengths) -> tuple[float, float]:
    """``(l2 + l3)² − (l1 + l4)²`` and ``(l4 − l1)² − (l2 − l3)²`` of the Heron form of Eq. 3.

    One of them is zero exactly for a change-point linkage: it is set to zero when it is within
    the classification tolerance, so that rounding in the lengths' sums (0.25 + 0.1 − 0.1 −
    0.25 ≠ 0 in floating point) does not spoil the positions near the change point.
    """
    l1, l2, l3, l4 = lengths
    k_far = ((l2 - l1) + (l3 - l4)) * (l2 + l3 + l1 + l4)
    k_near = ((l4 - l1) + (l3 - l2)) * ((l4 - l1) + (l2 - l3))
    tol = 4 * BOUND_TOLERANCE * (l1 + l2 + l3 + l4) ** 2
    return (0.0 if abs(k_far) <= tol else k_far), (0.0 if abs(k_near) <= tol else k_near)


def position(
    lengths: Lengths,
    theta1: ArrayLike,
    branch: str | ArrayLike = "+",
    *,
    check: bool = True,
) -> Position:
    """Dependent link vectors at crank angles ``theta1`` (Eq. 2–4).

    Parameters
    ----------
    lengths
        ``(l1, l2, l3, l4)``, m.
    theta1
        Crank angle(s), rad.
    branch
        ``"+"`` or ``"-"`` (see :class:`balancer.FourBar`), or an array of ±1 per angle.
    check
        Raise :class:`AssemblyError` for an angle outside the assembly range; otherwise such
        positions come back as NaN and flagged singular.

    Returns
    -------
    Position
        The configuration; positions within :data:`BOUND_TOLERANCE` of a triangle-inequality
        bound are put on it exactly and flagged.
    """
    l1, l2, l3, l4 = lengths
    t = as_1d(theta1)
    sign = _sign(branch) if isinstance(branch, str) else np.asarray(branch, dtype=float)
    c_half = np.cos(0.5 * t)
    s_half = np.sin(0.5 * t)
    v1 = np.empty(t.shape, complex)  # l̄1 = l1·exp(iθ1), from the half angles
    v1.real = l1 * (c_half * c_half - s_half * s_half)
    v1.imag = 2 * l1 * c_half * s_half
    v23 = l4 - v1  # l̄23 = −l̄1 − l̄4, from A1 to A3
    l23 = np.abs(v23)
    # h23 of Eq. 3 in Heron's form, 4·l23²·h23² = [(l2 + l3)² − l23²]·[l23² − (l2 − l3)²], with
    # both factors written through half-angles of θ1 so that neither suffers cancellation near
    # a triangle-inequality bound (where l23 varies only quadratically with θ1 and Eq. 3 as
    # written loses half the digits of h23):
    #   (l2 + l3)² − l23² = [(l2 + l3)² − (l1 + l4)²] + 4·l1·l4·cos²(θ1/2)
    #   l23² − (l2 − l3)² = [(l4 − l1)² − (l2 − l3)²] + 4·l1·l4·sin²(θ1/2)
    k_far, k_near = _heron_constants(lengths)
    far = k_far + 4 * l1 * l4 * c_half * c_half
    near = k_near + 4 * l1 * l4 * s_half * s_half
    with np.errstate(divide="ignore", invalid="ignore"):
        d23 = (l23 * l23 + l2 * l2 - l3 * l3) / (2 * l23)  # Eq. 3
        tol = BOUND_TOLERANCE * 4 * (l1 + l2 + l3 + l4) ** 2
        bad = (far < -tol) | (near < -tol) | (l23 <= BOUND_TOLERANCE * max(l1, l4))
        bad |= ~np.isfinite(d23)
        if check and bad.any():
            k = int(np.argmax(bad))
            rng = assembly_range(lengths)
            raise AssemblyError(
                f"the linkage cannot be assembled at crank angle θ1 = {t[k]:.6g} rad "
                f"({math.degrees(t[k]):.6g}°); it assembles for θ1 in {rng.describe()}",
                key="theta1",
                value=float(t[k]),
            )
        h23 = sign * np.sqrt(np.maximum(far, 0.0) * np.maximum(near, 0.0)) / (2 * l23)
        v2 = (d23 + 1j * h23) * (v23 / l23)  # Eq. 4
    v3 = v23 - v2
    if bad.any():
        v2[bad] = np.nan
        v3[bad] = np.nan
    s_mu = cross(v2, v3) / (l2 * l3)
    singular = bad | (np.abs(s_mu) < SINGULAR_TOLERANCE)
    return Position(lengths=lengths, theta1=t, l1=v1, l2=v2, l3=v3, singular=singular)


def position_of(linkage: FourBar, theta1: ArrayLike, *, check: bool = True) -> Position:
    """:func:`position` for a :class:`~balancer.FourBar` on its own branch."""
    return position(linkage.lengths, theta1, linkage.branch, check=check)


def transfer_functions(pos: Position) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """First-order kinematic transfer functions ``Θ2 = dθ2/dθ1``, ``Θ3 = dθ3/dθ1`` (Eq. 7).

    ``Θ2 = −⟨l̄3, il̄1⟩/⟨l̄3, il̄2⟩``, ``Θ3 = −⟨l̄2, il̄1⟩/⟨l̄2, il̄3⟩``; infinite at dead points.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        big2 = -cross(pos.l3, pos.l1) / cross(pos.l3, pos.l2)
        big3 = -cross(pos.l2, pos.l1) / cross(pos.l2, pos.l3)
    return big2, big3


@dataclass(frozen=True, eq=False)
class FourBarMotion:
    """Positions, angular velocities and accelerations of a four-bar at arrays of states.

    Attributes
    ----------
    pos
        The configuration.
    omega
        Angular velocities ``(ω1, ω2, ω3)``, rad/s, each shape ``(N,)``.
    alpha
        Angular accelerations ``(α1, α2, α3)``, rad/s², each shape ``(N,)``.
    transfer
        ``(Θ2, Θ3)`` of Eq. 7.
    """

    pos: Position
    omega: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    alpha: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    transfer: tuple[NDArray[np.float64], NDArray[np.float64]]

    @property
    def lengths(self) -> Lengths:
        """``(l1, l2, l3, l4)``, m."""
        return self.pos.lengths

    @property
    def size(self) -> int:
        """Number of states."""
        return self.pos.theta1.size

    @property
    def vectors(self) -> tuple[NDArray[np.complex128], ...]:
        """Link vectors ``(l̄1, l̄2, l̄3)``, m."""
        return (self.pos.l1, self.pos.l2, self.pos.l3)

    @cached_property
    def theta(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Link angles ``(θ1, θ2, θ3)``, rad (θ2, θ3 in (−π, π])."""
        return (self.pos.theta1, self.pos.theta2, self.pos.theta3)

    def vector_rate(self, k: int) -> NDArray[np.complex128]:
        """Time derivative ``i·ωk·l̄k`` of link vector ``k`` (0-based), m/s."""
        return 1j * self.omega[k] * self.vectors[k]

    def vector_acceleration(self, k: int) -> NDArray[np.complex128]:
        """Second derivative ``(i·αk − ωk²)·l̄k`` of link vector ``k`` (0-based), m/s²."""
        return (1j * self.alpha[k] - self.omega[k] ** 2) * self.vectors[k]

    @cached_property
    def joint_velocities(self) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """Velocities of A1 and A2, m/s."""
        v1 = self.vector_rate(0)
        return v1, v1 + self.vector_rate(1)

    @cached_property
    def joint_accelerations(self) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """Accelerations of A1 and A2, m/s²."""
        a1 = self.vector_acceleration(0)
        return a1, a1 + self.vector_acceleration(1)

    def joint_positions(self) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """Positions of A1 and A2, m."""
        return self.pos.A1, self.pos.A2


def dependent_accelerations(
    pos: Position,
    transfer: tuple[NDArray[np.float64], NDArray[np.float64]],
    omega: tuple[ArrayLike, ArrayLike, ArrayLike],
    alpha1: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Angular accelerations of coupler and rocker (Eq. 9–10).

    ``θ̈2 = Θ2·θ̈1 + (⟨l̄3,l̄1⟩θ̇1² + ⟨l̄3,l̄2⟩θ̇2² + l3²θ̇3²)/⟨l̄3, il̄2⟩`` and
    ``θ̈3 = Θ3·θ̈1 + (⟨l̄2,l̄1⟩θ̇1² + l2²θ̇2² + ⟨l̄2,l̄3⟩θ̇3²)/⟨l̄2, il̄3⟩``.
    """
    _, l2, l3, _ = pos.lengths
    w1, w2, w3 = (np.asarray(w) for w in omega)
    alpha = np.asarray(alpha1)
    v1, v2, v3 = pos.l1, pos.l2, pos.l3
    big2, big3 = transfer
    w1s, w2s, w3s = w1 * w1, w2 * w2, w3 * w3
    with np.errstate(divide="ignore", invalid="ignore"):
        a2 = big2 * alpha + (inner(v3, v1) * w1s + inner(v3, v2) * w2s + l3 * l3 * w3s) / (
            -cross(v3, v2)
        )
        a3 = big3 * alpha + (inner(v2, v1) * w1s + l2 * l2 * w2s + inner(v2, v3) * w3s) / (
            -cross(v2, v3)
        )
    return a2, a3


def motion(
    lengths: Lengths,
    theta1: ArrayLike,
    omega1: ArrayLike = 0.0,
    alpha1: ArrayLike = 0.0,
    branch: str | ArrayLike = "+",
    *,
    check: bool = True,
) -> FourBarMotion:
    """Full kinematics at crank states ``(θ1, θ̇1, θ̈1)`` (Eq. 2–10).

    Parameters
    ----------
    lengths
        ``(l1, l2, l3, l4)``, m.
    theta1, omega1, alpha1
        Crank angle (rad), angular velocity (rad/s) and acceleration (rad/s²); broadcast
        together.
    branch
        Assembly, see :func:`position`.
    check
        See :func:`position`.
    """
    t, w1, a1 = np.broadcast_arrays(as_1d(theta1), as_1d(omega1), as_1d(alpha1))
    pos = position(lengths, t, branch, check=check)
    big = transfer_functions(pos)
    w2 = big[0] * w1  # Eq. 6
    w3 = big[1] * w1
    a2, a3 = dependent_accelerations(pos, big, (w1, w2, w3), a1)
    return FourBarMotion(
        pos=pos,
        omega=(np.array(w1, dtype=float), w2, w3),
        alpha=(np.array(a1, dtype=float), a2, a3),
        transfer=big,
    )


def motion_of(
    linkage: FourBar,
    theta1: ArrayLike,
    omega1: ArrayLike = 0.0,
    alpha1: ArrayLike = 0.0,
    *,
    check: bool = True,
) -> FourBarMotion:
    """:func:`motion` for a :class:`~balancer.FourBar` on its own branch."""
    return motion(linkage.lengths, theta1, omega1, alpha1, linkage.branch, check=check)


def coupler_rates_eq11(
    lengths: Lengths,
    theta1: ArrayLike,
    theta3: ArrayLike,
    omega1: ArrayLike,
    omega3: ArrayLike,
    alpha1: ArrayLike,
    alpha3: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Coupler angular velocity and acceleration from θ1, θ3 and their rates only (Eq. 11).

    A second route to ``θ̇2`` and ``θ̈2`` that does not use θ2, for cross-checking Eq. 6 and 9.
    """
    l1, l2, l3, l4 = lengths
    t1, t3, w1, w3, a1, a3 = (np.asarray(x, dtype=float) for x in (
        theta1, theta3, omega1, omega3, alpha1, alpha3))
    c13 = np.cos(t1 - t3)
    s13 = np.sin(t1 - t3)
    k1 = l1 * (l1 + l3 * c13 - l4 * np.cos(t1))
    k3 = l3 * (l3 + l1 * c13 - l4 * np.cos(t3))
    w2 = (k1 * w1 + k3 * w3) / (l2 * l2)
    a2 = (
        k1 * a1
        - l1 * (l3 * s13 - l4 * np.sin(t1)) * w1 * w1
        + k3 * a3
        + l3 * (l1 * s13 + l4 * np.sin(t3)) * w3 * w3
    ) / (l2 * l2)
    return w2, a2


# ----------------------------------------------------------------------------------------------
# Change points: where the two assemblies meet and the motion can pass from one to the other


@lru_cache(maxsize=256)
def change_point_angles(lengths: Lengths, rtol: float = BOUND_TOLERANCE) -> tuple[float, ...]:
    """Crank angles in ``[0, 2π)`` at which all four joints are collinear while the crank turns.

    In a change-point linkage (s + l = p + q) the two assemblies meet at θ1 = 0 and/or π and a
    motion through such a position can continue on either; elsewhere they never meet while the
    crank turns.
    """
    c_lo, c_hi = cosine_bounds(lengths)
    tol = 4 * rtol
    out = []
    if abs(c_hi - 1) <= tol:
        out.append(0.0)
    if abs(c_lo + 1) <= tol:
        out.append(math.pi)
    return tuple(out)


@lru_cache(maxsize=256)
def smooth_continuation_flips(
    lengths: Lengths, theta_star: float, sign: float, delta: float = 1e-5
) -> bool:
    """Whether the smooth motion through the change point ``theta_star`` changes branch sign.

    The motion, arriving with increasing θ1 on the assembly ``sign``, follows the analytic
    continuation of its path: the assembly after the change point whose transfer function Θ2
    continues the one before it.
    """
    before = position(lengths, theta_star - delta, sign)
    big_before = transfer_functions(before)[0][0]
    after_same = transfer_functions(position(lengths, theta_star + delta, sign))[0][0]
    after_flip = transfer_functions(position(lengths, theta_star + delta, -sign))[0][0]
    return bool(abs(after_flip - big_before) < abs(after_same - big_before))


def branch_sign_along(
    lengths: Lengths, sign0: float, theta0: float, theta1: ArrayLike
) -> NDArray[np.float64] | float:
    """Assembly sign of the smooth motion at crank angle(s) ``theta1`` (unwrapped, rad).

    The motion is on assembly ``sign0`` at ``theta0`` and moves continuously in θ1; for a
    change-point linkage the sign changes at each change point it passes where the smooth
    continuation switches assembly (the parallelogram stays a parallelogram). Any other linkage
    keeps ``sign0``. ``theta0`` should not itself be a change point.
    """
    points = change_point_angles(lengths)
    if not points:
        return sign0
    t = np.asarray(theta1, dtype=float)
    flips = 0
    for theta_star in points:
        flip_plus = smooth_continuation_flips(lengths, theta_star, 1.0)
        flip_minus = smooth_continuation_flips(lengths, theta_star, -1.0)
        if flip_plus != flip_minus:  # never seen; be explicit rather than wrong
            raise NotImplementedError("a change point whose continuation depends on the branch")
        if flip_plus:
            # Number of points θ* + 2πn passed between θ0 and θ1.
            k0 = np.floor((theta0 - theta_star) / (2 * math.pi))
            k1 = np.floor((t - theta_star) / (2 * math.pi))
            flips = flips + np.abs(k1 - k0)
    signs = sign0 * np.where(np.mod(flips, 2) == 1, -1.0, 1.0)
    return signs if np.ndim(signs) else float(signs)


def cycle_branch_signs(
    lengths: Lengths, branch: str, theta1: ArrayLike
) -> NDArray[np.float64] | str:
    """Assembly sign at each crank angle of a smooth revolution θ1 ∈ [0, 2π).

    For most linkages this is just ``branch``. For a change-point linkage the given branch
    holds just after θ1 = 0 and the sign changes where the smooth motion passes from one
    assembly to the other.
    """
    if not change_point_angles(lengths):
        return branch
    t = np.mod(as_1d(theta1), 2 * math.pi)
    return np.asarray(branch_sign_along(lengths, _sign(branch), 1e-9, t), dtype=float) * np.ones(
        t.shape
    )


def motion_from_angles(
    lengths: Lengths,
    theta: tuple[ArrayLike, ArrayLike, ArrayLike],
    omega: tuple[ArrayLike, ArrayLike, ArrayLike],
    alpha: tuple[ArrayLike, ArrayLike, ArrayLike],
) -> FourBarMotion:
    """A :class:`FourBarMotion` from given link angles, rates and accelerations (no loop solve).

    For states that come from a simulation, which carries all three angles; the loop closure is
    whatever the state satisfies.
    """
    l1, l2, l3, _ = lengths
    th = [as_1d(x) for x in theta]
    n = max(x.size for x in th)
    th = [np.broadcast_to(x, (n,)) for x in th]
    vectors = [length * np.exp(1j * x) for length, x in zip((l1, l2, l3), th, strict=True)]
    s_mu = cross(vectors[1], vectors[2]) / (l2 * l3)
    pos = Position(
        lengths=lengths,
        theta1=np.array(th[0], dtype=float),
        l1=vectors[0],
        l2=vectors[1],
        l3=vectors[2],
        singular=np.abs(s_mu) < SINGULAR_TOLERANCE,
    )
    big = transfer_functions(pos)
    w1, w2, w3 = (np.broadcast_to(as_1d(x), (n,)).astype(float) for x in omega)
    a1, a2, a3 = (np.broadcast_to(as_1d(x), (n,)).astype(float) for x in alpha)
    return FourBarMotion(pos=pos, omega=(w1, w2, w3), alpha=(a1, a2, a3), transfer=big)


# ----------------------------------------------------------------------------------------------
# One state at a time: the same equations for Python scalars, for the integrators' right-hand
# sides (numpy's per-call overhead on size-1 arrays would dominate). Tested against the
# vectorised functions above.


def position_scalar(
    lengths: Lengths, theta1: float, sign: float
) -> tuple[complex, complex, complex]:
    """Link vectors ``(l̄1, l̄2, l̄3)`` at one crank angle (Eq. 2–4, as :func:`position`).

    Raises
    ------
    ValueError
        If the linkage cannot be assembled at ``theta1``.
    """
    l1, l2, l3, l4 = lengths
    c_half = math.cos(0.5 * theta1)
    s_half = math.sin(0.5 * theta1)
    v1 = complex(l1 * (c_half * c_half - s_half * s_half), 2 * l1 * c_half * s_half)
    v23 = l4 - v1
    l23 = abs(v23)
    k_far, k_near = _heron_constants(lengths)
    far = k_far + 4 * l1 * l4 * c_half * c_half
    near = k_near + 4 * l1 * l4 * s_half * s_half
    tol = BOUND_TOLERANCE * 4 * (l1 + l2 + l3 + l4) ** 2
    if far < -tol or near < -tol or l23 == 0.0:
        raise ValueError(f"the linkage cannot be assembled at θ1 = {theta1!r} rad")
    d23 = (l23 * l23 + l2 * l2 - l3 * l3) / (2 * l23)
    h23 = sign * math.sqrt(max(far, 0.0) * max(near, 0.0)) / (2 * l23)
    v2 = complex(d23, h23) * (v23 / l23)
    return v1, v2, v23 - v2


def rates_scalar(
    lengths: Lengths, vectors: tuple[complex, complex, complex], omega1: float
) -> tuple[float, float, float, float, float, float]:
    """Transfer functions and velocity terms at one state (Eq. 7, 9–10, as the vectorised ones).

    Returns ``(Θ2, Θ3, θ̇2, θ̇3, b2, b3)`` with ``θ̈k = Θk·θ̈1 + bk``.
    """
    _, l2, l3, _ = lengths
    v1, v2, v3 = vectors
    c23 = v2.real * v3.imag - v2.imag * v3.real  # l̄2 × l̄3
    big2 = (v3.real * v1.imag - v3.imag * v1.real) / c23  # −(l̄3 × l̄1)/(l̄3 × l̄2)
    big3 = -(v2.real * v1.imag - v2.imag * v1.real) / c23
    w2, w3 = big2 * omega1, big3 * omega1
    w1s, w2s, w3s = omega1 * omega1, w2 * w2, w3 * w3
    b2 = ((v3.real * v1.real + v3.imag * v1.imag) * w1s
          + (v3.real * v2.real + v3.imag * v2.imag) * w2s + l3 * l3 * w3s) / c23
    b3 = -((v2.real * v1.real + v2.imag * v1.imag) * w1s + l2 * l2 * w2s
           + (v2.real * v3.real + v2.imag * v3.imag) * w3s) / c23
    return big2, big3, w2, w3, b2, b3
