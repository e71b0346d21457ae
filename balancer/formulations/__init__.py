"""Forward dynamics of the four-bar in four formulations that must agree.

=================  ==================================================  =========================
name               formulation                                         state
=================  ==================================================  =========================
``opened-loop``    principal vectors, loop opened at A3 (Meijaard &     θ1, θ2, θ3, θ̇1, θ̇2, θ̇3
                   van der Wijk 2020, Eq. 22–28): five linear
                   equations for θ̈1..3 and R̄A3, R̄A0 from Eq. 28
``complex-masses`` complex joint masses, closed loop (Eq. 36–40),     θ1, θ̇1
                   reduced to one equation in θ1
``mass-matrix``    constant equivalent mass matrices, truss elements   r̄A1, r̄A2 and their rates
                   (Eq. 41–55): Cartesian joint coordinates with
                   length constraints, reactions from Eq. 52–54
``lie-group``      attitude vectors on the rotation group, reduced     Π1, q_A, q_B, q_D
                   to Hamiltonian form without multipliers (Bai, Xia
                   & Ge 2024, Eq. 82–85)
=================  ==================================================  =========================

Each is a :class:`Formulation`: it turns a state into its time derivative and evaluates the link
angles, rates, accelerations and the ground reactions at a state. The crank either moves freely
under the loads and gravity, or a motor on the ground holds it at constant speed; then the last
state component is the motor's work ``∫τ·θ̇1 dt`` and the driving torque is reported.
The integration itself (tolerances, projection of the non-minimal states, events, outputs) is
:mod:`balancer.simulate`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from ..inverse import dynamic_link
from ..kinematics import branch_sign_along, change_point_angles, position_scalar, rates_scalar
from ..model import FourBar


@dataclass(frozen=True)
class Evaluation:
    """What a formulation says about one state.

    Attributes
    ----------
    theta, omega, alpha
        Angles (rad), angular velocities (rad/s) and accelerations (rad/s²) of links 1–3 (a
        slider's are zero).
    RA0, RA3
        Forces of the mechanism on the ground at A0 and at A3 (a slider-crank: on the guide),
        complex ``x + i·y``, N.
    driving_torque
        Torque of the motor on the crank, N·m (zero in free motion).
    shaking_force, shaking_moment
        Sum of the forces on the frame (N) and their moment about A0 (N·m), when the
        formulation computes them itself (otherwise the simulation does, from the above).
    slider
        Slider position, velocity and acceleration along the guide (m, m/s, m/s²), if any.
    """

    theta: NDArray[np.float64]
    omega: NDArray[np.float64]
    alpha: NDArray[np.float64]
    RA0: complex
    RA3: complex
    driving_torque: float = 0.0
    shaking_force: complex | None = None
    shaking_moment: float | None = None
    slider: NDArray[np.float64] | None = None

    def at(self, index: int) -> Evaluation:
        """The state ``index`` of an evaluation of arrays (from ``evaluate_batch``)."""
        return Evaluation(
            theta=self.theta[:, index],
            omega=self.omega[:, index],
            alpha=self.alpha[:, index],
            RA0=complex(self.RA0[index]),
            RA3=complex(self.RA3[index]),
            driving_torque=float(np.asarray(self.driving_torque)[index]),
            shaking_force=None if self.shaking_force is None else complex(
                np.asarray(self.shaking_force)[index]),
            shaking_moment=None if self.shaking_moment is None else float(
                np.asarray(self.shaking_moment)[index]),
            slider=None if self.slider is None else np.asarray(self.slider)[:, index],
        )


class Formulation(ABC):
    """Equations of motion of a four-bar in one formulation.

    Parameters
    ----------
    linkage
        The four-bar (its counter-rotors add to the inertia of crank and rocker).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s².
    speed
        ``None`` for free motion; otherwise the constant crank speed (rad/s) a motor holds.
    """

    #: Name used by ``--method``.
    name: ClassVar[str]
    #: Whether the state is minimal (one coordinate and its rate): no constraints can drift.
    minimal: ClassVar[bool]
    #: Whether the formulation passes a dead point of the crank (coupler and rocker aligned).
    passes_dead_points: ClassVar[bool] = False
    #: Number of links that turn (a slider does not).
    rotating_links: ClassVar[int] = 3

    def __init__(
        self,
        linkage: FourBar,
        *,
        gravity: tuple[float, float] = (0.0, 0.0),
        speed: float | None = None,
    ) -> None:
        self.linkage = linkage
        self.gravity = complex(*gravity)
        self.speed = speed
        self.lengths = linkage.lengths
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
        self.theta1_start = 0.0
        self.sign0 = 1.0 if linkage.branch == "+" else -1.0

    @property
    def driven(self) -> bool:
        """Whether a motor holds the crank at constant speed."""
        return self.speed is not None

    def crank_angle(self, t: float) -> float:
        """Prescribed crank angle at time ``t`` (driven motion), rad."""
        assert self.speed is not None
        return self.theta1_start + self.speed * t

    @staticmethod
    def continuous_crank(wrapped: float, carried: float) -> float:
        """The crank angle continuous along a free motion, rad.

        Formulations whose coordinates give the crank angle only modulo 2π (nodal positions,
        attitudes) carry the continuous angle as an auxiliary state ``carried``, advanced by
        θ̇1; it is snapped here to the coordinates' ``wrapped`` angle.
        """
        return carried + math.remainder(wrapped - carried, 2 * math.pi)

    @abstractmethod
    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        """The state with the crank at ``theta1`` (rad) turning at ``omega1`` (rad/s) at t = 0."""

    @abstractmethod
    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Time derivative of the state."""

    @abstractmethod
    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        """Angles, rates, accelerations and reactions at a state."""

    def evaluate_batch(self, times, states) -> Evaluation:
        """:meth:`evaluate` at many states, as an :class:`Evaluation` of arrays.

        ``theta``, ``omega``, ``alpha`` have shape ``(3, n)``. Formulations override it with
        vectorised versions of their own equations.
        """
        evals = [self.evaluate(t, y) for t, y in zip(times, states, strict=True)]

        def stack(name):
            values = [getattr(e, name) for e in evals]
            return None if values[0] is None else np.array(values)

        slider = stack("slider")
        return Evaluation(
            theta=np.array([e.theta for e in evals]).T,
            omega=np.array([e.omega for e in evals]).T,
            alpha=np.array([e.alpha for e in evals]).T,
            RA0=np.array([e.RA0 for e in evals]),
            RA3=np.array([e.RA3 for e in evals]),
            driving_torque=np.array([e.driving_torque for e in evals]),
            shaking_force=stack("shaking_force"),
            shaking_moment=stack("shaking_moment"),
            slider=None if slider is None else slider.T,
        )

    @abstractmethod
    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        """``sin(θ3 − θ2)``: zero where coupler and rocker align (dead point or change point)."""

    # -- what the simulation driver needs to know of the mechanism (four-bar here) ------------

    def assembly_range(self):
        """Crank angles at which the mechanism assembles."""
        from ..kinematics import assembly_range

        return assembly_range(self.lengths)

    def change_points(self) -> tuple[float, ...]:
        """Crank angles at which the assemblies meet (passed on the smooth motion)."""
        return change_point_angles(self.lengths)

    def transmission_of_crank(self, theta1: float) -> float:
        """|sin(θ3 − θ2)| on the motion's assembly at ``theta1``: zero at a dead point."""
        sign = branch_sign_along(self.lengths, self.sign0, self.theta1_start, theta1)
        _, v2, v3 = position_scalar(self.lengths, theta1, float(sign))
        return abs(v2.real * v3.imag - v2.imag * v3.real) / (self.lengths[1] * self.lengths[2])

    def energy(self, theta, omega, alpha, slider=None):
        """Kinetic energy and the work of loads and gravity since the first state, J.

        At output states (arrays over time; angles continuous).
        """
        from ..inverse import kinetic_energy, link_com_kinematics
        from ..kinematics import motion_from_angles

        mo = motion_from_angles(self.lengths, tuple(theta), tuple(omega), tuple(alpha))
        kin = kinetic_energy(self.linkage, mo)
        coms, _ = link_com_kinematics(self.linkage, mo)
        work = 0.0 * kin
        for k, r in enumerate(coms):
            work = work + np.real(np.conj(self.forces[k]) * (r - r[0])) + self.moments[k] * (
                theta[k] - theta[k][0])
        return kin, work

    def shaking(self, ev: Evaluation) -> tuple:
        """Shaking force (N) and moment about A0 (N·m) from a (batch) evaluation."""
        if ev.shaking_force is not None and ev.shaking_moment is not None:
            return ev.shaking_force, ev.shaking_moment
        ra3 = np.asarray(ev.RA3, complex)
        tau = np.asarray(ev.driving_torque, float)
        moment = self.lengths[3] * ra3.imag - tau
        for k, link in enumerate(self.linkage.links):
            if link.counter_rotor:
                moment = moment + 2 * link.counter_rotor * np.asarray(ev.alpha)[k]
        return np.asarray(ev.RA0, complex) + ra3, moment

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        """Crank angle at a state, rad."""
        if self.driven:
            return self.crank_angle(t)
        return float(self.evaluate(t, y).theta[0])

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Put a state back on the constraint manifold (identity for minimal formulations)."""
        return y

    def near_change_point(self, theta1: float, width: float = 0.1) -> bool:
        """Whether the crank angle (rad) is within ``width`` of a change point of the linkage.

        There all joints become collinear, the loop-closure Jacobian loses rank and the two
        assemblies cross: a least-norm projection cannot tell them apart, so the non-minimal
        formulations project onto the assembly of the smooth motion instead
        (:meth:`branch_vectors`).
        """
        points = change_point_angles(self.lengths)
        return any(abs(math.remainder(theta1 - p, 2 * math.pi)) < width for p in points)

    def branch_vectors(self, theta1: float, omega1: float):
        """Link vectors and dependent rates ``(l̄1, l̄2, l̄3), θ̇2, θ̇3`` of the smooth motion.

        On the assembly the motion is on at crank angle ``theta1`` (unwrapped, rad) (Eq. 2–7).
        """
        sign = branch_sign_along(self.lengths, self.sign0, self.theta1_start, theta1)
        vectors = position_scalar(self.lengths, theta1, float(sign))
        _, _, w2, w3, _, _ = rates_scalar(self.lengths, vectors, omega1)
        return vectors, w2, w3

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        """Loop-closure residuals of a state: position (m) and velocity (m/s)."""
        return 0.0, 0.0

    def extra_power(self, t: float, y: NDArray[np.float64]) -> float:
        """Power of the loads whose work is not a function of the configuration, W.

        Such as a force that depends on the crank angle. The driver integrates it with the
        motion (:mod:`balancer.simulate`); constant loads and gravity need none (their work is
        in :meth:`energy`), nor the motor (its work is a state of the driven formulations).
        """
        return 0.0

    def motor_work(self, y: NDArray[np.float64]) -> float:
        """Work done by the motor since t = 0, J (zero in free motion)."""
        return float(y[-1]) if self.driven else 0.0


#: Formulations per mechanism type: name → (module, class); the first is the default.
FORMULATIONS: dict[str, dict[str, tuple[str, str]]] = {
    "four-bar": {
        "opened-loop": ("balancer.formulations.opened_loop", "OpenedLoop"),
        "complex-masses": ("balancer.formulations.complex_masses", "ComplexMasses"),
        "mass-matrix": ("balancer.formulations.mass_matrix", "MassMatrix"),
        "lie-group": ("balancer.formulations.lie_group", "LieGroup"),
    },
    "slider-crank": {
        "mass-matrix": ("balancer.slider_crank.formulations", "SliderMassMatrix"),
        "complex-masses": ("balancer.slider_crank.formulations", "SliderComplexMasses"),
    },
}


def default_method(mechanism_type: str) -> str:
    """The formulation used when none is asked for."""
    return next(iter(FORMULATIONS[mechanism_type]))


def formulation_class(name: str, mechanism_type: str = "four-bar") -> type[Formulation]:
    """The formulation called ``name`` for a mechanism type (see :data:`FORMULATIONS`)."""
    import importlib

    table = FORMULATIONS[mechanism_type]
    try:
        module, cls = table[name]
    except KeyError:
        raise ValueError(
            f"the {mechanism_type} has no formulation {name!r}; choose from {', '.join(table)}"
        ) from None
    return getattr(importlib.import_module(module), cls)


def make(
    name: str,
    linkage: FourBar,
    *,
    gravity: tuple[float, float] = (0.0, 0.0),
    speed: float | None = None,
) -> Formulation:
    """Instantiate the formulation called ``name`` for the mechanism."""
    return formulation_class(name, linkage.type)(linkage, gravity=gravity, speed=speed)
