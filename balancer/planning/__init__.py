"""Motion as a balancing lever: a path's time law chosen to shake the frame least.

A motion's path stays; how fast it is run — its argument ``τ(t)`` — is chosen by direct
transcription (:mod:`.transcription`) of the loads along the path (:mod:`.path_loads`), within
the inputs' limits and the duration. The result is a planned motion (its ``along`` and
``pace``, :class:`~balancer.model.motions.MotionSpec`) that every verb reads; its loads are the
one core's analysis along it (:func:`balancer.motion_analysis.motion_analysis`).

What is certified: the transcription is convex (its objective and limits, with the duration
relaxed to an upper bound); where that bound is active at the optimum, IPOPT's point is the
global optimum of the transcription, and the planned motion's analysis gives its figures
exactly. The transcription's own error falls with its mesh (second order in the intervals on
smooth paths). For a path from rest to rest, the least RMS shaking force of any time law has a
closed form (the total centre of mass moved along each axis by a cubic: ``√12·M·Δc/T²``,
with the weight's constant part), a lower bound the plan reports.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError, SpecError
from ..linkage import trajectory
from ..mechanisms import Mechanism, mechanism_of
from ..model import Design
from ..model.motions import REVOLUTION, MotionSpec
from ..model.plan import PlanSpec, PlanWeights
from ..motion_analysis import MotionAnalysis, frame_reactions, motion_analysis
from .path_loads import PathLoads, load_rows, path_loads
from .transcription import Problem, Transcribed, constant_parts, mesh, solve

__all__ = ["Plan", "objective_of", "path_of", "plan_motion", "revolution"]


@dataclass(frozen=True)
class Plan:
    """A planned time law and what it buys.

    Attributes
    ----------
    spec
        The ``[plan]`` it answers.
    path
        The motion whose path is run, at its own time law (a revolution: at constant speed).
    planned
        The planned motion: ``path``'s path at the planned pace.
    problem
        The transcription.
    solution
        Its optimum.
    starts
        The transcription's optimum from each start: the path's own time law, and where that
        optimum is not certified global, a constant pace.
    before, after
        The loads along ``path`` and along ``planned`` (the core's analysis).
    objective_before, objective_after
        The objective ``J`` along each motion (:func:`objective_of`), in its squared units.
    bound
        A lower bound of ``J`` over every time law where one is known (from rest to rest:
        the shaking force's closed form), or ``None``.
    halved
        The transcription's optimum on half the intervals: their difference estimates the
        transcription's error (it bounds it where the error falls at first order or faster);
        ``None`` where half the mesh is no coarser (a segment per interval) or did not solve.
    """

    spec: PlanSpec
    path: MotionSpec
    planned: MotionSpec
    problem: Problem
    solution: Transcribed
    starts: tuple[float, ...]
    before: MotionAnalysis
    after: MotionAnalysis
    objective_before: float
    objective_after: float
    bound: float | None
    halved: float | None

    @property
    def mesh_error(self) -> float | None:
        """The transcription's error estimate: its optimum's change from half its mesh."""
        return None if self.halved is None else abs(self.solution.objective - self.halved)

    @property
    def certified(self) -> bool:
        """Whether the transcription's optimum is certified global (module docstring)."""
        return self.solution.certified


def revolution(speed: float, samples: int = 400) -> MotionSpec:
    """A one-input linkage's revolution from its reference pose at constant ``speed`` (rad/s)."""
    period = 2.0 * math.pi / abs(speed)
    return MotionSpec(name=REVOLUTION, times=(0.0, period),
                      path=((0.0,), (math.copysign(2.0 * math.pi, speed),)), law="spline",
                      samples=samples, along=REVOLUTION, pace=((0.0, 1.0), (period, 1.0)))


def path_of(design: Design, name: str | None, *, key: str = "plan.motion") -> MotionSpec:
    """The motion whose path a plan runs: by name, the first, or a one-input revolution."""
    inputs = mechanism_of(design.mechanism).linkage.inputs
    if name == REVOLUTION or (name is None and not design.motions):
        if len(inputs) != 1 or design.operation is None:
            raise SpecError("a revolution is a one-input linkage's at its [operation] speed; "
                            "name a [[motion]]" if design.motions or len(inputs) != 1 else
                            "a one-input linkage's revolution needs its [operation] speed",
                            key=key, value=name)
        return revolution(design.operation.speed)
    if name is None:
        return design.motions[0]
    found = next((m for m in design.motions if m.name == name), None)
    if found is None:
        known = [m.name for m in design.motions] + ([REVOLUTION] if len(inputs) == 1 else [])
        raise SpecError(f"names no motion of the spec ({', '.join(known)})", key=key,
                        value=name)
    return found


def weights_of(names: tuple[str, ...], weights: PlanWeights) -> NDArray[np.float64]:
    """Each load's weight in ``J`` (``names`` as :class:`~.path_loads.PathLoads`')."""
    w = weights
    table = {"shaking_force_x": w.shaking_force + w.shaking_force_x,
             "shaking_force_y": w.shaking_force + w.shaking_force_y,
             "shaking_moment": w.shaking_moment,
             "rocking_couple_x": w.rocking_couple, "rocking_couple_y": w.rocking_couple}
    return np.array([table.get(name, w.torque) for name in names])


#: Gauss–Legendre points per panel of :func:`objective_of`.
GAUSS_POINTS = 5
#: Panels at least along a motion in :func:`objective_of`.
LEAST_PANELS = 256


def objective_of(mech: Mechanism, motion: MotionSpec, weights: NDArray[np.float64],
                 measure: str, gravity: tuple[float, float] = (0.0, 0.0)) -> float:
    """``J`` along a motion: the weighted sum of its loads' squares, ``Σ w·L²``.

    Its mean over the motion's time (``"rms"``) by Gauss–Legendre quadrature on panels that
    end at the motion's breaks (:func:`~balancer.linkage.trajectory.break_times`: between
    them the loads are smooth), or its largest value at the quadrature's points and the
    panels' ends (``"peak"``).
    """
    ends = np.concatenate([[motion.start], trajectory.break_times(motion), [motion.end]])
    per = max(1, -(-LEAST_PANELS // (ends.size - 1)))
    edges = np.concatenate([np.linspace(a, b, per + 1)[:-1] for a, b in zip(ends[:-1], ends[1:],
                                                                         strict=True)]
                           + [ends[-1:]])
    nodes, gauss = np.polynomial.legendre.leggauss(GAUSS_POINTS)
    half = np.diff(edges)[:, None] / 2.0
    t = ((edges[:-1, None] + edges[1:, None]) / 2.0 + half * nodes).ravel()
    if measure == "peak":
        t = np.concatenate([t, edges])
    state = trajectory.input_state(mech.structure, motion, t)
    _, rows = load_rows(mech.linkage.inputs,
                        frame_reactions(mech, mech.motion_at(state), gravity=gravity))
    total = np.sum(weights[:, None] * rows**2, axis=0)
    if measure == "peak":
        return float(np.max(total))
    return float(np.sum((half * gauss) * total.reshape(half.size, GAUSS_POINTS))
                 / motion.duration)


def _rest_bound(loads: PathLoads, weights: NDArray[np.float64], duration: float,
                measure: str) -> float | None:
    """The closed-form lower bound of ``J`` from rest to rest (module docstring), if any.

    Along each axis the total centre of mass moves ``Δc`` from rest to rest in ``T``: its
    least ``∫c̈²`` is the cubic's ``12·Δc²/T³`` and its least peak ``|c̈|`` the bang-bang's
    ``4·|Δc|/T²``. The shaking force is ``−M·c̈`` plus the weights (a constant ``C``; the mean
    of ``c̈`` is zero), so ``mean(F²) ≥ C² + 12·(M·Δc)²/T⁴``. Only where the loads at rest
    are constant along the path (no spring or applied load), and for a peak only without them.
    """
    rows = [loads.index("shaking_force_x"), loads.index("shaking_force_y")]
    if not np.any(weights[rows] > 0):
        return None
    static = loads.static[rows]
    scale = max(float(np.max(np.abs(loads.inertial[rows]))), float(np.max(np.abs(static))),
                np.finfo(float).tiny)
    if np.max(np.abs(static - static[:, :1])) > 1e-12 * scale:
        return None
    moved = loads.first_moment[-1] - loads.first_moment[0]
    w = weights[rows]
    if measure == "peak":
        if np.max(np.abs(static)) > 1e-12 * scale:
            return None
        return float(max(w[0] * (4 * moved.real / duration**2) ** 2,
                         w[1] * (4 * moved.imag / duration**2) ** 2))
    return float(w[0] * (static[0, 0] ** 2 + 12 * moved.real**2 / duration**4)
                 + w[1] * (static[1, 0] ** 2 + 12 * moved.imag**2 / duration**4))


def _rate2_of(motion: MotionSpec, tau: NDArray[np.float64], duration: float
              ) -> NDArray[np.float64]:
    """The motion's own ``τ̇²`` at arguments ``tau``, its time scaled to ``duration``."""
    low = np.full(tau.shape, motion.start)
    high = np.full(tau.shape, motion.end)
    for _ in range(64):  # τ(t) increases: bisection
        mid = 0.5 * (low + high)
        below = trajectory.time_argument(motion, mid)[0] < tau
        low, high = np.where(below, mid, low), np.where(below, high, mid)
    rate = trajectory.time_argument(motion, 0.5 * (low + high))[1]
    return np.asarray(rate, dtype=float) ** 2 * (motion.duration / duration) ** 2


#: Past this many seconds of solving, a plan makes no optional solve (another start, the
#: half-mesh estimate).
OPTIONAL_SECONDS = 10.0
#: A plan's duration at most this factor from its motion's own, either way.
DURATION_RANGE = 1e6
#: A limit's value within this factor of 1 in SI units, either way (its square stays finite).
LIMIT_RANGE = 1e100


def check_plan(mech: Mechanism, path: MotionSpec, spec: PlanSpec) -> None:
    """Refuse a plan that does not fit its mechanism and path (keys within ``[plan]``).

    Its limits name the mechanism's inputs and stay within :data:`LIMIT_RANGE`; its duration
    within :data:`DURATION_RANGE` of the motion's own; its mesh gives each of the path's
    segments an interval at least (the waypoints are its rows).
    """
    inputs = mech.linkage.inputs
    for key in ("max_speed", "max_acceleration", "max_torque"):
        limits = getattr(spec, key)
        for name, value in ((None, limits.every), *limits.each):
            where = f"plan.{key}" if name is None else f"plan.{key}.{name}"
            if name is not None and name not in inputs:
                raise SpecError(f"must name an input ({', '.join(inputs)})", key=where,
                                value=name)
            if value is not None and not 1 / LIMIT_RANGE <= value <= LIMIT_RANGE:
                raise SpecError(f"must be within {1 / LIMIT_RANGE:g} to {LIMIT_RANGE:g}",
                                key=where, value=value)
    if spec.duration is not None and not (path.duration / DURATION_RANGE <= spec.duration
                                          <= path.duration * DURATION_RANGE):
        raise SpecError(f"must be within {DURATION_RANGE:g} times the motion's own "
                        f"({path.duration:g} s) either way", key="plan.duration",
                        value=spec.duration)
    segments = len(path.times) - 1
    if spec.intervals is not None and spec.intervals < segments:
        raise SpecError(f"must be at least the path's segments ({segments}): its waypoints are "
                        "the transcription's rows", key="plan.intervals", value=spec.intervals)
    if spec.intervals_for(segments) > PlanSpec.INTERVALS[1]:
        raise SpecError(f"the path has {segments} segments, more than a transcription takes "
                        f"({PlanSpec.INTERVALS[1]}): resample the motion",
                        key="plan.intervals")


def plan_motion(mech: Mechanism, path: MotionSpec, spec: PlanSpec, *,
                gravity: tuple[float, float] = (0.0, 0.0)) -> Plan:
    """The time law of ``path``'s path that ``spec`` asks for (module docstring).

    Parameters
    ----------
    mech
        The mechanism.
    path
        The motion whose path is run (a revolution: :func:`revolution`).
    spec
        The plan.
    gravity
        ``(gx, gy)``, m/s², that the loads include.

    Raises
    ------
    SpecError
        If a limit names an unknown input.
    AssemblyError
        If the path leaves the workspace.
    SolverError
        If the limits cannot be met in the duration, or IPOPT fails.
    """
    check_plan(mech, path, spec)
    duration = path.duration if spec.duration is None else spec.duration
    intervals = spec.intervals_for(len(path.times) - 1)
    problem = _problem(mech, path, spec, intervals, duration, gravity)
    tau, weights = problem.loads.tau, problem.weights
    own = _rate2_of(path, tau, duration)
    steady = np.full(tau.shape, (problem.span / duration) ** 2)
    solutions: list[Transcribed] = []
    failures: list[SolverError] = []
    began = time.perf_counter()
    for start in (own, steady):
        if solutions and (solutions[0].certified or np.allclose(own, steady, rtol=1e-12,
                                                                atol=0.0)
                          or time.perf_counter() - began > OPTIONAL_SECONDS):
            break  # (a global optimum, one start, or no time for another)
        try:
            solutions.append(solve(problem, start))
        except SolverError as exc:
            failures.append(exc)
    if not solutions:
        raise failures[0]
    best = min(solutions, key=lambda s: s.objective)
    halved = None
    coarse_intervals = intervals // 2
    if (coarse_intervals >= len(path.times) - 1 and coarse_intervals >= 2
            and time.perf_counter() - began <= OPTIONAL_SECONDS):
        try:  # (an estimate of the mesh's error: not worth failing the plan for)
            coarse = _problem(mech, path, spec, coarse_intervals, duration, gravity)
            halved = solve(coarse, _rate2_of(path, coarse.loads.tau, duration)).objective
        except SolverError:
            halved = None
    rate = np.sqrt(np.maximum(best.rate2, 0.0))
    rate *= float(np.sum(problem.times(best.rate2))) / duration  # (the duration to rounding)
    name = spec.name or f"{path.name} planned"
    planned = replace(path, name=name, along=path.along or path.name,
                      pace=tuple((float(t), float(r)) for t, r in zip(tau, rate, strict=True)),
                      acc_time=None if path.law != "trapezoid" else path.acc_time)
    before = motion_analysis(mech, path, gravity=gravity)
    after = motion_analysis(mech, planned, gravity=gravity)
    return Plan(spec=spec, path=path, planned=planned, problem=problem, solution=best,
                starts=tuple(s.objective for s in solutions), before=before, after=after,
                objective_before=objective_of(mech, path, weights, spec.measure, gravity),
                objective_after=objective_of(mech, planned, weights, spec.measure, gravity),
                bound=None if path.periodic else _rest_bound(problem.loads, weights, duration,
                                                             spec.measure),
                halved=halved)


def _problem(mech: Mechanism, path: MotionSpec, spec: PlanSpec, intervals: int,
             duration: float, gravity: tuple[float, float]) -> Problem:
    """The transcription of ``spec`` on ``intervals`` intervals of ``path``'s path."""
    inputs = mech.linkage.inputs
    tau = mesh(np.asarray(path.times, dtype=float), intervals)
    loads = path_loads(mech, path, tau, gravity)
    return Problem(loads=loads, weights=weights_of(loads.names, spec.objective),
                   duration=duration, measure=spec.measure, periodic=path.periodic,
                   max_speed=tuple(spec.max_speed.of(n) for n in inputs),
                   max_acceleration=tuple(spec.max_acceleration.of(n) for n in inputs),
                   max_load=tuple(spec.max_torque.of(n) for n in inputs),
                   offsets=(constant_parts(loads) if spec.measure == "rms"
                            else np.zeros(len(loads.names))))
