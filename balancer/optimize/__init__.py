"""Balancing optimisers: the redesign problem of a spec's ``[balance]`` section, solved.

Two backends over one :class:`~balancer.problem.NumericProblem`:

``"convex"``
    The second-order cone program in the inertial parameters (:mod:`.convex`, CVXPY +
    Clarabel): a global optimum, or — when a link's inertia is bounded above while its centre
    of mass may move, the one non-convex condition — a relaxation whose optimum is a lower
    bound (then the design is moved into the inertia bounds and the gap is reported).
``"nlp"``
    The convex problem first (lower bound and start), then IPOPT on the designer's physical
    parameters (:mod:`.nlp`, CasADi). The result is the better of the two designs; on a tie
    (within ``1e-7`` relative) the convex one, which is the least change from the original
    among the optimal designs (IPOPT, an interior-point method, stops somewhere on a
    degenerate optimum that depends on its barrier).

The objective is **inertial**: applied loads are left out (see :mod:`balancer.problem`).

Example::

    from balancer import load_design
    from balancer.optimize import optimize
    result = optimize(load_design("examples/pb1.toml"))
    result.success, result.status, result.objective, result.gap
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from ..errors import SpecError
from ..inverse import cycle_analysis
from ..model import Design
from ..problem import NumericProblem, numeric_problem
from .convex import ConvexSolution, ConvexSolver
from .nlp import NlpSolution, NlpSolver
from .result import (
    GAP_TOLERANCE,
    BalanceResult,
    InfeasibleError,
    StageReport,
    Status,
    gap,
    gap_floor,
)

BACKENDS: tuple[str, ...] = ("nlp", "convex")
#: Relative objective difference within which the NLP's design does not replace the convex one
#: (the convex design may exceed the optimum by Clarabel's tolerance and the tie-break's,
#: :data:`.convex.TIE_ACCEPT`).
TIE_TOLERANCE = 1e-7

__all__ = [
    "BACKENDS",
    "BalanceResult",
    "ConvexSolution",
    "ConvexSolver",
    "InfeasibleError",
    "NlpSolution",
    "NlpSolver",
    "Optimizer",
    "StageReport",
    "Status",
    "gap",
    "optimize",
]


class Optimizer:
    """Both backends for one redesign problem, each built once (for repeated solves).

    Parameters
    ----------
    data
        The numeric problem (:func:`balancer.problem.numeric_problem`).
    """

    def __init__(self, data: NumericProblem) -> None:
        self.data = data
        self.convex = ConvexSolver(data)
        self._nlp: NlpSolver | None = None

    @property
    def nlp(self) -> NlpSolver:
        """The NLP solver (built when first asked for)."""
        if self._nlp is None:
            self._nlp = NlpSolver(self.data)
        return self._nlp

    def run(self, backend: str = "nlp") -> BalanceResult:
        """Solve with ``backend`` and assemble the result.

        Parameters
        ----------
        backend
            ``"nlp"`` or ``"convex"``.

        Raises
        ------
        SpecError
            For an unknown backend.
        InfeasibleError
            If no design within the bounds meets force balance.
        SolverError
            If Clarabel fails.
        """
        if backend not in BACKENDS:
            raise SpecError(
                f"unknown backend; choose from {', '.join(BACKENDS)}", key="backend", value=backend
            )
        data = self.data
        t0 = time.perf_counter()
        convex = self.convex.solve()
        stages: list[StageReport] = list(convex.stages)
        x, objective = convex.x, convex.objective
        feasible = not data.violations(x)
        notes = []
        if backend == "nlp":
            nlp = self.nlp.solve(convex.x)
            stages.append(nlp.stage)
            if nlp.status == "optimal" and nlp.feasible:
                scale = max(abs(objective), gap_floor(data.objective_reference))
                if not feasible or nlp.objective < objective - TIE_TOLERANCE * scale:
                    xb = self.convex.balanced(nlp.x)  # Eq. 58 to rounding, not to IPOPT's tol
                    if data.violations(xb):
                        xb = nlp.x
                    x, objective, feasible = xb, data.objective(xb), True
            else:
                notes.append(f"IPOPT: {nlp.stage.solver_status}")
        elapsed = time.perf_counter() - t0
        g = gap(objective, convex.lower_bound, data.objective_reference)
        stages = [
            replace(s, gap=gap(s.objective, convex.lower_bound, data.objective_reference))
            for s in stages
        ]
        if not feasible:
            status = Status.FAILED
        elif g <= GAP_TOLERANCE:
            status = Status.OPTIMAL
        else:
            status = Status.FEASIBLE
        balanced = data.linkage_of(x)
        before = cycle_analysis(
            data.linkage, data.speed, data.samples, route="newton-euler", loads=False
        )
        after = cycle_analysis(
            balanced, data.speed, data.samples, route="newton-euler", loads=False
        )
        message = _message(status, objective, data.original_objective, g, convex, notes)
        return BalanceResult(
            success=status is not Status.FAILED,
            status=status,
            message=message,
            backend=backend,
            linkage=balanced,
            original=data.linkage,
            x=np.array(x),
            objective=objective,
            original_objective=data.original_objective,
            lower_bound=convex.lower_bound,
            gap=g,
            relaxation_tight=convex.relaxation_tight,
            iterations=sum(s.iterations for s in stages),
            time=elapsed,
            stages=tuple(stages),
            before=before,
            after=after,
        )


def _message(
    status: Status,
    objective: float,
    original: float,
    g: float,
    convex: ConvexSolution,
    notes: list[str],
) -> str:
    text = {
        Status.OPTIMAL: "globally optimal",
        Status.FEASIBLE: "feasible, not proven optimal",
        Status.FAILED: "no feasible design found",
    }[status]
    value = f"J = {objective:.6g} (N·m)²"
    if original > 0 and objective >= 0:
        value += f" (√(J/J_original) = {math.sqrt(objective / original):.3g})"
    parts = [text, value, f"gap {g:.2g} to the lower bound {convex.lower_bound:.6g} (N·m)²"]
    if not convex.relaxation_tight:
        parts.append("convex relaxation not tight")
    return "; ".join(parts + notes)


def optimize(design: Design, backend: str = "nlp") -> BalanceResult:
    """Balance a design as its ``[balance]`` section asks.

    Parameters
    ----------
    design
        A spec with ``[balance]`` and ``[operation]``.
    backend
        ``"nlp"`` (convex, then IPOPT on the physical parameters) or ``"convex"``.

    Returns
    -------
    BalanceResult
        The balanced design, before/after analyses, status, lower bound and gap.

    Raises
    ------
    SpecError
        If the spec has no ``[balance]`` or ``[operation]``, or the backend is unknown.
    AssemblyError
        If the crank cannot turn a full revolution.
    InfeasibleError
        (a :class:`~balancer.errors.SolverError`, exit code 1) if force balance cannot be met
        within the bounds; the message names the bounds to widen and the values that would do.
    SolverError
        If a solver fails.
    """
    if backend not in BACKENDS:
        raise SpecError(
            f"unknown backend; choose from {', '.join(BACKENDS)}", key="backend", value=backend
        )
    return Optimizer(numeric_problem(design)).run(backend)
