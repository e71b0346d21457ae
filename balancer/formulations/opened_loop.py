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

import numpy as np
from numpy.typing import NDArray

from ..kinematics import cross_scalar, rates_scalar
from . import Evaluation
from .closed_form import FourBarFormulation


def _ip(x: complex, y: complex) -> float:
    """⟨x̄, ȳ⟩ = Re(x*·y)."""
    return x.real * y.real + x.imag * y.imag



class OpenedLoop(FourBarFormulation):
    """Opened loop with principal vectors, Eq. 12–28."""

    name = "opened-loop"
    minimal = False
    passes_dead_points = True

    def __init__(self, *args, **kwargs) -> None:
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

    def principal_vectors(self, vectors: tuple[complex, complex, complex]):
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

    def system(self, theta: NDArray[np.float64], omega: NDArray[np.float64]):
        """Matrices of Eq. 22 and 27 at a state.

        Returns ``(M, C, G, Q, b, pv, vectors)``: mass matrix, convective coefficients, the
        2×3 constraint Jacobian ``G`` (rows x, y of ``Σ i·l̄k·θ̈k``; ``D = Gᵀ``), generalised
        forces without a motor, the right-hand side ``b = Σ l̄k·θ̇k²`` of Eq. 27 as (x, y), the
        principal vectors and the link vectors.
        """
        l1, l2, l3, _ = self.lengths
        vectors = tuple(length * cmath.exp(1j * th) for length, th in zip(
            (l1, l2, l3), theta, strict=True))
        v1, v2, v3 = vectors
        pv = a12, a21, a23, a32, a14p = self.principal_vectors(vectors)
        mt = self.total_mass
        m1, m2, m3 = self.mass
        m12 = -mt * _ip(v1, a21)
        m13 = -mt * _ip(v1, a32)
        m23 = -mt * _ip(v2, a32)
        big_m = np.array(
            [
                [self.m_diag[0], m12, m13],
                [m12, self.m_diag[1], m23],
                [m13, m23, self.m_diag[2]],
            ]
        )
        c12 = mt * cross_scalar(v1, a21)
        c13 = mt * cross_scalar(v1, a32)
        c23 = mt * cross_scalar(v2, a32)
        big_c = np.array([[0.0, c12, c13], [-c12, 0.0, c23], [-c13, -c23, 0.0]])
        f1, f2, f3 = self.forces
        mo1, mo2, mo3 = self.moments
        q = np.array(
            [
                mo1 - cross_scalar(a14p, f1) - (m2 + m3) / m1 * cross_scalar(a12, f1)
                + cross_scalar(v1, f2 + f3),
                mo2 - (m1 + m2) / m2 * cross_scalar(a21, f2) - m3 / m2 * cross_scalar(a23, f2)
                + cross_scalar(v2, f3),
                mo3 - mt / m3 * cross_scalar(a32, f3),
            ]
        )  # Eq. 25
        g = np.array([[-v.imag for v in vectors], [v.real for v in vectors]])
        rhs = sum(v * w * w for v, w in zip(vectors, omega, strict=True))
        return big_m, big_c, g, q, np.array([rhs.real, rhs.imag]), pv, vectors

    # -- the formulation ---------------------------------------------------------------------

    def solve(self, t: float, y: NDArray[np.float64]):
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
        rhs_top = q - big_c @ (omega * omega)
        a = np.zeros((5, 5))
        a[3:5, 3:5] = 0.0
        if not self.driven:
            a[0:3, 0:3] = big_m
            a[0:3, 3:5] = g.T
            a[3:5, 0:3] = g
            z = np.linalg.solve(a, np.concatenate([rhs_top, b]))
            alpha, ra3, tau = z[0:3], complex(z[3], z[4]), 0.0
        else:
            # θ̈1 = 0 imposed; unknowns θ̈2, θ̈3, RA3x, RA3y and the motor torque τ (in Q1).
            a[0:3, 0:2] = big_m[:, 1:3]
            a[0:3, 2:4] = g.T
            a[0, 4] = -1.0
            a[3:5, 0:2] = g[:, 1:3]
            z = np.linalg.solve(a, np.concatenate([rhs_top, b]))
            alpha = np.array([0.0, z[0], z[1]])
            ra3, tau = complex(z[2], z[3]), float(z[4])
        return alpha, ra3, tau, pv, vectors

    def _solve_reduced(self, theta1: float, omega1: float):
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
        from ..kinematics import motion_of

        self.theta1_start = float(theta1)
        if self.driven:
            omega1 = float(self.speed)  # type: ignore[arg-type]
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
        alpha, ra3, tau, pv, _ = self.solve(t, y)
        omega = y[3:6]
        _, a21, _, a32, a14p = pv
        # Eq. 28 with r̄S from Eq. 16: m_tot·r̈S = F1 + F2 + F3 − R̄A0 − R̄A3.
        acc_s = -sum(
            a * (1j * al - w * w) for a, al, w in zip((a14p, a21, a32), alpha, omega, strict=True)
        )
        ra0 = sum(self.forces) - self.total_mass * acc_s - ra3
        return Evaluation(
            theta=np.array(y[0:3]),
            omega=np.array(omega),
            alpha=alpha,
            ground={"A0": complex(ra0), "A3": ra3},
            driving_torque=tau,
        )

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        return self.crank_angle(t) if self.driven else float(y[0])

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        return math.sin(y[2] - y[1])

    # -- constraints -------------------------------------------------------------------------

    def _closure(self, theta) -> tuple[complex, NDArray[np.float64]]:
        l1, l2, l3, l4 = self.lengths
        vectors = [length * cmath.exp(1j * th) for length, th in zip((l1, l2, l3), theta,
                                                                       strict=True)]
        g = np.array([[-v.imag for v in vectors], [v.real for v in vectors]])
        return sum(vectors) - l4, g

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        phi, g = self._closure(y[0:3])
        return abs(phi), float(np.linalg.norm(g @ y[3:6]))

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Least-norm Gauss–Newton correction onto the loop closure (Eq. 26) and its rate (Eq. 5).

        With the crank driven, θ1 and θ̇1 are prescribed and only θ2, θ3 and their rates are
        corrected; near a change point the state is put on the smooth motion's assembly.
        """
        y = np.array(y, dtype=float)
        free = slice(0, 3) if not self.driven else slice(1, 3)
        if self.driven:
            y[0] = self.crank_angle(t)
            y[3] = float(self.speed)  # type: ignore[arg-type]
        if self.near_change_point(y[0]):
            # On the assembly of the smooth motion, with θ1 and θ̇1 kept.
            vectors, w2, w3 = self.branch_vectors(y[0], y[3])
            y[1] += math.remainder(cmath.phase(vectors[1]) - y[1], 2 * math.pi)
            y[2] += math.remainder(cmath.phase(vectors[2]) - y[2], 2 * math.pi)
            y[4], y[5] = w2, w3
            return y
        scale = sum(self.lengths)
        for _ in range(4):
            phi, g = self._closure(y[0:3])
            if abs(phi) <= 1e-15 * scale:
                break
            gf = g[:, free]
            y[free] -= np.linalg.lstsq(gf, np.array([phi.real, phi.imag]), rcond=None)[0]
        _, g = self._closure(y[0:3])
        gf = g[:, free]
        resid = g @ y[3:6]
        y[3 + free.start : 3 + free.stop] -= np.linalg.lstsq(gf, resid, rcond=None)[0]
        return y
