"""The time-law problem transcribed on a mesh of the path's argument, solved by IPOPT.

Unknowns: the squared rate ``bₖ = τ̇²`` at the mesh's arguments ``τ₀ < … < τ_N``; between two
the argument's acceleration is constant, ``aₖ = (bₖ₊₁ − bₖ)/(2·Δτₖ)``, so the interval lasts
``Δtₖ = 2·Δτₖ/(√bₖ + √bₖ₊₁)`` and the time law is exact between the rows (a pace,
:attr:`balancer.model.motions.MotionSpec.pace`). At each row the loads are
``Lₖ = Aₖ·a + Bₖ·bₖ + Cₖ`` (:mod:`.path_loads`) with the acceleration of the interval before
and of the interval after — and at a waypoint, the coefficients of the path's piece each
interval runs on (its curvature jumps there).

- ``"rms"``: ``J = (1/T)·Σₖ Δtₖ/2·(Σ w·L²(τₖ, aₖ) + Σ w·L²(τₖ₊₁, aₖ))``, the trapezoid rule
  in time of the weighted mean square.
- ``"peak"``: ``J = z`` with ``Σ w·L² ≤ z`` at every row, on both sides.
- ``Σ Δtₖ = T``; periodic: ``b₀ = b_N``; ``q'ᵢ²·bₖ ≤ vᵢ²`` (bounds on ``b``);
  ``|q''ᵢ·bₖ + q'ᵢ·a| ≤ αᵢ`` and ``|L_τᵢ| ≤ τᵢ`` on both sides of each row.

Each term is convex in ``b``: ``Σ w·L²`` is convex quadratic (``L`` affine in ``b``), and a
convex non-negative quadratic over the concave positive ``√bₖ + √bₖ₊₁`` is convex; the limits
are linear (Verscheure, Demeulenaere, Swevers, De Schutter & Diehl 2009, IEEE TAC 54(10), for
the time-optimal problem). With ``Σ Δtₖ ≤ T`` (convex) in place of the equality the problem is
convex, and IPOPT's KKT point its global optimum; where that optimum lasts ``T`` it is the
transcription's (:attr:`Transcribed.certified`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError
from .path_loads import PathLoads

#: IPOPT's tolerance on the scaled problem (objective and constraints of order one).
TOLERANCE = 1e-10
#: Iterations at most.
MAX_ITERATIONS = 3000
#: IPOPT's time at most per solve, s (an unattainable limit is declared so, not waited on).
MAX_SECONDS = 20.0
#: IPOPT's ends short of its tolerance that are its optimum where the limits hold: at an
#: objective of zero (a constant pace that shakes nothing) its steps become too small.
SETTLED = ("Solved_To_Acceptable_Level", "Search_Direction_Becomes_Too_Small")
#: How near the convex relaxation's optimum a motion lasting ``T`` must come to be certified.
BOUND_TOLERANCE = 1e-8
#: A convex optimum lasting less than ``T`` by this share ends early.
EARLY = 1e-8
#: The least squared rate, as a share of the mean's (IPOPT keeps within bounds: √b stays real).
LEAST_RATE2 = 1e-10


@dataclass(frozen=True, eq=False)
class Problem:
    """A time-law problem on a mesh (module docstring).

    Attributes
    ----------
    loads
        The loads at the mesh's arguments.
    weights
        Each load's weight, ``(len(loads.names),)``.
    duration
        ``T``, s.
    measure
        ``"rms"`` or ``"peak"``.
    periodic
        Whether ``b₀ = b_N``.
    max_speed, max_acceleration, max_load
        Per input: its limit or ``None``.
    offsets
        Each load's constant part taken out of a mean square (:func:`constant_parts`), in its
        unit; zeros for a peak.
    """

    loads: PathLoads
    weights: NDArray[np.float64]
    duration: float
    measure: str
    periodic: bool
    max_speed: tuple[float | None, ...]
    max_acceleration: tuple[float | None, ...]
    max_load: tuple[float | None, ...]
    offsets: NDArray[np.float64]

    @cached_property
    def compiled(self) -> _Compiled:
        """Its NLP, built once for every start and for the duration relaxed or held."""
        return _compile(self)

    @property
    def span(self) -> float:
        """The path argument's span, s."""
        return float(self.loads.tau[-1] - self.loads.tau[0])

    def times(self, rate2: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each interval's duration at squared rates ``rate2``, s."""
        root = np.sqrt(np.maximum(rate2, 0.0))
        return 2.0 * np.diff(self.loads.tau) / (root[:-1] + root[1:])

    def accelerations(self, rate2: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each interval's argument acceleration ``aₖ``, 1/s."""
        return np.diff(rate2) / (2.0 * np.diff(self.loads.tau))

    def sides(self, rate2: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                          NDArray[np.float64]]:
        """The loads at each interval's start and end, ``(loads, N)`` each."""
        a = self.accelerations(rate2)
        at, to = self.loads, self.loads.arriving
        start = at.inertial[:, :-1] * a + at.centripetal[:, :-1] * rate2[:-1] + at.static[:, :-1]
        end = to.inertial[:, 1:] * a + to.centripetal[:, 1:] * rate2[1:] + to.static[:, 1:]
        return start, end

    def natural_objective(self) -> float:
        """``J``'s natural scale: each load's coefficients at a constant pace, summed unsigned.

        ``mean Σ w·(|A|·s/T² + |B|·s²/T² + |C − C₀|)²`` over the rows, ``s`` the argument's
        span, ``C₀`` the constant parts taken out: what the objective is measured against
        where the spec's own law makes it vanish.
        """
        at, span = self.loads, self.span
        typical = (np.abs(at.inertial) * span / self.duration**2
                   + np.abs(at.centripetal) * (span / self.duration) ** 2
                   + np.abs(at.static - self.offsets[:, None]))
        return float(np.mean(np.sum(self.weights[:, None] * typical**2, axis=0)))

    def objective(self, rate2: NDArray[np.float64]) -> float:
        """``J`` at squared rates ``rate2`` (in the loads' squared units).

        A mean square of loads less their constant parts, plus the parts' squares.
        """
        start, end = self.sides(rate2)
        start, end = start - self.offsets[:, None], end - self.offsets[:, None]
        w = self.weights[:, None]
        left, right = np.sum(w * start**2, axis=0), np.sum(w * end**2, axis=0)
        if self.measure == "peak":
            return float(max(left.max(), right.max()))
        return float(np.sum(self.times(rate2) * (left + right) / 2.0) / self.duration
                     + np.sum(self.weights * self.offsets**2))


@dataclass(frozen=True, eq=False)
class Transcribed:
    """A solved transcription.

    Attributes
    ----------
    rate2
        The optimal ``bₖ = τ̇²`` at the mesh's arguments.
    objective
        ``J`` there.
    violation
        The largest constraint violation, as a share of each constraint's scale.
    certified
        Whether the optimum is certified global for the transcription (the convex problem's,
        its duration ``T``).
    ends_early
        Whether the convex problem's optimum lasts less than ``T`` (then not the answer).
    iterations
        IPOPT's iterations.
    """

    rate2: NDArray[np.float64]
    objective: float
    violation: float
    certified: bool
    ends_early: bool
    iterations: int


def solve(problem: Problem, start: NDArray[np.float64]) -> Transcribed:
    """The optimal squared rates from squared rates ``start`` (module docstring).

    The convex problem first (its duration at most ``T``); where its optimum ends early (a
    faster motion shakes less: loads at rest dominate), the problem with the duration exactly
    ``T``, whose optimum is local — certified global where it reaches the convex one's bound.

    Raises
    ------
    SolverError
        If IPOPT does not converge, or the limits cannot all be met.
    """
    convex = _solve(problem, start, relaxed=True)
    if not convex.ends_early:
        return convex
    held = _solve(problem, convex.rate2, relaxed=False)
    # The convex optimum bounds every motion's from below: one that lasts T and reaches it
    # (a shorter motion only ties) is global too.
    reached = held.objective <= convex.objective + BOUND_TOLERANCE * abs(convex.objective)
    return replace(held, certified=reached) if reached else held


@dataclass(frozen=True, eq=False)
class _Compiled:
    """A problem's NLP, built once: IPOPT's solver and the bounds of its unknowns and rows.

    ``low`` holds the duration's row exactly (``T``); :func:`_solve` relaxes it.
    """

    solver: Any
    low: NDArray[np.float64]
    high: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    scale2: float
    reference: float


def _compile(problem: Problem) -> _Compiled:
    """The NLP of ``problem`` (module docstring), scaled to unknowns and a cost of order one."""
    import casadi as ca

    at = problem.loads
    count = at.tau.size
    scale2 = (problem.span / problem.duration) ** 2  # the mean squared rate
    b_hat = ca.SX.sym("b", count)
    b = b_hat * scale2
    dtau = np.diff(at.tau)
    a = (b[1:] - b[:-1]) / (2.0 * dtau)
    root = ca.sqrt(b)
    dt = 2.0 * dtau / (root[:-1] + root[1:])
    constant = float(np.sum(problem.weights * problem.offsets**2))  # (not IPOPT's to see)
    steady = np.full(count, scale2)
    reference = max(problem.objective(steady) - constant, problem.natural_objective(),
                    np.finfo(float).tiny)
    constraints: list[Any] = [(ca.sum1(dt) - problem.duration) / problem.duration]
    low: list[float] = [0.0]
    high: list[float] = [0.0]

    to = at.arriving  # (an interval's end: the path's piece it arrives on)

    def sides(row: int) -> tuple[Any, Any]:
        start_ = at.inertial[row, :-1] * a + at.centripetal[row, :-1] * b[:-1] \
            + at.static[row, :-1]
        end_ = to.inertial[row, 1:] * a + to.centripetal[row, 1:] * b[1:] + to.static[row, 1:]
        return start_, end_

    left: Any = ca.SX.zeros(count - 1)
    right: Any = ca.SX.zeros(count - 1)
    for row, weight in enumerate(problem.weights):
        if weight > 0:
            s, e = sides(row)
            left += weight * (s - problem.offsets[row]) ** 2
            right += weight * (e - problem.offsets[row]) ** 2
    if problem.measure != "peak":  # (the constant parts' squares added back by objective())
        cost = ca.sum1(dt * (left + right) / 2.0) / problem.duration / reference
        unknowns = b_hat
    else:
        peak = ca.SX.sym("z")
        cost = peak
        unknowns = ca.vertcat(b_hat, peak)
        constraints += [(left / reference - peak), (right / reference - peak)]
        low += [-math.inf] * 2 * (count - 1)
        high += [0.0] * 2 * (count - 1)
    if problem.periodic:
        constraints.append(b_hat[0] - b_hat[-1])
        low.append(0.0)
        high.append(0.0)
    for i, limit in enumerate(problem.max_acceleration):
        if limit is None:
            continue
        for side, of in ((slice(None, -1), at), (slice(1, None), to)):
            q_acc = of.curvature[i, side] * b[side] + of.slope[i, side] * a
            constraints.append(q_acc / limit)
            low += [-1.0] * (count - 1)
            high += [1.0] * (count - 1)
    for i, limit in enumerate(problem.max_load):
        if limit is None:
            continue
        row = at.index(at.names[5 + i])
        for load in sides(row):
            constraints.append(load / limit)
            low += [-1.0] * (count - 1)
            high += [1.0] * (count - 1)
    upper = np.full(count, math.inf)
    lower = np.full(count, LEAST_RATE2)
    for i, limit in enumerate(problem.max_speed):
        if limit is not None:
            with np.errstate(divide="ignore"):
                steepest = np.maximum(at.slope[i] ** 2, to.slope[i] ** 2)
                own = limit**2 / steepest / scale2
            if np.any(own < lower):
                raise SolverError(f"plan.max_speed: input {at.names[5 + i][len('torque_'):]}'s "
                                  f"limit {limit:g} all but stops the motion on its path "
                                  f"in {problem.duration:g} s: widen it or lengthen the "
                                  "duration")
            upper = np.minimum(upper, own)
    solver = ca.nlpsol("plan", "ipopt", {"x": unknowns, "f": cost,
                                         "g": ca.vertcat(*constraints)},
                       {"print_time": False,
                        "ipopt": {"print_level": 0, "sb": "yes", "tol": TOLERANCE,
                                  "bound_relax_factor": 0.0,  # (√b of b within its bounds)
                                  "max_iter": MAX_ITERATIONS, "max_cpu_time": MAX_SECONDS,
                                  # (adaptive μ stalls on a peak's many constraints)
                                  "mu_strategy": "monotone"}})
    return _Compiled(solver=solver, low=np.array(low), high=np.array(high), lower=lower,
                     upper=upper, scale2=scale2, reference=reference)


def _solve(problem: Problem, start: NDArray[np.float64], *, relaxed: bool) -> Transcribed:
    """:func:`solve` with the duration at most ``T`` (``relaxed``) or exactly ``T``.

    On the problem's one NLP (:attr:`Problem.compiled`), from squared rates ``start``.
    """
    nlp = problem.compiled
    count = problem.loads.tau.size
    scale2 = nlp.scale2
    low = nlp.low.copy()
    if relaxed:
        low[0] = -math.inf
    x0 = np.clip(start / scale2, nlp.lower, np.minimum(nlp.upper, 1e6))
    lbx, ubx = nlp.lower, np.minimum(nlp.upper, 1e12)
    if problem.measure == "peak":
        first = np.asarray(problem.sides(x0 * scale2))
        x0 = np.append(x0, 1.5 * float(np.max(np.sum(problem.weights[None, :, None]
                                                            * first**2, axis=1)))
                       / nlp.reference)
        lbx, ubx = np.append(lbx, 0.0), np.append(ubx, math.inf)
    result = nlp.solver(x0=x0, lbx=lbx, ubx=ubx, lbg=low, ubg=nlp.high)
    stats = nlp.solver.stats()
    values = np.asarray(result["g"]).ravel()
    violation = float(np.max(np.maximum(low - values, values - nlp.high), initial=0.0))
    if stats["return_status"] == "Maximum_CpuTime_Exceeded":
        raise SolverError(f"IPOPT did not solve the time law within {MAX_SECONDS:g} s: take "
                          f"fewer intervals (its mesh has {count - 1})")
    limited = any(x is not None for x in (*problem.max_speed, *problem.max_acceleration,
                                           *problem.max_load))
    if not stats["success"] and violation > 1e-6 and limited:
        raise SolverError(f"the time law cannot meet its limits in {problem.duration:g} s "
                          f"(IPOPT: {stats['return_status']}; largest violation "
                          f"{violation:.2g} of a limit): lengthen the duration or widen them")
    if not stats["success"] and (stats["return_status"] not in SETTLED or violation > 1e-8):
        raise SolverError(f"IPOPT did not converge on the time law ({stats['return_status']}; "
                          f"largest constraint violation {violation:.2g})")
    rate2 = np.asarray(result["x"]).ravel()[:count] * scale2
    early = bool(values[0] < -EARLY)
    return Transcribed(rate2=rate2, objective=problem.objective(rate2), violation=violation,
                       certified=relaxed and not early and bool(stats["success"]),
                       ends_early=relaxed and early, iterations=int(stats["iter_count"]))


#: The loads that are a momentum's rate of change on the frame (with their parts at rest): a
#: constant part of one adds its square to a mean square, its cross term with the rest being
#: the constant times the momentum's change — zero from rest to rest and over a period.
MOMENTUM_RATES = ("shaking_force_x", "shaking_force_y", "shaking_moment", "rocking_couple_x",
                  "rocking_couple_y")


def constant_parts(loads: PathLoads) -> NDArray[np.float64]:
    """Each load's part at rest where it is constant along the path and a momentum's rate.

    The weights (``M·g``, constant) in a shaking force: its mean square over ``T`` is the
    weights' square plus the mean square of the rest, whatever the time law; taken out of
    the transcription, a motion that ends early does not gain by carrying them for less time.
    """
    out = np.zeros(len(loads.names))
    for name in MOMENTUM_RATES:
        row = loads.index(name)
        static = loads.static[row]
        scale = max(float(np.max(np.abs(loads.inertial[row]))),
                    float(np.max(np.abs(loads.centripetal[row]))),
                    float(np.max(np.abs(static))), np.finfo(float).tiny)
        if np.max(np.abs(static - static[0])) <= 1e-12 * scale:
            out[row] = static[0]
    return out


def mesh(knots: NDArray[np.float64], intervals: int) -> NDArray[np.float64]:
    """``intervals`` intervals of the path's argument, the waypoints' among the rows.

    Each segment between waypoints gets intervals in proportion to its length (at least one,
    by largest remainders), equally spaced within it.
    """
    lengths = np.diff(knots)
    share = intervals * lengths / lengths.sum()
    counts = np.maximum(1, np.floor(share).astype(int))
    while counts.sum() < intervals:
        counts[int(np.argmax(share - counts))] += 1
    while counts.sum() > intervals and np.any(counts > 1):
        counts[int(np.argmax(np.where(counts > 1, counts - share, -np.inf)))] -= 1
    rows = [np.linspace(a, b, n + 1)[:-1] for a, b, n in zip(knots[:-1], knots[1:], counts,
                                                           strict=True)]
    return np.concatenate([*rows, knots[-1:]])
