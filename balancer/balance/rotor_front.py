"""An engine's trade-off front: the least shaking against the mass·radius its balancing adds.

DESIGN.md, "Balancing an engine": ``pareto --against added-mass`` for an engine bounds the sum of
the chosen ``|mr|`` (kg·m; their masses, kg, where ``[balance.counterweights] radius`` is given —
the new shafts' eccentrics then counted at the same radius). What it minimises is the spec's
objective without its unbalance term, ``J'`` (:mod:`.sites`; the bound on the masses takes the
unbalance term's place): where ``J'`` weighs one quantity alone the front is of that quantity's
RMS (the RMS rocking couple by default), else of ``√J'``, the weighted RMS (N·m).

Each point is the balancing's convex program (:class:`.convex.ConvexSolver`, in its scaled
variables ``u = x/max_mr``, ``‖u_i‖ ≤ 1``) with one more variable per mass·radius,
``t_i ≥ ‖u_i‖``, and the cap

    Σ c_i·t_i ≤ ε,   c_i = max_mr_i (kg·m) or max_mr_i/radius (kg),

so that ``Σ c_i·t_i`` bounds ``Σ |mr_i|`` (or the masses): a second-order cone program, solved
by Clarabel, with its certified lower bound (:func:`.certificate.lower_bound`, over the box
``|u| ≤ 1``, ``0 ≤ t ≤ 1``, which holds a minimiser: ``t_i = ‖u_i‖`` is feasible whenever any
``t`` is). ``ε`` runs on an even grid from nothing added to the least sum among the designs of
least ``J'`` (the front's two ends). Where ``J'`` weighs the largest main-bearing load, its
epigraph variable ``τ`` (:mod:`.largest`) follows the ``t_i``, with its cones and its row of
the objective; in the certificate's box ``τ`` lies within what the box's ``u`` can make of it.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError, SpecError
from ..model import Design
from ..model.balance import RotorBalanceProblem
from .certificate import Constraint, ConvexObjective, lower_bound
from .conic import ACCURACY_FALLBACKS, ConicProgram, ConicSolution, solve_program
from .convex import CERTIFY_AGAIN, ConvexSolver
from .front import Front, FrontPoint, mark_knee
from .largest import over_working_set, pad
from .problem import NumericProblem, numeric_problem
from .sites import Sites

#: Room given to an end of the front when it becomes a constraint (relative to its scale): a
#: hundred times Clarabel's tolerance, so that the constrained program stays feasible.
END_ROOM = 1e-8
#: The quantities ``J'`` may weigh alone, whose RMS the front then shows in its own unit.
SINGLE = ("rocking_couple", "shaking_force", "shaking_moment", "main_bearing_load",
          "largest_bearing_load")


class _RotorFront:
    """The ε-constraint programs of an engine's balancing, in ``(u, t)``."""

    def __init__(self, data: NumericProblem) -> None:
        assert data.sites is not None, "an engine's problem"
        self.data = data
        self.sites: Sites = data.sites
        self.solver = solver = ConvexSolver(data)
        n, s = solver.layout.size, len(self.sites.chosen)
        chosen = [k for i in self.sites.chosen for k in range(data.size)[self.sites.entries(i)]]
        assert list(solver.layout.primary) == chosen, "the variables are the chosen sites'"
        self.n, self.s = n, s
        largest = solver.largest
        width = n + s + (largest is not None)
        self.width = width
        problem = self.sites.problem
        radius = None if problem.counterweights is None else problem.counterweights.radius
        self.per_mr = 1.0 if radius is None else 1.0 / radius
        self.unit = "kg·m" if radius is None else "kg"
        self.weights = np.array([self.sites.sites[i].max_mr for i in self.sites.chosen]
                                ) * self.per_mr
        self.rescale(float(self.weights.sum()))
        cones = pad(solver.base_constraints, width)
        for i in range(s):  # the variables are the chosen sites' scaled entries, in order
            m = np.zeros((3, width))
            m[0, n + i] = 1.0
            m[1, 2 * i] = m[2, 2 * i + 1] = 1.0
            cones.append(Constraint("soc", m, np.zeros(3)))
        compressed = solver.compressed
        self.P = np.hstack([compressed.P, np.zeros((compressed.P.shape[0], width - n))])
        self.q = compressed.q
        self.lo = np.r_[-np.ones(n), np.zeros(width - n)]
        self.hi = np.ones(width)
        if largest is not None:  # its row ‖(P·u + q, τ)‖
            tau_row = np.zeros((1, width))
            tau_row[0, -1] = 1.0
            self.P, self.q = np.vstack([self.P, tau_row]), np.append(self.q, 0.0)
            self.hi[-1] = largest.bound(self.lo[:n], self.hi[:n])
        self.base = cones
        #: Every cone: the bounds', the sites' ``t_i``, and the supports' rows (bounded, or
        #: ``τ`` above them) all.
        self.cones = [*cones, *self.row_cones(None)]
        #: The cones of the last program :meth:`least_objective` solved (its certificate's).
        self.last_cones = self.cones
        self.norm = ConvexObjective(P=self.P, q=self.q, norm=True, g=np.zeros(width), g0=0.0)

    def row_cones(self, rows: NDArray[np.intp] | None) -> list[Constraint]:
        """The supports' rows ``rows`` (all where ``None``): the bound's cones, ``τ``'s."""
        solver, width = self.solver, self.width
        bound = solver.bound_constraints if rows is None or not solver.bound_constraints else [
            solver.bound_constraints[r] for r in rows]
        out = pad(bound, width)
        if solver.largest is not None:
            out += solver.largest.cones(width, width - 1, rows)
        return out

    def x(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """The design vector (kg·m) of scaled ``u``, each mass·radius within its bound."""
        return self.sites.into_bounds(self.solver.layout.x(u[: self.n]))

    def figures(self, x: NDArray[np.float64]) -> dict[str, float]:
        """The RMS of each load at ``x``, N or N·m.

        The shaking force, rocking couple and shaking moment; the main-bearing loads too (over
        the bearings) where the problem has them.
        """
        reg = self.data.regressors
        out = {name: float(np.sqrt(np.mean(np.abs(getattr(reg, name) @ x) ** 2)))
               for name in ("shaking_force", "rocking_couple", "shaking_moment")}
        if reg.supports is not None:
            loads = np.abs(reg.supports @ x)
            out["main_bearing_load"] = float(np.sqrt(np.mean(loads**2)))
            out["largest_bearing_load"] = float(np.max(loads, initial=0.0))
        return out

    def rescale(self, scale: float) -> None:
        """Measure the cap in units of ``scale`` (its unit).

        The front's own extent, once known: the sum of the bounds may be far larger than any
        mass the front uses.
        """
        self.value_scale = scale if scale > 0 else float(self.weights.sum())
        self.cap_row = np.r_[np.zeros(self.n), self.weights / self.value_scale,
                             np.zeros(self.width - self.n - self.s)]

    def value(self, x: NDArray[np.float64]) -> float:
        """``Σ |mr_i|`` of ``x``'s chosen sites (kg·m), or the masses at the radius (kg)."""
        return math.fsum(abs(self.sites.vector(x, i)) for i in self.sites.chosen) * self.per_mr

    def cap(self, epsilon: float) -> Constraint:
        """``Σ c_i·t_i ≤ ε`` (``ε`` in :attr:`unit`) as a cone constraint."""
        return Constraint("nonneg", -self.cap_row[None, :],
                          np.array([epsilon / self.value_scale]))

    def least_objective(self, extra: list[Constraint],
                        settings: dict[str, Any] | None = None) -> ConicSolution:
        """``min ‖P·u + q‖`` within the bounds and ``extra``.

        ``settings``: Clarabel's, over the solver's (another solve's, for a tighter bound).
        With the supports' rows, over a working set of them until the optimum breaks none
        (:mod:`.largest`); :attr:`last_cones` are the program's.
        """
        options = {**self.solver.settings, **(settings or {})}
        supports = self.data.regressors.supports

        def solve(rows: NDArray[np.intp] | None) -> ConicSolution:
            cones = [*self.base, *self.row_cones(rows), *extra]
            self.last_cones = cones
            return solve_program(ConicProgram(self.width, cones, objective="norm", P=self.P,
                                              q=self.q), options)

        def limits(solution: ConicSolution) -> tuple[NDArray[np.float64], float]:
            assert solution.u is not None and supports is not None
            return np.abs(supports @ self.x(solution.u)), self.solver.row_limit(
                None if self.solver.largest is None else float(solution.u[-1]))

        rows = self.solver.working_rows
        if rows is None or supports is None:
            return solve(None)
        return over_working_set(rows, solve, limits)[0]

    def least_value(self, root: float) -> ConicSolution:
        """``min Σ c_i·t_i`` among the designs with ``‖P·u + q‖ ≤ root``."""
        cap = Constraint("soc", np.vstack([np.zeros((1, self.width)), self.P]),
                         np.r_[root, self.q])
        program = ConicProgram(self.width, [*self.cones, cap], objective="squares",
                               P=np.zeros((0, self.width)), q=np.zeros(0), g=self.cap_row)
        return solve_program(program, self.solver.settings)

    def least_feasible(self) -> float:
        """The least ``Σ c_i·t_i`` of any design within the bounds (0 without a support bound).

        Raises :class:`SolverError` if Clarabel fails (an unreachable bound: the optimiser's
        own error names it first).
        """
        if self.data.support_bound is None:
            return 0.0
        program = ConicProgram(self.width, self.cones, objective="squares",
                               P=np.zeros((0, self.width)), q=np.zeros(0), g=self.cap_row)
        solution = solve_program(program, self.solver.settings)
        if solution.u is None:
            raise SolverError(f"the least added mass within the bounds could not be solved "
                              f"(Clarabel: {solution.status})")
        return float(self.cap_row @ solution.u) * self.value_scale

    def certified(self, solution: ConicSolution, cap: Constraint) -> float:
        """The certified least ``√J'`` under ``cap``, N·m (0 where none is made)."""
        assert solution.u is not None  # solved: the caller has checked
        y = np.asarray(solution.u, float)
        v = (None if solution.epigraph_dual is None
             else -np.asarray(solution.epigraph_dual[1:]))
        bound = lower_bound(self.norm, self.last_cones, None, y, list(solution.duals), v,
                            self.lo, self.hi, self.norm.value(y))
        return 0.0 if bound is None else max(bound.value, 0.0) * self.data.objective_scale


def rotor_front(design: Design, against: str, points: int) -> Front:
    """The front of an engine's balancing (see the module docstring).

    Raises
    ------
    SpecError
        For a second objective other than ``added-mass``, or an objective that weighs only
        the unbalance (nothing to trade it against).
    SolverError
        If Clarabel fails.
    """
    problem = design.balance
    if not isinstance(problem, RotorBalanceProblem):
        raise TypeError("design.balance must be a RotorBalanceProblem")
    if against != "added-mass":
        raise SpecError("an engine's balancing trades its shaking against the mass it adds: "
                        "give --against added-mass", key="--against", value=against)
    weights = replace(problem.objective, unbalance=0.0)
    if not weights.terms:
        what = "only the unbalance" if problem.objective.unbalance else "nothing"
        raise SpecError(f"weighs {what}: nothing to trade against the added mass; weigh the "
                        "rocking couple, the shaking force or the shaking moment",
                        key="balance.objective")
    data = numeric_problem(replace(design, balance=replace(problem, objective=weights)))
    single = weights.single
    minimised = single.name if single is not None and single.name in SINGLE else "rms"
    per_weight = 1.0 / math.sqrt(single.weight) if minimised != "rms" and single else 1.0
    programs = _RotorFront(data)
    scale = data.objective_scale

    def least(x: NDArray[np.float64]) -> float:
        return math.sqrt(data.objective(x)) * per_weight

    def solved(solution: ConicSolution, what: str) -> NDArray[np.float64]:
        if solution.u is None:
            raise SolverError(f"{what} could not be solved (Clarabel: {solution.status})")
        return programs.x(solution.u)

    best = solved(programs.least_objective([]), "the least shaking")
    # The front's extent is at most the mass of that optimum: the cap's unit from here on
    # (not below a millionth of the bounds' sum: an optimum that adds nothing is one point).
    programs.rescale(max(programs.value(best), 1e-6 * float(programs.weights.sum())))
    top = programs.least_value(math.sqrt(data.objective(best)) / scale + END_ROOM)
    high = programs.value(solved(top, "the least mass of the least shaking")
                          if top.u is not None else best)
    slack = END_ROOM * programs.value_scale
    # (the least mass any design within the bounds has: none, unless a bound on the main
    # bearings' loads asks for some)
    low = programs.least_feasible()
    grid = ([low + slack] if high <= low + slack
            else list(np.linspace(low + slack, high + slack, points)))
    out: list[FrontPoint] = []
    for epsilon in grid:
        cap = programs.cap(float(epsilon))
        solution = programs.least_objective([cap])
        x = solved(solution, f"a point of the front (ε = {epsilon:.6g} {programs.unit})")
        x = data.built(x)  # as the spec would say it
        bound = programs.certified(solution, cap)
        # A dual off by more than its tolerance leaves the bound loose: solved again with other
        # settings, the highest bound kept (each valid by weak duality), as the convex
        # program's certificate is (ConvexSolver._certified).
        for settings in ACCURACY_FALLBACKS:
            if math.sqrt(data.objective(x)) - bound <= CERTIFY_AGAIN * scale:
                break
            again = programs.least_objective([cap], settings)
            if again.u is not None:
                bound = max(bound, programs.certified(again, cap))
        out.append(FrontPoint(least=least(x), value=programs.value(x), epsilon=float(epsilon),
                              lower_bound=bound * per_weight,
                              x=x, figures=programs.figures(x)))
    out.sort(key=lambda p: p.value)
    return Front(against=against, points=tuple(mark_knee(out)),
                 original=(programs.value(data.x0), least(data.x0)),
                 minimised=minimised, value_unit=None if programs.unit == "kg" else "kg·m",
                 original_figures=programs.figures(data.x0), masses=True)


__all__ = ["rotor_front"]
