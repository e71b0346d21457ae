"""Result objects of the balancing optimisers and the error for an infeasible problem.

A result says whether it succeeded in its own terms (:attr:`BalanceResult.success`,
:class:`Status`), never by a raw solver string; the solvers' own words are kept per stage in
:class:`StageReport` for diagnosis.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError
from ..inverse import CycleAnalysis
from ..model import Design, FourBar

#: Relative gap to the convex lower bound within which a design counts as globally optimal.
GAP_TOLERANCE = 1e-6


class Status(StrEnum):
    """Outcome of a balancing."""

    OPTIMAL = "optimal"
    """A feasible design whose objective is within :data:`GAP_TOLERANCE` of the proven lower
    bound: globally optimal."""
    FEASIBLE = "feasible"
    """A feasible design (all bounds, exact force balance) that is not proven optimal: a local
    optimum, or the convex design made feasible when its relaxation was not tight."""
    FAILED = "failed"
    """No feasible design: the solver failed."""


@dataclass(frozen=True, kw_only=True)
class StageReport:
    """One solver run inside a balancing.

    Attributes
    ----------
    name
        ``"convex"`` (the SOCP), ``"tie-break"`` (nearest-to-original among the optimal
        designs), ``"nlp"`` (IPOPT on the physical parameters).
    converged
        Whether the solver reported convergence.
    solver_status
        The solver's own status word (for diagnosis only).
    iterations
        Solver iterations.
    time
        Wall-clock time of the stage, s.
    objective
        The objective ``J`` at the stage's design, (N·m)² (``nan`` if it has none).
    """

    name: str
    converged: bool
    solver_status: str
    iterations: int
    time: float
    objective: float


@dataclass(frozen=True, kw_only=True)
class BalanceResult:
    """A balanced design and how it was found (shaped like SciPy's ``OptimizeResult``).

    The objective is the **inertial** one: applied loads are left out (they are not linear in
    the design); the balanced links keep the original loads.

    Attributes
    ----------
    success
        A feasible design was found (status ``optimal`` or ``feasible``).
    status
        See :class:`Status`.
    message
        One line for a report.
    backend
        ``"convex"`` or ``"nlp"``.
    linkage
        The balanced four-bar.
    original
        The design it came from.
    x
        Its inertial parameters (:data:`balancer.inverse.PARAMETER_NAMES`): kg, kg·m, kg·m,
        kg·m² per link, then counter-rotor inertias, kg·m².
    objective
        ``J`` of the balanced design, (N·m)² (mean-square form, see :mod:`balancer.problem`).
    original_objective
        ``J`` of the original design, (N·m)².
    lower_bound
        The convex optimum: no feasible design has a smaller ``J`` (to the solver's tolerance),
        (N·m)².
    gap
        ``(objective − lower_bound)/max(|lower_bound|, floor)``, dimensionless; the floor is
        ``1e-12`` of the original's objective, so that a zero optimum gives a gap of 0.
    relaxation_tight
        Whether the convex relaxation was exact at its optimum (always, unless a link has a
        bounded inertia about a centre of mass that may move).
    iterations
        Solver iterations over all stages.
    time
        Wall-clock time of the solves, s (building the problem and the analyses excluded).
    stages
        Each solver run.
    before, after
        Cycle analyses of the original and the balanced design without loads (Newton–Euler
        route: an independent check of the objective, which the optimisers compute from the
        mass-matrix regressors).
    """

    success: bool
    status: Status
    message: str
    backend: str
    linkage: FourBar
    original: FourBar
    x: NDArray[np.float64]
    objective: float
    original_objective: float
    lower_bound: float
    gap: float
    relaxation_tight: bool
    iterations: int
    time: float
    stages: tuple[StageReport, ...]
    before: CycleAnalysis
    after: CycleAnalysis

    @property
    def optimal(self) -> bool:
        """Whether the design is proven globally optimal."""
        return self.status is Status.OPTIMAL

    def balanced_design(self, design: Design) -> Design:
        """The spec ``design`` with the balanced linkage, and the original kept as ``original``."""
        return replace(
            design,
            mechanism=self.linkage,
            original=design.original if design.original is not None else self.original,
        )


class InfeasibleError(SolverError):
    """The redesign problem has no feasible design (exit code 1).

    Attributes
    ----------
    needed
        The bounds that would make it feasible together: ``(key, needed value, current value,
        unit)`` per bound, e.g. ``("balance.crank.com_radius", 1.758, 1.0, "m")``.
    """

    def __init__(
        self, message: str, *, needed: tuple[tuple[str, float, float | None, str], ...] = ()
    ) -> None:
        self.needed = needed
        super().__init__(message)
