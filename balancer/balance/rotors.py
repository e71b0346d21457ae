"""Balancing by counterweights on the crank's rotor and eccentrics of new shafts: a convex program.

DESIGN.md, "Balancing an engine". The designer names the planes where counterweights may go on
the crankshaft (``[balance.counterweights]``) and the shafts there may be (``[[balance.shafts]]``:
ratio, axis, planes); the optimiser chooses each mass·radius vector ``x_i = mr_i·e^{iφ_i}``
(its size within ``max_mr``, its angle any). A mass·radius on a rotor turning at ``k·θ1`` about
``ā`` puts on the frame, at constant crank speed ω (:class:`balancer.linkage.rotors.Rotor`):

- the force ``F = x·(kω)²·e^{ikθ1}`` (complex; its centrifugal force on its bearing),
- the rocking couple ``i·z·F`` (``Mx + i·My``, its plane ``z``),
- the shaking moment about z ``ā × F``,

and nothing on the driving torque: every load is linear in ``(Re x, Im x)``. The engine with
the labelled counterweights of the chosen planes taken off (the *base*) shakes as its cycle
analysis says; the objective is

    J(x) = w_R·mean|C_base + Σ C_i|² + w_F·mean|F_base + Σ F_i|²
           + w_M·mean(M_base + Σ M_i)² + w_U·Σ (|x_i|·ω²)²                     (N·m)²

(DESIGN's weights; ``ω`` the crank's speed in the unbalance term), the squared norm of an
affine map ``K·x + k``, and the bounds ``|x_i| ≤ max_mr_i`` are second-order cones. So the
problem is convex, with a certified optimum:

1. ``[K k]`` is reduced to its triangular factor and its numerical rank (rows of rounding
   spoil Clarabel's equilibration), the variables scaled by their bounds;
2. Clarabel minimises ``‖P·u + q‖`` (the root, so that a zero optimum is reached accurately);
   its multipliers give the certified lower bound by weak duality
   (:func:`balancer.balance.certificate.lower_bound`);
3. where the optimum is not unique (no unbalance term, more planes than the orders they can
   reach), a tie-break picks among the optimal designs the one of least ``Σ (|x_i|/max_mr_i)²``;
4. the ``nlp`` backend then runs IPOPT (CasADi) on ``x`` from there and keeps its design if it
   is better beyond the tolerance.

The original design is the base with its replaced counterweights, summed per plane, and no new
shaft: ``J(x0)`` is the original's objective. This module imports neither CVXPY nor CasADi at
its top.
"""

from __future__ import annotations

import contextlib
import io
import math
import sys
import time
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from .. import interrupts
from ..cycle import cycle_analysis
from ..errors import SolverError, SpecError
from ..linkage.rotors import Eccentric, Rotor
from ..model import Design
from ..model import MechanismModel as Model
from ..model.balance import (
    Objective,
    PlacedMass,
    RotorBalanced,
    RotorBalanceProblem,
    ShaftDesign,
)
from ..parts.sizing import most_mr
from ..quantities import squared_parts
from .certificate import Constraint, ConvexObjective, lower_bound
from .conic import ConicProgram, ConicSolution
from .convex import CLARABEL_SETTINGS, TIE_ACCEPT, solve_program
from .nlp import IPOPT_OPTIONS
from .objective_scale import BALANCED_SHARE, ROUNDING_FACTOR
from .result import GAP_TOLERANCE, BalanceResult, RotorMasses, StageReport, Status

#: A mass·radius below this share of its bound is none (an interior-point method reaches the
#: apex of a cone, a mass of nothing, only to its tolerance).
ABSENT = 1e-9
#: A mass·radius within this share of its bound is held by it (:meth:`RotorSolver.polish`).
ACTIVE_SHARE = 1e-6
#: Singular values of the objective's map below this share of the largest are rounding.
RANK_TOLERANCE = 1e-12
#: The NLP's design replaces the convex one only if better by more than this share of the
#: problem's scale (as for linkages, :data:`balancer.balance.optimizer.TIE_TOLERANCE`).
TIE_TOLERANCE = 1e-7


@dataclass(frozen=True)
class Site:
    """One mass·radius the optimiser chooses.

    Attributes
    ----------
    shaft
        ``None`` for a counterweight on the crankshaft, else the new shaft's index (from 0).
    ratio
        The rotor's speed over the crank's.
    at
        Its axis, complex ``x + i·y``, m.
    z
        Its plane, m.
    max_mr
        Its bound, kg·m.
    """

    shaft: int | None
    ratio: int
    at: complex
    z: float
    max_mr: float

    def rotor(self, angle: float) -> Rotor:
        """A unit mass·radius here at ``angle`` (rad), as a rotor without inertia."""
        return Rotor(ratio=float(self.ratio), inertia=0.0, axis=self.at,
                     eccentrics=(Eccentric(mr=1.0, angle=angle, z=self.z),))


def _placed(z: float, vector: NDArray[np.float64], bound: float) -> PlacedMass:
    """A mass·radius vector ``(Re, Im)`` as its size and angle (none below :data:`ABSENT`)."""
    a, b = float(vector[0]), float(vector[1])
    mr = math.hypot(a, b)
    if mr <= ABSENT * bound:
        return PlacedMass(z=z, mr=0.0, phase_deg=0.0)
    return PlacedMass(z=z, mr=min(mr, bound), phase_deg=math.degrees(math.atan2(b, a)) % 360.0)


class RotorProblem:
    """The convex program of a spec's engine balancing, built once.

    Parameters
    ----------
    design
        A spec whose ``balance`` is a :class:`~balancer.model.balance.RotorBalanceProblem` and
        whose mechanism can take counterweights and shafts
        (:class:`~balancer.model.balance.RotorBalanced`).
    """

    def __init__(self, design: Design) -> None:
        problem = design.balance
        if not isinstance(problem, RotorBalanceProblem):
            raise TypeError("design.balance must be a RotorBalanceProblem")
        if design.operation is None:
            raise SpecError("missing required key: the balancing objective is evaluated at the "
                            "operating speed", key="operation.speed")
        self.problem = problem
        self.weights: Objective = problem.objective
        self.original: Model = design.mechanism
        model = cast("RotorBalanced", design.mechanism)
        self._model = model
        cws = problem.counterweights
        self.replaced: tuple[float, ...] = () if cws is None else cws.planes
        self.speed = design.operation.speed
        self.samples = design.operation.samples
        # A crank-web sector's room bounds each plane's mass·radius (balancer.parts.sizing).
        room = math.inf if cws is None or cws.part is None else most_mr(cws.part)
        sites = [Site(None, 1, 0j, z, min(mr, room)) for z, mr in zip(
            self.replaced, () if cws is None else cws.max_mr, strict=True)]
        for j, shaft in enumerate(problem.shafts):
            sites += [Site(j, shaft.ratio, complex(*shaft.at), z, mr)
                      for z, mr in zip(shaft.planes, shaft.max_mr, strict=True)]
        if not sites:
            raise SpecError("nothing to choose: name counterweight planes "
                            "([balance.counterweights]) or a shaft ([[balance.shafts]])",
                            key="balance")
        self.sites = tuple(sites)
        self.base: Model = model.with_rotor_masses((), (), self.replaced)
        self.before = cycle_analysis(self.original, self.speed, self.samples,
                                     route="newton-euler", loads=False)
        base = cycle_analysis(self.base, self.speed, self.samples, route="newton-euler",
                              loads=False)
        theta = base.theta1
        self.theta1 = theta
        n = 2 * len(self.sites)
        zero = np.zeros(theta.size)
        force = np.zeros((theta.size, n), complex)
        couple = np.zeros((theta.size, n), complex)
        moment = np.zeros((theta.size, n))
        for i, site in enumerate(self.sites):
            for col, angle in ((2 * i, 0.0), (2 * i + 1, math.pi / 2)):
                loads = site.rotor(angle).loads(theta, self.speed, zero)
                force[:, col], couple[:, col], moment[:, col] = (loads.force, loads.couple,
                                                                 loads.moment)
        r = base.reactions
        #: Per load on the frame: each entry's columns per kg·m and the base engine's samples
        #: (the shaking force and rocking couple complex, N and N·m; the moment about z, N·m).
        #: A shaft's bearing force is its eccentrics' columns of the shaking force.
        self.loads: dict[str, tuple[NDArray[Any], NDArray[Any]]] = {
            "shaking_force": (force, r.shaking_force),
            "rocking_couple": (couple, r.rocking_couple),
            "shaking_moment": (moment, r.shaking_moment)}
        w = self.weights
        # each mean-square term's parts: the columns of its loads, and the base engine's
        rows = [math.sqrt(term.weight / theta.size) * np.column_stack([a, b])
                for term in w.terms
                for a, b in zip(squared_parts(term.name, lambda key: self.loads[key][0]),
                                squared_parts(term.name, lambda key: self.loads[key][1]),
                                strict=True)]
        if w.unbalance:
            rows.append(np.column_stack([math.sqrt(w.unbalance) * self.speed**2 * np.eye(n),
                                         np.zeros(n)]))
        stacked = np.vstack(rows) if rows else np.zeros((0, n + 1))
        #: ``[K k]`` as its triangular factor: ``J(x) = ‖R·(x, 1)‖²``.
        self.factor = cast("NDArray[np.float64]", np.linalg.qr(stacked, mode="r"))
        self.bounds = np.repeat([s.max_mr for s in self.sites], 2)
        self.x0 = self._original_vector()

    # -- the objective -------------------------------------------------------------------------

    @property
    def size(self) -> int:
        """Number of entries of ``x`` (two per site)."""
        return 2 * len(self.sites)

    def objective(self, x: NDArray[np.float64]) -> float:
        """``J(x)``, (N·m)²."""
        r = self.factor @ np.append(np.asarray(x, float), 1.0)
        return float(r @ r)

    def _original_vector(self) -> NDArray[np.float64]:
        """The original's ``x``: its replaced counterweights summed per plane; no new shaft."""
        x = np.zeros(self.size)
        for c in self._model.counterweights_in(self.replaced):
            i = next(i for i, s in enumerate(self.sites) if s.shaft is None and s.z == c.z)
            x[2 * i : 2 * i + 2] += c.mr * np.array([math.cos(math.radians(c.phase_deg)),
                                                     math.sin(math.radians(c.phase_deg))])
        return x

    @property
    def original_objective(self) -> float:
        """``J`` of the original design, (N·m)²."""
        return self.objective(self.x0)

    @cached_property
    def inertial_scale(self) -> float:
        """The largest RMS a change of every mass·radius by its bound makes, N·m."""
        return float(np.linalg.norm(self.factor[:, :-1] * self.bounds, 2))

    @cached_property
    def objective_scale(self) -> float:
        """The problem's scale of ``√J``: the original's, or a share of the inertial scale."""
        value = max(math.sqrt(self.original_objective),
                    BALANCED_SHARE * self.inertial_scale)
        return value if value > 0 else 1.0

    def gap(self, objective: float, lower: float) -> float:
        """``(√J − √J_low)/scale``, dimensionless."""
        return (math.sqrt(max(objective, 0.0)) - math.sqrt(max(lower, 0.0))) \
            / self.objective_scale

    def rounding(self, x: NDArray[np.float64]) -> float:
        """How much rounding can blur ``√J`` at ``x``, in the units of :meth:`gap`."""
        eps = float(np.finfo(float).eps)
        blur = ROUNDING_FACTOR * eps * float(
            np.linalg.norm(np.abs(self.factor) @ np.abs(np.append(x, 1.0))))
        return blur / self.objective_scale

    def violations(self, x: NDArray[np.float64], tol: float = 1e-9) -> list[str]:
        """The bounds ``x`` breaks by more than ``tol`` of the bound, as text."""
        out = []
        for i, s in enumerate(self.sites):
            mr = math.hypot(x[2 * i], x[2 * i + 1])
            if mr > s.max_mr * (1 + tol):
                where = "crankshaft" if s.shaft is None else f"shaft {s.shaft + 1}"
                out.append(f"{where} at z = {s.z:g} m: mr {mr:.9g} kg·m above {s.max_mr:.9g}")
        return out

    # -- the design ----------------------------------------------------------------------------

    def masses(self, x: NDArray[np.float64]) -> tuple[tuple[PlacedMass, ...],
                                                      tuple[ShaftDesign, ...]]:
        """The counterweights (per chosen plane) and new shafts of ``x``."""
        cws: list[PlacedMass] = []
        per_shaft: list[list[PlacedMass]] = [[] for _ in self.problem.shafts]
        for i, s in enumerate(self.sites):
            placed = _placed(s.z, x[2 * i : 2 * i + 2], s.max_mr)
            (cws if s.shaft is None else per_shaft[s.shaft]).append(placed)
        shafts = tuple(ShaftDesign(ratio=f.ratio, at=f.at, eccentrics=tuple(e))
                       for f, e in zip(self.problem.shafts, per_shaft, strict=True))
        return tuple(cws), shafts

    def vector_of(self, counterweights: tuple[PlacedMass, ...],
                  shafts: tuple[ShaftDesign, ...]) -> NDArray[np.float64]:
        """``x`` of the masses as placed (their sizes and angles, as the spec will say)."""
        placed = list(counterweights) + [e for s in shafts for e in s.eccentrics]
        x = np.zeros(self.size)
        for i, c in enumerate(placed):
            phase = math.radians(c.phase_deg)
            x[2 * i : 2 * i + 2] = c.mr * math.cos(phase), c.mr * math.sin(phase)
        return x

    def model_of(self, counterweights: tuple[PlacedMass, ...],
                 shafts: tuple[ShaftDesign, ...]) -> Model:
        """The balanced model."""
        return self._model.with_rotor_masses(counterweights, shafts, self.replaced)

    def figures(self, x: NDArray[np.float64]) -> dict[str, float]:
        """The RMS of each load of :attr:`loads` with the masses ``x`` (N, N·m)."""
        return {name: float(np.sqrt(np.mean(np.abs(columns @ x + base) ** 2)))
                for name, (columns, base) in self.loads.items()}

    def unbalance(self, x: NDArray[np.float64]) -> float:
        """``√Σ (|x_i|·ω²)²``, N."""
        return float(np.linalg.norm(x)) * self.speed**2

    def bearing_loads(self, x: NDArray[np.float64]) -> tuple[float, ...]:
        """Each new shaft's largest bearing force over the cycle, N.

        Its eccentrics' columns of the shaking force (:attr:`loads`) times their entries of
        ``x``.
        """
        columns = self.loads["shaking_force"][0]
        out = []
        for j in range(len(self.problem.shafts)):
            cols = np.repeat([s.shaft == j for s in self.sites], 2)
            force = columns[:, cols] @ x[cols]
            out.append(float(np.max(np.abs(force), initial=0.0)))
        return tuple(out)


class RotorSolver:
    """Clarabel (and IPOPT) on a :class:`RotorProblem`, the programs assembled once."""

    def __init__(self, data: RotorProblem) -> None:
        self.data = data
        n = data.size
        scale = data.objective_scale
        full = data.factor[:, :-1] * data.bounds / scale  # in u = x / max_mr
        offset = data.factor[:, -1] / scale
        u_svd, sing, vt = np.linalg.svd(full, full_matrices=False)
        keep = sing > RANK_TOLERANCE * max(float(sing[0]) if sing.size else 0.0, 1e-300)
        seen = u_svd[:, keep].T @ offset
        rest = float(np.linalg.norm(offset - u_svd[:, keep] @ seen))
        self.rank = int(keep.sum())
        self.P = np.vstack([sing[keep, None] * vt[keep], np.zeros((1, n))])
        self.q = np.append(seen, rest)
        self.constraints = []
        for i in range(len(data.sites)):
            m = np.zeros((3, n))
            m[1, 2 * i] = m[2, 2 * i + 1] = 1.0
            self.constraints.append(Constraint("soc", m, np.array([1.0, 0.0, 0.0])))
        self._norm = ConicProgram(n, self.constraints, objective="norm", P=self.P, q=self.q)
        self._seen = self.P[: self.rank]
        self._nearest = (ConicProgram(n, self.constraints, objective="nearest",
                                      equality=(self._seen, np.zeros(self.rank)))
                         if self.rank < n else None)
        self.settings = dict(CLARABEL_SETTINGS)

    def solve_program(self, program: ConicProgram,
                      **data: NDArray[np.float64]) -> ConicSolution:
        """``program`` by Clarabel, again where it did not solve fully (:func:`.solve_program`)."""
        return solve_program(program, self.settings, **data)

    def x(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """Physical ``x`` (kg·m) of scaled ``u``, each vector within its bound."""
        u = np.asarray(u, float).copy()
        for i in range(len(self.data.sites)):
            size = math.hypot(u[2 * i], u[2 * i + 1])
            if size > 1.0:
                u[2 * i : 2 * i + 2] /= size
        return u * self.data.bounds

    def convex(self) -> tuple[NDArray[np.float64], float, list[StageReport]]:
        """The certified optimum: ``x``, the lower bound on ``J`` ((N·m)²) and the stages."""
        data = self.data
        scale = data.objective_scale
        t0 = time.perf_counter()
        first = self.solve_program(self._norm)
        stages = [StageReport(name="convex", converged=first.u is not None,
                              solver_status=first.status, iterations=first.iterations,
                              time=time.perf_counter() - t0,
                              objective=(data.objective(self.x(first.u))
                                         if first.u is not None else math.nan))]
        if first.u is None:
            raise SolverError(f"the balancing failed: Clarabel: {first.status} after "
                              f"{first.iterations} iterations")
        u = np.asarray(first.u, float)
        x = self.x(u)
        norm = ConvexObjective(P=self.P, q=self.q, norm=True, g=np.zeros(data.size), g0=0.0)
        v = None if first.epigraph_dual is None else -np.asarray(first.epigraph_dual[1:])
        bound = lower_bound(norm, self.constraints, None, u, list(first.duals), v,
                            -np.ones(data.size), np.ones(data.size),
                            norm.value(u))
        lower = 0.0 if bound is None else (max(bound.value, 0.0) * scale) ** 2
        if self._nearest is not None:
            t1 = time.perf_counter()
            second = self.solve_program(self._nearest, target=np.zeros(data.size),
                                 equality_rhs=self._seen @ u)
            objective2 = (data.objective(self.x(second.u)) if second.u is not None
                          else math.nan)
            stages.append(StageReport(name="tie-break", converged=second.u is not None,
                                      solver_status=second.status,
                                      iterations=second.iterations,
                                      time=time.perf_counter() - t1, objective=objective2))
            if second.u is not None and data.gap(objective2, data.objective(x)) <= TIE_ACCEPT:
                x = self.x(second.u)
        return self.polish(x), lower, stages

    def polish(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """``x`` with its masses off their bounds solved for exactly, the others kept.

        Where the bound does not hold a mass·radius the objective is a least-squares problem in
        it: solved by a factorisation, its residual is rounding, where the interior-point
        iterate leaves the part of the shaking those masses can cancel at the square root of
        its tolerance (the part they cannot dominates the objective's gradient). The least-norm
        solution in the scaled variables, as the tie-break chooses; kept only if every mass
        stays within its bound and the objective is no worse.
        """
        data = self.data
        bounds = data.bounds
        u = x / bounds
        free = np.zeros(data.size, bool)
        for i in range(len(data.sites)):
            if math.hypot(u[2 * i], u[2 * i + 1]) < 1 - ACTIVE_SHARE:
                free[2 * i : 2 * i + 2] = True
        if not free.any():
            return x
        a = data.factor[:, :-1] * bounds
        rhs = -(data.factor[:, -1] + a[:, ~free] @ u[~free])
        solved, *_ = np.linalg.lstsq(a[:, free], rhs, rcond=RANK_TOLERANCE)
        candidate = u.copy()
        candidate[free] = solved
        if any(math.hypot(candidate[2 * i], candidate[2 * i + 1]) > 1.0
               for i in range(len(data.sites))):
            return x
        y = candidate * bounds
        return y if data.objective(y) <= data.objective(x) else x

    @cached_property
    def _ipopt(self) -> Any:
        """IPOPT's solver of the problem in ``x``, kg·m (built when first asked for)."""
        import casadi as ca

        data = self.data
        xs = ca.SX.sym("x", data.size)
        residual = ca.mtimes(ca.DM(data.factor / data.objective_scale), ca.vertcat(xs, 1.0))
        bounds = data.bounds
        g = [(xs[2 * i] ** 2 + xs[2 * i + 1] ** 2) / bounds[2 * i] ** 2
             for i in range(len(data.sites))]
        return ca.nlpsol("rotors", "ipopt", {"x": xs, "f": ca.dot(residual, residual),
                                             "g": ca.vertcat(*g)}, cast("Any", IPOPT_OPTIONS))

    def nlp(self, x_start: NDArray[np.float64]) -> tuple[NDArray[np.float64] | None,
                                                         StageReport]:
        """IPOPT on ``x`` (kg·m) from ``x_start``: its design (``None`` if it failed)."""
        data = self.data
        solver = self._ipopt
        bounds = data.bounds
        t0 = time.perf_counter()
        said = io.StringIO()
        with interrupts.checked(), contextlib.redirect_stderr(said):
            sol = solver(x0=x_start, lbg=-np.inf, ubg=1.0)
        sys.stderr.write(said.getvalue())
        word = str(solver.stats().get("return_status", "unknown"))
        ok = word in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
        found = np.array(sol["x"]).ravel()
        # (From the convex optimum IPOPT may find no step to take: its point is still one.)
        x = self.x(found / bounds) if np.all(np.isfinite(found)) else None
        return x, StageReport(name="nlp", converged=ok, solver_status=word,
                              iterations=int(solver.stats().get("iter_count", 0)),
                              time=time.perf_counter() - t0,
                              objective=data.objective(x) if x is not None else math.nan)


def optimize(design: Design, backend: str = "nlp") -> BalanceResult:
    """Balance an engine as its ``[balance]`` section asks (DESIGN.md, "Balancing an engine").

    Raises
    ------
    SpecError
        If the spec has no ``[operation]`` or names nothing to choose.
    SolverError
        If Clarabel fails.
    """
    t0 = time.perf_counter()
    data = RotorProblem(design)
    solver = RotorSolver(data)
    x, lower, stages = solver.convex()
    objective = data.objective(x)
    notes: list[str] = []
    if backend == "nlp":
        xn, stage = solver.nlp(x)
        stages.append(stage)
        if xn is not None and not data.violations(xn):
            better = data.objective(xn)
            if data.gap(objective, better) > TIE_TOLERANCE:
                x, objective = xn, better
        else:
            notes.append(f"IPOPT: {stage.solver_status}")
    counterweights, shafts = data.masses(x)
    x = data.vector_of(counterweights, shafts)  # as the spec will say it
    objective = data.objective(x)
    elapsed = time.perf_counter() - t0
    g = data.gap(objective, lower)
    stages = [replace(s, gap=data.gap(s.objective, lower)) if math.isfinite(s.objective)
              else s for s in stages]
    blur = data.rounding(x)
    status = Status.OPTIMAL if g + blur <= GAP_TOLERANCE else Status.FEASIBLE
    balanced = data.model_of(counterweights, shafts)
    after = cycle_analysis(balanced, data.speed, data.samples, route="newton-euler",
                           loads=False)
    masses = RotorMasses(
        counterweights=counterweights, shafts=shafts,
        radius=None if data.problem.counterweights is None else data.problem.counterweights.radius,
        replaced=data.replaced, unbalance_before=data.unbalance(data.x0),
        unbalance_after=data.unbalance(x), bearing_loads=data.bearing_loads(x))
    result = BalanceResult(
        success=True, status=status, message="", backend=backend, linkage=balanced,
        original=data.original, x=x, objective=objective,
        original_objective=data.original_objective, lower_bound=lower, gap=g,
        scale=data.objective_scale, rms_form=True, relaxation_tight=True,
        iterations=sum(s.iterations for s in stages), time=elapsed, stages=tuple(stages),
        before=data.before, after=after,
        gravity=design.operation.gravity if design.operation is not None else (0.0, 0.0),
        weights=data.weights, rotor_masses=masses)
    return replace(result, message=result.summary(notes))


__all__ = ["RotorProblem", "RotorSolver", "Site", "optimize"]
