"""Opened kinematic loop with principal vectors (Meijaard & van der Wijk 2020, Sect. 3).

The loop is opened at A3: the three link angles are coordinates, the reaction R̄A3 closes the
loop. Equations of motion (Eq. 22)::

    Σk (Mjk·θ̈k + Cjk·θ̇k²) + Djx·RA3x + Djy·RA3y = Qj      (j = 1, 2, 3)

with the mass matrix and convective terms from the principal vectors (Eq. 12–13, 23), the
reaction coefficients ``Djx = −lj·sin θj``, ``Djy = lj·cos θj`` (Eq. 24), the generalised
forces of Eq. 25, and the loop closed at acceleration level (Eq. 27). These five linear
equations give θ̈1, θ̈2, θ̈3, RA3x, RA3y; R̄A0 follows from the motion of the centre of mass
(Eq. 28). With the crank driven, θ̈1 = 0 and the motor torque in Q1 is the fifth unknown.

The state (θ1, θ2, θ3, θ̇1, θ̇2, θ̇3) is not minimal: the integrator projects it back onto the
loop closure (Eq. 26) and its derivative by least-norm corrections, which stay well defined at
a dead point of the crank (coupler and rocker aligned), so a non-Grashof linkage swings through
its limits.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...linkage.vectors import Num, cross_scalar
from ..formulation import Evaluation, least_norm_many
from .closed_form import FourBarFormulation
from .kinematics import motion_of, rates_scalar

#: Three values of the links (complex numbers, or complex arrays over many states).
Three: TypeAlias = tuple[Num, Num, Num]
#: Eq. 22 and 27 at a state (or many): ``M``, ``C``, ``G``, ``Q``, ``b``, the principal vectors
#: and the link vectors (:meth:`OpenedLoop.system`).
System: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                          NDArray[np.float64], NDArray[np.float64], tuple[Num, ...], Three]
#: The accelerations, R̄A3, the motor torque, the principal and the link vectors at a state.
Solution: TypeAlias = tuple[NDArray[np.floating], complex, float, tuple[Num, ...], Three]


def _ip(x: complex, y: complex) -> float:
    """⟨x̄, ȳ⟩ = Re(x*·y)."""
    return x.real * y.real + x.imag * y.imag



class OpenedLoop(FourBarFormulation):
    """Opened loop with principal vectors, Eq. 12–28."""

    name = "opened-loop"
    minimal = False
    passes_dead_points = True

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        (l1, l2, _, _), (c1, c2, c3) = self.lengths, self.links
        m1, m2, m3 = self.mass
        # Constant diagonal of the mass matrix (Eq. 23, second forms): inertias of the reduced
        # systems about the links' first joints.
        self.m_diag = (
            c1.inertia + m1 * abs(c1.com) ** 2 + (m2 + m3) * l1 * l1,
            c2.inertia + m2 * abs(c2.com) ** 2 + m3 * l2 * l2,
            c3.inertia + m3 * abs(c3.com) ** 2,
        )

    # -- principal vectors -------------------------------------------------------------------

    def principal_vectors(self, vectors: Three) -> tuple[Num, Num, Num, Num, Num]:
        """``(ā12, ā21, ā23, ā32, ā'14)`` at link vectors ``l̄1, l̄2, l̄3`` (Eq. 12–13), m."""
        v1, v2, v3 = vectors
        m1, m2, m3 = self.mass
        mt = self.total_mass
        z1, z2, z3 = self.zeta
        a12 = v1 * (1 - z1) * m1 / mt
        a21 = -v2 * (m3 + m2 * z2) / mt
        a23 = a21 + v2
        a32 = -v3 * z3 * m3 / mt
        a14p = a12 - v1
        return a12, a21, a23, a32, a14p

    def _terms(self, vectors: Three) -> tuple[Three, Three, Three, tuple[Num, ...]]:
        """The entries of Eq. 22–25 that depend on the pose, from the link vectors.

        ``vectors`` are ``l̄1, l̄2, l̄3`` as complex numbers or complex arrays (many states);
        returns ``(m12, m13, m23), (c12, c13, c23), (Q1, Q2, Q3), pv``: the mass matrix's
        off-diagonal (Eq. 23), the convective coefficients, the generalised forces without a
        motor (Eq. 25) and the principal vectors (Eq. 12–13).
        """
        v1, v2, v3 = vectors
        pv = a12, a21, a23, a32, a14p = self.principal_vectors(vectors)
        mt = self.total_mass
        m1, m2, m3 = self.mass
        f1, f2, f3 = self.forces
        mo1, mo2, mo3 = self.moments
        inertia = (-mt * _ip(v1, a21), -mt * _ip(v1, a32), -mt * _ip(v2, a32))
        convective = (mt * cross_scalar(v1, a21), mt * cross_scalar(v1, a32),
                      mt * cross_scalar(v2, a32))
        forces = (
            mo1 - cross_scalar(a14p, f1) - (m2 + m3) / m1 * cross_scalar(a12, f1)
            + cross_scalar(v1, f2 + f3),
            mo2 - (m1 + m2) / m2 * cross_scalar(a21, f2) - m3 / m2 * cross_scalar(a23, f2)
            + cross_scalar(v2, f3),
            mo3 - mt / m3 * cross_scalar(a32, f3),
        )  # Eq. 25
        return inertia, convective, forces, pv

    def system(self, theta: NDArray[np.float64], omega: NDArray[np.float64]) -> System:
        """Matrices of Eq. 22 and 27 at a state.

        Returns ``(M, C, G, Q, b, pv, vectors)``: mass matrix, convective coefficients, the
        2×3 constraint Jacobian ``G`` (rows x, y of ``Σ i·l̄k·θ̈k``; ``D = Gᵀ``), generalised
        forces without a motor, the right-hand side ``b = Σ l̄k·θ̇k²`` of Eq. 27 as (x, y), the
        principal vectors and the link vectors.
        """
        l1, l2, l3, _ = self.lengths
        v1, v2, v3 = (length * cmath.exp(1j * th) for length, th in zip(
            (l1, l2, l3), theta, strict=True))
        vectors = (v1, v2, v3)
        (m12, m13, m23), (c12, c13, c23), q, pv = self._terms(vectors)
        big_m = np.array(
            [
                [self.m_diag[0], m12, m13],
                [m12, self.m_diag[1], m23],
                [m13, m23, self.m_diag[2]],
            ]
        )
        big_c = np.array([[0.0, c12, c13], [-c12, 0.0, c23], [-c13, -c23, 0.0]])
        g = np.array([[-v.imag for v in vectors], [v.real for v in vectors]])
        rhs = sum(v * w * w for v, w in zip(vectors, omega, strict=True))
        return big_m, big_c, g, np.array(q), np.array([rhs.real, rhs.imag]), pv, vectors

    def _system_batch(self, theta: NDArray[np.float64], omega: NDArray[np.float64]) -> System:
        """:meth:`system` at many states, ``theta`` and ``omega`` of shape ``(3, N)``.

        ``M``, ``C`` and ``G`` come as ``(N, 3, 3)``, ``(N, 3, 3)``, ``(N, 2, 3)``, ``Q`` and
        ``b`` as ``(N, 3)``, ``(N, 2)``; the principal and link vectors as complex arrays.
        """
        v1, v2, v3 = (length * np.exp(1j * th) for length, th in zip(
            self.lengths[:3], theta, strict=True))
        vectors = (v1, v2, v3)
        (m12, m13, m23), (c12, c13, c23), q, pv = self._terms(vectors)
        count = theta.shape[1]
        big_m = np.empty((count, 3, 3))
        big_m[:, [0, 1, 2], [0, 1, 2]] = self.m_diag
        big_m[:, 0, 1] = big_m[:, 1, 0] = m12
        big_m[:, 0, 2] = big_m[:, 2, 0] = m13
        big_m[:, 1, 2] = big_m[:, 2, 1] = m23
        big_c = np.zeros((count, 3, 3))
        big_c[:, 0, 1], big_c[:, 0, 2], big_c[:, 1, 2] = c12, c13, c23
        big_c[:, 1, 0], big_c[:, 2, 0], big_c[:, 2, 1] = -c12, -c13, -c23
        g = np.stack([np.stack([-v.imag for v in vectors], axis=-1),
                      np.stack([v.real for v in vectors], axis=-1)], axis=1)
        rhs = sum(v * w * w for v, w in zip(vectors, omega, strict=True))
        return (big_m, big_c, g, np.stack(q, axis=-1), np.stack([rhs.real, rhs.imag], axis=-1),
                pv, vectors)

    # -- the formulation ---------------------------------------------------------------------

    def solve(self, t: float, y: NDArray[np.float64]) -> Solution:
        """Accelerations, R̄A3 and the motor torque at a state: the five equations of Eq. 22, 27.

        Near a change point the five equations are singular (the loop-closure Jacobian loses
        rank); there the paper's single equation in θ1 is used instead (end of Sect. 3): Eq. 22
        times (1, Θ2, Θ3), which eliminates the constraint force, on the assembly of the smooth
        motion.
        """
        theta, omega = y[0:3], y[3:6]
        if self.near_change_point(theta[0]):
            return self._solve_reduced(theta[0], omega[0])
        big_m, big_c, g, q, b, pv, vectors = self.system(theta, omega)
        alpha, ra3, tau = self._kkt(big_m, big_c, g, q, b, omega)
        return alpha, complex(ra3), float(tau), pv, vectors

    def _kkt(self, big_m: NDArray[np.float64], big_c: NDArray[np.float64],
             g: NDArray[np.float64], q: NDArray[np.float64], b: NDArray[np.float64],
             omega: NDArray[np.float64]
             ) -> tuple[NDArray[np.floating], NDArray[np.complexfloating], NDArray[np.floating]]:
        """Eq. 22 and 27 solved: ``θ̈`` (…, 3), ``R̄A3`` and the motor torque (…).

        For one state (``M`` of shape ``(3, 3)``, ``omega`` ``(3,)``) or many (``(N, 3, 3)``,
        ``omega`` ``(N, 3)``); LAPACK's LU with partial pivoting on each 5×5 system.
        """
        w2 = omega * omega
        rhs = np.empty((*q.shape[:-1], 5))
        rhs[..., 0:3] = q - (big_c @ w2[..., None])[..., 0]
        rhs[..., 3:5] = b
        a = np.zeros((*big_m.shape[:-2], 5, 5))
        g_t = g.swapaxes(-1, -2)
        if not self.driven:
            a[..., 0:3, 0:3] = big_m
            a[..., 0:3, 3:5] = g_t
            a[..., 3:5, 0:3] = g
            z = np.linalg.solve(a, rhs[..., None])[..., 0]
            return z[..., 0:3], z[..., 3] + 1j * z[..., 4], 0.0 * z[..., 4]
        # θ̈1 = 0 imposed; unknowns θ̈2, θ̈3, RA3x, RA3y and the motor torque τ (in Q1).
        a[..., 0:3, 0:2] = big_m[..., 1:3]
        a[..., 0:3, 2:4] = g_t
        a[..., 0, 4] = -1.0
        a[..., 3:5, 0:2] = g[..., 1:3]
        z = np.linalg.solve(a, rhs[..., None])[..., 0]
        alpha = np.empty((*z.shape[:-1], 3))
        alpha[..., 0] = 0.0
        alpha[..., 1:3] = z[..., 0:2]
        return alpha, z[..., 2] + 1j * z[..., 3], z[..., 4]

    def _solve_reduced(self, theta1: float, omega1: float) -> Solution:
        """The single equation in θ1 with ``θ̈k = Θk·θ̈1 + bk`` (Eq. 7, 9–10).

        Then R̄A3 from Eq. 22 by least squares.
        """
        vectors, w2, w3 = self.branch_vectors(theta1, omega1)
        big2, big3, _, _, b2, b3 = rates_scalar(self.lengths, vectors, omega1)
        theta = np.array([theta1, cmath.phase(vectors[1]), cmath.phase(vectors[2])])
        omega = np.array([omega1, w2, w3])
        big_m, big_c, g, q, _, pv, vectors = self.system(theta, omega)
        big = np.array([1.0, big2, big3])
        b = np.array([0.0, b2, b3])
        rest = q - big_c @ (omega * omega) - big_m @ b
        if self.driven:
            alpha1, tau = 0.0, float(-(big @ rest))
        else:
            alpha1, tau = float(big @ rest) / float(big @ big_m @ big), 0.0
        alpha = big * alpha1 + b
        lhs = q - big_c @ (omega * omega) - big_m @ alpha + np.array([tau, 0.0, 0.0])
        r = np.linalg.lstsq(g.T, lhs, rcond=None)[0]
        return alpha, complex(r[0], r[1]), tau, pv, vectors

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        self.theta1_start = float(theta1)
        if self.driven:
            omega1 = self._motor_speed
        mo = motion_of(self.linkage, theta1, omega1, 0.0)
        y = [mo.theta[0][0], mo.theta[1][0], mo.theta[2][0]]
        y += [mo.omega[0][0], mo.omega[1][0], mo.omega[2][0]]
        if self.driven:
            y.append(0.0)
        return np.array(y, dtype=float)

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        alpha, _, tau, _, _ = self.solve(t, y)
        dy = np.concatenate([y[3:6], alpha])
        if self.driven:
            dy = np.append(dy, tau * y[3])
        return dy

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        return self.evaluate_batch([t], [y]).at(0)

    def _near(self, theta1: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Which crank angles are near a change point (:meth:`near_change_point`)."""
        if not self.change_points():
            return np.zeros(theta1.shape, bool)
        return np.array([self.near_change_point(float(x)) for x in theta1], bool)

    def evaluate_batch(self, times: Sequence[float] | NDArray[np.float64],
                       states: Sequence[NDArray[np.float64]]) -> Evaluation:
        """:meth:`evaluate` at every state at once.

        Eq. 22 and 27 (the reduced equation near a change point); R̄A0 from the motion of the
        centre of mass, Eq. 28 with r̄S from Eq. 16.
        """
        ys = np.array(states, dtype=float).reshape(len(states), -1)
        theta, omega = ys[:, 0:3].T, ys[:, 3:6].T
        count = ys.shape[0]
        alpha, ra3, tau = np.empty((3, count)), np.empty(count, complex), np.empty(count)
        pv = [np.empty(count, complex) for _ in range(5)]
        near = self._near(theta[0])
        regular = ~near
        if regular.any():
            big_m, big_c, g, q, b, pvs, _ = self._system_batch(theta[:, regular],
                                                               omega[:, regular])
            acc, ra3[regular], tau[regular] = self._kkt(big_m, big_c, g, q, b,
                                                        omega[:, regular].T)
            alpha[:, regular] = acc.T
            for whole, part in zip(pv, pvs, strict=True):
                whole[regular] = part
        for i in np.flatnonzero(near):
            acc, r, torque, pvs, _ = self._solve_reduced(theta[0, i], omega[0, i])
            alpha[:, i], ra3[i], tau[i] = acc, r, torque
            for whole, part in zip(pv, pvs, strict=True):
                whole[i] = part
        _, a21, _, a32, a14p = pv
        acc_s = -sum(a * (1j * al - w * w)
                     for a, al, w in zip((a14p, a21, a32), alpha, omega, strict=True))
        ra0 = sum(self.forces) - self.total_mass * acc_s - ra3
        return Evaluation(theta=theta.copy(), omega=omega.copy(), alpha=alpha,
                          ground={"A0": ra0, "A3": ra3}, driving_torque=tau)

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        return self.crank_angle(t) if self.driven else float(y[0])

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        return math.sin(y[2] - y[1])

    # -- constraints -------------------------------------------------------------------------

    def _closure(self, theta: ArrayLike) -> tuple[Num, NDArray[np.float64]]:
        """Loop closure ``Σ l̄k − l4`` (Eq. 26) and its Jacobian ``G`` at angles ``(…, 3)``.

        Complex residuals ``(…)`` and Jacobians ``(…, 2, 3)``.
        """
        vectors = np.asarray(self.lengths[:3]) * np.exp(1j * np.asarray(theta, dtype=float))
        g = np.stack([-vectors.imag, vectors.real], axis=-2)
        return vectors.sum(axis=-1) - self.lengths[3], g

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        phi, g = self._closure(y[0:3])
        return abs(phi), float(np.linalg.norm(g @ y[3:6]))

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.project_many([t], [y])[0]

    def project_many(self, times: Sequence[float] | NDArray[np.float64],
                     states: Sequence[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
        """Least-norm Gauss–Newton corrections onto the loop closure, at every state at once.

        The closure is Eq. 26, its rate Eq. 5. With the crank driven, θ1 and θ̇1 are
        prescribed and only θ2, θ3 and their rates are corrected; near a change point the state
        is put on the smooth motion's assembly.
        """
        ys = np.array(states, dtype=float).reshape(len(states), -1)
        at = np.asarray(times, dtype=float)
        free = np.arange(3) if not self.driven else np.arange(1, 3)
        if self.driven:
            ys[:, 0] = self.crank_angle(at)
            ys[:, 3] = self._motor_speed
        near = self._near(ys[:, 0])
        for i in np.flatnonzero(near):
            self._onto_smooth_motion(ys[i])
        regular = np.flatnonzero(~near)
        scale = sum(self.lengths)
        active = regular
        for _ in range(4):
            phi, g = self._closure(ys[active, 0:3])
            off = np.abs(phi) > 1e-15 * scale
            active, phi, g = active[off], phi[off], g[off]
            if not active.size:
                break
            step = least_norm_many(g[:, :, free], np.stack([phi.real, phi.imag], axis=-1))
            ys[active[:, None], free] -= step
        _, g = self._closure(ys[regular, 0:3])
        resid = np.matmul(g, ys[regular, 3:6, None])[..., 0]
        ys[regular[:, None], 3 + free] -= least_norm_many(g[:, :, free], resid)
        return list(ys)

    def _onto_smooth_motion(self, y: NDArray[np.float64]) -> None:
        """Put a state near a change point on the smooth motion's assembly (θ1, θ̇1 kept)."""
        vectors, w2, w3 = self.branch_vectors(y[0], y[3])
        y[1] += math.remainder(cmath.phase(vectors[1]) - y[1], 2 * math.pi)
        y[2] += math.remainder(cmath.phase(vectors[2]) - y[2], 2 * math.pi)
        y[4], y[5] = w2, w3

