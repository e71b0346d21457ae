"""Exact trade-off fronts: the least RMS shaking moment against a second objective.

A designer chooses between the shaking moment and the driving torque, the mass added, or (when
force balance is not imposed) the shaking force. With the redesign problem's constraints (force
balance, every link's bounds: :mod:`.convex`), each of them is convex in the design vector —
the RMS driving torque and RMS shaking force are norms ``‖R·x‖`` of their regressor factors, the
added mass is linear — so the front is traced by the ε-constraint method, each point a second-
order cone program solved to its global optimum:

    S(ε) = min ‖R_M·x‖  subject to  g(x) ≤ ε  and the balancing constraints,

with ``ε`` on an even grid from ``g``'s least value over the feasible designs to its least
value among the designs of least shaking moment (the two ends of the front; a lexicographic
solve each). ``S`` is convex and non-increasing in ``ε``; each point carries the certified lower
bound of its program (weak duality, :func:`.certificate.lower_bound`, with the ε-constraint
as one more cone). The designs are repaired onto the bounds exactly
(:meth:`.convex.ConvexSolver.finalize`), and both objectives are reported for the design that
results. The knee is the point farthest from the chord between the ends, each objective
measured over its range.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError, SpecError
from ..force_balance import RESIDUAL_FLOOR, force_balance_residual
from ..model import Design
from ..model.balance import Objective, RotorBalanceProblem, missing_balance
from .certificate import Constraint, ConvexObjective, lower_bound
from .conic import ACCURACY_FALLBACKS, ConicProgram, ConicSolution, solve_program
from .convex import (
    CERTIFY_AGAIN,
    Compressed,
    ConvexSolver,
)
from .front import AGAINST, Against, Front, FrontPoint, mark_knee
from .problem import NumericProblem, numeric_problem
from .rotor_front import rotor_front

#: Most points of one front (each a conic program: ~10 ms).
MAX_POINTS = 1000
#: Room given to an end of the front when it becomes a constraint (relative to the objective's
#: scale): a hundred times Clarabel's tolerance, so that the constrained program stays feasible.
END_ROOM = 1e-8


class _Programs:
    """The ε-constraint programs of one redesign problem, in the convex solver's variables."""

    def __init__(self, data: NumericProblem, against: Against) -> None:
        self.data = data
        self.solver = solver = ConvexSolver(data)
        lay = solver.layout
        self.n = lay.size
        self.equality = solver.equality
        n_samples = data.samples
        reg = data.regressors
        # (R alone: numpy's stubs say qr gives a QRResult whatever its mode.)
        moment = cast("NDArray[np.float64]",
                      np.linalg.qr(reg.shaking_moment / math.sqrt(n_samples), mode="r"))
        self.moment_scale = _scale(moment, data)
        self.moment = Compressed.of(moment @ lay.T / self.moment_scale,
                                    moment @ lay.c / self.moment_scale)
        self.moment_full = ConvexObjective(P=moment @ lay.T / self.moment_scale,
                                           q=moment @ lay.c / self.moment_scale, norm=True,
                                           g=np.zeros(self.n), g0=0.0)
        self.against = against
        if against == "added-mass":
            self.other_scale = data.original_mass
            self.mass_row = lay.T[data.mass_entries].sum(axis=0) / self.other_scale
            self.mass_offset = (float(lay.c[data.mass_entries].sum()) - data.original_mass) \
                / self.other_scale
        else:
            if against == "driving-torque":  # (several inputs: every input's rows, stacked)
                rows, count = reg.driving_torque, reg.driving_torque.shape[0]
            else:  # (x and y: the mean square of the magnitude over the samples)
                rows = np.vstack([reg.shaking_force.real, reg.shaking_force.imag])
                count = n_samples
            factor = cast("NDArray[np.float64]",
                          np.linalg.qr(rows / math.sqrt(count), mode="r"))  # (as above)
            self.other_scale = _scale(factor, data)
            self.other = Compressed.of(factor @ lay.T / self.other_scale,
                                       factor @ lay.c / self.other_scale)

    def other_value(self, x: NDArray[np.float64]) -> float:
        """The second objective of design vector ``x`` (its unit), from the full regressors."""
        data = self.data
        reg = data.regressors
        if self.against == "added-mass":
            return data.total_mass(x) - data.original_mass
        if self.against == "driving-torque":
            return float(np.sqrt(np.mean((reg.driving_torque @ x) ** 2)))
        return float(np.sqrt(np.mean(np.abs(reg.shaking_force @ x) ** 2)))

    def moment_value(self, x: NDArray[np.float64]) -> float:
        """RMS shaking moment of design vector ``x``, N·m, from the full regressors."""
        return float(np.sqrt(np.mean((self.data.regressors.shaking_moment @ x) ** 2)))

    def cap(self, epsilon: float) -> Constraint:
        """``g ≤ ε`` as a cone constraint in the solver's variables (``ε`` in its unit)."""
        e = epsilon / self.other_scale
        if self.against == "added-mass":
            return Constraint("nonneg", -self.mass_row[None, :],
                              np.array([e - self.mass_offset]))
        c = self.other
        return Constraint("soc", np.vstack([np.zeros((1, self.n)), c.P]),
                          np.concatenate([[e], c.q]))

    def moment_cap(self, value: float) -> Constraint:
        """``RMS shaking moment ≤ value`` (N·m) as a cone constraint."""
        c = self.moment
        return Constraint("soc", np.vstack([np.zeros((1, self.n)), c.P]),
                          np.concatenate([[value / self.moment_scale], c.q]))

    def least_other(self, extra: list[Constraint]) -> ConicSolution:
        """The program ``min g`` within the bounds and ``extra``; its solution."""
        cones = [*self.solver.constraints, *extra]
        if self.against == "added-mass":
            program = ConicProgram(self.n, cones, equality=self.equality, objective="squares",
                                   P=np.zeros((0, self.n)), q=np.zeros(0), g=self.mass_row)
        else:
            program = ConicProgram(self.n, cones, equality=self.equality, objective="norm",
                                   P=self.other.P, q=self.other.q)
        return solve_program(program, self.solver.settings)

    def least_moment(self, extra: list[Constraint], settings: dict[str, Any] | None = None
                     ) -> ConicSolution:
        """The program ``min ‖R_M·x‖`` within the bounds and ``extra``; its solution.

        ``settings``: Clarabel's, over the solver's (another solve's, for a tighter bound).
        """
        program = ConicProgram(self.n, [*self.solver.constraints, *extra], equality=self.equality,
                               objective="norm", P=self.moment.P, q=self.moment.q)
        return solve_program(program, {**self.solver.settings, **(settings or {})})


def _scale(factor: NDArray[np.float64], data: NumericProblem) -> float:
    """A positive scale of ``‖factor·x‖``: the original design's, else what the inertias make."""
    value = float(np.linalg.norm(factor @ data.x0))
    if value > 0:
        return value
    value = float(np.linalg.norm(factor * data.scales, 2))
    return value if value > 0 else 1.0


def pareto_front(design: Design, against: Against, points: int = 11) -> Front:
    """The front of least RMS shaking moment against ``against`` (see the module docstring).

    An engine's balancing (a :class:`~balancer.model.balance.RotorBalanceProblem`) has its
    own front: :func:`.rotor_front.rotor_front`.

    Parameters
    ----------
    design
        A design with ``[balance]`` and ``[operation]``.
    against
        ``"driving-torque"``, ``"added-mass"`` or ``"shaking-force"``.
    points
        Number of points, the two ends included (at least 2).

    Raises
    ------
    SpecError
        For an unknown second objective, fewer than two points, or a front against the shaking
        force of a problem that imposes force balance (it is zero at every point).
    InfeasibleError, SolverError
        If the balancing problem has no feasible design, or Clarabel fails.
    """
    if against not in AGAINST:
        raise SpecError(f"must be one of {', '.join(AGAINST)}", key="--against", value=against)
    if design.balance is None:
        raise missing_balance(design.mechanism)
    if not 2 <= points <= MAX_POINTS:
        raise SpecError(f"a front has from 2 to {MAX_POINTS} points", key="--points",
                        value=points)
    if isinstance(design.balance, RotorBalanceProblem):
        return rotor_front(design, against, points)
    if against == "shaking-force" and design.balance.force_balance:
        raise SpecError("with force balance imposed the shaking force is zero at every point: "
                        "there is no front against it; set [balance] force_balance = false to "
                        "trade the shaking force against the shaking moment",
                        key="--against", value=against)
    # The problem with both objectives weighted, so that the entries it leaves out as inert
    # (:attr:`NumericProblem.inert`) are those that neither sees.
    weights = Objective(shaking_moment=1.0,
                        driving_torque=1.0 if against == "driving-torque" else 0.0,
                        shaking_force=1.0 if against == "shaking-force" else 0.0)
    data = numeric_problem(replace(design, balance=replace(design.balance, objective=weights)))
    programs = _Programs(data, against)
    solver = programs.solver
    solver.check_consistent()
    # The moment's end: its least value, then the least g among the designs that reach it.
    best = programs.least_moment([])
    if best.u is None:
        raise solver.infeasible(f"Clarabel: {best.status}")
    moment_min = programs.moment_value(solver.layout.x(best.u))
    room = END_ROOM * programs.moment_scale
    top = programs.least_other([programs.moment_cap(moment_min + room)])
    high_u = top.u if top.u is not None else best.u
    high = programs.other_value(solver.layout.x(high_u))
    # The other end: g's least value.
    low_solution = programs.least_other([])
    if low_solution.u is None:
        raise SolverError(f"the least {AGAINST[against][0]} could not be found "
                          f"(Clarabel: {low_solution.status})")
    low = programs.other_value(solver.layout.x(low_solution.u))
    slack = END_ROOM * programs.other_scale
    if high - low <= slack:
        grid = [high + slack]
    else:
        grid = list(np.linspace(low + slack, high + slack, points))
    out: list[FrontPoint] = []
    for epsilon in grid:
        cap = programs.cap(epsilon)
        solution = programs.least_moment([cap])
        if solution.u is None:
            raise SolverError(f"a point of the front (ε = {epsilon:.6g} {programs.against}) "
                              f"could not be solved (Clarabel: {solution.status})")
        x, _ = solver.repair(solution.u)
        x = data.settle(x)
        x, _ = solver.finalize(x)
        least = programs.moment_value(x)
        bound = _certified(programs, cap, solution, x)
        # A dual off by more than its tolerance leaves the bound loose: solved again with other
        # settings, the highest bound kept (each valid by weak duality), as the convex
        # program's certificate is (ConvexSolver._certified).
        for settings in ACCURACY_FALLBACKS:
            if least - bound <= CERTIFY_AGAIN * programs.moment_scale:
                break
            again = programs.least_moment([cap], settings)
            if again.u is not None:
                bound = max(bound, _certified(programs, cap, again, x))
        out.append(FrontPoint(least=least,
                              value=programs.other_value(x), epsilon=float(epsilon),
                              lower_bound=bound, x=x))
    out.sort(key=lambda p: p.value)
    original = (programs.other_value(data.x0), programs.moment_value(data.x0))
    notes = (() if design.balance.max_speed_fluctuation is None else (
        "[balance] max_speed_fluctuation: the flywheel it asks for is not put on the points' "
        "cranks (it changes none of their figures); optimize sizes it",))
    return Front(against=against, points=tuple(mark_knee(out)), original=original,
                 force_balance=design.balance.force_balance,
                 original_force_balanced=force_balance_residual(data.mechanism) <= RESIDUAL_FLOOR,
                 notes=notes)


def _certified(programs: _Programs, cap: Constraint, solution: ConicSolution,
               x: NDArray[np.float64]) -> float:
    """The certified least RMS shaking moment under ``cap``, N·m (0 where none is made)."""
    solver = programs.solver
    assert solution.u is not None  # solved: the caller has checked
    lo, hi = solver.box()
    upper = programs.moment_full.value(solver.layout.u(x))
    norm_dual = None
    if solution.epigraph_dual is not None:
        norm_dual = -(programs.moment.basis @ solution.epigraph_dual[1:])
    bound = lower_bound(programs.moment_full, [*solver.constraints, cap], programs.equality,
                        solution.u, list(solution.duals), norm_dual, lo, hi,
                        upper + abs(upper) + 1e-9)
    if bound is None:
        return 0.0
    return max(bound.value, 0.0) * programs.moment_scale
