"""Forward dynamics of the slider-crank in two formulations that must agree.

``complex-masses``
    One equation in θ1. The rod's linear momentum is carried by complex masses at its joints
    (Meijaard & van der Wijk 2020, Eq. 29): ``m2·ṙ2 = m̄2p·ṙA1 + m̄2q·ṙA2``, and with
    ``ṙA1 = i·l̄1·θ̇1``, ``ṙA2 = X·θ̇1`` (X = dx/dθ1), ``θ̇2 = Θ2·θ̇1`` the kinetic energy is
    ``T = Σ(θ1)·θ̇1²/2`` with::

        Σ = I1 + m1·s1² + |m̄2p·i·l̄1 + m̄2q·X|²/m2 + I2·Θ2² + m3·X²

    so that ``Σ·θ̈1 + Σ'·θ̇1²/2 = Q`` (Lagrange). The reactions follow from Newton–Euler with
    the accelerations found.
``mass-matrix``
    Truss elements (Sect. 4.2, 5.1): nodes A1 and A2 in Cartesian coordinates, the equivalent
    mass matrices of crank and rod (Eq. 45) and the slider's mass at A2, the constraints
    ``|r̄A1|² = r²``, ``|r̄A2 − r̄A1|² = L²`` and ``y_A2 = e`` with multipliers; the reactions are
    the multipliers: the guide's normal force directly, R̄A0 from node A0's equation.

Both take the gas force as acting between slider and frame along the guide.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...linkage import rotors
from ...linkage.massmodels import equivalent_joint_forces, equivalent_mass_matrix
from ...linkage.vectors import Num, cross_scalar
from ...model import Link
from ...model.assembly import AssemblyRange
from ..chains import ClosedForm, NodalTruss, NodeAccelerations
from ..formulation import DrivenRates, Evaluation
from .dynamics import kinetic_energy, newton_euler
from .kinematics import Lengths, SliderMotion, assembly_range, motion
from .model import SliderCrank


class _SliderFormulation(ClosedForm):
    """What both slider-crank formulations share: the mechanism's geometry for the driver."""

    linkage: SliderCrank
    lengths: Lengths

    rotating_links = 2
    passes_dead_points = False

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.sign0 = 1.0 if self.linkage.branch == "+" else -1.0
        self.offset = self.lengths[2]

    def assembly_range(self) -> AssemblyRange:
        return assembly_range(self.lengths)

    def change_points(self) -> tuple[float, ...]:
        return ()

    def transmission_of_crank(self, theta1: float) -> float:
        r, big_l, e = self.lengths
        s2 = (e - r * math.sin(theta1)) / big_l
        return math.sqrt(max(1 - s2 * s2, 0.0))

    @overload
    def gas(self, theta1: float) -> float: ...
    @overload
    def gas(self, theta1: NDArray[np.float64]) -> NDArray[np.float64]: ...

    def gas(self, theta1: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        return self.linkage.gas_force.at(theta1)

    def motion_of(self, theta1: ArrayLike, omega1: ArrayLike = 0.0,
                  alpha1: ArrayLike = 0.0) -> SliderMotion:
        return motion(self.lengths, theta1, omega1, alpha1, self.sign0, check=False)

    def energy(self, theta: NDArray[np.float64], omega: NDArray[np.float64],
               alpha: NDArray[np.float64], slider: NDArray[np.float64] | None = None,
               states: Sequence[NDArray[np.float64]] | None = None
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kinetic energy and the work of the loads and gravity since the start, J."""
        mo = self.motion_of(theta[0], omega[0], alpha[0])
        kin = kinetic_energy(self.linkage, mo)
        r, big_l, _ = self.lengths
        z1, z2 = self.linkage.crank.com / r, self.linkage.rod.com / big_l
        coms = (z1 * mo.l1, mo.l1 + z2 * mo.l2, mo.A2 + self.linkage.slider.com)
        work = 0.0 * kin
        for k, c in enumerate(coms):
            work = work + np.real(np.conj(self.forces[k]) * (c - c[0]))
        for k in range(2):
            work = work + self.moments[k] * (theta[k] - theta[k][0])
        # The gas force's work is integrated with the motion (extra_power).
        return kin, work

    def shaking(self, ev: Evaluation) -> tuple[Any, Any]:
        return ev.shaking_force, ev.shaking_moment

    def _evaluation(self, theta1: NDArray[np.float64], omega1: NDArray[np.float64],
                    alpha1: NDArray[np.float64], driving_torque: NDArray[np.float64]
                    ) -> Evaluation:
        """Reactions and everything else from the crank's state and acceleration."""
        mo = self.motion_of(theta1, omega1, alpha1)
        ne = newton_euler(self.linkage, mo, gravity=(self.gravity.real, self.gravity.imag))
        theta = np.array([mo.theta1, np.angle(mo.l2), 0.0 * mo.theta1])
        return Evaluation(
            theta=theta,
            omega=np.array([mo.omega[0], mo.omega[1], 0.0 * mo.theta1]),
            alpha=np.array([mo.alpha[0], mo.alpha[1], 0.0 * mo.theta1]),
            ground=ne.ground,
            slider_normal=ne.slider_normal,
            slider_couple=ne.slider_couple,
            driving_torque=driving_torque,
            shaking_force=ne.shaking_force,
            shaking_moment=ne.shaking_moment,
            slider=np.array([mo.x, mo.v, mo.a]),
        )


class SliderComplexMasses(_SliderFormulation):
    """One equation in θ1 with the rod's complex joint masses."""

    name = "complex-masses"
    minimal = True

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        c1, c2, c3 = self.links
        self.m2p = c2.mass * (1 - self.zeta[1])
        self.m2q = c2.mass * self.zeta[1]
        self.crank_inertia = c1.inertia + c1.mass * abs(c1.com) ** 2  # about A0, rotor included

    def _crank(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        if self.driven:
            return self.crank_angle(t), self._motor_speed
        return float(y[0]), float(y[1])

    def reduced(self, theta1: float, omega1: float, torque: float = 0.0
                ) -> tuple[float, float, float]:
        """``(Σ, Σ'/2, Q)`` at a state.

        The generalised inertia, half its derivative, and the generalised force of loads,
        gravity, gas force and motor torque. The kinematics of one state in plain floats
        (:func:`~balancer.mechanisms.slidercrank.kinematics.motion`'s equations, which
        :meth:`_terms` uses on arrays: a free motion's integrator calls this thousands of times).
        """
        return self._combine(*self._transfer(theta1), float(self.gas(theta1)), torque)

    def _transfer(self, theta1: float) -> tuple[complex, float, float, float, float]:
        """``(l̄1, Θ2, X, dΘ2/dθ1, dX/dθ1)`` at one crank angle, in plain floats."""
        r, big_l, e = self.lengths
        c1, s1 = math.cos(theta1), math.sin(theta1)
        s2 = (e - r * s1) / big_l
        c2 = self.sign0 * math.sqrt(max((big_l - e + r * s1) * (big_l + e - r * s1), 0.0)) / big_l
        big2 = -r * c1 / (big_l * c2)  # Θ2 = dθ2/dθ1
        big_x = -r * s1 - big_l * s2 * big2  # X = dx/dθ1
        d_big2 = (r * s1 + big_l * s2 * big2 * big2) / (big_l * c2)  # dΘ2/dθ1
        d_big_x = -r * c1 - big_l * (s2 * d_big2 + c2 * big2 * big2)  # dX/dθ1
        return complex(r * c1, r * s1), big2, big_x, d_big2, d_big_x

    def _combine(self, v1: Num, big2: Num, big_x: Num, d_big2: Num, d_big_x: Num, gas: Num,
                 torque: Num = 0.0) -> tuple[Num, Num, Num]:
        """``(Σ, Σ'/2, Q)`` from the kinematics' transfer functions, for numbers or arrays."""
        c1, c2, c3 = self.links
        m2 = c2.mass
        p = self.m2p * 1j * v1 + self.m2q * big_x  # rod momentum per unit θ̇1 (times m2)
        dp = -self.m2p * v1 + self.m2q * d_big_x
        sigma = (self.crank_inertia + abs(p) ** 2 / m2 + c2.inertia * big2 * big2
                 + c3.mass * big_x * big_x)
        half_dsigma = ((p.real * dp.real + p.imag * dp.imag) / m2 + c2.inertia * big2 * d_big2
                       + c3.mass * big_x * d_big_x)
        f1, f2, f3 = self.forces
        z1 = self.zeta[0]
        q = (self.moments[0] + torque + cross_scalar(z1 * v1, f1)
             + (p.real * f2.real + p.imag * f2.imag) / m2 + self.moments[1] * big2
             + (f3.real + gas) * big_x)
        return sigma, half_dsigma, q

    def _terms(self, theta1: NDArray[np.float64]
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                          NDArray[np.float64]]:
        """``(Σ, Σ'/2, Q, X)`` at an array of crank angles (``Q`` without the motor's torque).

        ``X = dx/dθ1``, the slider's velocity per unit crank rate.
        """
        at_rest = self.motion_of(theta1, 0.0, 1.0)  # velocity maps: accelerations for θ̈1 = 1
        turning = self.motion_of(theta1, 1.0, 0.0)  # their derivatives: for θ̇1 = 1
        big2, big_x = at_rest.transfer
        sigma, half_dsigma, q = self._combine(at_rest.l1, big2, big_x, turning.alpha[1],
                                              turning.a, self.gas(theta1))
        return sigma, half_dsigma, q, big_x

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        self.theta1_start = float(theta1)
        motion(self.lengths, theta1, 0.0, 0.0, self.sign0)  # raises if it does not assemble
        return np.array([0.0]) if self.driven else np.array([theta1, omega1], dtype=float)

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        theta1, omega1 = self._crank(t, y)
        sigma, half_dsigma, q = self.reduced(theta1, omega1)
        if self.driven:
            tau = half_dsigma * omega1 * omega1 - q  # Σ·0 + Σ'ω²/2 = Q + τ
            return np.array([tau * omega1])
        return np.array([omega1, (q - half_dsigma * omega1 * omega1) / sigma])

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        return self.evaluate_batch([t], [y]).at(0)

    def evaluate_batch(self, times: Sequence[float] | NDArray[np.float64],
                       states: Sequence[NDArray[np.float64]]) -> Evaluation:
        cranks = np.array([self._crank(t, y) for t, y in zip(times, states, strict=True)],
                          dtype=float).reshape(-1, 2)
        theta1, omega1 = cranks[:, 0], cranks[:, 1]
        sigma, half_dsigma, q, _ = self._terms(theta1)
        if self.driven:
            alphas, torques = 0.0 * theta1, half_dsigma * omega1 * omega1 - q
        else:
            alphas, torques = (q - half_dsigma * omega1 * omega1) / sigma, 0.0 * theta1
        return self._evaluation(theta1, omega1, alphas, torques)

    def driven_rates(self, times: ArrayLike) -> DrivenRates | None:
        """The motor's power ``τ·θ̇1`` and the gas force's ``G·X·θ̇1`` at many times."""
        if not self.time_only:
            return None
        theta1 = self.crank_angle(np.asarray(times, dtype=float))
        omega1 = self._motor_speed
        _, half_dsigma, q, big_x = self._terms(theta1)
        tau = half_dsigma * omega1 * omega1 - q  # as rhs
        extra = (0.0 * theta1 if self.linkage.gas_force.is_zero
                 else self.gas(theta1) * big_x * omega1)
        r, big_l, e = self.lengths
        s2 = (e - r * np.sin(theta1)) / big_l
        return DrivenRates(rates=(tau * omega1)[:, None], extra_power=extra,
                           transmission=np.sqrt(np.maximum(1 - s2 * s2, 0.0)))

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        return self.crank_angle(t) if self.driven else float(y[0])

    def extra_power(self, t: float, y: NDArray[np.float64]) -> float:
        """The gas force's power ``G(θ1)·X·θ̇1``, W."""
        if self.linkage.gas_force.is_zero:
            return 0.0
        theta1, omega1 = self._crank(t, y)
        return float(self.gas(theta1)) * self._transfer(theta1)[2] * omega1

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        return self.transmission_of_crank(self._crank(t, y)[0])


# The four-bar's nodal truss (a FourBarFormulation) with the slider-crank's linkage and lengths,
# which come first: their types are the slider-crank's.
class SliderMassMatrix(_SliderFormulation, NodalTruss):
    """Truss elements for crank and rod, the slider a mass at its pin, the guide a constraint."""

    name = "mass-matrix"
    minimal = False

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        c1, c2, c3 = self.links
        r, big_l, _ = self.lengths
        # Eq. 45 for crank (A0→A1) and rod (A1→A2) over the nodes A0, A1, A2, and the slider's
        # mass at A2 (it does not turn): a constant 6×6 matrix.
        m6 = np.zeros((6, 6))
        m6[0:4, 0:4] += _element(c1, r)
        m6[2:6, 2:6] += _element(c2, big_l)
        m6[4, 4] += c3.mass
        m6[5, 5] += c3.mass
        self.m_global = m6
        self.m_free = m6[2:6, 2:6]
        self.node_tolerance = 1e-16 * sum(abs(v) for v in self.lengths)

    # -- geometry ----------------------------------------------------------------------------

    def constraints(self, x: NDArray[np.float64]
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``Φ`` and ``∂Φ/∂x`` for x = (A1x, A1y, A2x, A2y).

        Crank and rod ``(|l̄|² − l²)/2`` (m²), the guide ``y_A2 − e`` (m).
        """
        r, big_l, e = self.lengths
        a1, a2 = complex(x[0], x[1]), complex(x[2], x[3])
        v1, v2 = a1, a2 - a1
        phi = np.array([0.5 * (abs(v1) ** 2 - r * r), 0.5 * (abs(v2) ** 2 - big_l * big_l),
                        x[3] - e])
        jac = np.array([[v1.real, v1.imag, 0.0, 0.0],
                        [-v2.real, -v2.imag, v2.real, v2.imag],
                        [0.0, 0.0, 0.0, 1.0]])
        return phi, jac

    def _forces(self, x: NDArray[np.float64], tau: float, gas: float) -> list[complex]:
        """Nodal applied forces at A0, A1, A2 (Eq. 46), the gas force and the motor torque in."""
        r, big_l, _ = self.lengths
        a1, a2 = complex(x[0], x[1]), complex(x[2], x[3])
        out: list[complex] = [0j, 0j, 0j]
        for k, (vec, length, (p, q)) in enumerate(((a1, r, (0, 1)), (a2 - a1, big_l, (1, 2)))):
            link = self.links[k]
            loaded = Link(mass=link.mass, inertia=link.inertia, e=link.e, f=link.f,
                          force=(self.forces[k].real, self.forces[k].imag),
                          moment=self.moments[k] + (tau if k == 0 else 0.0))
            fp, fq = equivalent_joint_forces(loaded, length, vec)
            out[p] += fp
            out[q] += fq
        out[2] += self.forces[2] + gas
        return out

    def solve(self, t: float, y: NDArray[np.float64]) -> NodeAccelerations:
        """Accelerations, multipliers (crank, rod, guide) and the motor torque at a state."""
        x, xd = y[0:4], y[4:8]
        a1d, a2d = complex(xd[0], xd[1]), complex(xd[2], xd[3])
        _, jac = self.constraints(x)
        gamma = np.array([-abs(a1d) ** 2, -abs(a2d - a1d) ** 2, 0.0])
        f = self._forces(x, 0.0, float(self.gas(self.theta1_of(t, y))))
        f_free = np.array([f[1].real, f[1].imag, f[2].real, f[2].imag])
        return self.node_accelerations(jac, gamma, f_free, complex(x[0], x[1]))

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        self.theta1_start = float(theta1)
        if self.driven:
            omega1 = self._motor_speed
        mo = motion(self.lengths, theta1, omega1, 0.0, self.sign0)
        return self.node_state(mo.A1[0], mo.A2[0], mo.vector_rate(0)[0], complex(mo.v[0]), theta1)

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        acc, lam, tau = self.solve(t, y)
        x, xd = y[0:4], y[4:8]
        a1, a2 = complex(x[0], x[1]), complex(x[2], x[3])
        vel1, vel2 = complex(xd[0], xd[1]), complex(xd[2], xd[3])
        acc1, acc2 = complex(acc[0], acc[1]), complex(acc[2], acc[3])
        v1, v2 = a1, a2 - a1
        theta1 = self.theta1_of(t, y)
        omega = (cross_scalar(v1, vel1) / abs(v1) ** 2,
                 cross_scalar(v2, vel2 - vel1) / abs(v2) ** 2)
        alpha = (cross_scalar(v1, acc1) / abs(v1) ** 2,
                 cross_scalar(v2, acc2 - acc1) / abs(v2) ** 2)
        gas = float(self.gas(theta1))
        f = self._forces(x, tau, gas)
        node_acc = np.array([0.0, 0.0, acc[0], acc[1], acc[2], acc[3]])
        inertia = self.m_global @ node_acc
        # Node A0's equation: R̄A0 = F_A0 − (M·ẍ)_A0 + l̄1·λ1 (Eq. 52–54 with the axial force).
        ra0 = f[0] - complex(inertia[0], inertia[1]) + v1 * lam[0]
        n_guide = -lam[2]  # the guide's normal force on the slider
        # The guide also resists the slider's turning: its couple balances the slider's moment.
        c3 = self.links[2]
        m_guide = -(self.moments[2] + cross_scalar(c3.com, self.forces[2] - c3.mass * acc2.real))
        h = self.offset
        moment = -a2.real * n_guide - m_guide + h * gas - tau
        if self.linkage.crank.counter_rotor:
            moment += rotors.ground_couple(self.linkage.crank.counter_rotor, alpha[0])
        return Evaluation(
            theta=np.array([theta1, math.atan2(v2.imag, v2.real), 0.0]),
            omega=np.array([omega[0], omega[1], 0.0]),
            alpha=np.array([alpha[0], alpha[1], 0.0]),
            ground={"A0": ra0},
            slider_normal={"slider": -n_guide},
            slider_couple={"slider": -m_guide},
            driving_torque=tau,
            shaking_force=ra0 - 1j * n_guide - gas,
            shaking_moment=moment,
            slider=np.array([a2.real, vel2.real, acc2.real]),
        )

    def extra_power(self, t: float, y: NDArray[np.float64]) -> float:
        """The gas force's power ``G(θ1)·ẋA2``, W."""
        if self.linkage.gas_force.is_zero:
            return 0.0
        return float(self.gas(self.theta1_of(t, y))) * float(y[6])

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        v2 = complex(y[2] - y[0], y[3] - y[1])
        return v2.real / abs(v2)

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        phi, jac = self.constraints(y[0:4])
        r, big_l, _ = self.lengths
        pos = max(abs(phi[0]) / r, abs(phi[1]) / big_l, abs(phi[2]))
        return float(pos), float(np.max(np.abs(jac @ y[4:8])))


def _element(link: Link, length: float) -> NDArray[np.float64]:
    return equivalent_mass_matrix(link.inertial_parameters, length)
