"""What the seeds' closed forms share: a chain of links given by its lengths.

The four-bar's (Meijaard & van der Wijk 2020; Bai, Xia & Ge 2024) and the slider-crank's
(Wunderlich 1964) closed forms: the tolerance at which a closed-form position counts as singular,
and the common ground of their formulations of the equations of motion: :class:`ClosedForm` (the
lengths, the links as the dynamics see them, the loads with the weights, the centres of mass as
fractions of the link vectors ``ζk = s̄k/lk``) and :class:`NodalTruss` (truss elements with
moving nodes A1 and A2, Eq. 41–55). Their inverse dynamics give the frame's loads as the
general core's record, :class:`~balancer.linkage.loads.Reactions`.
"""

from __future__ import annotations

import math
from abc import abstractmethod
from typing import ClassVar, TypeAlias

import numpy as np
from numpy.typing import NDArray

from ..linkage.rotors import dynamic_link
from ..linkage.vectors import cross_scalar
from ..model.mechanisms import ChainModel
from .base import Mechanism
from .formulation import Formulation


class ClosedForm(Formulation):
    """A formulation of a mechanism given by its lengths and its links in a chain.

    Parameters
    ----------
    mechanism
        A mechanism whose data is a :class:`~balancer.model.ChainModel` (a four-bar, a
        slider-crank; its counter-rotors add to the inertia of their links).
    gravity, speed
        As for :class:`~balancer.mechanisms.formulation.Formulation`.
    """

    linkage: ChainModel

    #: Number of links that turn (a slider does not).
    rotating_links: ClassVar[int] = 3

    def __init__(self, mechanism: Mechanism, *, gravity: tuple[float, float] = (0.0, 0.0),
                 speed: float | None = None) -> None:
        super().__init__(mechanism, gravity=gravity, speed=speed)
        linkage = mechanism.model
        assert isinstance(linkage, ChainModel), "a mechanism given by its lengths"
        self.lengths: tuple[float, ...] = linkage.lengths
        #: Links as the dynamics see them (counter-rotor inertia added).
        self.links = tuple(dynamic_link(link) for link in linkage.links)
        #: Applied force on each link at its centre of mass, weight included, N.
        self.forces = tuple(link.force_complex + link.mass * self.gravity for link in linkage.links)
        #: Applied moment on each link, N·m.
        self.moments = tuple(link.moment for link in linkage.links)
        self.mass = tuple(link.mass for link in linkage.links)
        self.total_mass = sum(self.mass)
        #: Centres of mass as fractions of the link vectors, ``ζk = s̄k/lk`` (rotating links).
        self.zeta = tuple(
            link.com / length
            for link, length in zip(linkage.links[: self.rotating_links], self.lengths,
                                    strict=False)
        )
        self.sign0 = 1.0 if linkage.branch == "+" else -1.0


#: Node accelerations ẍ (m/s²), the constraints' multipliers λ and the motor torque (N·m) at a
#: state.
NodeAccelerations: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64], float]


#: The same, and the link vectors there (m).
NodalSolution: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64], float,
                                 tuple[complex, complex, complex]]


class NodalTruss(ClosedForm):
    """What a linkage of truss elements with moving nodes A1 (crank pin) and A2 shares.

    State ``y = (x, ẋ, a)`` with ``x = (r_A1x, r_A1y, r_A2x, r_A2y)`` (m) and ``a`` the
    continuous crank angle (free motion, rad) or the motor's work (driven, J). A subclass gives
    the constant free-node mass matrix :attr:`m_free` (4×4, Eq. 48) and three constraints
    :meth:`constraints` ``(Φ, Φx)``; the first is the crank's ``(|r̄A1|² − l1²)/2``.
    """

    m_free: NDArray[np.float64]
    #: Newton on the positions stops when every |Φ| is below this, in Φ's units.
    node_tolerance: float

    @abstractmethod
    def constraints(
        self, x: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``Φ(x)`` (3) and ``∂Φ/∂x`` (3×4)."""

    @abstractmethod
    def solve(self, t: float, y: NDArray[np.float64]) -> NodeAccelerations | NodalSolution:
        """``(ẍ, λ, τ, …)``: node accelerations, multipliers and the motor torque at a state."""

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        """The crank angle, continuous along the motion (:meth:`continuous_crank`).

        The nodes give it only modulo 2π; free motion carries the continuous angle as the
        auxiliary state.
        """
        if self.driven:
            return self.crank_angle(t)
        return self.continuous_crank(math.atan2(y[1], y[0]), float(y[8]))

    def node_state(self, a1: complex, a2: complex, v_a1: complex, v_a2: complex,
                   theta1: float) -> NDArray[np.float64]:
        """The state of node positions (m) and velocities (m/s) at crank angle ``theta1``."""
        y = [a1.real, a1.imag, a2.real, a2.imag, v_a1.real, v_a1.imag, v_a2.real, v_a2.imag]
        y.append(0.0 if self.driven else float(theta1))  # motor work, or the crank angle
        return np.array(y, dtype=float)

    def node_accelerations(
        self,
        jac: NDArray[np.float64],
        gamma: NDArray[np.float64],
        f_free: NDArray[np.float64],
        a1: complex,
    ) -> NodeAccelerations:
        """``(ẍ, λ, τ)`` from ``M·ẍ + Φxᵀ·λ = F``, ``Φx·ẍ = γ`` (Eq. 48–50).

        Free motion: one linear solve for ẍ and λ (τ = 0). Driven: r̈A1 is the prescribed
        circle's ``−ω²·r̄A1``; the unknowns are r̈A2, λ and the motor torque τ, which enters
        the crank's nodal force at A1 as ``i·τ·r̄A1/l1²`` (Eq. 46).
        """
        m = self.m_free
        if not self.driven:
            a = np.zeros((7, 7))
            a[0:4, 0:4] = m
            a[0:4, 4:7] = jac.T
            a[4:7, 0:4] = jac
            z = np.linalg.solve(a, np.concatenate([f_free, gamma]))
            return z[0:4], z[4:7], 0.0
        omega = self._motor_speed
        acc_a1 = -omega * omega * a1
        x1 = np.array([acc_a1.real, acc_a1.imag])
        couple = 1j * a1 / self.lengths[0] ** 2
        a = np.zeros((6, 6))
        a[0:4, 0:2] = m[:, 2:4]
        a[0:4, 2:5] = jac.T
        a[0:2, 5] = [-couple.real, -couple.imag]
        a[4:6, 0:2] = jac[1:3, 2:4]
        rhs = np.concatenate([f_free - m[:, 0:2] @ x1, gamma[1:3] - jac[1:3, 0:2] @ x1])
        z = np.linalg.solve(a, rhs)
        return np.concatenate([x1, z[0:2]]), z[2:5], float(z[5])

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        acc, _, tau = self.solve(t, y)[:3]
        dy = np.concatenate([y[4:8], acc])
        if self.driven:
            return np.append(dy, tau * self._motor_speed)
        a1, v_a1 = complex(y[0], y[1]), complex(y[4], y[5])
        return np.append(dy, cross_scalar(a1, v_a1) / abs(a1) ** 2)  # θ̇1

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Least-norm Newton correction of the nodes onto the constraints, then of their rates.

        Driven, the crank node is put on its prescribed place first and only A2 is corrected.
        """
        y = np.array(y, dtype=float)
        rows, free = slice(0, 3), slice(0, 4)
        if self.driven:
            th = self.crank_angle(t)
            a1 = self.lengths[0] * complex(math.cos(th), math.sin(th))
            v1 = 1j * self._motor_speed * a1
            y[0:2] = a1.real, a1.imag
            y[4:6] = v1.real, v1.imag
            rows, free = slice(1, 3), slice(2, 4)
        for _ in range(4):
            phi, jac = self.constraints(y[0:4])
            if np.max(np.abs(phi[rows])) <= self.node_tolerance:
                break
            y[free] -= np.linalg.lstsq(jac[rows, free], phi[rows], rcond=None)[0]
        _, jac = self.constraints(y[0:4])
        resid = (jac @ y[4:8])[rows]
        vf = slice(4 + free.start, 4 + free.stop)
        y[vf] -= np.linalg.lstsq(jac[rows, free], resid, rcond=None)[0]
        if not self.driven:
            y[8] = self.theta1_of(t, y)
        return y
