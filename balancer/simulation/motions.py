"""Forward dynamics of a linkage with several inputs: driven along a motion, or free.

DESIGN.md, "Mechanisms with several inputs". Two formulations, which must agree:

- ``multibody`` — absolute coordinates ``q`` of every link's frame with the constraints'
  multipliers (:class:`~balancer.formulations.multibody.Multibody`; Nikravesh 1988, ch. 11):
  ``M(q)·q̈ + Φ_qᵀ·λ = Q(q, q̇)``, ``Φ_q·q̈ = γ``. Driven, each input has a driver whose ``γ``
  is its prescribed acceleration, and the multipliers give the forces on the frame and each
  motor's torque; free, the drivers are left out and the state ``(q, q̇)`` is integrated
  (DOP853) and projected back onto the constraints after every step.
- ``input-coordinates`` — the inputs' own coordinates ``θ`` (n of them): the linkage core's
  position, rate and inverse-dynamics analysis group by group
  (:func:`balancer.linkage.dynamics.inverse_dynamics`, the route the analysis and the balancing
  use). The motors' torques are affine in the inputs' accelerations, ``τ = M(θ)·θ̈ + h(θ, θ̇)``
  (Lagrange's equations in the inputs, the several-input form of the crank-angle
  formulation's ``m(θ1)·θ̈1``): free, ``θ̈ = −M⁻¹·h``, with ``h`` the torques at ``θ̈ = 0``
  and ``M``'s columns the torques at unit accelerations and rest without gravity or loads.

A driven motion is prescribed: both formulations evaluate their equations at the motion's
states (the links' coordinates from the core's position and rate analysis, on the
constraints); what is integrated is the motors' work ``∫ Σ τ_i·θ̇_i dt``, by adaptive
Gauss–Kronrod quadrature to the tolerances (:mod:`.quadrature`), its integrand evaluated at
whatever times the quadrature asks (inverse kinematics for a point's path). The energy
balance ``T − T0 = W_config + W_motors`` (:attr:`MotionRun.energy_error`) then checks each
formulation's torques against its kinetic energy — the multibody's ``q̇ᵀ·M·q̇/2``, the core's
from each link's velocity, rate and mass properties — and the work of the loads, gravity and
springs, a function of the configuration. A free run's balance ``T − T0 = W_config`` is a first
integral of the integrated system: it measures the integration.
"""

from __future__ import annotations

import time as _time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from ..columns import Columns
from ..errors import AssemblyError, SolverError, SpecError
from ..formulations.compiled import configuration_work
from ..formulations.multibody import Multibody
from ..linkage import rotors, trajectory
from ..linkage.constraints import GROUND_INDEX, Pose
from ..linkage.inputs import InputState
from ..linkage.kinematics import Motion
from ..linkage.loads import Reactions
from ..linkage.vectors import V
from ..mechanisms import Mechanism, mechanism_of
from ..mechanisms.formulation import continuous_angles
from ..model import MechanismModel
from ..model.motions import MotionSpec
from ..motion_analysis import Load, frame_loads, motion_columns
from .integrator import DOP853, CompiledDOP853, DenseOutput, Stages
from .quadrature import cumulative
from .stepper import MAX_STEPS, STALL_WINDOW, floored_atol

#: The formulations of a linkage with several inputs, the default (the check's) first.
METHODS = ("multibody", "input-coordinates")
Method = Literal["multibody", "input-coordinates"]
#: What drives a run: every input along a motion, or nothing (free from a state).
Drive = Literal["motion", "free"]


@dataclass(frozen=True, eq=False)
class MotionRun:
    """A simulated motion of a linkage with several inputs.

    Attributes
    ----------
    mechanism
        The simulated mechanism.
    method
        The formulation (one of :data:`METHODS`).
    drive
        ``"motion"`` (every input prescribed along :attr:`motion`) or ``"free"``.
    motion
        The motion's name (driven), or ``None``.
    t
        Output times, s.
    state
        The inputs' angles (rad, the driven links' frame angles), rates (rad/s) and
        accelerations (rad/s²) at those times.
    reactions
        The loads on the frame there (each motor's torque zero in free motion).
    kinetic_energy, work
        The kinetic energy (J) and the work since ``t[0]`` of the loads, gravity, springs and
        motors (J).
    energy_error
        ``max|T − T0 − W|`` relative to the energy's scale (the largest of ``T``, ``|W|`` and
        what gravity and the loads could exchange over the linkage's size).
    drift
        The largest constraint residual of position (m) and velocity (m/s) before projection
        (a free multibody run; zeros otherwise).
    evaluations
        The equations' evaluations: the integrator's (free) or the quadrature's (driven).
    steps
        The integrator's accepted steps (free), or the quadrature's panels (driven): what
        the run's error grows with.
    rtol, atol
        The tolerances of the integration or quadrature.
    """

    mechanism: Mechanism
    method: str
    drive: Drive
    motion: str | None
    t: NDArray[np.float64]
    state: InputState
    reactions: Reactions
    kinetic_energy: NDArray[np.float64]
    work: NDArray[np.float64]
    energy_error: float
    drift: tuple[float, float]
    evaluations: int
    rtol: float
    atol: float
    steps: int = 0

    @property
    def inputs(self) -> tuple[str, ...]:
        """The inputs' names, in the mechanism's order."""
        return self.mechanism.linkage.inputs

    @property
    def changes(self) -> tuple[NDArray[np.float64], ...]:
        """Each input's change from the reference pose, rad (m along a slide)."""
        s = self.mechanism.structure
        return tuple(np.asarray(p, dtype=float) - ref
                     for p, ref in zip(self.state.positions, s.input_references, strict=True))

    def columns(self) -> tuple[list[str], Columns]:
        """The columns of ``simulate --out``: those of ``analyze --csv`` along a motion."""
        return motion_columns(self.mechanism, self.t, self.changes, self.reactions)

    def loads(self) -> dict[str, Load]:
        """RMS and maximum of each frame load over the output times (:func:`frame_loads`)."""
        return frame_loads(self.inputs, self.reactions)

    @property
    def largest_reaction(self) -> float:
        """The largest force at one ground point or guide over the run, N."""
        return self.reactions.largest_force()


def _multibody(mech: Mechanism, gravity: tuple[float, float], prescribed: bool) -> Multibody:
    """The multibody formulation (drivers prescribed, or none), built once per mechanism."""
    cache = mech.structure.cache.setdefault("formulations", {})
    key = ("multibody-inputs", complex(*gravity), prescribed)
    if key not in cache:
        cache[key] = Multibody(mech, gravity=gravity, prescribed=prescribed)
    formulation: Multibody = cache[key]
    return formulation


def _core_energies(mech: Mechanism, mo: Motion, t: NDArray[np.float64],
                   gravity: tuple[float, float]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Kinetic energy and the configuration's work since the first state, from the core, J.

    Per link, with ``v`` its frame origin's velocity, ``ω`` its rate, ``S̄`` its first moment
    about the origin (turned with it) and ``J_O`` its inertia there (a counter-rotor's added):
    ``T = m·|v|²/2 + ω·(S̄ × v) + J_O·ω²/2``. The work is the configuration's (loads,
    gravity and springs, functions of the configuration:
    :func:`~balancer.formulations.compiled.configuration_work`).
    """
    kinetic: NDArray[np.float64] = np.zeros(mo.count)
    for k, link in enumerate(mech.linkage.links):
        _, me, mf, j = link.inertial_parameters
        c, s = mo.pose.cos[k], mo.pose.sin[k]
        first_x, first_y = me * c - mf * s, me * s + mf * c
        v, w = mo.velocity[k], np.asarray(mo.rate[k], dtype=float)
        j_origin = j + rotors.link_inertia(link.counter_rotor)
        kinetic = kinetic + np.ravel(0.5 * link.mass * (v.x**2 + v.y**2)
                                     + w * (first_x * v.y - first_y * v.x)
                                     + 0.5 * j_origin * w**2)
    count = mo.count
    angles = _continuous(np.array([np.broadcast_to(np.asarray(a, float), (count,))
                                   for a in mo.pose.angles]).T,
                         np.array([np.broadcast_to(np.asarray(w, float), (count,))
                                   for w in mo.rate]).T, t).T
    pose = Pose(list(mo.pose.origins), list(angles), list(mo.pose.cos), list(mo.pose.sin))
    work = configuration_work(mech, gravity, pose, angles)
    return kinetic, work


def _energy_floor(mech: Mechanism, duration: float) -> float:
    """The rounding of the linkage's energies over a run, J: ``10³·ε·M·L²/T²``.

    ``M`` its moving mass, ``L`` its size, ``T`` the run's duration: what a motion across the
    linkage in that time would exchange, to rounding.
    """
    mass = sum(link.mass for link in mech.linkage.links)
    size = mech.structure.length_scale()
    return max(1e3 * float(np.finfo(float).eps) * mass * size**2 / duration**2, 1e-300)


def _energy_error(kinetic: NDArray[np.float64], config: NDArray[np.float64],
                  motors: NDArray[np.float64], floor: float = 1e-300) -> float:
    """``max|T − T0 − W|`` over the energy the run exchanges, relative.

    ``W`` the configuration's work (loads, gravity, springs) and the motors'; the scale the
    largest of the kinetic energy, of either work's swing over the run — what moves, not what
    gravity could exchange over the linkage's size, which would hide an error in the torques
    of a heavy robot's slow motion.
    """
    def swing(x: NDArray[np.float64]) -> float:
        return float(np.max(x) - np.min(x)) if x.size else 0.0

    scale = max(float(np.max(np.abs(kinetic))), swing(config), swing(motors), floor)
    return float(np.max(np.abs(kinetic - kinetic[0] - config - motors)) / scale)


def _checked(run: MotionRun) -> MotionRun:
    """``run``, or :class:`SolverError` where its energy balance fails (:data:`ENERGY_FAILURE`).

    Its formulation's loads do not account for its motion: samples too coarse for the
    motion (a turn between two), or a singular pose passed.
    """
    if not run.energy_error <= ENERGY_FAILURE:
        what = f"along motion {run.motion}" if run.motion else "in free motion"
        raise SolverError(
            f"the energy balance of the {run.method} formulation {what} fails by "
            f"{run.energy_error:.2g} of the energy exchanged: its samples are too coarse for "
            "the motion (take more), or it passes a singular pose")
    return run


#: Energy error (relative, :attr:`MotionRun.energy_error`) beyond which a run has failed: a
#: tenth of the energy unaccounted for (the one-input simulation's threshold).
ENERGY_FAILURE = 0.1


def _continuous(angles: NDArray[np.float64], rates: NDArray[np.float64],
                t: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angles ``(count, n)`` continuous over the times ``t`` from their values modulo 2π.

    Each step takes the turn nearest its rates' trapezoidal prediction
    (:func:`~balancer.mechanisms.formulation.continuous_angles`): a link may turn more than
    half a turn between two samples.
    """
    return np.column_stack([continuous_angles(angles[:, k], rates[:, k], t)
                            for k in range(angles.shape[1])]) if angles.size else angles


# -- driven along a motion ----------------------------------------------------------------------


def _driven_loads(mech: Mechanism, method: str, state: InputState,
                  gravity: tuple[float, float]) -> tuple[Reactions, Motion | None,
                                                         NDArray[np.float64] | None]:
    """The frame's loads at prescribed states in one formulation.

    Also the core's motion (input coordinates) or the multibody's ``(q, q̇)`` stacked, for the
    energies.
    """
    if method == "multibody":
        solved = _multibody(mech, gravity, True).prescribed_dynamics(state)
        with np.errstate(all="ignore"):
            couple = mech.rocking_couple(mech.motion_at(state), gravity=gravity)
        reactions = replace(solved.reactions, rocking_couple=np.ravel(couple.complex()))
        return reactions, None, np.hstack([solved.q, solved.qd])
    with np.errstate(all="ignore"):
        mo = mech.motion_at(state)
        forces = mech.inverse_dynamics(mo, gravity=gravity)
        couple = mech.rocking_couple(mo, gravity=gravity)
    return Reactions.of(replace(forces, rocking_couple=couple)), mo, None


def _power(mech: Mechanism, method: str, spec: MotionSpec, gravity: tuple[float, float]
           ) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
    """The motors' power ``Σ τ_i·θ̇_i`` at any times of the motion, W (a column)."""
    structure = mech.structure

    def power(t: NDArray[np.float64]) -> NDArray[np.float64]:
        state = trajectory.input_state(structure, spec, t)
        torques: tuple[Any, ...]
        if method == "multibody":  # (the torques alone: no rocking couple, no record)
            torques = _multibody(mech, gravity, True).prescribed_dynamics(state).reactions.torques
        else:
            with np.errstate(all="ignore"):
                torques = mech.inverse_dynamics(mech.motion_at(state),
                                                gravity=gravity).input_torques
        total = sum(np.ravel(tau) * np.asarray(rate)
                    for tau, rate in zip(torques, state.rates, strict=True))
        return np.asarray(total, dtype=float).reshape(-1, 1)

    return power


def simulate_along(model: MechanismModel | Mechanism, spec: MotionSpec, *,
                   method: str = "multibody", gravity: tuple[float, float] = (0.0, 0.0),
                   rtol: float = 1e-10, atol: float = 1e-12) -> MotionRun:
    """Every input driven along ``spec`` (module docstring), at the motion's samples.

    ``rtol``, ``atol``: the quadrature's of the motors' work (``atol`` in J).

    Raises
    ------
    SpecError
        If the method is not one of :data:`METHODS`, or the motion does not fit the linkage.
    AssemblyError
        If a point's path leaves the workspace.
    SolverError
        If the multibody equations are singular at a state (a singular pose), or the
        quadrature does not converge.
    """
    mech = model if isinstance(model, Mechanism) else mechanism_of(model)
    _check_method(method)
    t = trajectory.sample_times(spec)
    state = trajectory.input_state(mech.structure, spec)
    reactions, mo, qs = _driven_loads(mech, method, state, gravity)
    if qs is not None:
        n = qs.shape[1] // 2
        q, qd = qs[:, :n].copy(), qs[:, n:]
        q[:, 2::3] = _continuous(q[:, 2::3], qd[:, 2::3], t)
        kinetic, config = _multibody(mech, gravity, True).energies(q, qd)
    else:
        assert mo is not None
        kinetic, config = _core_energies(mech, mo, t, gravity)
    # The work's absolute tolerance at most rtol of the energy the motion exchanges (a light
    # robot's joules are few: atol alone would be its whole error).
    exchanged = max(float(np.max(np.abs(kinetic))), float(np.ptp(config)), 1e-300)
    # ... and at least the rounding of the linkage's energies (a motion of a picometre
    # exchanges energy below it: its power is rounding, its work 0 to that).
    floor = _energy_floor(mech, spec.duration)
    motors = cumulative(_power(mech, method, spec, gravity), t, rtol=rtol,
                        atol=max(min(atol, rtol * exchanged), floor),
                        breaks=trajectory.break_times(spec).tolist())
    return _checked(MotionRun(
        mechanism=mech, method=method, drive="motion", motion=spec.name, t=t, state=state,
        reactions=reactions, kinetic_energy=kinetic, work=config + motors.values[:, 0],
        energy_error=_energy_error(kinetic, config, motors.values[:, 0], floor),
        drift=(0.0, 0.0),
        evaluations=motors.evaluations, rtol=rtol, atol=atol, steps=motors.panels))


def _check_method(method: str) -> None:
    if method not in METHODS:
        raise SpecError(f"a linkage with several inputs has no such formulation; choose from "
                        f"{', '.join(METHODS)}", key="method", value=method)


# -- free motion --------------------------------------------------------------------------------


def _inputs_of(mech: Mechanism, q: NDArray[np.float64], qd: NDArray[np.float64],
               qdd: NDArray[np.float64]) -> InputState:
    """The inputs' positions, rates and accelerations at the links' coordinates ``(N, 3n)``.

    Each driver's position at the pose, its Jacobian row times the rates, and times the
    accelerations less its ``γ`` without a prescribed acceleration (an angle's: θ, θ̇, θ̈; a
    slide's: the place, speed and acceleration along it).
    """
    n = mech.structure.size
    pose = Pose([V(q[:, 3 * k], q[:, 3 * k + 1]) for k in range(n)],
                [q[:, 3 * k + 2] for k in range(n)])
    vel = [V(qd[:, 3 * k], qd[:, 3 * k + 1]) for k in range(n)]
    rate = [qd[:, 3 * k + 2] for k in range(n)]
    positions, rates, accelerations = [], [], []
    for d in mech.structure.drivers:
        row = [(k, c[0]) for k, c in d.jacobian(pose) if k != GROUND_INDEX]
        positions.append(np.asarray(d.position(pose), dtype=float))
        rates.append(sum(c[0] * qd[:, 3 * k] + c[1] * qd[:, 3 * k + 1] + c[2] * qd[:, 3 * k + 2]
                         for k, c in row))
        accelerations.append(sum(c[0] * qdd[:, 3 * k] + c[1] * qdd[:, 3 * k + 1]
                                 + c[2] * qdd[:, 3 * k + 2] for k, c in row)
                             - d.gamma(pose, vel, rate)[0])
    return InputState.of(positions, rates, accelerations)


def _free_multibody(mech: Mechanism, f: Multibody, t: NDArray[np.float64],
                    ys: NDArray[np.float64], gravity: tuple[float, float]
                    ) -> tuple[InputState, Reactions, NDArray[np.float64], NDArray[np.float64]]:
    """A free multibody run's inputs, loads on the frame and energies at its output states."""
    solved = f.free_dynamics(t, ys)  # (one compiled call for every output state)
    state = _inputs_of(mech, solved.q, solved.qd, solved.qdd)
    with np.errstate(all="ignore"):
        couple = mech.rocking_couple(mech.motion_at(state), gravity=gravity)
    reactions = replace(solved.reactions, rocking_couple=np.ravel(couple.complex()))
    kinetic, work = f.energies(solved.q, solved.qd)  # (its angles integrated: continuous)
    return state, reactions, kinetic, work


class _InputCoordinates:
    """Lagrange's equations in the inputs' coordinates from the core's inverse dynamics."""

    def __init__(self, mech: Mechanism, gravity: tuple[float, float]) -> None:
        self.mech = mech
        self.gravity = gravity
        self.n = len(mech.structure.inputs)
        #: The unit accelerations, one state per input (M's columns).
        self.unit = np.eye(self.n)

    def accelerations(self, theta: NDArray[np.float64], omega: NDArray[np.float64]
                      ) -> NDArray[np.float64]:
        """``θ̈ = −M(θ)⁻¹·h(θ, θ̇)``, rad/s² (no motor acts).

        The torques at ``n + 1`` states of the same positions and rates, with the loads and
        gravity: ``h`` at no acceleration, ``M``'s column ``i`` at a unit acceleration of
        input ``i`` less ``h`` (what depends on the configuration alone — springs, slider
        forces — cancels).
        """
        n = self.n
        state = InputState.of([np.full(n + 1, x) for x in theta],
                              [np.full(n + 1, w) for w in omega],
                              list(np.vstack([np.zeros(n), self.unit]).T))
        with np.errstate(all="ignore"):
            torques = self.mech.inverse_dynamics(self.mech.motion_at(state),
                                                 gravity=self.gravity).input_torques
        at = np.array([np.ravel(x) for x in torques])  # row i: input i's torque at each state
        h = at[:, 0]
        mass = at[:, 1:] - h[:, None]  # column j: the torques per unit acceleration of j
        if not (np.all(np.isfinite(mass)) and np.all(np.isfinite(h))):
            return np.full(self.n, np.nan)  # (a trial stage where it does not assemble)
        try:
            return np.asarray(np.linalg.solve(mass, -h), dtype=float)
        except np.linalg.LinAlgError:  # a singular pose: the step is refused and shortened
            return np.full(self.n, np.nan)

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        n = self.n
        return np.concatenate([y[n:], self.accelerations(y[:n], y[n:])])


def _integrate(rhs: Callable[[float, NDArray[np.float64]], NDArray[np.float64]],
               y0: NDArray[np.float64], t_out: NDArray[np.float64], *, rtol: float, atol: float,
               stages: Stages | None = None,
               project: Callable[[float, NDArray[np.float64]], NDArray[np.float64]] | None = None,
               residual: Callable[[float, NDArray[np.float64]], tuple[float, float]] | None = None,
               groups: tuple[NDArray[np.intp], ...] = (), max_seconds: float | None = None,
               ) -> tuple[NDArray[np.float64], tuple[float, float], int, int]:
    """DOP853 from ``y0`` at ``t_out[0] = 0``: the states at ``t_out``, drift, evaluations, steps.

    After each step a non-minimal state is projected (``project``) and its residual before
    (``residual``) kept; the outputs come from each step's dense output.
    """
    duration = float(t_out[-1])
    tol = floored_atol(atol, groups, y0)
    solver: DOP853 = (DOP853(rhs, 0.0, y0, duration, rtol=rtol, atol=tol) if stages is None
                      else CompiledDOP853(rhs, 0.0, y0, duration, stages=stages, rtol=rtol,
                                          atol=tol))
    out = np.empty((t_out.size, y0.size))
    out[0] = y0
    k, steps, drift = 1, 0, (0.0, 0.0)
    started = _time.perf_counter()
    recent: deque[float] = deque([0.0], maxlen=STALL_WINDOW + 1)
    while solver.status == "running" and k < t_out.size:
        message = solver.step()
        if solver.status == "failed":
            raise SolverError(f"the integrator failed at t = {solver.t:.6g} s: {message}")
        steps += 1
        recent.append(solver.t)
        if len(recent) > STALL_WINDOW:  # (the steps shrink without end: a singular pose)
            advance, remaining = recent[-1] - recent[0], duration - solver.t
            if remaining > 0 and advance * MAX_STEPS < remaining * STALL_WINDOW:
                raise SolverError(
                    f"the free motion stalled at t = {solver.t:.6g} s: its last "
                    f"{STALL_WINDOW} steps advanced {advance:.3g} s, near a singular pose "
                    "(the input coordinates cannot pass one; the multibody formulation can), "
                    "or with loads far stiffer than the motion")
        if steps > MAX_STEPS:
            raise SolverError(f"the free motion needed more than {MAX_STEPS:.0e} steps by "
                              f"t = {solver.t:.6g} s (a near-singular pose?)")
        if max_seconds is not None and _time.perf_counter() - started > max_seconds:
            raise SolverError(f"the free motion took more than {max_seconds:g} s to reach "
                              f"t = {solver.t:.6g} s: its steps shrink near a singular pose "
                              "(the input coordinates cannot pass one; the multibody "
                              "formulation can), or its loads are far stiffer than the motion")
        dense: DenseOutput | None = None
        end = k
        while end < t_out.size and t_out[end] <= solver.t + 1e-14 * max(1.0, solver.t):
            end += 1
        if end > k:
            dense = solver.dense_output()
            out[k:end] = dense(np.minimum(t_out[k:end], solver.t)).T
            k = end
        if project is not None:
            assert residual is not None
            res = residual(solver.t, solver.y)
            drift = (max(drift[0], res[0]), max(drift[1], res[1]))
            solver.y = project(solver.t, solver.y)
            solver.f = rhs(solver.t, solver.y)
        if groups:
            solver.atol = floored_atol(atol, groups, solver.y)
    if project is not None:
        out[1:] = np.array([project(float(t), y) for t, y in zip(t_out[1:], out[1:],
                                                                  strict=True)])
    return out, drift, solver.nfev, steps


def simulate_free(model: MechanismModel | Mechanism, start: InputState, duration: float, *,
                  method: str = "multibody", gravity: tuple[float, float] = (0.0, 0.0),
                  outputs: int = 201, rtol: float = 1e-10, atol: float = 1e-12,
                  max_seconds: float | None = None) -> MotionRun:
    """Free motion from the inputs' positions and rates in ``start`` (one state), no motor.

    Raises
    ------
    SpecError
        If the method is not one of :data:`METHODS`, or the duration or outputs are not
        positive.
    AssemblyError
        If the linkage does not assemble at the start.
    SolverError
        If the integration fails (a singular pose on the way).
    """
    mech = model if isinstance(model, Mechanism) else mechanism_of(model)
    _check_method(method)
    if not duration > 0:
        raise SpecError("must be more than 0 s", key="simulation.duration", value=duration)
    if outputs < 2:
        raise SpecError("must be at least 2", key="simulation.outputs", value=outputs)
    t = np.linspace(0.0, duration, outputs)
    with np.errstate(all="ignore"):
        mo0 = mech.motion_at(start)
    f = _multibody(mech, gravity, False)
    q0, qd0 = f.coordinates(mo0, 1)
    if not (np.all(np.isfinite(q0)) and np.all(np.isfinite(qd0))):
        raise AssemblyError("the linkage cannot be assembled at the initial state",
                            key="simulation.start", value=[float(np.ravel(p)[0])
                                                           for p in start.positions])
    if method == "multibody":
        stages = f.compiled.get("dop853 free")
        if stages is None and "dop853 free" not in f.compiled:
            symbolic = f.symbolic_rhs()
            stages = f.compiled["dop853 free"] = None if symbolic is None else Stages(symbolic)
        ys, drift, evaluations, steps = _integrate(
            f.rhs, np.concatenate([q0[0], qd0[0]]), t, rtol=rtol, atol=atol, stages=stages,
            project=f.project, residual=f.constraint_residual, groups=f.like_components(),
            max_seconds=max_seconds)
        state, reactions, kinetic, work = _free_multibody(mech, f, t, ys, gravity)
    else:
        n = len(mech.structure.inputs)
        system = _InputCoordinates(mech, gravity)
        y0 = np.array([*(float(np.ravel(p)[0]) for p in start.positions),
                       *(float(np.ravel(r)[0]) for r in start.rates)])
        ys, drift, evaluations, steps = _integrate(system.rhs, y0, t, rtol=rtol, atol=atol,
                                                   max_seconds=max_seconds)
        theta, omega = ys[:, :n].T, ys[:, n:].T
        alpha = np.array([system.accelerations(th, om)
                          for th, om in zip(theta.T, omega.T, strict=True)]).T
        state = InputState.of(list(theta), list(omega), list(alpha))
        reactions, mo, _ = _driven_loads(mech, method, state, gravity)
        assert mo is not None
        kinetic, work = _core_energies(mech, mo, t, gravity)
    return _checked(MotionRun(
        mechanism=mech, method=method, drive="free", motion=None, t=t, state=state,
        reactions=reactions, kinetic_energy=kinetic, work=work,
        energy_error=_energy_error(kinetic, work, np.zeros_like(work),
                                   _energy_floor(mech, duration)), drift=drift,
        evaluations=evaluations, rtol=rtol, atol=atol, steps=steps))
