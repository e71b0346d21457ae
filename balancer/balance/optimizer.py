"""Balancing optimisers: the redesign problem of a spec's ``[balance]`` section, solved.

Two backends over one :class:`~balancer.balance.problem.NumericProblem`:

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

The objective is **inertial**: applied loads are left out (see :mod:`balancer.balance.problem`).

Example::

    from balancer import load_design
    from balancer.balance.optimizer import optimize
    result = optimize(load_design("examples/pb1.toml"))
    result.success, result.status, result.objective, result.gap

The same problem under new bounds, without rebuilding what does not depend on them::

    import dataclasses
    from balancer.balance.optimizer import Optimizer
    design = load_design("examples/pb1.toml")
    optimizer = Optimizer.of(design)
    wider = dataclasses.replace(design.balance.link("rocker"), mass=(1.0, 6.0))
    problem = design.balance.with_link("rocker", wider)
    optimizer.with_problem(problem).run("convex")
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Literal, cast, get_args

import numpy as np
from numpy.typing import NDArray

from ..cycle import CycleAnalysis, cycle_analysis
from ..errors import SpecError
from ..model import Design, MechanismModel
from ..model.balance import BalanceProblem, RotorBalanceProblem, missing_balance
from ..model.motions import MotionSpec, Workspace
from ..motion_analysis import AlongMotions, along_motions
from .convex import ConvexSolution, ConvexSolver
from .feasibility import ROUNDING_TOLERANCE
from .flywheel import sized
from .nlp import NlpSolution, NlpSolver
from .problem import NumericProblem, numeric_problem
from .result import (
    GAP_TOLERANCE,
    BalanceResult,
    InfeasibleError,
    RotorMasses,
    StageReport,
    Status,
)

#: The optimisers: ``"nlp"`` (the convex optimum, then IPOPT on the designer's parameters) or
#: ``"convex"`` (the certified optimum of the second-order cone program alone).
Backend = Literal["nlp", "convex"]
BACKENDS: tuple[str, ...] = get_args(Backend)
#: Gap (relative to the problem's scale, :meth:`NumericProblem.gap`) within which the NLP's
#: design does not replace the convex one (which may exceed the optimum by Clarabel's
#: tolerance and the tie-break's, :data:`.convex.TIE_ACCEPT`).
TIE_TOLERANCE = 1e-7

__all__ = [
    "BACKENDS",
    "Backend",
    "BalanceResult",
    "ConvexSolution",
    "ConvexSolver",
    "InfeasibleError",
    "NlpSolution",
    "NlpSolver",
    "Optimizer",
    "StageReport",
    "Status",
    "optimize",
]


class Optimizer:
    """Both backends for one redesign problem, each built once (for repeated solves).

    Parameters
    ----------
    data
        The numeric problem (:func:`balancer.balance.problem.numeric_problem`).
    """

    def __init__(self, data: NumericProblem, *, like: Optimizer | None = None,
                 gravity: tuple[float, float] = (0.0, 0.0),
                 motions: tuple[MotionSpec, ...] = (),
                 workspace: Workspace | None = None) -> None:
        self.data = data
        self.gravity: tuple[float, float] = gravity if like is None else like.gravity
        #: The motions a linkage with several inputs is balanced along (its before and after
        #: are analysed along them).
        self.motions: tuple[MotionSpec, ...] = motions if like is None else like.motions
        self.workspace: Workspace | None = workspace if like is None else like.workspace
        self.convex: ConvexSolver = ConvexSolver(data, like=None if like is None else like.convex)
        self._nlp: NlpSolver | None = None
        # The original design's analysis: the same under any bounds.
        self._before: CycleAnalysis | AlongMotions | None = (None if like is None
                                                             else like._before)

    @classmethod
    def of(cls, design: Design, *, along: bool = False) -> Optimizer:
        """The optimiser of a design spec's ``[balance]`` problem (``along`` its motions).

        Raises as :func:`~balancer.balance.problem.numeric_problem`.
        """
        if along and isinstance(design.balance, RotorBalanceProblem):
            raise SpecError("an engine's counterweights and shafts are balanced over a "
                            "revolution at its operating speed, not along a motion",
                            key="balance")
        data = numeric_problem(design, along=along)  # (it has checked [operation], or motions)
        gravity = design.operation.gravity if design.operation is not None else (0.0, 0.0)
        return cls(data, gravity=gravity, motions=design.motions, workspace=design.workspace)

    def with_problem(self, problem: BalanceProblem) -> Optimizer:
        """The optimiser of the same design under another redesign problem (new bounds).

        It shares what does not depend on the bounds
        (:meth:`~balancer.balance.problem.NumericProblem.with_problem`): a sweep over bounds
        re-solves without rebuilding the regressors. ``problem`` is a
        :class:`~balancer.model.balance.BalanceProblem`, e.g. ``dataclasses.replace`` of
        ``design.balance``, or another spec's.

        Raises
        ------
        SpecError
            If ``problem`` is contradictory.
        """
        return Optimizer(self.data.with_problem(problem), like=self)

    @property
    def nlp(self) -> NlpSolver:
        """The NLP solver (built when first asked for)."""
        if self._nlp is None:
            self._nlp = NlpSolver(self.data)
        return self._nlp

    def run(self, backend: Backend = "nlp") -> BalanceResult:
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
        x, feasible = convex.x, convex.converged
        objective = data.objective(x)
        notes: list[str] = []
        if backend == "nlp":
            if self._nlp is None:  # (from the convex optimum: a bound's working set there)
                self._nlp = NlpSolver(data, start=convex.x)
            nlp = self._nlp.solve(convex.x)  # None: no freedom beyond Eq. 58 to improve on
            if nlp is not None:
                stages.append(nlp.stage)
            if nlp is not None and nlp.status == "optimal" and nlp.feasible:
                if not feasible or not data.within(objective, nlp.objective, TIE_TOLERANCE):
                    xb, ok = self.convex.finalize(nlp.x)  # bounds exactly, Eq. 58 to rounding
                    # (made exactly feasible it may have lost what it gained: in a thin
                    # feasible set the projection costs more than the tolerance)
                    if ok and (not feasible or data.objective(xb) < objective):
                        # What IPOPT left where nothing pulls (a counterweight that may be none
                        # at its barrier's middle) is put back as the convex stage puts it.
                        polished, _ = self.convex.polish(xb, data.preferred,
                                                         data.reduced_objective(xb))
                        xp, exact = self.convex.finalize(polished)
                        if exact and data.within(data.objective(xp), data.objective(xb), 1e-12):
                            xb = xp
                        xb = self.convex.without_idle_counterweights(xb)
                        x, objective, feasible = xb, data.objective(xb), True
            elif nlp is not None:
                notes.append(f"IPOPT: {nlp.stage.solver_status}")
        # The design as its physical values, exactly in their bounds (what the spec will say).
        x = data.built(x)
        sizing = None
        bound = getattr(data.problem, "max_speed_fluctuation", None)
        if bound is not None and feasible and data.speed is not None:
            # the flywheel it needs, on the crank (inert at the operating speed; a balancing
            # along motions, as plan --with-masses asks, has no operating speed to keep)
            x, sizing = sized(data, x, bound, self.gravity)
        objective = data.objective(x)
        feasible = feasible and not data.violations(x, tol=ROUNDING_TOLERANCE)
        if not feasible and data.force_balance is not None:
            diagnosis = self.convex.diagnose()  # a problem just on the infeasible side
            if diagnosis is not None:
                raise diagnosis
        elapsed = time.perf_counter() - t0
        lower = convex.lower_bound
        g = data.gap(objective, lower)
        stages = [replace(s, gap=data.gap(s.objective, lower))
                  if math.isfinite(s.objective) else s for s in stages]
        blur = data.rounding(x)  # rounding can hide this much of a gap
        if not feasible:
            status = Status.FAILED
        elif g + blur <= GAP_TOLERANCE:
            status = Status.OPTIMAL
        else:
            status = Status.FEASIBLE
            if blur > GAP_TOLERANCE:
                notes.append(f"rounding blurs the objective by {blur:.1e} of the scale (links "
                             "of very different masses): optimality cannot be decided finer")
        balanced = data.linkage_of(x)
        if self._before is None:
            self._before = self._inertial(data.linkage)
        before = self._before
        after = self._inertial(balanced)
        result = BalanceResult(
            success=status is not Status.FAILED,
            status=status,
            message="",
            backend=backend,
            linkage=balanced,
            original=data.linkage,
            x=np.array(x),
            objective=objective,
            original_objective=data.original_objective,
            lower_bound=lower,
            gap=g,
            scale=data.objective_scale,
            rms_form=data.rms_form,
            relaxation_tight=convex.relaxation_tight,
            iterations=sum(s.iterations for s in stages),
            time=elapsed,
            stages=tuple(stages),
            before=before,
            after=after,
            gravity=self.gravity,
            weights=data.weights,
            rotor_masses=None if data.sites is None else self._rotor_masses(x),
            flywheel=sizing,
        )
        return replace(result, message=result.summary(notes))

    def _rotor_masses(self, x: NDArray[np.float64]) -> RotorMasses:
        """What an engine's balancing builds: its chosen masses in ``x``, and their figures."""
        data = self.data
        sites = data.sites
        assert sites is not None
        counterweights, shafts = sites.masses(x)
        problem = cast("RotorBalanceProblem", data.problem)
        return RotorMasses(
            counterweights=counterweights, shafts=shafts,
            radius=None if problem.counterweights is None else problem.counterweights.radius,
            replaced=sites.replaced, unbalance_before=sites.unbalance(data.x0),
            unbalance_after=sites.unbalance(x),
            bearing_loads=sites.bearing_loads(x, data.regressors.shaking_force))


    def _inertial(self, model: MechanismModel) -> CycleAnalysis | AlongMotions:
        """A design's inertial loads, as the objective weighs them (loads and gravity left out).

        Over the revolution at the operating speed, or along the motions.
        """
        data = self.data
        if data.speed is None:
            # (a linkage's: an engine's turns at its operating speed)
            problem = cast("BalanceProblem", data.problem)
            weights = problem.weights_of([m.name for m in self.motions])
            return along_motions(model, self.motions, workspace=self.workspace, loads=False,
                                 weights=weights)
        return cycle_analysis(model, data.speed, data.samples, route="newton-euler",
                              loads=False)


def optimize(design: Design, backend: Backend = "nlp") -> BalanceResult:
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
    if design.balance is None:
        raise missing_balance(design.mechanism)
    return Optimizer.of(design).run(backend)
