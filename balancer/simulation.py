"""Forward dynamics: integrate a formulation, project, detect events, report what happened.

The integrator is the explicit Runge–Kutta method of order 8, DOP853 (:mod:`.integration`),
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
(:mod:`balancer.quadrature`, to the same tolerances), and the energy balance checks the driving
torque of the formulation against its kinetic energy and the loads' work. Where the power is not
vectorised, or the motion comes near a dead point, the integrator steps as for any motion.
"""

from __future__ import annotations

import math
import time as _time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from .columns import simulation_columns
from .errors import AssemblyError, LockupError, SolverError, SpecError
from .formulations import (
    DEAD_POINT_THRESHOLD,
    Formulation,
    continuous_angles,
    default_method,
    formulation_class,
    formulation_names,
    make,
)
from .integration import DOP853, CompiledDOP853, Stages, TimeOnlyDOP853, with_extra_work
from .mechanisms import mechanism_of
from .model import RTOL_MIN, Design, SimulationSettings, check_scales
from .quadrature import cumulative

#: Most integration steps a simulation may take (under a minute with the slowest formulation,
#: multibody with its projections, at some 2 000 steps a second on a 2-core machine): a
#: duration that needs more is refused, from the rate of its first steps.
MAX_STEPS = 100_000
#: Steps after which the rate is extrapolated to the whole duration.
PROJECT_AFTER = 200
#: Energy error (relative to the energy's scale, :attr:`Trajectory.energy_error`) beyond which
#: an integration has failed, whatever its tolerances: a tenth of the energy unaccounted for.
ENERGY_FAILURE = 0.1
#: Distance in θ1 from a change point, rad, within which a motion is near it (passable by
#: a dead-point event, named as the cause of a stall).
CHANGE_POINT_NEAR = 0.05
#: Largest angle, rad, the crank turns over one quadrature panel of a driven motion's work
#: (:meth:`_Stepper._prescribed`): a sixteenth of a revolution, so that the panels resolve the
#: power's harmonics and the Gauss and Kronrod rules cannot agree on a wrong value.
PANEL_ANGLE = math.pi / 8
#: Largest crank angle, rad, between two states through which a prescribed motion's angles
#: are followed from one output time to the next (a link turns a few times that at most).
GUIDE_ANGLE = 0.1
#: Most output times of a run that resamples its outputs to a resolution.
MAX_OUTPUTS = 100_000
#: Steps over which the recent rate is judged: a run whose last ``STALL_WINDOW`` steps would
#: need more than :data:`MAX_STEPS` more to finish has stalled (near-singular motion).
STALL_WINDOW = 1000


@dataclass(frozen=True)
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
    ground
        Force of the mechanism on the ground at each ground point, complex, N.
    slider_normal, slider_couple
        For each slider on a ground guide (keyed by the sliding link): the normal force on the
        guide (N) and its couple about the slider's point (N·m).
    driving_torque
        Motor torque on the crank, N·m (zero in free motion).
    shaking_force, shaking_moment
        Sum of the forces on the frame (N) and their moment about the origin with the motor's
        reaction and the counter-rotors' (N·m).
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
    drive: str
    links: tuple[str, ...]
    t: NDArray[np.float64]
    theta: NDArray[np.float64]
    omega: NDArray[np.float64]
    alpha: NDArray[np.float64]
    ground: dict[str, NDArray[np.complex128]]
    slider_normal: dict[str, NDArray[np.float64]]
    slider_couple: dict[str, NDArray[np.float64]]
    driving_torque: NDArray[np.float64]
    shaking_force: NDArray[np.complex128]
    shaking_moment: NDArray[np.float64]
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
    model: object = field(repr=False, default=None)
    slider: NDArray[np.float64] | None = field(repr=False, default=None)

    def __repr__(self) -> str:
        return (f"Trajectory({self.method}, {self.drive}, {self.t.size} outputs over "
                f"{self.t[-1] - self.t[0]:g} s, {self.steps} steps; energy balance to "
                f"{self.energy_error:.2g})")

    @property
    def largest_reaction(self) -> float:
        """Largest magnitude of any force on the frame over the run, N (0 if none)."""
        values = [np.max(np.abs(v), initial=0.0) for v in (
            *self.ground.values(), *self.slider_normal.values())]
        return float(max(values, default=0.0))

    def columns(self, all_columns: bool = False) -> tuple[list[str], list]:
        """The columns of ``simulate``'s CSV: names and values over the output times.

        See :func:`balancer.columns.simulation_columns`.
        """
        return simulation_columns(self, all_columns)

    def state(self, index: int) -> dict:
        """Angles, rates and accelerations of the links at output ``index``.

        Each a list in link order, or (``named_states``) an object keyed by link name.
        """
        out = {}
        for key, values in (("theta", self.theta), ("omega", self.omega),
                            ("alpha", self.alpha)):
            numbers = [float(x) + 0.0 for x in values[:, index]]
            out[key] = dict(zip(self.links, numbers, strict=True)) if self.named_states \
                else numbers
        return out


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


class _Stepper:
    """One integration with projection, dense outputs and events."""

    def __init__(self, f: Formulation, duration: float, rtol: float, atol: float,
                 outputs: int, progress: Callable[[float, float], None] | None,
                 resolution: float | None = None) -> None:
        self.f = f
        self.duration = duration
        self.rtol = rtol
        self.atol = atol
        self.t_out = np.linspace(0.0, duration, outputs)
        self.progress = progress
        self.extra_fev = 0
        self.t_end = duration
        self.resolution = resolution
        #: Each step's end and dense output, kept where the outputs may be resampled.
        self.pieces: list[tuple[float, object]] = []
        #: States between the output times (the steps' ends; a prescribed motion's at every
        #: :data:`GUIDE_ANGLE` of crank, :meth:`_guide_times`), as ``(times, states)``: the
        #: angles are followed through them from one output to the next (:func:`_trajectory`).
        self.guide: tuple[list[float], list[NDArray[np.float64]]] = ([], [])

    def run(self, y0: NDArray[np.float64], stop_at: float | None):
        """Integrate from ``y0``; the states returned carry the extra work as a last entry."""
        t_end = self.duration if stop_at is None else min(stop_at, self.duration)
        self.t_end = t_end
        if self.f.driven:  # up to t_end: before the lock of a crank driven into one
            prescribed = (self._prescribed(y0) if self.f.time_only
                          else self._prescribed_motion(y0))
            if prescribed is not None:
                return prescribed
        f = _WithExtraWork(self.f)
        y0 = np.append(y0, 0.0)
        groups = self.f.like_components()
        atol = floored_atol(self.atol, groups, y0)
        stages = self._stages()
        if stages is None and f.time_only:
            solver = TimeOnlyDOP853(f.rhs, 0.0, y0, t_end, rtol=self.rtol, atol=atol)
        elif stages is None:
            solver = DOP853(f.rhs, 0.0, y0, t_end, rtol=self.rtol, atol=atol)
        else:
            solver = CompiledDOP853(f.rhs, 0.0, y0, t_end, stages=stages, rtol=self.rtol,
                                    atol=atol)
        states: list[NDArray[np.float64]] = []
        times: list[float] = []
        drift = [0.0, 0.0]
        k = 0
        steps = 0
        # A driven crank that locks: the dead point ahead is the lock, which simulate() finds
        # from the assembly range and ends the run before (the event would race it).
        passes_dead_points = f.passes_dead_points or (self.f.driven and stop_at is not None)
        change_points = f.change_points()
        # The first output is the initial state.
        while k < self.t_out.size and self.t_out[k] <= 0.0:
            states.append(np.array(y0))
            times.append(float(self.t_out[k]))
            k += 1
        initial = len(states)
        stopped: tuple[float, NDArray[np.float64]] | None = None
        recent: deque[float] = deque([0.0], maxlen=STALL_WINDOW + 1)
        while solver.status == "running":
            message = solver.step()
            if solver.status == "failed":
                raise SolverError(f"the integrator failed at t = {solver.t:.6g} s: {message}")
            steps += 1
            self._check_budget(steps, solver.t)
            recent.append(solver.t)
            self._check_stall(recent, f, solver.t, solver.y, change_points)
            # The step's dense output (three more evaluations for DOP853) is made only for a
            # step that holds an output time or an event, and before a projection moves y.
            dense = None

            def interp(t, _solver=solver):
                nonlocal dense
                if dense is None:
                    dense = _solver.dense_output()
                return dense(t)

            if self.resolution is not None:
                interp(solver.t)
                self.pieces.append((solver.t, dense))
            if not f.minimal:
                if not passes_dead_points or (k < self.t_out.size and self.t_out[k] <= solver.t
                                              + 1e-14 * max(1.0, solver.t)):
                    interp(solver.t)
                res = f.constraint_residual(solver.t, solver.y)
                drift = [max(drift[0], res[0]), max(drift[1], res[1])]
                y_new = f.project(solver.t, solver.y)
                solver.y = y_new
                solver.f = f.rhs(solver.t, y_new)  # the next step starts from the projection
                self.extra_fev += 1
            if groups:
                solver.atol = floored_atol(self.atol, groups, solver.y)
            self.guide[0].append(float(solver.t))
            self.guide[1].append(np.array(solver.y))
            if not passes_dead_points:
                event = self._dead_point(interp, solver.t_old, solver.t, solver.y,
                                         change_points)
                if event is not None:
                    stopped = event
                    solver.status = "finished"
            t_hi = solver.t if stopped is None else stopped[0]
            end = k
            while end < self.t_out.size and self.t_out[end] <= t_hi + 1e-14 * max(1.0, t_hi):
                end += 1
            if end > k:  # the outputs within this step, in one evaluation
                t_step = self.t_out[k:end]
                states += list(interp(np.minimum(t_step, solver.t)).T)
                times += t_step.tolist()
                k = end
            if self.progress is not None:
                self.progress(solver.t, self.duration)
        if self.resolution is not None and len(times) >= 2:
            times, states = self._resampled(f, times, states, initial)
        if not f.minimal and len(states) > initial:  # every output onto the constraints at once
            states[initial:] = f.project_many(times[initial:], states[initial:])
        return times, states, drift, solver.nfev + self.extra_fev, steps, stopped

    def _resampled(self, f, times: list[float], states: list, initial: int):
        """The outputs, more of them where the crank turned farther than the resolution.

        From the steps' dense outputs (:attr:`pieces`), without integrating again: output times
        at least twice as many each round, until the crank turns at most :attr:`resolution`
        between two (or :data:`MAX_OUTPUTS`).
        """
        last = times[-1]
        ends = np.array([end for end, _ in self.pieces])
        outputs = self.t_out.size
        while outputs < MAX_OUTPUTS:
            theta1 = np.array([f.theta1_of(t, y) for t, y in zip(times, states, strict=True)])
            step = float(np.max(np.abs(np.diff(theta1))))
            if not step > self.resolution * (1 + 1e-9):
                break
            need = math.ceil(1.1 * step / self.resolution * (outputs - 1)) + 1
            outputs = min(MAX_OUTPUTS, max(need, 2 * outputs))
            grid = np.linspace(0.0, self.duration, outputs)
            grid = grid[grid <= last + 1e-14 * max(1.0, last)]
            head = int(np.count_nonzero(grid <= 0.0))
            where = np.minimum(np.searchsorted(ends, grid[head:], side="left"), ends.size - 1)
            fresh = [states[0]] * head
            for index in np.unique(where):
                at = grid[head:][where == index]
                fresh += list(self.pieces[index][1](np.minimum(at, ends[index])).T)
            times, states = grid.tolist(), fresh
            self.t_out = np.linspace(0.0, self.duration, outputs)
        return times, states

    def _prescribed(self, y0: NDArray[np.float64]):
        """A driven crank's prescribed motion, its work by quadrature instead of steps.

        The state of a :attr:`~balancer.formulations.Formulation.time_only` formulation is a
        function of the time whose derivative is known at every time: its values at the output
        times are the cumulative integrals of :meth:`~balancer.formulations.Formulation.
        driven_rates` (:func:`balancer.quadrature.cumulative`, to the run's tolerances; a panel
        is reported as a step). ``None`` where the formulation has no vectorised rates, or the
        motion comes within :data:`~balancer.formulations.DEAD_POINT_THRESHOLD` of a dead point
        (away from a change point): the integrator then steps, and its event stops the run.
        """
        f = self.f
        if not self.prescribes(y0):
            return None
        self._check_panels(self.t_end)
        outs = self._outputs()
        near_dead_point = False
        points = f.change_points()

        def integrand(t: NDArray[np.float64]) -> NDArray[np.float64]:
            nonlocal near_dead_point
            rates = f.driven_rates(t)
            if not f.passes_dead_points:
                low = np.abs(rates.transmission) <= DEAD_POINT_THRESHOLD
                if np.any(low):
                    theta1 = f.crank_angle(t[low])
                    near = [np.abs(np.remainder(theta1 - p + math.pi, 2 * math.pi) - math.pi)
                            < CHANGE_POINT_NEAR for p in points]
                    near_dead_point |= not np.all(np.logical_or.reduce(near)) if near else True
            return np.column_stack([rates.rates, rates.extra_power])

        # The state at the guide's times too (a carried crank angle is part of it): the
        # quadrature takes times inside its panels at no cost.
        guide = self._guide_times(outs)
        times = np.union1d(outs, guide)
        with np.errstate(divide="ignore", invalid="ignore"):
            work = cumulative(integrand, times, rtol=self.rtol, atol=self.atol,
                              max_width=PANEL_ANGLE / abs(f.speed))
        if near_dead_point:
            return None
        start = np.append(y0, 0.0)
        states = list(start + work.values[np.searchsorted(times, outs)])
        self.guide = (guide.tolist(),
                      list(start + work.values[np.searchsorted(times, guide)]))
        if self.progress is not None:
            self.progress(self.duration, self.duration)
        return outs.tolist(), states, [0.0, 0.0], work.evaluations, work.panels, None

    def prescribes(self, y0: NDArray[np.float64]) -> bool:
        """Whether a driven crank's motion is prescribed (its work by quadrature, no steps).

        So it is where the formulation gives its rates (a minimal one) or its motion (one that
        is not) at the first output time.
        """
        f = self.f
        if not f.driven:
            return False
        if f.time_only:
            return f.driven_rates(self.t_out[:1]) is not None
        return not f.minimal and f.driven_motion(self.t_out[:1], y0) is not None

    def check_up_front(self, y0: NDArray[np.float64], stop_at: float | None) -> None:
        """Raise what :meth:`run` would refuse before it works (a prescribed motion's panels)."""
        if self.prescribes(y0):
            self._check_panels(self.duration if stop_at is None else min(stop_at,
                                                                         self.duration))

    def _check_panels(self, t_end: float) -> None:
        """Refuse a prescribed motion that needs more than :data:`MAX_STEPS` panels.

        At least one panel per :data:`PANEL_ANGLE` of crank up to ``t_end`` (s): refused, as
        a run of as many steps would be, before the panels' nodes are laid out (a 1e5 s run:
        1e8 nodes).
        """
        panels = abs(float(self.f.speed)) * t_end / PANEL_ANGLE  # type: ignore[arg-type]
        if panels > MAX_STEPS:
            raise SpecError(
                f"would take about {panels:.2g} quadrature panels of the crank's prescribed "
                f"motion (one per {math.degrees(PANEL_ANGLE):g}° of crank at the least), more "
                f"than the {MAX_STEPS:.0e} allowed: shorten it", key="simulation.duration",
                value=self.duration)

    def _outputs(self) -> NDArray[np.float64]:
        """The output times up to where the run ends (before a lock, if driven into one)."""
        return self.t_out[self.t_out <= self.t_end]

    def _guide_times(self, outs: NDArray[np.float64]) -> NDArray[np.float64]:
        """Times between the outputs through which a driven crank's angles are followed.

        Every :data:`GUIDE_ANGLE` of crank; none where the (equally spaced) output times
        ``outs`` are that close already.
        """
        turn = abs(float(self.f.speed))  # type: ignore[arg-type]
        if outs.size < 2 or turn * (outs[1] - outs[0]) <= GUIDE_ANGLE:
            return np.zeros(0)
        grid = np.linspace(0.0, outs[-1], math.ceil(turn * outs[-1] / GUIDE_ANGLE) + 1)
        return grid[(grid > 0) & (grid < outs[-1]) & ~np.isin(grid, outs)]

    def _prescribed_motion(self, y0: NDArray[np.float64]):
        """A driven crank's prescribed motion in a formulation that is not minimal.

        The states at the output times are the motion itself
        (:meth:`~balancer.formulations.Formulation.driven_motion`: the mechanism's position
        and rate analysis); the motor's work and the extra work are the cumulative integrals of
        their powers, the formulation's own driving torque times the crank's speed and
        :meth:`~balancer.formulations.Formulation.extra_power`, by quadrature
        (:func:`balancer.quadrature.cumulative`, to the run's tolerances; a panel is reported
        as a step). The drift is the constraints' residual at the output states. ``None`` where
        the formulation has no such route: the integrator then steps.
        """
        f = self.f
        if not self.prescribes(y0):
            return None
        self._check_panels(self.t_end)  # before the outputs and guide times are laid out
        outs = self._outputs()
        guide = self._guide_times(outs)
        times = np.union1d(outs, guide)
        motion = f.driven_motion(times, y0)
        if motion is None:
            return None
        speed = float(f.speed)  # type: ignore[arg-type]

        def integrand(t: NDArray[np.float64]) -> NDArray[np.float64]:
            states = f.driven_motion(t, y0)
            if states is None:
                raise SolverError("the prescribed motion does not exist at a quadrature node "
                                  f"within 0 ≤ t ≤ {self.t_end:.6g} s")
            states = [np.append(y, 0.0) for y in states]  # the motor's work: not used
            torque = np.asarray(f.evaluate_batch(t, states).driving_torque, float)
            extra = [f.extra_power(ti, y) for ti, y in zip(t, states, strict=True)]
            return np.column_stack([torque * speed, extra])

        work = cumulative(integrand, times, rtol=self.rtol, atol=self.atol,
                          max_width=PANEL_ANGLE / abs(speed))
        everywhere = [np.concatenate([y, w]) for y, w in zip(motion, work.values, strict=True)]
        states = [everywhere[i] for i in np.searchsorted(times, outs)]
        self.guide = (guide.tolist(), [everywhere[i] for i in np.searchsorted(times, guide)])
        drift = f.constraint_residuals(outs, [y[:-1] for y in states])
        if self.progress is not None:
            self.progress(self.duration, self.duration)
        return outs.tolist(), states, list(drift), work.evaluations, work.panels, None

    def _stages(self):
        """The formulation's compiled DOP853 stages (built once per formulation), or None."""
        cache = self.f.compiled
        if "dop853" not in cache:
            symbolic = self.f.symbolic_rhs()
            if symbolic is None:
                cache["dop853"] = None
            else:
                cache["dop853"] = Stages(with_extra_work(symbolic))
        return cache["dop853"]

    def _check_budget(self, steps: int, t: float) -> None:
        """Refuse a duration that would take more than :data:`MAX_STEPS` steps.

        After :data:`PROJECT_AFTER` steps, from the rate so far; at any time, the limit itself.
        (A motion whose steps come ever faster is caught by :meth:`_check_stall`.)
        """
        if steps < PROJECT_AFTER or t <= 0:
            return
        projected = steps * self.t_end / t  # to where this run ends (before a lock, if driven)
        if projected > MAX_STEPS:
            raise SpecError(
                f"would take about {projected:.2g} integration steps at the rate of the first "
                f"{t:.3g} s ({steps} steps), more than the {MAX_STEPS:.0e} allowed: shorten "
                "it, or loosen rtol", key="simulation.duration", value=self.duration)

    def _check_stall(self, recent: deque[float], f, t: float, y, change_points) -> None:
        """Fail a run whose last :data:`STALL_WINDOW` steps project past :data:`MAX_STEPS`.

        The integrator keeps its error within rtol and atol by shrinking its steps; near a
        singular configuration (a change point, links whose masses differ by many orders of
        magnitude) it may shrink them without end instead of failing.
        """
        if len(recent) <= STALL_WINDOW:
            return
        advance = recent[-1] - recent[0]
        remaining = self.t_end - t  # to where this run ends (before a lock, if driven)
        if remaining <= 0 or advance * MAX_STEPS > remaining * STALL_WINDOW:
            return
        theta1 = f.theta1_of(t, y)
        where = f"t = {t:.9g} s, θ1 = {theta1:.9g} rad"
        near = [p for p in change_points
                if abs(math.remainder(theta1 - p, 2 * math.pi)) < CHANGE_POINT_NEAR]
        cause = (f"near the change point θ1 = {near[0]:.6g} rad (all joints in line), where "
                 "the crank's rate does not determine the others'"
                 + ("" if f.passes_change_points else
                    f"; the {f.name} formulation cannot pass it{_passing_change(f.f.linkage)}")
                 if near else
                 "where the motion is too sensitive for these tolerances (masses or loads of "
                 "very different magnitudes, or a near-singular configuration)")
        raise SolverError(
            f"the integrator stalled at {where}, {cause}: its last {STALL_WINDOW} steps "
            f"advanced {advance:.3g} s, so the remaining {remaining:.3g} s would need over "
            f"{MAX_STEPS:.0e} steps at rtol = {self.rtol:g}, atol = {self.atol:g}; loosen "
            f"the tolerances or end the run before t = {t:.6g} s")

    def _dead_point(self, interp, t0: float, t1: float, y1, change_points):
        """The time at which |sin(θ3 − θ2)| falls to the threshold within a step, or None.

        ``y1`` is the state at the step's end (the dense output is made only for an event).
        """
        f = _WithExtraWork(self.f)

        def gap(t: float, y=None) -> float:
            y = interp(t) if y is None else y
            if change_points and _near_change_point(f, t, y, change_points):
                return 1.0  # passable: the smooth motion goes through
            return abs(f.transmission(t, y)) - DEAD_POINT_THRESHOLD

        if gap(t1, y1) > 0:
            return None
        from scipy.optimize import brentq  # only for an event (its import costs 0.3–0.5 s)

        t_event = brentq(gap, t0, t1, xtol=1e-12) if gap(t0) > 0 else t0
        return t_event, interp(t_event)


def floored_atol(atol: float, groups, y: NDArray[np.float64]) -> float | NDArray[np.float64]:
    """The absolute tolerance of each component of the state ``y``.

    ``atol``, but for a component of one of the ``groups``
    (:meth:`~balancer.formulations.Formulation.like_components`) at least
    :data:`~balancer.model.RTOL_MIN` (100 ε, the tightest ``rtol`` accepted) times the group's
    largest magnitude. A component that is zero for the motion (the velocity of a frame pinned
    to the ground at its origin) is computed from the others and carries their rounding: in a
    linkage 200 m across turning at 130 rad/s, with velocities of 10⁴ m/s and accelerations of
    10⁷ m/s², a pinned origin's acceleration comes out as 10⁻⁶ m/s² of noise, and an absolute
    tolerance of 10⁻¹³ m/s on its velocity held the steps to 10⁻⁷ s (30 000 steps a turn, a
    minute of a 0.05 s verification; the floor: 80).
    """
    if not groups:
        return atol
    out = np.full(y.shape, float(atol))
    for g in groups:
        out[g] = max(float(atol), RTOL_MIN * float(np.max(np.abs(y[g]), initial=0.0)))
    return out


class _WithExtraWork:
    """A formulation whose state carries, as a last entry, the work of the extra power.

    ``Ẇ_extra`` = :meth:`~balancer.formulations.Formulation.extra_power` (a force that depends
    on the crank angle, such as a gas force): integrated with the motion, so that the energy
    balance ``T − T0 = W_config + W_motor + W_extra`` is a first integral of the integrated
    system. Projection and events see the formulation's own state.
    """

    def __init__(self, f: Formulation) -> None:
        self.f = f
        self.minimal = f.minimal
        self.passes_dead_points = f.passes_dead_points
        self.passes_change_points = f.passes_change_points
        self.name = f.name
        self.time_only = f.time_only

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        own = y[:-1]
        out = np.empty(y.size)  # (np.append costs as much as a small formulation's rhs)
        out[:-1] = self.f.rhs(t, own)
        out[-1] = self.f.extra_power(t, own)
        return out

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.append(self.f.project(t, y[:-1]), y[-1])

    def project_many(self, times, states) -> list[NDArray[np.float64]]:
        own = self.f.project_many(times, [y[:-1] for y in states])
        return [np.append(p, y[-1]) for p, y in zip(own, states, strict=True)]

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        return self.f.constraint_residual(t, y[:-1])

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        return self.f.transmission(t, y[:-1])

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        return self.f.theta1_of(t, y[:-1])

    def change_points(self) -> tuple[float, ...]:
        return self.f.change_points()


def _passing_change(model) -> str:
    """The formulations of a mechanism that pass change points, as a parenthesis."""
    names = [n for n in formulation_names(model)
             if formulation_class(n, model).passes_change_points]
    return f" ({' and '.join(names)} can)" if names else ""


def _passing(model) -> str:
    """The formulations of a mechanism that pass dead points, as a parenthesis."""
    names = [n for n in formulation_names(model)
             if formulation_class(n, model).passes_dead_points]
    return f" ({' and '.join(names)} can)" if names else ""


def _near_change_point(f, t: float, y, points) -> bool:
    theta1 = f.theta1_of(t, y)
    return any(abs(math.remainder(theta1 - p, 2 * math.pi)) < CHANGE_POINT_NEAR for p in points)


@dataclass(frozen=True)
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


def _prepare(linkage, settings: SimulationSettings, *, resolution: float | None = None,
             **overrides) -> _Setup:
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


def check(linkage, settings: SimulationSettings, *, resolution: float | None = None,
          **overrides) -> None:
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
    stepper = _Stepper(run.f, run.settings.duration, run.settings.rtol, run.settings.atol,
                       run.outputs, None, resolution)
    stepper.check_up_front(run.y0, run.end)


def simulate(
    linkage,
    settings: SimulationSettings,
    *,
    method: str | None = None,
    drive: str | None = None,
    duration: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    outputs: int | None = None,
    progress: Callable[[float, float], None] | None = None,
    resolution: float | None = None,
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

    Raises
    ------
    SpecError
        For bad settings or an initial crank angle where the linkage does not assemble.
    LockupError
        If the motion reaches a position the formulation cannot pass (its ``partial``
        attribute holds the trajectory up to there).
    """
    run = _prepare(linkage, settings, method=method, drive=drive, duration=duration,
                   rtol=rtol, atol=atol, outputs=outputs, resolution=resolution)
    f, y0, end = run.f, run.y0, run.end
    duration, rtol, atol = run.settings.duration, run.settings.rtol, run.settings.atol
    start = _time.perf_counter()
    stepper = _Stepper(f, duration, rtol, atol, run.outputs, progress, resolution)
    with np.errstate(divide="ignore", invalid="ignore"):
        times, states, drift, nfev, steps, stopped = stepper.run(y0, end)
    traj = _trajectory(f, times, states, drift, nfev, steps, rtol, atol,
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
            + _passing(linkage),
            t_event, th, traj)
    if run.stop_at is not None:
        th = f.crank_angle(run.stop_at)
        raise _lockup(
            f"the crank, driven at {f.speed:g} rad/s, reaches the end of the range where the "
            f"linkage assembles at t = {run.stop_at:.6g} s, θ1 = {th:.6g} rad: the linkage "
            "locks", run.stop_at, th, traj)
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
    err.partial = partial  # type: ignore[attr-defined]
    return err


def _trajectory(f: Formulation, times, states, drift, nfev, steps, rtol, atol,
                seconds, guide=None) -> Trajectory:
    t = np.array(times)
    extra = np.array([y[-1] for y in states])
    states = [y[:-1] for y in states]
    ev = f.evaluate_batch(times, states)
    omega, alpha = np.asarray(ev.omega, float), np.asarray(ev.alpha, float)
    theta = _followed_angles(f, t, np.asarray(ev.theta, float), omega, guide)
    tau = np.asarray(ev.driving_torque, float) * np.ones(t.size)
    motor = np.array([f.motor_work(y) for y in states])
    slider = None if ev.slider is None else np.asarray(ev.slider, float)
    # Energy: T − T0 = work of loads and gravity (a function of the configuration) + motor
    # + the extra work integrated with the motion (a gas force).
    kin, work = f.energy(theta, omega, alpha, slider, states=states)
    work = work + motor + extra
    scale = max(np.max(np.abs(kin)), np.max(np.abs(work)), _exchangeable_energy(f), 1e-300)
    energy_error = float(np.max(np.abs(kin - kin[0] - work)) / scale)
    shaking_force, moment = f.shaking(ev)
    return Trajectory(
        method=f.name,
        drive="constant-speed" if f.driven else "free",
        speed=f.speed,
        links=f.link_names,
        t=t,
        theta=theta,
        omega=omega,
        alpha=alpha,
        ground={p: np.asarray(v, complex) * np.ones(t.size) for p, v in ev.ground.items()},
        slider_normal={k: np.asarray(v, float) * np.ones(t.size)
                       for k, v in ev.slider_normal.items()},
        slider_couple={k: np.asarray(v, float) * np.ones(t.size)
                       for k, v in ev.slider_couple.items()},
        driving_torque=tau,
        shaking_force=np.asarray(shaking_force, complex) * np.ones(t.size),
        shaking_moment=np.asarray(moment, float) * np.ones(t.size),
        kinetic_energy=kin,
        work=work,
        energy_error=energy_error,
        drift=(float(drift[0]), float(drift[1])),
        nfev=int(nfev),
        steps=int(steps),
        seconds=float(seconds),
        rtol=rtol,
        atol=atol,
        named_states=mechanism_of(f.linkage).named_states,
        model=f.linkage,
        slider=slider,
    )


def _followed_angles(f: Formulation, t, theta, omega, guide) -> NDArray[np.float64]:
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

    ``L·Σ(m·|g| + |F|) + 2π·Σ|M| + Σ k·(L + l0)²`` with ``L`` the linkage's length scale: the
    energy balance's scale where the motion itself exchanges almost none (a linkage at rest in
    equilibrium, whose kinetic energy and work are both rounding).
    """
    mech = mechanism_of(f.linkage)
    length = mech.structure.length_scale()
    g = abs(f.gravity)
    total = sum((link.mass * g + math.hypot(*link.force)) * length
                + 2 * math.pi * abs(link.moment) for link in mech.links)
    for spring in mech.linkage.springs:
        total += spring.stiffness * (length + abs(spring.free_length)) ** 2
    return float(total)


def simulate_design(design: Design, **overrides) -> Trajectory:
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
