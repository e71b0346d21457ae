"""Closed loop with complex joint masses (Meijaard & van der Wijk 2020, Sect. 4.1).

The coupler's linear momentum is carried by two complex masses at its joints,
``m̄2p = m2(1 − s̄2/l2) = m2ᵃ − i·m2ᶜ`` at A1 and ``m̄2q = m2·s̄2/l2 = m2ᵇ + i·m2ᶜ`` at A2
(Eq. 29). With the positions of A1 and A2 written through θ1 and θ3 (the loop is not opened),
the equations of motion (Eq. 36) have the mass matrix of Eq. 37 (``M12 = M23 = 0``,
``M22 = I2``), the single convective pair ``C13 = −C31`` of Eq. 38 and the generalised forces of
Eq. 39. Multiplying the second and third equations by the transfer functions Θ2, Θ3 and adding
(the constraint forces do no work) leaves one equation in θ1::

    (Θᵀ·M·Θ)·θ̈1 = Θᵀ·(Q − M·b − C·θ̇²),     Θ = (1, Θ2, Θ3),  θ̈k = Θk·θ̈1 + bk  (Eq. 7, 9–10)

The reactions follow from virtual displacements of the whole system (Eq. 40: a translation for
the resultant force, Eq. 35 for the accelerations) and of the ground pivot A3 with A0 and A1
held, which separates R̄A3 from R̄A0.

The state (θ1, θ̇1) is minimal; the dependent positions come from Eq. 2–4 on the assembly the
motion is on (which changes only at the change points of a change-point linkage). At a dead
point of the crank (coupler and rocker aligned) this chart is singular: the simulation stops
there and says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...linkage.vectors import Num, cross_scalar
from ..formulation import DrivenRates, Evaluation
from .closed_form import FourBarFormulation
from .kinematics import branch_sign_along, motion, position_scalar, rates_scalar

#: The kinematics the reduced equation needs, at one state (numbers) or many (arrays):
#: ``((l̄1, l̄2, l̄3), Θ2, Θ3, θ̇2, θ̇3, b2, b3)`` with ``θ̈k = Θk·θ̈1 + bk``.
Kinematics: TypeAlias = tuple[tuple[Num, Num, Num], Num, Num, Num, Num, Num, Num]


def _ip(x: complex, y: complex) -> float:
    """⟨x̄, ȳ⟩ = Re(x*·y)."""
    return x.real * y.real + x.imag * y.imag


class ComplexMasses(FourBarFormulation):
    """Complex joint masses, Eq. 29 and 36–40, reduced to one equation in θ1."""

    name = "complex-masses"
    minimal = True

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        (l1, _, l3, _), (c1, c2, c3) = self.lengths, self.links
        m2 = c2.mass
        self.m2p = m2 * (1 - self.zeta[1])  # m2ᵃ − i·m2ᶜ
        self.m2q = m2 * self.zeta[1]  # m2ᵇ + i·m2ᶜ
        # Eq. 37, second forms: constant diagonal entries.
        self.m11 = c1.inertia + c1.mass * abs(c1.com) ** 2 + l1 * l1 * abs(self.m2p) ** 2 / m2
        self.m22 = c2.inertia
        self.m33 = (
            c3.inertia + c3.mass * abs(l3 - c3.com) ** 2 + l3 * l3 * abs(self.m2q) ** 2 / m2
        )

    # -- kinematics on the current assembly ----------------------------------------------------

    def _vectors(self, theta1: float) -> tuple[complex, complex, complex]:
        sign = branch_sign_along(self.lengths, self.sign0, self.theta1_start, theta1)
        return position_scalar(self.lengths, theta1, float(sign))

    def _crank(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        if self.driven:
            return self.crank_angle(t), self._motor_speed
        return float(y[0]), float(y[1])

    # -- Eq. 36–39 -----------------------------------------------------------------------------

    def _reduced(self, theta1: float, omega1: float) -> tuple[float, float, Kinematics]:
        """Terms of the reduced equation at one state: ``(ΘᵀMΘ, ΘᵀQ − ΘᵀMb − ΘᵀCθ̇², kin)``."""
        vectors = self._vectors(theta1)
        kin: Kinematics = (vectors, *rates_scalar(self.lengths, vectors, omega1))
        inertia, force = self._dynamics(kin, omega1)
        return inertia, force, kin

    def _dynamics(self, kin: Kinematics, omega1: Num) -> tuple[Num, Num]:
        """Eq. 36–39 reduced to θ1, for scalars or arrays of states.

        ``kin = ((l̄1, l̄2, l̄3), Θ2, Θ3, θ̇2, θ̇3, b2, b3)`` with ``θ̈k = Θk·θ̈1 + bk``.
        """
        (v1, _, v3), big2, big3, w2, w3, b2, b3 = kin
        m2 = self.mass[1]
        m13 = -_ip(self.m2p * v1, self.m2q * v3) / m2  # Eq. 37
        c13 = cross_scalar(self.m2p * v1, self.m2q * v3) / m2  # Eq. 38, C31 = −C13
        f1, f2, f3 = self.forces
        mo1, mo2, mo3 = self.moments
        z1, _, z3 = self.zeta
        q1 = mo1 + cross_scalar(z1 * v1, f1) + cross_scalar(self.m2p * v1, f2) / m2  # Eq. 39
        q2 = mo2
        q3 = mo3 - cross_scalar(self.m2q * v3, f2) / m2 + cross_scalar((z3 - 1) * v3, f3)
        # Θᵀ·M·Θ with M = [[m11, 0, m13], [0, m22, 0], [m13, 0, m33]].
        inertia = self.m11 + 2 * m13 * big3 + self.m22 * big2 * big2 + self.m33 * big3 * big3
        mb = (m13 * b3, self.m22 * b2, self.m33 * b3)  # M·b with b = (0, b2, b3)
        cw = (c13 * w3 * w3, 0.0, -c13 * omega1 * omega1)  # C·θ̇²
        force = (q1 - mb[0] - cw[0]) + big2 * (q2 - mb[1] - cw[1]) + big3 * (q3 - mb[2] - cw[2])
        return inertia, force

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        self.theta1_start = float(theta1)
        self._vectors(theta1)  # raises if the linkage cannot be assembled there
        return np.array([0.0]) if self.driven else np.array([theta1, omega1], dtype=float)

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        theta1, omega1 = self._crank(t, y)
        inertia, force, _ = self._reduced(theta1, omega1)
        if self.driven:
            return np.array([-force * omega1])  # motor work rate τ·θ̇1 with τ = −force
        return np.array([omega1, force / inertia])

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        theta1, omega1 = self._crank(t, y)
        inertia, force, kin = self._reduced(theta1, omega1)
        return self._evaluation(theta1, omega1, inertia, force, kin)

    def _kinematics_batch(self, theta1: NDArray[np.float64], omega1: NDArray[np.float64]
                          ) -> Kinematics:
        """``kin`` of :meth:`_dynamics` at arrays of crank states (Eq. 2–10, vectorised)."""
        signs = branch_sign_along(self.lengths, self.sign0, self.theta1_start, theta1)
        mo = motion(self.lengths, theta1, omega1, 0.0, signs * np.ones_like(theta1), check=False)
        v1, v2, v3 = mo.vectors
        return ((v1, v2, v3), *mo.transfer, mo.omega[1], mo.omega[2], mo.alpha[1], mo.alpha[2])

    def evaluate_batch(self, times: Sequence[float] | NDArray[np.float64],
                       states: Sequence[NDArray[np.float64]]) -> Evaluation:
        """The same equations on arrays of states, with the vectorised kinematics (Eq. 2–10)."""
        cranks = [self._crank(t, y) for t, y in zip(times, states, strict=True)]
        theta1 = np.array([c[0] for c in cranks])
        omega1 = np.array([c[1] for c in cranks])
        kin = self._kinematics_batch(theta1, omega1)
        inertia, force = self._dynamics(kin, omega1)
        return self._evaluation(theta1, omega1, inertia, force, kin)

    def driven_rates(self, times: ArrayLike) -> DrivenRates | None:
        """The motor's power ``τ·θ̇1`` (``τ = −force``, as :meth:`rhs`) at many times."""
        if not self.time_only:
            return None
        theta1 = self.crank_angle(np.asarray(times, dtype=float))
        omega1 = np.full(theta1.shape, self._motor_speed)
        kin = self._kinematics_batch(theta1, omega1)
        _, force = self._dynamics(kin, omega1)
        _, v2, v3 = kin[0]
        transmission = (v2.real * v3.imag - v2.imag * v3.real) / (self.lengths[1]
                                                                  * self.lengths[2])
        return DrivenRates(rates=(-force * omega1)[:, None], extra_power=np.zeros(theta1.shape),
                           transmission=transmission)

    def _evaluation(self, theta1: Num, omega1: Num, inertia: Num, force: Num,
                    kin: Kinematics) -> Evaluation:
        vectors, big2, big3, w2, w3, b2, b3 = kin
        if self.driven:
            alpha1, tau = 0.0 * force, -force
        else:
            alpha1, tau = force / inertia, 0.0 * force
        alpha = np.array([alpha1 + 0.0 * big2, big2 * alpha1 + b2, big3 * alpha1 + b3])
        omega = np.array([omega1 + 0.0 * w2, w2, w3])
        ra0, ra3 = self._reactions(vectors, omega, alpha)
        theta = np.array([theta1 + 0.0 * big2, np.angle(vectors[1]), np.angle(vectors[2])])
        return Evaluation(theta=theta, omega=omega, alpha=alpha, ground={"A0": ra0, "A3": ra3},
                          driving_torque=tau)

    def _reactions(self, vectors: tuple[Num, Num, Num], omega: NDArray[Any],
                   alpha: NDArray[Any]) -> tuple[Num, Num]:
        """R̄A0, R̄A3 by virtual displacements with the complex masses (Eq. 35, 40).

        For scalars or arrays of states.
        """
        v1, v2, v3 = vectors
        m1, m2, m3 = self.mass
        z1, _, z3 = self.zeta
        f1, f2, f3 = self.forces
        mo = self.moments
        inertias = [link.inertia for link in self.links]
        e1, _, e3 = ((1j * a - w * w) for a, w in zip(alpha, omega, strict=True))
        # Eq. 35: the links' linear momenta through the complex joint masses.
        p1 = m1 * z1 * e1 * v1
        p2 = self.m2p * e1 * v1 - self.m2q * e3 * v3
        p3 = m3 * (z3 - 1) * e3 * v3
        # Translation of the whole system (Eq. 40, δr̄S): the resultant force on the ground.
        shaking = f1 + f2 + f3 - p1 - p2 - p3
        # A3 moved by δ with A0, A1 held: i·(l̄2·δθ2 + l̄3·δθ3) = δ.
        c23 = cross_scalar(v2, v3)
        ra3 = 0j * v1
        for delta in (1.0, 1j):
            d2 = _ip(v3, delta) / c23
            d3 = -_ip(v2, delta) / c23
            d_a2 = 1j * v2 * d2
            d_r2 = self.m2q * d_a2 / m2
            d_r3 = (1 - z3) * d_a2 + z3 * delta
            work = (
                _ip(d_r2, f2 - p2)
                + (mo[1] - inertias[1] * alpha[1]) * d2
                + _ip(d_r3, f3 - p3)
                + (mo[2] - inertias[2] * alpha[2]) * d3
            )
            ra3 += work * delta  # ⟨δ, R̄A3⟩ = virtual work of links 2 and 3
        return shaking - ra3, ra3

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        return self.crank_angle(t) if self.driven else float(y[0])

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        theta1, _ = self._crank(t, y)
        _, v2, v3 = self._vectors(theta1)
        return cross_scalar(v2, v3) / (self.lengths[1] * self.lengths[2])
