"""Attitude vectors on the rotation group, without multipliers (Bai, Xia & Ge 2024).

Each link's attitude is a unit vector ``q = R·e1`` (their Eq. 18): ``q_A`` along the crank
A0→A1, ``q_B`` along the coupler A1→A2 and ``q_D`` along the rocker *from its ground pivot*,
A3→A2 (their D→C; our θ3 is the angle of −q_D). The loop closure is
``l1·q_A + l2·q_B − l3·q_D = l4·e1`` (Eq. 25, 86). Variations and rates of the dependent
attitudes follow from the crank's through ``K`` (Eq. 35): ``(ω_B, ω_D) = K·ω_A``, and
``K_N = (1; K)`` (Sect. 6). With the centres of mass ``ρ = Z1·q + z1`` (Eq. 46) the Lagrangian
reduces to ``L = Σ(q)·ω1²/2 − V`` with (Eq. 83)::

    Σ = K_Nᵀ·J·K_N + (Z1·Z2·S·q)ᵀ·M·(Z1·Z2·S·q)

and the state ``(Π1, q)``, ``Π1 = Σ·ω1`` (Eq. 82), obeys the first-order equations (Eq. 84–85)::

    Π̇1 = (Π1/Σ)²·P + Q,       q̇ = (Π1/Σ)·Z2·S·q

where ``P = K_Nᵀ·J·δK_N + (Z1·Z2·S·q)ᵀ·M·Z1·(δZ2·S·q + Z2·S·δq)`` is the variation of the
kinetic energy per unit ω1² (their Eq. 84's bracket, with the variations of Eq. 62–68 and
Eq. 70–73) and ``Q`` the generalised force of the loads and of gravity (their Eq. 84 has gravity
only; loads enter the same way). No multipliers, no constraint forces.

Corrections to the extracted text, checked by a second route in the tests: ``Z1`` of Eq. 46 is
block lower-triangular (``[[Γ1, 0, 0], [l1·I, Γ2, 0], [0, 0, Γ3]]``), and the variation of
``K_B`` (Eq. 71, 73) is ``δ(q_Dᵀ·S1·q_A) = q_Dᵀ·q_A·(η_D − η_A)`` (similarly for ``q_B``), the
opposite sign of the printed form; ``δK`` is verified against finite differences of ``K``.

Reactions are not part of this formulation; they come from the links' Newton–Euler equations
with the accelerations it gives. Its chart is the crank angle, so it is singular where coupler
and rocker align (``q_Dᵀ·S1·q_B = 0``): the simulation stops at such a dead point.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..formulation import Evaluation
from .closed_form import FourBarFormulation
from .inverse import newton_euler
from .kinematics import motion_from_angles, motion_of

S1 = np.array([[0.0, -1.0], [1.0, 0.0]])  # the generator of planar rotations (Eq. 1)
E1 = np.array([1.0, 0.0])
I2 = np.eye(2)


def _gamma(rho: complex) -> NDArray[np.float64]:
    """``Γ = ρx·I + ρy·S1`` (Eq. 39): the centre-of-mass offset in a link's own frame."""
    return rho.real * I2 + rho.imag * S1


def _blockdiag(*blocks: NDArray[np.float64]) -> NDArray[np.float64]:
    n = sum(b.shape[0] for b in blocks)
    m = sum(b.shape[1] for b in blocks)
    out = np.zeros((n, m))
    i = j = 0
    for b in blocks:
        out[i : i + b.shape[0], j : j + b.shape[1]] = b
        i += b.shape[0]
        j += b.shape[1]
    return out


class LieGroup(FourBarFormulation):
    """Bai, Xia & Ge's attitude-vector formulation, Eq. 18–85."""

    name = "lie-group"
    minimal = False

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        (l1, _, l3, _), (c1, c2, c3) = self.lengths, self.links
        # Centre-of-mass offsets in each body frame: the rocker's frame starts at A3 along q_D.
        self.rho = (c1.com, c2.com, complex(l3 - c3.e, -c3.f))
        g1, g2, g3 = (_gamma(r) for r in self.rho)
        self.z1 = np.block(  # Eq. 46 (block lower-triangular)
            [
                [g1, np.zeros((2, 2)), np.zeros((2, 2))],
                [l1 * I2, g2, np.zeros((2, 2))],
                [np.zeros((2, 2)), np.zeros((2, 2)), g3],
            ]
        )
        self.z1_const = np.concatenate([np.zeros(4), self.lengths[3] * E1])
        self.big_s = _blockdiag(S1, S1, S1)
        self.j = np.diag([c.inertia for c in self.links])  # Eq. 52
        self.m = np.diag(np.repeat(self.mass, 2))
        # Loads per link at the centre of mass (weight included) and moments.
        self.f_stack = np.concatenate([[f.real, f.imag] for f in self.forces])
        self.mom = np.array(self.moments)

    # -- the constraint K and its variation --------------------------------------------------

    def k_matrix(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """``K = K_A·K_B`` (Eq. 35, 69): ``(ω_B, ω_D) = K·ω_A``."""
        l1, l2, l3, _ = self.lengths
        qa, qb, qd = q[0:2], q[2:4], q[4:6]
        k_a = -l1 / (l2 * l3 * (qd @ S1 @ qb))
        k_b = np.array([l3 * (qd @ S1 @ qa), l2 * (qb @ S1 @ qa)])
        return k_a * k_b

    def k_variation(self, q: NDArray[np.float64], k: NDArray[np.float64]) -> NDArray[np.float64]:
        """``δK`` per unit ``η_A`` (Eq. 70–73, sign of δK_B corrected)."""
        l1, l2, l3, _ = self.lengths
        qa, qb, qd = q[0:2], q[2:4], q[4:6]
        k_a = -l1 / (l2 * l3 * (qd @ S1 @ qb))
        k_b = np.array([l3 * (qd @ S1 @ qa), l2 * (qb @ S1 @ qa)])
        eta_b, eta_d = k  # η_B, η_D per unit η_A
        d_k_a = -(l2 * l3 / l1) * (qd @ qb) * k_a * k_a * (eta_b - eta_d)
        d_k_b = np.array([l3 * (qd @ qa) * (eta_d - 1.0), l2 * (qb @ qa) * (eta_b - 1.0)])
        return d_k_a * k_b + k_a * d_k_b

    # -- Eq. 82–85 ---------------------------------------------------------------------------

    def terms(self, q: NDArray[np.float64]
              ) -> tuple[float, float, float, NDArray[np.float64], NDArray[np.float64],
                         NDArray[np.float64]]:
        """``(Σ, P, Q_loads, K, δK, velocity map)`` at attitudes ``q`` (Eq. 83–84)."""
        k = self.k_matrix(q)
        dk = self.k_variation(q, k)
        k_n = np.concatenate([[1.0], k])
        dk_n = np.concatenate([[0.0], dk])
        z2 = _blockdiag(I2, k[0] * I2, k[1] * I2)  # Eq. 49
        dz2 = _blockdiag(np.zeros((2, 2)), dk[0] * I2, dk[1] * I2)  # Eq. 68
        sq = self.big_s @ q
        vel = self.z1 @ z2 @ sq  # centre-of-mass velocities per unit ω1 (Eq. 51)
        sigma = k_n @ self.j @ k_n + vel @ self.m @ vel  # Eq. 83
        # δq = S_q·K_N (Eq. 67): each attitude turns by its own η.
        dq = np.concatenate([sq[0:2] * k_n[0], sq[2:4] * k_n[1], sq[4:6] * k_n[2]])
        d_vel = self.z1 @ (dz2 @ sq + z2 @ self.big_s @ dq)  # Eq. 63 per unit ω1·η_A
        p = k_n @ self.j @ dk_n + vel @ self.m @ d_vel
        # Generalised force: loads at the centres of mass (δρ = Z1·δq, Eq. 64) and moments.
        q_loads = self.f_stack @ (self.z1 @ dq) + self.mom @ k_n
        return sigma, p, q_loads, k, dk, z2

    def _omega1(self, t: float, y: NDArray[np.float64], sigma: float) -> float:
        return self._motor_speed if self.driven else float(y[0]) / sigma

    @staticmethod
    def _q(y: NDArray[np.float64], driven: bool) -> NDArray[np.float64]:
        return y[0:6] if driven else y[1:7]

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        self.theta1_start = float(theta1)
        mo = motion_of(self.linkage, theta1, omega1, 0.0)
        u1, u2, u3 = (v[0] / abs(v[0]) for v in mo.vectors)
        q = np.array([u1.real, u1.imag, u2.real, u2.imag, -u3.real, -u3.imag])
        if self.driven:
            return np.append(q, 0.0)
        sigma = self.terms(q)[0]
        return np.concatenate([[sigma * omega1], q, [theta1]])  # Eq. 82; the crank angle

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        q = self._q(y, self.driven)
        sigma, p, q_loads, _, _, z2 = self.terms(q)
        w1 = self._omega1(t, y, sigma)
        q_dot = w1 * (z2 @ self.big_s @ q)  # Eq. 85
        if self.driven:
            tau = p * w1 * w1 - q_loads
            return np.append(q_dot, tau * w1)
        pi_dot = p * w1 * w1 + q_loads  # Eq. 84
        return np.concatenate([[pi_dot], q_dot, [w1]])

    def _kinematic_state(self, t: float, y: NDArray[np.float64]
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                    NDArray[np.float64], float]:
        """Angles, rates, accelerations and motor torque at a state (Eq. 82–85)."""
        q = self._q(y, self.driven)
        sigma, p, q_loads, k, dk, _ = self.terms(q)
        w1 = self._omega1(t, y, sigma)
        if self.driven:
            alpha1, tau = 0.0, p * w1 * w1 - q_loads
        else:
            pi_dot = p * w1 * w1 + q_loads
            alpha1 = (pi_dot - 2 * p * w1 * w1) / sigma  # Π̇1 = Σ·α1 + Σ̇·ω1, Σ̇ = 2P·ω1
            tau = 0.0
        omega = np.array([w1, k[0] * w1, k[1] * w1])
        alpha = np.array([alpha1, *(k * alpha1 + dk * w1 * w1)])
        theta = np.array(
            [self.theta1_of(t, y), math.atan2(q[3], q[2]), math.atan2(-q[5], -q[4])]
        )
        return theta, omega, alpha, tau

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        return self.evaluate_batch([t], [y]).at(0)

    def evaluate_batch(self, times: Sequence[float] | NDArray[np.float64],
                       states: Sequence[NDArray[np.float64]]) -> Evaluation:
        """Accelerations per state, then reactions from Newton–Euler in one vectorised call."""
        parts = [self._kinematic_state(t, y) for t, y in zip(times, states, strict=True)]
        theta = np.array([p[0] for p in parts]).T
        omega = np.array([p[1] for p in parts]).T
        alpha = np.array([p[2] for p in parts]).T
        tau = np.array([p[3] for p in parts])
        mo = motion_from_angles(self.lengths, tuple(theta), tuple(omega), tuple(alpha))
        ne = newton_euler(self.linkage, mo, gravity=(self.gravity.real, self.gravity.imag))
        return Evaluation(theta=theta, omega=omega, alpha=alpha,
                          ground=ne.ground, driving_torque=tau)

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        """The crank angle, continuous along the motion (:meth:`continuous_crank`).

        ``q_A`` gives it only modulo 2π; free motion carries the continuous angle as an
        auxiliary state after ``(Π1, q)``, bookkeeping outside the formulation's own equations.
        """
        if self.driven:
            return self.crank_angle(t)
        return self.continuous_crank(math.atan2(y[2], y[1]), float(y[7]))

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        q = self._q(y, self.driven)
        return float(q[4:6] @ S1 @ q[2:4])  # q_Dᵀ·S1·q_B = sin(θ3 − θ2)

    # -- constraints (Eq. 86) ----------------------------------------------------------------

    def _closure(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        l1, l2, l3, l4 = self.lengths
        return l1 * q[0:2] + l2 * q[2:4] - l3 * q[4:6] - l4 * E1

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        q = self._q(y, self.driven)
        norms = max(abs(np.linalg.norm(q[i : i + 2]) - 1) for i in (0, 2, 4))
        return float(max(np.linalg.norm(self._closure(q)), norms * max(self.lengths))), 0.0

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Normalise the attitudes and solve Eq. 86 for q_B, q_D by Newton's method.

        As the paper does for its initial state; Π1 is kept.
        """
        y = np.array(y, dtype=float)
        off = 0 if self.driven else 1
        q = y[off : off + 6]
        if self.driven:
            th = self.crank_angle(t)
            q[0:2] = math.cos(th), math.sin(th)
        else:
            q[0:2] /= np.linalg.norm(q[0:2])
        theta1 = self.theta1_of(t, y)
        if self.near_change_point(theta1):
            # On the assembly of the smooth motion (Eq. 86 has two solutions that cross here).
            (_, v2, v3), _, _ = self.branch_vectors(theta1, 0.0)
            u2, u3 = v2 / abs(v2), v3 / abs(v3)
            q[2:6] = u2.real, u2.imag, -u3.real, -u3.imag
            y[off : off + 6] = q
            if not self.driven:
                y[7] = theta1
            return y
        l1, l2, l3, _ = self.lengths
        phi_b = math.atan2(q[3], q[2])
        phi_d = math.atan2(q[5], q[4])
        for _ in range(4):
            qb = np.array([math.cos(phi_b), math.sin(phi_b)])
            qd = np.array([math.cos(phi_d), math.sin(phi_d)])
            q[2:4], q[4:6] = qb, qd
            res = self._closure(q)
            if np.linalg.norm(res) <= 1e-16 * sum(self.lengths):
                break
            jac = np.column_stack([l2 * S1 @ qb, -l3 * S1 @ qd])
            dphi = np.linalg.lstsq(jac, -res, rcond=None)[0]
            phi_b += dphi[0]
            phi_d += dphi[1]
        y[off : off + 6] = q
        if not self.driven:
            y[7] = self.theta1_of(t, y)
        return y
