"""The stepping of a simulation: DOP853 by hand, projections, events, budgets, quadrature.

:class:`Stepper` integrates a formulation's equations of motion over a duration (see
:mod:`balancer.simulation` for what it guarantees): accepted steps projected back onto the
constraints, outputs from the dense output, a dead point or a lock as an event, the step budget
refused from the first steps' rate, and a driven crank's prescribed motion by quadrature.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable, Sequence
from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import SolverError, SpecError
from ..formulations import (
    DEAD_POINT_THRESHOLD,
    Formulation,
    formulation_class,
    formulation_names,
)
from ..mechanisms.base import Mechanism
from ..model import RTOL_MIN
from ..model import MechanismModel as Model
from .integrator import (
    DOP853,
    CompiledDOP853,
    DenseOutput,
    Stages,
    TimeOnlyDOP853,
    with_extra_work,
)
from .quadrature import cumulative

#: Most integration steps a simulation may take (under a minute with the slowest formulation,
#: multibody with its projections, at some 2 000 steps a second on a 2-core machine): a
#: duration that needs more is refused, from the rate of its first steps.
MAX_STEPS = 100_000


#: Steps after which the rate is extrapolated to the whole duration.
PROJECT_AFTER = 200


#: Distance in θ1 from a change point, rad, within which a motion is near it (passable by
#: a dead-point event, named as the cause of a stall).
CHANGE_POINT_NEAR = 0.05


#: Largest angle, rad, the crank turns over one quadrature panel of a driven motion's work
#: (:meth:`Stepper._prescribed`): a sixteenth of a revolution, so that the panels resolve the
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

#: A run's outputs (:meth:`Stepper.run`): the output times (s), the states there (each with
#: the extra work as its last entry), the largest constraint drift of position and velocity,
#: the right-hand sides evaluated, the steps taken, and where a dead point stopped it (its
#: time and state) or ``None``.
Run: TypeAlias = tuple[list[float], list[NDArray[np.float64]], list[float], int, int,
                       tuple[float, NDArray[np.float64]] | None]


class Stepper:
    """One integration with projection, dense outputs and events."""

    def __init__(self, f: Formulation, duration: float, rtol: float, atol: float,
                 outputs: int, progress: Callable[[float, float], None] | None,
                 resolution: float | None = None, max_seconds: float | None = None) -> None:
        self.f = f
        self.max_seconds = max_seconds
        self.started = time.perf_counter()
        self.duration = duration
        self.rtol = rtol
        self.atol = atol
        self.t_out = np.linspace(0.0, duration, outputs)
        self.progress = progress
        self.extra_fev = 0
        self.t_end = duration
        self.resolution = resolution
        #: Each step's end and dense output, kept where the outputs may be resampled.
        self.pieces: list[tuple[float, DenseOutput | None]] = []
        #: States between the output times (the steps' ends; a prescribed motion's at every
        #: :data:`GUIDE_ANGLE` of crank, :meth:`_guide_times`), as ``(times, states)``: the
        #: angles are followed through them from one output to the next (:func:`trajectory_of`).
        self.guide: tuple[list[float], list[NDArray[np.float64]]] = ([], [])

    def run(self, y0: NDArray[np.float64], stop_at: float | None) -> Run:
        """Integrate from ``y0``; the states returned carry the extra work as a last entry."""
        t_end = self.duration if stop_at is None else min(stop_at, self.duration)
        self.t_end = t_end
        self.started = time.perf_counter()
        if self.f.driven:  # up to t_end: before the lock of a crank driven into one
            prescribed = (self._prescribed(y0) if self.f.time_only
                          else self._prescribed_motion(y0))
            if prescribed is not None:
                return prescribed
        f = WithExtraWork(self.f)
        y0 = np.append(y0, 0.0)
        groups = self.f.like_components()
        atol = floored_atol(self.atol, groups, y0)
        stages = self._stages()
        solver: DOP853
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
            dense: DenseOutput | None = None

            def interp(t: ArrayLike, _solver: DOP853 = solver) -> NDArray[np.float64]:
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
                assert solver.t_old is not None  # a step was taken
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

    def _resampled(self, f: WithExtraWork, times: list[float],
                   states: list[NDArray[np.float64]], initial: int
                   ) -> tuple[list[float], list[NDArray[np.float64]]]:
        """The outputs, more of them where the crank turned farther than the resolution.

        From the steps' dense outputs (:attr:`pieces`), without integrating again: output times
        at least twice as many each round, until the crank turns at most :attr:`resolution`
        between two (or :data:`MAX_OUTPUTS`).
        """
        assert self.resolution is not None  # a run that resamples
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
                piece = self.pieces[index][1]
                assert piece is not None  # made for every step of a run that resamples
                fresh += list(piece(np.minimum(at, ends[index])).T)
            times, states = grid.tolist(), fresh
            self.t_out = np.linspace(0.0, self.duration, outputs)
        return times, states

    def _prescribed(self, y0: NDArray[np.float64]) -> Run | None:
        """A driven crank's prescribed motion, its work by quadrature instead of steps.

        The state of a :attr:`~balancer.formulations.Formulation.time_only` formulation is a
        function of the time whose derivative is known at every time: its values at the output
        times are the cumulative integrals of :meth:`~balancer.formulations.Formulation.
        driven_rates` (:func:`.quadrature.cumulative`, to the run's tolerances; a panel
        is reported as a step). ``None`` where the formulation has no vectorised rates, or the
        motion comes within :data:`~balancer.formulations.DEAD_POINT_THRESHOLD` of a dead point
        (away from a change point): the integrator then steps, and its event stops the run.
        """
        f = self.f
        if not self.prescribes(y0):
            return None
        assert f.speed is not None  # driven
        self._check_panels(self.t_end)
        outs = self._outputs()
        near_dead_point = False
        points = f.change_points()

        def integrand(t: NDArray[np.float64]) -> NDArray[np.float64]:
            nonlocal near_dead_point
            rates = f.driven_rates(t)
            assert rates is not None  # (prescribes() has checked)
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
        assert self.f.speed is not None  # driven
        panels = abs(float(self.f.speed)) * t_end / PANEL_ANGLE
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
        assert self.f.speed is not None  # driven
        turn = abs(float(self.f.speed))
        if outs.size < 2 or turn * (outs[1] - outs[0]) <= GUIDE_ANGLE:
            return np.zeros(0)
        grid = np.linspace(0.0, outs[-1], math.ceil(turn * outs[-1] / GUIDE_ANGLE) + 1)
        return grid[(grid > 0) & (grid < outs[-1]) & ~np.isin(grid, outs)]

    def _prescribed_motion(self, y0: NDArray[np.float64]) -> Run | None:
        """A driven crank's prescribed motion in a formulation that is not minimal.

        The states at the output times are the motion itself
        (:meth:`~balancer.formulations.Formulation.driven_motion`: the mechanism's position
        and rate analysis); the motor's work and the extra work are the cumulative integrals of
        their powers, the formulation's own driving torque times the crank's speed and
        :meth:`~balancer.formulations.Formulation.extra_power`, by quadrature
        (:func:`.quadrature.cumulative`, to the run's tolerances; a panel is reported
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
        assert f.speed is not None  # driven
        speed = float(f.speed)

        def integrand(t: NDArray[np.float64]) -> NDArray[np.float64]:
            moving = f.driven_motion(t, y0)
            if moving is None:
                raise SolverError("the prescribed motion does not exist at a quadrature node "
                                  f"within 0 ≤ t ≤ {self.t_end:.6g} s")
            states = [np.append(y, 0.0) for y in moving]  # the motor's work: not used
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

    def _stages(self) -> Stages | None:
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

        Or, with ``max_seconds``, more than that wall-clock time at the rate so far. After
        :data:`PROJECT_AFTER` steps, from the rate so far; at any time, the limit itself. (A
        motion whose steps come ever faster is caught by :meth:`_check_stall`.)
        """
        if steps < PROJECT_AFTER or t <= 0:
            return
        projected = steps * self.t_end / t  # to where this run ends (before a lock, if driven)
        if projected > MAX_STEPS:
            raise SpecError(
                f"would take about {projected:.2g} integration steps at the rate of the first "
                f"{t:.3g} s ({steps} steps), more than the {MAX_STEPS:.0e} allowed: shorten "
                "it, or loosen rtol", key="simulation.duration", value=self.duration)
        if self.max_seconds is not None:
            seconds = (time.perf_counter() - self.started) * self.t_end / t
            if seconds > self.max_seconds:
                raise SpecError(
                    f"would take about {seconds:.2g} s on this machine ({projected:.2g} "
                    f"integration steps at the rate of the first {t:.3g} s, {steps} steps), "
                    f"more than the {self.max_seconds:g} s a check may take: the motion is "
                    "much faster than the duration (its loads, gravity or speed): shorten it, "
                    "or loosen rtol", key="simulation.duration", value=self.duration)

    def _check_stall(self, recent: deque[float], f: WithExtraWork, t: float,
                     y: NDArray[np.float64], change_points: tuple[float, ...]) -> None:
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
                    f"; the {f.name} formulation cannot pass it{passing_change(f.f.linkage)}")
                 if near else
                 "where the motion is too sensitive for these tolerances (masses or loads of "
                 "very different magnitudes, or a near-singular configuration)")
        raise SolverError(
            f"the integrator stalled at {where}, {cause}: its last {STALL_WINDOW} steps "
            f"advanced {advance:.3g} s, so the remaining {remaining:.3g} s would need over "
            f"{MAX_STEPS:.0e} steps at rtol = {self.rtol:g}, atol = {self.atol:g}; loosen "
            f"the tolerances or end the run before t = {t:.6g} s")

    def _dead_point(self, interp: Callable[[ArrayLike], NDArray[np.float64]], t0: float,
                    t1: float, y1: NDArray[np.float64], change_points: tuple[float, ...]
                    ) -> tuple[float, NDArray[np.float64]] | None:
        """The time at which |sin(θ3 − θ2)| falls to the threshold within a step, or None.

        ``y1`` is the state at the step's end (the dense output is made only for an event).
        """
        f = WithExtraWork(self.f)

        def gap(t: float, y: NDArray[np.float64] | None = None) -> float:
            y = interp(t) if y is None else y
            if change_points and near_change_point(f, t, y, change_points):
                return 1.0  # passable: the smooth motion goes through
            return abs(f.transmission(t, y)) - DEAD_POINT_THRESHOLD

        if gap(t1, y1) > 0:
            return None
        from scipy.optimize import brentq  # only for an event (its import costs 0.3–0.5 s)

        t_event = brentq(gap, t0, t1, xtol=1e-12) if gap(t0) > 0 else t0
        return t_event, interp(t_event)


def floored_atol(atol: float, groups: Sequence[NDArray[np.intp]], y: NDArray[np.float64]
                 ) -> float | NDArray[np.float64]:
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


class WithExtraWork:
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

    def project_many(self, times: Sequence[float] | NDArray[np.float64],
                     states: Sequence[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
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


def passing_change(model: Model | Mechanism) -> str:
    """The formulations of a mechanism that pass change points, as a parenthesis."""
    names = [n for n in formulation_names(model)
             if formulation_class(n, model).passes_change_points]
    return f" ({' and '.join(names)} can)" if names else ""


def passing(model: Model | Mechanism) -> str:
    """The formulations of a mechanism that pass dead points, as a parenthesis."""
    names = [n for n in formulation_names(model)
             if formulation_class(n, model).passes_dead_points]
    return f" ({' and '.join(names)} can)" if names else ""


def near_change_point(f: WithExtraWork, t: float, y: NDArray[np.float64],
                      points: Sequence[float]) -> bool:
    """Whether the state ``y`` at ``t`` is within :data:`CHANGE_POINT_NEAR` of a change point."""
    theta1 = f.theta1_of(t, y)
    return any(abs(math.remainder(theta1 - p, 2 * math.pi)) < CHANGE_POINT_NEAR for p in points)
