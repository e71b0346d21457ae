"""Forward dynamics: integrate a formulation, project, detect events, report what happened.

The integrator is the explicit Runge–Kutta method of order 8, DOP853 (:mod:`.integrator`),
stepped by hand so that after every accepted step the non-minimal formulations' states are
projected back onto the loop closure and its derivative (the drift before projection is
reported). Output values come from the step's dense output, all those within a step in one
evaluation, at equally spaced times; they are projected in the same way, all together at the
end of the run. No component is held to an
absolute error below 100 ε of the largest of its kind (:func:`floored_atol`).

Events:

- a formulation whose coordinate is the crank angle (``complex-masses``, ``lie-group``) cannot
  pass a dead point of the crank, where coupler and rocker align: the simulation stops there
  with a :class:`~balancer.errors.LockupError` that names the time and the crank angle (the
  ``opened-loop`` and ``mass-matrix`` formulations pass through such points);
- the change points of a change-point linkage (all joints collinear) are passed on the smooth
  motion by every formulation;
- a crank driven at constant speed that would leave the range where the linkage assembles locks
  the linkage: the simulation stops there.

Energy: the kinetic energy change must equal the work of the loads, of gravity and of the motor.
The loads are constant forces at the centres of mass and constant moments, so their work is a
function of the configuration, ``W = Σ F̄k·(r̄k − r̄k0) + Mk·(θk − θk0)``; the motor's work and
the work of a force that depends on the crank angle (a gas force) are integrated with the state:
the driver appends one component ``W_extra`` with ``Ẇ_extra`` =
:meth:`~balancer.formulations.Formulation.extra_power`. ``T − T0 − W`` is then a first integral
of the integrated system, which the integrator keeps to its tolerance: the reported
:attr:`Trajectory.energy_error` is a check of the integration, at no extra cost.

A driven crank's motion is prescribed. A formulation whose coordinate is the crank angle
(``complex-masses``) then has nothing to integrate but the work, a function of the time alone:
it is found by adaptive Gauss–Kronrod quadrature of the vectorised power at the output times
(:mod:`.quadrature`, to the same tolerances), and the energy balance checks the driving
torque of the formulation against its kinetic energy and the loads' work. Where the power is not
vectorised, or the motion comes near a dead point, the integrator steps as for any motion.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import AssemblyError, LockupError, SolverError, SpecError
from ..formulations import (
    DEAD_POINT_THRESHOLD,
    Formulation,
    default_method,
    formulation_class,
    make,
)
from ..mechanisms import mechanism_of
from ..model import Design, Drive, SimulationSettings, check_scales
from ..model import MechanismModel as Model
from ..rounding import speed_text
from .stepper import MAX_OUTPUTS, MAX_STEPS, Stepper, passing
from .trajectory import Trajectory, trajectory_of

#: Energy error (relative to the energy's scale, :attr:`Trajectory.energy_error`) beyond which
#: an integration has failed, whatever its tolerances: a tenth of the energy unaccounted for.
ENERGY_FAILURE = 0.1
#: Distance (rad) from a change point within which a motion cannot start: √ε, where the
#: rates of the dependent links are lost to rounding (they are 0/0 at the change point).
CHANGE_POINT_MARGIN = 1.5e-8


def _check_start(f: Formulation, theta1: float) -> None:
    rng = f.assembly_range()
    if not rng.contains(theta1):
        raise AssemblyError(
            f"the linkage cannot be assembled at the initial crank angle; it assembles for θ1 "
            f"in {rng.describe()}",
            key="simulation.theta1",
            value=theta1,
        )
    for point in f.change_points():
        if abs(math.remainder(theta1 - point, 2 * math.pi)) < CHANGE_POINT_MARGIN:
            raise SpecError(
                f"is a change point of the linkage (θ1 = {point:.6g} rad: all joints in line), "
                "where the rates of coupler and rocker are not determined by the crank's; "
                f"start at least {CHANGE_POINT_MARGIN:g} rad away from it",
                key="simulation.theta1", value=theta1)


def _lock_time(f: Formulation, theta1: float, speed: float, duration: float) -> float | None:
    """First time a crank driven at ``speed`` leaves the assembly range, or None."""
    rng = f.assembly_range()
    if rng.full or speed == 0:
        return None
    for a, b in rng.intervals:
        # Bring θ1 into the interval's own 2π window.
        w = a + math.fmod(theta1 - a, 2 * math.pi) % (2 * math.pi)
        if a - 1e-12 <= w <= b + 1e-12:
            end = b if speed > 0 else a
            t_lock = (end - w) / speed
            return t_lock if t_lock <= duration else None
    return None


@dataclass(frozen=True, eq=False)
class _Setup:
    """A simulation's checked settings and formulation, before any integration."""

    f: Formulation
    settings: SimulationSettings
    y0: NDArray[np.float64]
    #: The output times' number (more for a driven crank at a resolution).
    outputs: int
    #: When a driven crank reaches the end of its assembly range, s (``None``: never).
    stop_at: float | None
    #: Where the run ends before that lock, s (``None``: at its duration).
    end: float | None


def _prepare(linkage: Model, settings: SimulationSettings, *,
             resolution: float | None = None, **overrides: Any) -> _Setup:
    """The settings with the overrides, checked, and the formulation at its initial state.

    Raises :class:`SpecError` for what :func:`simulate` refuses before it integrates (bad
    settings, forces beyond double precision, a start where the linkage does not assemble).
    """
    # The settings with the overrides, checked as a spec's would be (SimulationSettings).
    settings = replace(settings, **{k: x for k, x in overrides.items() if x is not None})
    method = settings.method or default_method(linkage)
    drive, duration, outputs = settings.drive, settings.duration, settings.outputs
    formulation_class(method, linkage)  # a SpecError naming those that apply, if none
    theta1, omega1 = settings.theta1, settings.omega1
    if theta1 is None:
        theta1 = mechanism_of(linkage).start_angle
    check_scales(linkage, {"simulation.omega1": omega1},
                 {"simulation.gravity": settings.gravity})
    speed = None
    if drive == "constant-speed":
        if omega1 == 0:
            raise SpecError("a crank driven at constant speed needs a non-zero speed: give it "
                            "here or as the operating speed [operation] speed",
                            key="simulation.omega1", value=omega1)
        speed = omega1
    f = make(method, linkage, gravity=settings.gravity, speed=speed)
    _check_start(f, theta1)
    stop_at = None if speed is None else _lock_time(f, theta1, speed, duration)
    y0 = f.initial_state(theta1, omega1)
    if not np.all(np.isfinite(y0)):  # the pose assembles, its rates are not determined
        raise SpecError(f"is a singular pose of the linkage (θ1 = {theta1:.9g} rad: a dead "
                        "point, where the crank's rate does not determine the others'); start "
                        "the motion elsewhere", key="simulation.theta1", value=theta1)
    if resolution is not None and speed is not None:  # the crank's prescribed turning
        need = math.ceil(abs(speed) * duration / resolution) + 1
        outputs = min(MAX_OUTPUTS, max(outputs, need))
    # A driven crank that locks: integrate up to just before the dead point, where the torque
    # it would need grows without bound.
    end = None if stop_at is None else _before_lock(f, stop_at)
    return _Setup(f=f, settings=settings, y0=y0, outputs=outputs, stop_at=stop_at, end=end)


def check(linkage: Model, settings: SimulationSettings, *, resolution: float | None = None,
          **overrides: Any) -> None:
    """Raise what :func:`simulate` with these arguments would refuse before it integrates.

    Its settings, scales and start, and a driven crank's prescribed motion that would need more
    than :data:`MAX_STEPS` quadrature panels; nothing is integrated. (A run whose steps exceed
    the budget is refused from the rate of its first :data:`PROJECT_AFTER` steps, which only
    the run finds.)

    Parameters
    ----------
    linkage, settings, resolution, **overrides
        As for :func:`simulate` (``method``, ``drive``, ``duration`` in s, ``rtol``, ``atol``,
        ``outputs``).
    """
    run = _prepare(linkage, settings, resolution=resolution, **overrides)
    stepper = Stepper(run.f, run.settings.duration, run.settings.rtol, run.settings.atol,
                       run.outputs, None, resolution)
    stepper.check_up_front(run.y0, run.end)


def simulate(
    linkage: Model,
    settings: SimulationSettings,
    *,
    method: str | None = None,
    drive: Drive | None = None,
    duration: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    outputs: int | None = None,
    progress: Callable[[float, float], None] | None = None,
    resolution: float | None = None,
    max_seconds: float | None = None,
) -> Trajectory:
    """Simulate the linkage's motion.

    Parameters
    ----------
    linkage
        The mechanism (a four-bar, slider-crank or general linkage model).
    settings
        The spec's ``[simulation]`` settings; the keyword arguments override them.
    method
        Formulation (one of the mechanism's: :func:`balancer.formulations.formulation_table`).
    drive
        ``"free"`` or ``"constant-speed"`` (the crank held at ``settings.omega1``).
    duration
        Simulated time, s.
    rtol, atol
        Integrator tolerances.
    outputs
        Number of equally spaced output times.
    progress
        Called as ``progress(t, duration)`` after every step.
    resolution
        Most angle, rad, the crank may turn between two output times: more outputs than
        ``outputs`` where it turns faster (from the steps' dense outputs, at most
        :data:`MAX_OUTPUTS`).
    max_seconds
        Most wall-clock time the integration may take, s: a run that would take longer at
        the rate of its first steps is refused (``None``: only :data:`MAX_STEPS` steps).

    Raises
    ------
    SpecError
        For bad settings or an initial crank angle where the linkage does not assemble; for a
        run that would take more than :data:`MAX_STEPS` steps or ``max_seconds``.
    LockupError
        If the motion reaches a position the formulation cannot pass (its ``partial``
        attribute holds the trajectory up to there).
    """
    run = _prepare(linkage, settings, method=method, drive=drive, duration=duration,
                   rtol=rtol, atol=atol, outputs=outputs, resolution=resolution)
    f, y0, end = run.f, run.y0, run.end
    duration, rtol, atol = run.settings.duration, run.settings.rtol, run.settings.atol
    start = _time.perf_counter()
    stepper = Stepper(f, duration, rtol, atol, run.outputs, progress, resolution, max_seconds)
    with np.errstate(divide="ignore", invalid="ignore"):
        times, states, drift, nfev, steps, stopped = stepper.run(y0, end)
    traj = trajectory_of(f, times, states, drift, nfev, steps, rtol, atol,
                       _time.perf_counter() - start, guide=stepper.guide)
    if not traj.energy_error <= ENERGY_FAILURE:
        raise SolverError(
            f"the {f.name} integration lost its own energy balance (an error of "
            f"{traj.energy_error:.2g} of the energy's scale, at rtol = {rtol:g}): its results "
            "cannot be trusted; tighten rtol or choose another formulation")
    if stopped is not None:
        t_event, y_event = stopped
        th = f.theta1_of(t_event, y_event)
        raise _lockup(
            f"the motion reaches a dead point (sine of the transmission angle "
            f"below {DEAD_POINT_THRESHOLD:g}) at t = {t_event:.6g} s, θ1 = {th:.6g} rad; the "
            f"{f.name} formulation uses the crank angle as its coordinate and cannot pass it"
            + passing(linkage),
            t_event, th, traj)
    if run.stop_at is not None:
        th = f.crank_angle(run.stop_at)
        speed = f.speed or 0.0  # (a run that stops where the linkage ends is driven)
        raise _lockup(
            f"the crank, driven at {speed_text(speed)}, reaches "
            f"the end of the range where the linkage assembles at t = {run.stop_at:.6g} s, "
            f"θ1 = {th:.6g} rad: the linkage locks", run.stop_at, th, traj)
    return traj


def _before_lock(f: Formulation, t_lock: float) -> float:
    """The time before ``t_lock`` at which the prescribed motion's |sin(θ3 − θ2)| is small.

    That is, where it falls to :data:`DEAD_POINT_THRESHOLD`; a pose that does not assemble
    counts as below it. Where it is still above at ``t_lock`` (the end of the assembly range
    is known to the precision of its search, and the transmission falls as the square root of
    the distance to it), ``t_lock`` itself.
    """
    def gap(t: float) -> float:
        value = f.transmission_of_crank(f.crank_angle(t)) - DEAD_POINT_THRESHOLD
        return value if math.isfinite(value) else -1.0

    if gap(0.0) <= 0:
        return 0.0
    if gap(t_lock) > 0:
        return t_lock
    from scipy.optimize import brentq  # only for a lock (its import costs 0.3–0.5 s)

    return brentq(gap, 0.0, t_lock, xtol=1e-14)


def _lockup(message: str, t: float, theta1: float, partial: Trajectory) -> LockupError:
    err = LockupError(message, time=t, theta1=theta1)
    err.partial = partial
    return err


def simulate_design(design: Design, **overrides: Any) -> Trajectory:
    """:func:`simulate` with a design's own linkage and ``[simulation]`` settings.

    A crank driven at constant speed turns at ``[simulation] omega1`` where that is given and
    non-zero, else at the operating speed ``[operation] speed`` (a constant speed of zero is no
    motion: ``omega1 = 0`` is a free motion's start from rest).
    """
    settings = design.simulation
    drive = overrides.get("drive") or settings.drive
    if drive == "constant-speed" and settings.omega1 == 0 and design.operation is not None:
        settings = replace(settings, omega1=design.operation.speed)
    return simulate(design.mechanism, settings, **overrides)


__all__ = [
    "ENERGY_FAILURE",
    "MAX_OUTPUTS",
    "MAX_STEPS",
    "Trajectory",
    "check",
    "simulate",
    "simulate_design",
]
