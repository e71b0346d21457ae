"""Constant equivalent mass matrices: the four-bar as three truss elements.

Meijaard & van der Wijk 2020, Sect. 4.2 and 5.1.

Each link is a truss element between two nodes with the constant 4×4 mass matrix of Eq. 45 and
its loads reduced to the nodes (Eq. 46). The coordinates are the Cartesian positions of the
moving joints ``x = (r_A1x, r_A1y, r_A2x, r_A2y)`` (Eq. 50), held to the link lengths by three
constraints ``Φk = (|r̄q − r̄p|² − lk²)/2 = 0`` with multipliers λk (the elements' axial forces
divided by their length). The equations of motion are linear in the accelerations::

    M·ẍ + Φxᵀ·λ = F(x),        Φx·ẍ = −|ẋq − ẋp|²  (per element)

with ``M`` of Eq. 48 and ``F`` of Eq. 49. The reactions are those of the ground nodes with the
axial forces of the crank and the rocker (Eq. 52–54)::

    R̄A0 = F_A0 − (M_r·ẍ)_A0 + l̄1·λ1,      R̄A3 = F_A3 − (M_r·ẍ)_A3 − l̄3·λ3

The link angles are derived quantities (Eq. 55). With the crank driven, r̄A1 follows the
prescribed circle and the motor torque, which enters F through the crank's moment (Eq. 46), is
an unknown. The state is not minimal: the integrator projects it back onto the length
constraints and their derivatives.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
from numpy.typing import NDArray

from ..kinematics import rates_scalar
from ..massmodels import fourbar_force_vector, global_mass_matrix
from ..model import Link
from . import Evaluation, Formulation


class MassMatrix(Formulation):
    """Truss elements with the equivalent mass matrix, Eq. 41–55."""

    name = "mass-matrix"
    minimal = False
    passes_dead_points = True

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        # Eq. 45 assembled over the nodes A0, A1, A2, A3 (8×8), counter-rotors in the inertia.
        self.m_global = global_mass_matrix(
            self.linkage, inertias=[link.inertia for link in self.links]
        )
        self.m_free = self.m_global[2:6, 2:6]  # Eq. 48
        # Links carrying their weight as part of the applied force (Eq. 46 reduces both).
        self.loaded = self.linkage.with_links(
            {
                name: Link(
                    mass=link.mass,
                    inertia=link.inertia,
                    e=link.e,
                    f=link.f,
                    force=(force.real, force.imag),
                    moment=link.moment,
                )
                for name, link, force in zip(
                    self.linkage.link_names, self.linkage.links, self.forces, strict=True
                )
            }
        )
        self.a3 = complex(self.lengths[3], 0.0)

    # -- geometry ----------------------------------------------------------------------------

    @staticmethod
    def _nodes(y: NDArray[np.float64]) -> tuple[complex, complex, complex, complex]:
        return complex(y[0], y[1]), complex(y[2], y[3]), complex(y[4], y[5]), complex(y[6], y[7])

    def _vectors(self, a1: complex, a2: complex) -> tuple[complex, complex, complex]:
        return a1, a2 - a1, self.a3 - a2

    def _jacobian(self, a1: complex, a2: complex) -> NDArray[np.float64]:
        """∂Φ/∂x (3×4): rows are the crank, coupler and rocker constraints."""
        v1, v2, v3 = self._vectors(a1, a2)
        return np.array(
            [
                [v1.real, v1.imag, 0.0, 0.0],
                [-v2.real, -v2.imag, v2.real, v2.imag],
                [0.0, 0.0, -v3.real, -v3.imag],
            ]
        )

    def _forces(self, vectors, tau: float = 0.0) -> tuple[complex, ...]:
        """Nodal applied forces at A0…A3 (Eq. 46, 49, 54), with a motor torque on the crank."""
        pos = SimpleNamespace(l1=vectors[0], l2=vectors[1], l3=vectors[2])
        moments = (self.moments[0] + tau, self.moments[1], self.moments[2])
        return fourbar_force_vector(self.loaded, pos, moments=moments)

    # -- the formulation ---------------------------------------------------------------------

    def solve(self, t: float, y: NDArray[np.float64]):
        """Accelerations ẍ, multipliers λ and the motor torque at a state.

        Near a change point the constrained system is singular (the length constraints become
        dependent); there the paper's own reduction is used (Eq. 47, 50–51): ``ẍ = J·θ̈1 + c``
        on the assembly of the smooth motion, ``Jᵀ(M·ẍ − F) = 0``, and λ by least squares.
        """
        theta1 = self._unwrapped_crank(t, y)
        if self.near_change_point(theta1):
            return self._solve_reduced(t, y, theta1)
        a1, a2, v_a1, v_a2 = self._nodes(y)
        vectors = self._vectors(a1, a2)
        jac = self._jacobian(a1, a2)
        gamma = np.array([-abs(v_a1) ** 2, -abs(v_a2 - v_a1) ** 2, -abs(v_a2) ** 2])
        f = self._forces(vectors)
        f_free = np.array([f[1].real, f[1].imag, f[2].real, f[2].imag])
        if not self.driven:
            a = np.zeros((7, 7))
            a[0:4, 0:4] = self.m_free
            a[0:4, 4:7] = jac.T
            a[4:7, 0:4] = jac
            z = np.linalg.solve(a, np.concatenate([f_free, gamma]))
            return z[0:4], z[4:7], 0.0, vectors
        # Driven: r̈A1 of the prescribed circle; unknowns r̈A2 (2), λ1..3 and τ.
        omega = float(self.speed)  # type: ignore[arg-type]
        acc_a1 = -omega * omega * a1
        x1 = np.array([acc_a1.real, acc_a1.imag])
        # τ enters the crank's nodal force at A1 as i·τ·l̄1/l1² (Eq. 46).
        couple = 1j * vectors[0] / self.lengths[0] ** 2
        a = np.zeros((6, 6))
        a[0:4, 0:2] = self.m_free[:, 2:4]
        a[0:4, 2:5] = jac.T
        a[0:2, 5] = [-couple.real, -couple.imag]
        a[4:6, 0:2] = jac[1:3, 2:4]
        rhs = np.concatenate([f_free - self.m_free[:, 0:2] @ x1, gamma[1:3] - jac[1:3, 0:2] @ x1])
        z = np.linalg.solve(a, rhs)
        return np.concatenate([x1, z[0:2]]), z[2:5], float(z[5]), vectors

    def _solve_reduced(self, t: float, y: NDArray[np.float64], theta1: float):
        a1 = complex(y[0], y[1])
        omega1 = float(self.speed) if self.driven else _cross(a1, complex(y[4], y[5])) / abs(
            a1) ** 2
        vectors, w2, w3 = self.branch_vectors(theta1, omega1)
        v1, v2, v3 = vectors
        _, big3, _, _, _, b3 = rates_scalar(self.lengths, vectors, omega1)
        # Eq. 50–51: δx per δθ1 and the part of ẍ without θ̈1.
        d_a1, d_a2 = 1j * v1, -1j * big3 * v3
        jac_1 = np.array([d_a1.real, d_a1.imag, d_a2.real, d_a2.imag])
        c_a1 = -omega1 * omega1 * v1
        c_a2 = -(1j * b3 - w3 * w3) * v3
        c = np.array([c_a1.real, c_a1.imag, c_a2.real, c_a2.imag])
        f = self._forces(vectors)
        f_free = np.array([f[1].real, f[1].imag, f[2].real, f[2].imag])
        residual = jac_1 @ (f_free - self.m_free @ c)
        if self.driven:
            alpha1, tau = 0.0, float(-residual)
        else:
            alpha1, tau = float(residual / (jac_1 @ self.m_free @ jac_1)), 0.0
        acc = jac_1 * alpha1 + c
        couple = 1j * v1 / self.lengths[0] ** 2
        f_tau = f_free + tau * np.array([couple.real, couple.imag, 0.0, 0.0])
        jac = self._jacobian(v1, v1 + v2)
        lam = np.linalg.lstsq(jac.T, f_tau - self.m_free @ acc, rcond=None)[0]
        return acc, lam, tau, vectors

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        from ..kinematics import motion_of

        self.theta1_start = float(theta1)
        if self.driven:
            omega1 = float(self.speed)  # type: ignore[arg-type]
        mo = motion_of(self.linkage, theta1, omega1, 0.0)
        a1, a2 = mo.pos.A1[0], mo.pos.A2[0]
        v1, v2 = mo.joint_velocities[0][0], mo.joint_velocities[1][0]
        y = [a1.real, a1.imag, a2.real, a2.imag, v1.real, v1.imag, v2.real, v2.imag]
        y.append(0.0 if self.driven else float(theta1))  # motor work, or the crank angle
        return np.array(y, dtype=float)

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        acc, _, tau, _ = self.solve(t, y)
        dy = np.concatenate([y[4:8], acc])
        if self.driven:
            return np.append(dy, tau * float(self.speed))  # type: ignore[arg-type]
        a1, v_a1 = complex(y[0], y[1]), complex(y[4], y[5])
        return np.append(dy, _cross(a1, v_a1) / abs(a1) ** 2)  # θ̇1

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        acc, lam, tau, vectors = self.solve(t, y)
        a1, a2, v_a1, v_a2 = self._nodes(y)
        acc_a1, acc_a2 = complex(acc[0], acc[1]), complex(acc[2], acc[3])
        rates = (v_a1, v_a2 - v_a1, -v_a2)
        accels = (acc_a1, acc_a2 - acc_a1, -acc_a2)
        # Eq. 55: angles from the nodal coordinates; rates from l̄ × l̄̇ = ω·l².
        theta = np.array([math.atan2(v.imag, v.real) for v in vectors])
        theta[0] = self._unwrapped_crank(t, y)
        omega = np.array([_cross(v, r) / abs(v) ** 2 for v, r in zip(vectors, rates, strict=True)])
        alpha = np.array([_cross(v, a) / abs(v) ** 2 for v, a in zip(vectors, accels, strict=True)])
        f = self._forces(vectors, tau)
        node_acc = np.array([0.0, 0.0, acc[0], acc[1], acc[2], acc[3], 0.0, 0.0])
        inertia = self.m_global @ node_acc  # Eq. 52–53: rows A0 and A3 give M_r·ẍ
        ra0 = f[0] - complex(inertia[0], inertia[1]) + vectors[0] * lam[0]
        ra3 = f[3] - complex(inertia[6], inertia[7]) - vectors[2] * lam[2]
        return Evaluation(theta=theta, omega=omega, alpha=alpha, RA0=ra0, RA3=ra3,
                          driving_torque=tau)

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        return self.crank_angle(t) if self.driven else math.atan2(y[1], y[0])

    def _unwrapped_crank(self, t: float, y: NDArray[np.float64]) -> float:
        """The crank angle, continuous along the motion.

        The nodes give it only modulo 2π; free motion carries the continuous angle as an
        auxiliary state (advanced by θ̇1, snapped to the nodes), driven motion prescribes it.
        """
        if self.driven:
            return self.crank_angle(t)
        return float(y[8]) + math.remainder(math.atan2(y[1], y[0]) - y[8], 2 * math.pi)

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        a1, a2, _, _ = self._nodes(y)
        _, v2, v3 = self._vectors(a1, a2)
        return _cross(v2, v3) / (self.lengths[1] * self.lengths[2])

    # -- constraints -------------------------------------------------------------------------

    def _phi(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        a1, a2 = complex(x[0], x[1]), complex(x[2], x[3])
        l1, l2, l3, _ = self.lengths
        return 0.5 * np.array(
            [abs(a1) ** 2 - l1 * l1, abs(a2 - a1) ** 2 - l2 * l2, abs(self.a3 - a2) ** 2 - l3 * l3]
        )

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        a1, a2 = complex(y[0], y[1]), complex(y[2], y[3])
        l1, l2, l3, _ = self.lengths
        pos = max(abs(abs(a1) - l1), abs(abs(a2 - a1) - l2), abs(abs(self.a3 - a2) - l3))
        vel = self._jacobian(a1, a2) @ y[4:8] / np.array([l1, l2, l3])
        return float(pos), float(np.max(np.abs(vel)))

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Least-norm Newton correction of the nodes onto the lengths, then of their rates."""
        y = np.array(y, dtype=float)
        free = slice(0, 4)
        rows = slice(0, 3)
        theta1 = self._unwrapped_crank(t, y)
        if self.near_change_point(theta1):
            # On the assembly of the smooth motion: nodes from Eq. 2–4 at the crank angle, rates
            # from Eq. 6 with the crank's rate kept.
            a1 = complex(y[0], y[1])
            v_a1 = complex(y[4], y[5])
            omega1 = self.speed if self.driven else _cross(a1, v_a1) / abs(a1) ** 2
            (v1, v2, v3), w2, w3 = self.branch_vectors(theta1, float(omega1))
            a2 = v1 + v2
            v_a1 = 1j * omega1 * v1
            v_a2 = v_a1 + 1j * w2 * v2
            y[0:8] = [v1.real, v1.imag, a2.real, a2.imag, v_a1.real, v_a1.imag,
                      v_a2.real, v_a2.imag]
            return y
        if self.driven:
            th = self.crank_angle(t)
            a1 = self.lengths[0] * complex(math.cos(th), math.sin(th))
            v1 = 1j * float(self.speed) * a1  # type: ignore[arg-type]
            y[0:2] = a1.real, a1.imag
            y[4:6] = v1.real, v1.imag
            free, rows = slice(2, 4), slice(1, 3)
        scale = sum(self.lengths) ** 2
        for _ in range(4):
            phi = self._phi(y[0:4])[rows]
            if np.max(np.abs(phi)) <= 1e-16 * scale:
                break
            jac = self._jacobian(complex(y[0], y[1]), complex(y[2], y[3]))[rows, free]
            y[free] -= np.linalg.lstsq(jac, phi, rcond=None)[0]
        jac = self._jacobian(complex(y[0], y[1]), complex(y[2], y[3]))
        resid = (jac @ y[4:8])[rows]
        vf = slice(4 + free.start, 4 + free.stop)
        y[vf] -= np.linalg.lstsq(jac[rows, free], resid, rcond=None)[0]
        if not self.driven:
            y[8] = self._unwrapped_crank(t, y)
        return y


def _cross(x: complex, y: complex) -> float:
    return x.real * y.imag - x.imag * y.real
