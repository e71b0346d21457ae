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


def gap_floor(reference: float) -> float:
    """The least denominator of a relative gap, ``1e-10·reference`` (N·m)².

    ``reference`` is a positive scale of the objective
    (:attr:`balancer.problem.NumericProblem.objective_reference`, the original design's mean
    squares); ``1e-10`` is Clarabel's tolerance on the objective scaled by it. A zero
    optimum (complete balancing) would otherwise divide by zero; with this floor a gap of at
    most :data:`GAP_TOLERANCE` there means an RMS below ``1e-8`` of the original's.
    """
    return max(1e-10 * abs(reference), 1e-300)


def gap(objective: float, lower_bound: float, reference: float) -> float:
    """Relative gap ``(J − J_low)/max(|J_low|, floor)`` (see :func:`gap_floor`), dimensionless."""
    return (objective - lower_bound) / max(abs(lower_bound), gap_floor(reference))


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
    gap
        That objective's relative gap to the convex lower bound (see :func:`gap`; ``nan``
        until the bound is known).
    """

    name: str
    converged: bool
    solver_status: str
    iterations: int
    time: float
    objective: float
    gap: float = float("nan")


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
        ``1e-10`` of the original's mean squares (:func:`gap_floor`), for a zero optimum.
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
        Bounds that would make it feasible: ``(key, needed value, current value or None,
        unit)`` each, e.g. ``("balance.crank.com_radius", 0.5859, 0.3, "m")``.
    jointly
        ``False``: each of :attr:`needed` suffices alone (the others kept); ``True``: they
        suffice together.
    """

    def __init__(
        self,
        message: str,
        *,
        needed: tuple[tuple[str, float, float | None, str], ...] = (),
        jointly: bool = False,
    ) -> None:
        self.needed = needed
        self.jointly = jointly
        super().__init__(message)
