"""A simulated motion (:class:`Trajectory`), assembled from a formulation's states.

The links' angles made continuous through the states between the outputs, the forces on the
frame, the shaking, the energy balance of :mod:`balancer.simulation`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..columns import Columns, simulation_columns
from ..formulations import (
    Formulation,
    continuous_angles,
)
from ..linkage.loads import Reactions
from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism, in_one_plane
from ..model import Drive
from ..model import MechanismModel as Model


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A simulated motion at equally spaced output times.

    Attributes
    ----------
    method
        Formulation used.
    drive
        ``"free"`` or ``"constant-speed"``.
    speed
        The crank's constant speed of a driven run, rad/s (``None`` in free motion).
    links
        Names of the moving links, in the order of the rows of ``theta``, ``omega``, ``alpha``.
    t
        Output times, s, shape ``(n,)``.
    theta, omega, alpha
        Link angles (rad, continuous from their initial values), angular velocities (rad/s)
        and accelerations (rad/s²), each of shape ``(links, n)``.
    reactions
        What the mechanism does to its frame at the output times: the forces at the ground
        points, the sliders' on their ground guides, the shaking force and moment, the rocking
        couple and the motor's torque on the crank (zero in free motion); each also an
        attribute of the trajectory itself (:attr:`ground`, :attr:`shaking_force`, …).
    kinetic_energy
        Kinetic energy of the moving parts, counter-rotors included, J.
    work
        Work of the loads, gravity, springs and the motor since t = 0, J.
    energy_error
        ``max|T − T0 − W|`` relative to the largest of ``|T|``, ``|W|`` and the energy the loads,
        gravity and springs could exchange over the linkage's size (dimensionless). A run
        beyond :data:`ENERGY_FAILURE` raises a :class:`~balancer.errors.SolverError`.
    drift
        Largest constraint residual before projection: position (m) and velocity (m/s).
    nfev
        Right-hand-side evaluations.
    steps
        Accepted integration steps (of a driven crank's prescribed motion whose work is found
        by quadrature: the quadrature's panels).
    seconds
        Wall-clock time of the integration and the outputs, s.
    rtol, atol
        Integrator tolerances used.
    named_states
        Whether :meth:`state` keys the links by name (a general linkage) or lists them.
    model
        The mechanism simulated.
    slider
        A formulation's own slider coordinate (the slider-crank's): position, velocity and
        acceleration along the guide, shape ``(3, n)`` (m, m/s, m/s²).
    """

    method: str
    drive: Drive
    links: tuple[str, ...]
    t: NDArray[np.float64]
    theta: NDArray[np.float64]
    omega: NDArray[np.float64]
    alpha: NDArray[np.float64]
    reactions: Reactions
    kinetic_energy: NDArray[np.float64]
    work: NDArray[np.float64]
    energy_error: float
    drift: tuple[float, float]
    nfev: int
    steps: int
    seconds: float
    rtol: float
    atol: float
    named_states: bool = False
    speed: float | None = None
    model: Model | None = field(repr=False, default=None)
    slider: NDArray[np.float64] | None = field(repr=False, default=None)

    def __repr__(self) -> str:
        return (f"Trajectory({self.method}, {self.drive}, {self.t.size} outputs over "
                f"{self.t[-1] - self.t[0]:g} s, {self.steps} steps; energy balance to "
                f"{self.energy_error:.2g})")

    @property
    def ground(self) -> dict[str, NDArray[np.complex128]]:
        """Force of the mechanism on the ground at each ground point, complex, N."""
        return self.reactions.ground

    @property
    def slider_normal(self) -> dict[str, NDArray[np.float64]]:
        """For each slider on a ground guide (by the sliding link): its normal force on it, N."""
        return self.reactions.slider_normal

    @property
    def slider_couple(self) -> dict[str, NDArray[np.float64]]:
        """For each slider on a ground guide: its couple about the slider's point, N·m."""
        return self.reactions.slider_couple

    @property
    def driving_torque(self) -> NDArray[np.float64]:
        """Motor torque on the crank, N·m (zero in free motion)."""
        return self.reactions.driving_torque

    @property
    def shaking_force(self) -> NDArray[np.complex128]:
        """Sum of the forces on the frame, complex, N."""
        return self.reactions.shaking_force

    @property
    def shaking_moment(self) -> NDArray[np.float64]:
        """Their moment about the origin with the motor's reaction and the counter-rotors', N·m."""
        return self.reactions.shaking_moment

    @property
    def rocking_couple(self) -> NDArray[np.complex128]:
        """The couple about ``x`` and ``y`` from links in planes along the crank's axis, N·m.

        Complex ``Mx + i·My``; zero for a mechanism in one plane.
        """
        return self.reactions.rocking_couple

    @property
    def largest_reaction(self) -> float:
        """Largest magnitude of any force on the frame over the run, N (0 if none).

        (A state that does not exist, NaN, makes it NaN: unlike a cycle analysis' samples at a
        change point, a simulation's are all states of its motion.)
        """
        values = [np.max(np.abs(v), initial=0.0) for v in (
            *self.ground.values(), *self.slider_normal.values())]
        return float(max(values, default=0.0))

    def columns(self, all_columns: bool = False) -> tuple[list[str], Columns]:
        """The columns of ``simulate``'s CSV: names and values over the output times.

        See :func:`balancer.columns.simulation_columns`.
        """
        return simulation_columns(self, all_columns)

    def state(self, index: int) -> dict[str, list[float] | dict[str, float]]:
        """Angles, rates and accelerations of the links at output ``index``.

        Each a list in link order, or (``named_states``) an object keyed by link name.
        """
        out: dict[str, list[float] | dict[str, float]] = {}
        for key, values in (("theta", self.theta), ("omega", self.omega),
                            ("alpha", self.alpha)):
            numbers = [float(x) + 0.0 for x in values[:, index]]
            out[key] = dict(zip(self.links, numbers, strict=True)) if self.named_states \
                else numbers
        return out


#: States between the output times: ``(times, states)``.
Guide = tuple[Sequence[float], Sequence[NDArray[np.float64]]]


def trajectory_of(f: Formulation, times: Sequence[float], states: Sequence[NDArray[np.float64]],
                  drift: Sequence[float], nfev: int, steps: int, rtol: float, atol: float,
                  seconds: float, guide: Guide | None = None) -> Trajectory:
    """The :class:`Trajectory` of formulation ``f``'s states at the output times.

    Each state carries the work integrated with it as its last component; ``drift``, ``nfev``,
    ``steps``, ``seconds``, the tolerances and ``guide`` (the states between the outputs
    through which the angles are followed) are the stepper's.
    """
    t = np.array(times)
    extra = np.array([y[-1] for y in states])
    own = [y[:-1] for y in states]
    ev = f.evaluate_batch(times, own)
    omega, alpha = np.asarray(ev.omega, float), np.asarray(ev.alpha, float)
    theta = _followed_angles(f, t, np.asarray(ev.theta, float), omega, guide)
    tau = np.asarray(ev.driving_torque, float) * np.ones(t.size)
    motor = np.array([f.motor_work(y) for y in own])
    slider = None if ev.slider is None else np.asarray(ev.slider, float)
    # Energy: T − T0 = work of loads and gravity (a function of the configuration) + motor
    # + the extra work integrated with the motion (a gas force).
    kin, work = f.energy(theta, omega, alpha, slider, states=own)
    work = work + motor + extra
    scale = max(np.max(np.abs(kin)), np.max(np.abs(work)), _exchangeable_energy(f), 1e-300)
    energy_error = float(np.max(np.abs(kin - kin[0] - work)) / scale)
    shaking_force, moment = f.shaking(ev)
    crank = list(f.link_names).index(f.mechanism.linkage.input)
    gravity = (f.gravity.real, f.gravity.imag)
    rocking = _rocking_couple(f.mechanism, theta[crank], omega[crank], alpha[crank], gravity)
    ground: dict[str, NDArray[np.complex128]] = {
        p: np.asarray(v, complex) * np.ones(t.size, complex) for p, v in ev.ground.items()}
    # (The formulations' equations carry the rotors' weights' couple on the crank.)
    geared = f.mechanism.rotor_loads(theta[crank], omega[crank], alpha[crank], gravity,
                                     weights_on_crank=True)
    if geared is not None:  # rotors geared to the crank: their bearings and what they shake
        for point, value in geared.bearings.items():
            ground[point] = ground.get(point, 0.0) + value
        shaking_force = shaking_force + geared.force
        moment = moment + geared.moment
        tau = tau + geared.torque
    return Trajectory(
        method=f.name,
        drive="constant-speed" if f.driven else "free",
        speed=f.speed,
        links=f.link_names,
        t=t,
        theta=theta,
        omega=omega,
        alpha=alpha,
        reactions=Reactions(
            ground=ground,
            slider_normal={k: np.asarray(v, float) * np.ones(t.size)
                           for k, v in ev.slider_normal.items()},
            slider_couple={k: np.asarray(v, float) * np.ones(t.size)
                           for k, v in ev.slider_couple.items()},
            torques=(tau,),
            # (numpy's stubs type a complex array times a real one as real)
            shaking_force=cast("NDArray[np.complex128]",
                               np.asarray(shaking_force, complex) * np.ones(t.size)),
            shaking_moment=np.asarray(moment, float) * np.ones(t.size),
            rocking_couple=rocking),
        kinetic_energy=kin,
        work=work,
        energy_error=energy_error,
        drift=(float(drift[0]), float(drift[1])),
        nfev=int(nfev),
        steps=int(steps),
        seconds=float(seconds),
        rtol=rtol,
        atol=atol,
        named_states=mechanism_of(f.linkage).presentation.named_states,
        model=f.linkage,
        slider=slider,
    )


def _followed_angles(f: Formulation, t: NDArray[np.float64], theta: NDArray[np.float64],
                     omega: NDArray[np.float64], guide: Guide | None) -> NDArray[np.float64]:
    """The links' angles at the output times, continuous over the motion, rad.

    Each step from one time to the next takes the 2π branch nearest to the trapezoidal
    prediction from the rates (:func:`~balancer.formulations.continuous_angles`), through the
    ``guide`` states (the integrator's steps, a prescribed motion's crank grid) that lie
    between two output times: coarse output times (a whole turn of a link apart, or more) would
    leave the prediction unable to count the turns.
    """
    if guide is not None and len(guide[0]) and t.size:
        g_t = np.asarray(guide[0], dtype=float)
        inside = (g_t > t[0]) & (g_t < t[-1]) & ~np.isin(g_t, t)
        if inside.any():
            ev = f.evaluate_batch(g_t[inside], [y[:-1] for y, keep
                                                 in zip(guide[1], inside, strict=True) if keep])
            merged = np.concatenate([t, g_t[inside]])
            order = np.argsort(merged, kind="stable")
            rank = np.empty_like(order)
            rank[order] = np.arange(order.size)
            both_theta = np.hstack([theta, np.asarray(ev.theta, float)])[:, order]
            both_omega = np.hstack([omega, np.asarray(ev.omega, float)])[:, order]
            followed = np.array([continuous_angles(row, both_omega[k], merged[order])
                                 for k, row in enumerate(both_theta)])
            return followed[:, rank[: t.size]]
    return np.array([continuous_angles(row, omega[k], t) for k, row in enumerate(theta)])


def _exchangeable_energy(f: Formulation) -> float:
    """An energy the loads, gravity and springs could exchange over the linkage's size, J.

    ``L·Σ(m·|g| + |F|) + L·Σ max|F_gas| + 2π·Σ|M| + Σ k·(L + l0)²`` with ``L`` the linkage's
    length scale and ``F_gas`` a slider's force along its guide (a gas force): the energy
    balance's scale where the motion itself exchanges almost none (a linkage at rest in
    equilibrium, whose kinetic energy and work are both rounding; a slider-crank at rest on a
    dead centre with its gas force pressing along the rod).
    """
    mech = mechanism_of(f.linkage)
    length = mech.structure.length_scale()
    g = abs(f.gravity)
    total = sum((link.mass * g + math.hypot(*link.force)) * length
                + 2 * math.pi * abs(link.moment) for link in mech.linkage.links)
    for _, gas in mech.model.gas_forces:
        total += max(abs(x) for x in gas.values) * length
    for spring in mech.linkage.springs:
        total += spring.stiffness * (length + abs(spring.free_length)) ** 2
    return float(total)


def _rocking_couple(mech: Mechanism, theta1: NDArray[np.float64], omega1: NDArray[np.float64],
                    alpha1: NDArray[np.float64], gravity: tuple[float, float]
                    ) -> NDArray[np.complex128]:
    """The rocking couple at the crank's states, complex ``Mx + i·My``, N·m (loads included).

    The pose is the crank's on the mechanism's branch; none for a mechanism in one plane.
    """
    theta1 = np.atleast_1d(np.asarray(theta1, dtype=float))
    if in_one_plane(mech):
        return np.zeros(theta1.size, complex)
    with np.errstate(all="ignore"):
        mo = mech.motion(theta1, omega1, alpha1)
    return mech.rocking_couple(mo, loads=True, gravity=gravity).complex()[:, 0]
