"""The interface every formulation of the equations of motion implements (:class:`Formulation`).

What a formulation evaluates at a state (:class:`Evaluation`), the driven crank's rates
(:class:`DrivenRates`), and what several formulations share: the least-norm step of those that
project onto their constraints, continuous link angles. The formulations themselves and their
registry: :mod:`balancer.formulations`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, overload

import numpy as np
from numpy.typing import NDArray

from ..linkage import rotors
from ..model.assembly import AssemblyRange
from .base import Mechanism, frame_positions

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca

#: The transmission (|sin(θ3 − θ2)|, or the square root of a group's assembly gap) at which a
#: formulation that cannot pass a dead point stops before it (:mod:`balancer.simulation`).
DEAD_POINT_THRESHOLD = 1e-3


def continuous_angles(theta: NDArray[np.float64], omega: NDArray[np.float64],
                      t: NDArray[np.float64]) -> NDArray[np.float64]:
    """An angle continuous over time from its values modulo 2π, rad.

    ``theta`` at increasing times ``t`` (s), ``omega`` its rate there (rad/s): each step takes
    the 2π branch nearest to the trapezoidal prediction ``(ω_i + ω_{i+1})·Δt/2``; the first
    value is kept.
    """
    theta = np.asarray(theta, dtype=float)
    predicted = 0.5 * (omega[:-1] + omega[1:]) * np.diff(t)
    turns = np.round((predicted - np.diff(theta)) / (2 * math.pi))
    return theta + 2 * math.pi * np.concatenate([[0.0], np.cumsum(turns)])


def least_norm(jac: NDArray[np.float64], res: NDArray[np.float64]) -> NDArray[np.float64]:
    """The least-norm ``Δ`` with ``J·Δ = r``: ``Jᵀ·(J·Jᵀ)⁻¹·r`` (J of full row rank).

    At a pose where the constraints are dependent (a singular position) ``J·Jᵀ`` is singular
    and the least-squares solution by SVD is taken instead.
    """
    try:
        return jac.T @ np.linalg.solve(jac @ jac.T, res)
    except np.linalg.LinAlgError:
        return np.asarray(np.linalg.lstsq(jac, res, rcond=None)[0], dtype=float)


def least_norm_many(jac: NDArray[np.float64], res: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`least_norm` of each of a stack of Jacobians ``(k, rows, n)`` and residuals.

    Shared by the formulations that project onto their constraints (the opened loop's loop
    closure, the multibody formulation's joints).
    """
    try:
        x = np.linalg.solve(jac @ jac.transpose(0, 2, 1), res[..., None])[..., 0]
    except np.linalg.LinAlgError:  # one of them singular: each by itself
        return np.array([least_norm(j, r) for j, r in zip(jac, res, strict=True)])
    return np.einsum("kri,kr->ki", jac, x)


@dataclass(frozen=True, eq=False)
class DrivenRates:
    """A driven crank's prescribed motion at many times (:meth:`Formulation.driven_rates`).

    Attributes
    ----------
    rates
        The time derivative of the formulation's state, shape ``(times, state size)``: the
        motor's power ``τ·θ̇1`` for its work (W), the crank's speed for a carried crank angle.
    extra_power
        :meth:`Formulation.extra_power` at those times, W, shape ``(times,)``.
    transmission
        How far each pose is from a dead point, as :meth:`Formulation.transmission` measures
        it (0 there), shape ``(times,)``.
    """

    rates: NDArray[np.float64]
    extra_power: NDArray[np.float64]
    transmission: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Evaluation:
    """What a formulation says about one state (or, from ``evaluate_batch``, about many).

    Attributes
    ----------
    theta, omega, alpha
        Angles (rad), angular velocities (rad/s) and accelerations (rad/s²) of the moving links
        in the mechanism's order (:attr:`Formulation.link_names`), shape ``(n,)`` or
        ``(n, count)`` (a slider's angle stays constant).
    ground
        Force of the mechanism on the ground at each ground point, complex ``x + i·y``, N.
    driving_torque
        Torque of the motor on the crank, N·m (zero in free motion).
    shaking_force, shaking_moment
        Sum of the forces on the frame (N) and their moment about the origin (N·m), when the
        formulation computes them itself (otherwise :meth:`Formulation.shaking` does).
    slider_normal, slider_couple
        For each slider on a ground guide (keyed by the sliding link): the normal force (N,
        along the guide's direction turned by +90°) and the couple about the slider's point
        (N·m) that it exerts on the guide.
    slider
        A formulation's own slider coordinate: position, velocity and acceleration along the
        guide (m, m/s, m/s²), if it has one.
    """

    theta: NDArray[np.float64]
    omega: NDArray[np.float64]
    alpha: NDArray[np.float64]
    ground: dict[str, Any]
    driving_torque: Any = 0.0
    shaking_force: Any = None
    shaking_moment: Any = None
    slider_normal: dict[str, Any] = field(default_factory=dict)
    slider_couple: dict[str, Any] = field(default_factory=dict)
    slider: NDArray[np.float64] | None = None

    def at(self, index: int) -> Evaluation:
        """The state ``index`` of an evaluation of arrays (from ``evaluate_batch``)."""
        def pick(x: Any, kind: type[complex] | type[float]) -> complex | float | None:
            return None if x is None else kind(np.asarray(x)[index])

        return Evaluation(
            theta=self.theta[:, index],
            omega=self.omega[:, index],
            alpha=self.alpha[:, index],
            ground={p: complex(np.asarray(v)[index]) for p, v in self.ground.items()},
            driving_torque=float(np.asarray(self.driving_torque)[index]),
            shaking_force=pick(self.shaking_force, complex),
            shaking_moment=pick(self.shaking_moment, float),
            slider_normal={k: float(np.asarray(v)[index]) for k, v in self.slider_normal.items()},
            slider_couple={k: float(np.asarray(v)[index]) for k, v in self.slider_couple.items()},
            slider=None if self.slider is None else np.asarray(self.slider)[:, index],
        )

    @staticmethod
    def stack(evaluations: list[Evaluation]) -> Evaluation:
        """Evaluations at single states as one of arrays (the inverse of :meth:`at`)."""
        first = evaluations[0]

        def arrays(name: str) -> NDArray[Any] | None:
            values = [getattr(e, name) for e in evaluations]
            return None if values[0] is None else np.array(values)

        def keyed(name: str, dtype: type[complex] | type[float]) -> dict[str, NDArray[Any]]:
            return {k: np.array([getattr(e, name)[k] for e in evaluations], dtype)
                    for k in getattr(first, name)}

        slider = arrays("slider")
        return Evaluation(
            theta=np.array([e.theta for e in evaluations]).T,
            omega=np.array([e.omega for e in evaluations]).T,
            alpha=np.array([e.alpha for e in evaluations]).T,
            ground=keyed("ground", complex),
            driving_torque=np.array([e.driving_torque for e in evaluations], float),
            shaking_force=arrays("shaking_force"),
            shaking_moment=arrays("shaking_moment"),
            slider_normal=keyed("slider_normal", float),
            slider_couple=keyed("slider_couple", float),
            slider=None if slider is None else slider.T,
        )


class Formulation(ABC):
    """Equations of motion of a mechanism in one formulation.

    Parameters
    ----------
    mechanism
        The mechanism (its data is :attr:`linkage`).
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
    #: Whether it follows the smooth motion through a change point (all joints in line).
    passes_change_points: ClassVar[bool] = True
    #: Whether one instance serves every simulation of its mechanism (compiled once; its
    #: state is all set by :meth:`initial_state`).
    reusable: ClassVar[bool] = False

    def __init__(
        self,
        mechanism: Mechanism,
        *,
        gravity: tuple[float, float] = (0.0, 0.0),
        speed: float | None = None,
    ) -> None:
        #: The mechanism (:func:`balancer.mechanisms.mechanism_of`) and its data.
        self.mechanism = mechanism
        self.linkage = mechanism.model
        self.gravity = complex(*gravity)
        self.speed = speed
        self.theta1_start = 0.0
        #: What a formulation compiles once and keeps (the integrator's stages).
        self.compiled: dict[str, Any] = {}

    @property
    def driven(self) -> bool:
        """Whether a motor holds the crank at constant speed."""
        return self.speed is not None

    @overload
    def crank_angle(self, t: float) -> float: ...
    @overload
    def crank_angle(self, t: NDArray[np.float64]) -> NDArray[np.float64]: ...

    def crank_angle(self, t: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """Prescribed crank angle at time ``t`` (s, a number or an array; driven motion), rad."""
        assert self.speed is not None
        return self.theta1_start + self.speed * t

    @property
    def _motor_speed(self) -> float:
        """The speed at which the motor holds the crank, rad/s (driven motion only)."""
        assert self.speed is not None, "a driven motion's"
        return float(self.speed)

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

    def evaluate_batch(self, times: Sequence[float] | NDArray[np.float64],
                       states: Sequence[NDArray[np.float64]]) -> Evaluation:
        """:meth:`evaluate` at many states, as an :class:`Evaluation` of arrays.

        ``theta``, ``omega``, ``alpha`` have shape ``(n, count)``. Formulations override it
        with vectorised versions of their own equations.
        """
        return Evaluation.stack([self.evaluate(t, y) for t, y in zip(times, states, strict=True)])

    @property
    def time_only(self) -> bool:
        """Whether :meth:`rhs` depends on the time alone, not on the state.

        So it is for a minimal formulation with the crank driven: the motion is prescribed and
        the state is only the motor's work.
        """
        return self.minimal and self.driven

    def driven_rates(self, times: NDArray[np.float64]) -> DrivenRates | None:
        """:meth:`rhs` and :meth:`extra_power` at many times of a :attr:`time_only` motion.

        Vectorised over the times: the simulation then finds the motor's work at its output
        times by quadrature (:mod:`balancer.simulation.quadrature`) instead of stepping an
        integrator. ``None`` (the default) where a formulation has no vectorised form.
        """
        return None

    def driven_motion(self, times: NDArray[np.float64],
                      start: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The states of a driven crank's prescribed motion at many times, or ``None``.

        For a formulation that is not minimal: its coordinates and rates at the times (in
        increasing order), shape ``(times, state size − 1)`` (all but the motor's work, the
        last entry), found from the mechanism's position and rate analysis at the crank angles
        :meth:`crank_angle` gives, on the constraints, angles continuous from the state
        ``start`` at ``t = 0``. The simulation then takes the motor's work by quadrature
        instead of stepping an integrator. ``None`` (the default) where a formulation has no
        such route, or the motion does not exist at some time.
        """
        return None

    def symbolic_rhs(self) -> ca.Function | None:
        """:meth:`rhs` as a CasADi function ``(t, y) → ẏ``, or ``None``.

        Offered only where :meth:`extra_power` is zero: the integrator then evaluates a step's
        stages in one compiled call (:mod:`balancer.simulation.integrator`).
        """
        return None

    @abstractmethod
    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        """``sin(θ3 − θ2)``: zero where coupler and rocker align (dead point or change point)."""

    # -- what the simulation driver needs to know of the mechanism --------------------------

    def assembly_range(self) -> AssemblyRange:
        """Crank angles at which the mechanism assembles."""
        return self.mechanism.assembly_range()

    def change_points(self) -> tuple[float, ...]:
        """Crank angles at which the assemblies meet (passed on the smooth motion); none."""
        return ()

    @abstractmethod
    def transmission_of_crank(self, theta1: float) -> float:
        """How far from a dead point the motion's pose at crank angle ``theta1`` is (0 there)."""

    @abstractmethod
    def energy(self, theta: NDArray[np.float64], omega: NDArray[np.float64],
               alpha: NDArray[np.float64], slider: NDArray[np.float64] | None = None,
               states: Sequence[NDArray[np.float64]] | None = None
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kinetic energy and the work of loads, gravity and springs since the first state, J.

        At output states: arrays over time of the angles (continuous), rates and
        accelerations, the formulation's own slider coordinate, and the states themselves.
        """

    def shaking(self, ev: Evaluation) -> tuple[Any, Any]:
        """Shaking force (N) and moment about the origin (N·m) from a (batch) evaluation.

        From the forces at the ground points, the motor's reaction and the counter-rotors'
        (``+2J·α`` each), unless the formulation computed them itself.
        """
        if ev.shaking_force is not None and ev.shaking_moment is not None:
            return ev.shaking_force, ev.shaking_moment
        force: Any = 0.0
        moment = -np.asarray(ev.driving_torque, float)
        positions = frame_positions(self.mechanism)
        for point, value in ev.ground.items():
            value = np.asarray(value, complex)
            force = force + value
            moment = moment + (np.conj(positions[point]) * value).imag
        for k, link in enumerate(self.mechanism.linkage.links):
            if link.counter_rotor:
                moment = moment + rotors.ground_couple(link.counter_rotor,
                                                        np.asarray(ev.alpha)[k])
        return force, moment

    @property
    def link_names(self) -> tuple[str, ...]:
        """Names of the moving links, in the order of ``theta``, ``omega``, ``alpha``."""
        return self.mechanism.linkage.link_names

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        """Crank angle at a state, rad."""
        if self.driven:
            return self.crank_angle(t)
        return float(self.evaluate(t, y).theta[0])

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Put a state back on the constraint manifold (identity for minimal formulations)."""
        return y

    def project_many(self, times: Sequence[float] | NDArray[np.float64],
                     states: Sequence[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
        """:meth:`project` at many states (a step's output times), as a list.

        One by one, unless a formulation projects them together.
        """
        return [self.project(t, y) for t, y in zip(times, states, strict=True)]

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        """Loop-closure residuals of a state: position (m) and velocity (m/s)."""
        return 0.0, 0.0

    def constraint_residuals(self, times: Sequence[float] | NDArray[np.float64],
                             states: Sequence[NDArray[np.float64]]) -> tuple[float, float]:
        """The largest :meth:`constraint_residual` over many states: position and velocity."""
        pos = vel = 0.0
        for t, y in zip(times, states, strict=True):
            p, v = self.constraint_residual(t, y)
            pos, vel = max(pos, p), max(vel, v)
        return pos, vel

    def like_components(self) -> tuple[NDArray[np.intp], ...]:
        """Groups of the state's components that are quantities of one kind, as indices.

        Such as the links' positions, angles, velocities and rates. The integrator holds no
        component of a group to an absolute error below the rounding of the group's largest
        (:func:`balancer.simulation.stepper.floored_atol`): a component that is zero for the
        motion (the velocity of a frame pinned at its origin) is computed from the others to
        their rounding, and a tolerance below that makes the steps shrink to the noise. None by
        default (each component is its own kind).
        """
        return ()

    def extra_power(self, t: float, y: NDArray[np.float64]) -> float:
        """Power of the loads whose work is not a function of the configuration, W.

        Such as a force that depends on the crank angle. The driver integrates it with the
        motion (:mod:`balancer.simulation`); constant loads and gravity need none (their work is
        in :meth:`energy`), nor the motor (its work is a state of the driven formulations).
        """
        return 0.0

    def motor_work(self, y: NDArray[np.float64]) -> float:
        """Work done by the motor since t = 0, J (zero in free motion)."""
        return float(y[-1]) if self.driven else 0.0
