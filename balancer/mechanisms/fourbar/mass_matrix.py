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
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...linkage.vectors import cross_scalar
from ...model import Link
from ..chains import NodalSolution, NodalTruss
from ..formulation import Evaluation
from .closed_form import FourBarFormulation
from .kinematics import motion_of, rates_scalar
from .massmodels import fourbar_force_vector, global_mass_matrix


class MassMatrix(NodalTruss, FourBarFormulation):
    """Truss elements with the equivalent mass matrix, Eq. 41–55."""

    name = "mass-matrix"
    minimal = False
    passes_dead_points = True

    def __init__(self, *args: Any, **kwargs: Any) -> None:
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
        self.node_tolerance = 1e-16 * sum(self.lengths) ** 2  # Φ in m²

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

    def _forces(self, vectors: tuple[complex, complex, complex], tau: float = 0.0
                ) -> tuple[complex, ...]:
        """Nodal applied forces at A0…A3 (Eq. 46, 49, 54), with a motor torque on the crank."""
        pos = SimpleNamespace(l1=vectors[0], l2=vectors[1], l3=vectors[2])
        moments = (self.moments[0] + tau, self.moments[1], self.moments[2])
        return fourbar_force_vector(self.loaded, pos, moments=moments)

    # -- the formulation ---------------------------------------------------------------------

    def solve(self, t: float, y: NDArray[np.float64]) -> NodalSolution:
        """Accelerations ẍ, multipliers λ and the motor torque at a state.

        Near a change point the constrained system is singular (the length constraints become
        dependent); there the paper's own reduction is used (Eq. 47, 50–51): ``ẍ = J·θ̈1 + c``
        on the assembly of the smooth motion, ``Jᵀ(M·ẍ − F) = 0``, and λ by least squares.
        """
        theta1 = self.theta1_of(t, y)
        if self.near_change_point(theta1):
            return self._solve_reduced(t, y, theta1)
        a1, a2, v_a1, v_a2 = self._nodes(y)
        vectors = self._vectors(a1, a2)
        jac = self._jacobian(a1, a2)
        gamma = np.array([-abs(v_a1) ** 2, -abs(v_a2 - v_a1) ** 2, -abs(v_a2) ** 2])
        f = self._forces(vectors)
        f_free = np.array([f[1].real, f[1].imag, f[2].real, f[2].imag])
        acc, lam, tau = self.node_accelerations(jac, gamma, f_free, a1)
        return acc, lam, tau, vectors

    def _solve_reduced(self, t: float, y: NDArray[np.float64], theta1: float
                       ) -> NodalSolution:
        a1 = complex(y[0], y[1])
        v_a1 = complex(y[4], y[5])
        omega1 = self._motor_speed if self.driven else cross_scalar(a1, v_a1) / abs(a1) ** 2
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
        self.theta1_start = float(theta1)
        if self.driven:
            omega1 = self._motor_speed
        mo = motion_of(self.linkage, theta1, omega1, 0.0)
        return self.node_state(mo.pos.A1[0], mo.pos.A2[0], mo.joint_velocities[0][0],
                               mo.joint_velocities[1][0], theta1)

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        acc, lam, tau, vectors = self.solve(t, y)
        a1, a2, v_a1, v_a2 = self._nodes(y)
        acc_a1, acc_a2 = complex(acc[0], acc[1]), complex(acc[2], acc[3])
        rates = (v_a1, v_a2 - v_a1, -v_a2)
        accels = (acc_a1, acc_a2 - acc_a1, -acc_a2)
        # Eq. 55: angles from the nodal coordinates; rates from l̄ × l̄̇ = ω·l².
        theta = np.array([math.atan2(v.imag, v.real) for v in vectors])
        theta[0] = self.theta1_of(t, y)
        omega = np.array([cross_scalar(v, r) / abs(v) ** 2
                          for v, r in zip(vectors, rates, strict=True)])
        alpha = np.array([cross_scalar(v, a) / abs(v) ** 2
                          for v, a in zip(vectors, accels, strict=True)])
        f = self._forces(vectors, tau)
        node_acc = np.array([0.0, 0.0, acc[0], acc[1], acc[2], acc[3], 0.0, 0.0])
        inertia = self.m_global @ node_acc  # Eq. 52–53: rows A0 and A3 give M_r·ẍ
        ra0 = f[0] - complex(inertia[0], inertia[1]) + vectors[0] * lam[0]
        ra3 = f[3] - complex(inertia[6], inertia[7]) - vectors[2] * lam[2]
        return Evaluation(theta=theta, omega=omega, alpha=alpha, ground={"A0": ra0, "A3": ra3},
                          driving_torque=tau)

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        a1, a2, _, _ = self._nodes(y)
        _, v2, v3 = self._vectors(a1, a2)
        return cross_scalar(v2, v3) / (self.lengths[1] * self.lengths[2])

    # -- constraints -------------------------------------------------------------------------

    def constraints(
        self, x: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``Φk = (|r̄q − r̄p|² − lk²)/2`` for crank, coupler and rocker (m²), and ``∂Φ/∂x``."""
        a1, a2 = complex(x[0], x[1]), complex(x[2], x[3])
        l1, l2, l3, _ = self.lengths
        phi = 0.5 * np.array(
            [abs(a1) ** 2 - l1 * l1, abs(a2 - a1) ** 2 - l2 * l2, abs(self.a3 - a2) ** 2 - l3 * l3]
        )
        return phi, self._jacobian(a1, a2)

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        a1, a2 = complex(y[0], y[1]), complex(y[2], y[3])
        l1, l2, l3, _ = self.lengths
        pos = max(abs(abs(a1) - l1), abs(abs(a2 - a1) - l2), abs(abs(self.a3 - a2) - l3))
        vel = self._jacobian(a1, a2) @ y[4:8] / np.array([l1, l2, l3])
        return float(pos), float(np.max(np.abs(vel)))

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """:meth:`NodalTruss.project`, except near a change point.

        There the length constraints are dependent: the nodes are put on the assembly of the
        smooth motion from Eq. 2–4 at the crank angle, their rates from Eq. 6 with the crank's
        rate kept.
        """
        theta1 = self.theta1_of(t, y)
        if not self.near_change_point(theta1):
            return super().project(t, y)
        y = np.array(y, dtype=float)
        a1 = complex(y[0], y[1])
        v_a1 = complex(y[4], y[5])
        omega1 = self._motor_speed if self.driven else cross_scalar(a1, v_a1) / abs(a1) ** 2
        (v1, v2, v3), w2, w3 = self.branch_vectors(theta1, float(omega1))
        a2 = v1 + v2
        v_a1 = 1j * omega1 * v1
        v_a2 = v_a1 + 1j * w2 * v2
        y[0:8] = [v1.real, v1.imag, a2.real, a2.imag, v_a1.real, v_a1.imag,
                  v_a2.real, v_a2.imag]
        return y

