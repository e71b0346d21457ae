"""Convex balancing: a second-order cone program in the inertial parameters (Clarabel).

With the crank at constant speed the shaking moment, driving torque and shaking force are
linear in the design vector ``x`` (the mechanism's layout,
:class:`balancer.linkage.dynamics.Layout`), and force balance is linear equations
(:mod:`balancer.force_balance`; Eq. 58 for the four-bar). Per link, with ``S = (m·e,
m·f)`` and ``c`` the position of ``com_about`` in the link's frame:

- mass bounds ``m_low ≤ m ≤ m_high``;
- centre of mass in a disc: ``‖S − m·c‖ ≤ m·R`` (a second-order cone);
- realisable inertia about the centre of mass ``I = J − ‖S‖²/m``:
  ``‖S‖²/m ≤ J − max(I_low, m·ρ²)`` (``quad_over_lin``, a rotated cone);
- an upper inertia bound ``I ≤ I_high`` on a link whose centre of mass may move is not convex
  (``J − I_high ≤ ‖S‖²/m``); it is replaced by its convex envelope over the disc,
  ``J − I_high ≤ m·(R² − |c|²) + 2·c·S`` (valid because ``|s̄ − c| ≤ R``), and
  :attr:`ConvexSolution.relaxation_tight` says whether the optimum met the exact bound;
- counter-rotor bounds; fixed entries are eliminated (a fixed centre of mass makes
  ``S = m·s̄``, a fixed inertia with it ``J = I + m·|s̄|²``: both linear).

Objective: ``‖K·x‖`` (the root of the weighted mean squares, minimised as a norm so that a zero
optimum is reached accurately), or ``‖K·x‖² + w_m·Δm`` when mass is penalised; ``K`` is
compressed to its square triangular factor ``R``, and ``R·T`` (in the free variables) to its
numerical rank for the solver: the shaking's harmonic content often gives it far fewer
independent rows than the design vector has entries, and rows of rounding inside the norm's
cone spoil Clarabel's equilibration (it then stalls "almost solved" at 1e-10).

Two stages: the SOCP gives the optimum, and its multipliers the certified lower bound (weak
duality, :mod:`balancer.balance.certificate`: valid whatever Clarabel's tolerances and
status); then, because the optimum is usually not unique (the crank's inertia and
counter-rotor do nothing at constant speed, the shaking moment sees only the difference of the
rocker's inertia and its counter-rotor, and complete balance leaves a whole family of
couplers), a **tie-break** picks, among the designs that give the same ``K·x`` (unique at the
optimum, as ``J`` is strictly convex in it) and the same total mass, the one nearest the
original in scaled parameters.

An infeasible problem (force balance cannot be met within the bounds) is diagnosed from the
value each bound needs alone (or an elastic, phase-1, problem with a slack on each bound) and
raises :class:`InfeasibleError` naming the bounds to widen and the values that would do.

Variables are scaled per link (kg by the original mass, kg·m by ``m·l``, kg·m² by ``m·l²``) and
the objective by the original design's; both programs are assembled once per
:class:`~balancer.balance.problem.NumericProblem`, in numbers, and handed to Clarabel directly
(:mod:`.conic`: a solve takes about a millisecond, where CVXPY's canonicalisation took 30–40 ms);
CVXPY builds only the diagnosis of an infeasible problem, and is the tests' second route.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import NDArray

from .certificate import Constraint, ConvexObjective, lower_bound
from .conic import (
    ACCURACY_FALLBACKS,
    CLARABEL_SETTINGS,
    ConicProgram,
    ConicSolution,
    solve_program,
)
from .diagnosis import Diagnosis
from .feasibility import FORCE_BALANCE_TOLERANCE
from .largest import LargestLoad, initial_rows, over_working_set, pad
from .lsq import pinv as pseudo_inverse
from .problem import NumericProblem
from .repair import Repairs
from .result import StageReport
from .variables import Compressed, layout

#: A certified gap (relative to the problem's scale) above this, well inside the certified
#: tolerance (:data:`~.result.GAP_TOLERANCE`, 1e-6), has the SOCP solved again for a tighter
#: bound (:meth:`ConvexSolver._certified`): whether a design is proven optimal must not hinge on
#: the machine's rounding.
CERTIFY_AGAIN = 1e-8
#: The tie-break's design replaces the SOCP's if it is feasible and its objective is no worse
#: by more than this, relative to the problem's scale (:meth:`NumericProblem.within`).
TIE_ACCEPT = 1e-8
#: The bound on the supports' loads as the first stage's working set gives it to Clarabel: this
#: share tighter (ten times its feasibility tolerance), so that the design keeps the bound
#: itself to rounding (:meth:`ConvexSolver._stage_program`).
BOUND_ROOM = 1e-9
#: Room given to the largest load's hold in the tie-break (:meth:`ConvexSolver.solve`), in the
#: problem's scaled units (the objective's scale is one): Clarabel's tolerance, so that the
#: held program stays feasible; the tie-break's design is kept only within :data:`TIE_ACCEPT`.
TIE_HOLD = 1e-10
#: A counterweight whose mass may be zero and that the optimum gives less than this share of
#: its link's mass is tried at none (:meth:`ConvexSolver._without_small_counterweights`).
SMALL_COUNTERWEIGHT = 1e-3
#: An affine function ``a·u + a0`` of the solver's variables: ``(a, a0)``.
Affine: TypeAlias = tuple[NDArray[np.float64], float]




@dataclass(frozen=True, kw_only=True, eq=False)
class ConvexSolution:
    """The convex optimum (after the tie-break) and its lower bound.

    Attributes
    ----------
    x
        Design vector (inert entries settled); when the relaxation was not tight, the convex
        design made feasible by moving each inertia into its bounds.
    objective
        ``J(x)``, (N·m)².
    lower_bound
        No feasible design does better, (N·m)²: weak duality at the SOCP's multipliers
        (:mod:`balancer.balance.certificate`), whatever Clarabel's tolerances.
    relaxation_tight
        Whether the convex optimum met the exact (non-convex) inertia bounds.
    converged
        Whether Clarabel solved the SOCP.
    stages
        The solver runs.
    """

    x: NDArray[np.float64]
    objective: float
    lower_bound: float
    relaxation_tight: bool
    converged: bool
    stages: tuple[StageReport, ...]


def _with_row(p: NDArray[np.float64], q: NDArray[np.float64], at: int
              ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``‖P·u + q‖`` with the epigraph variable ``τ`` after ``u``, its row ``(0, 1)`` at ``at``."""
    out = np.insert(np.hstack([p, np.zeros((p.shape[0], 1))]), at, 0.0, axis=0)
    out[at, -1] = 1.0
    return out, np.insert(q, at, 0.0)


class ConvexSolver(Repairs, Diagnosis):
    """The SOCP of a redesign problem, built once and solved on demand.

    Parameters
    ----------
    data
        The numeric problem.
    settings
        Clarabel settings to override :data:`CLARABEL_SETTINGS`.
    like
        A solver of the same mechanism under other bounds (:meth:`NumericProblem.with_problem`)
        whose work this one may share where the free variables are the same.
    """

    def __init__(self, data: NumericProblem, *, settings: dict[str, Any] | None = None,
                 like: ConvexSolver | None = None) -> None:
        self.data = data
        self.settings = {**CLARABEL_SETTINGS, **(settings or {})}
        self.layout = layout(data)
        n = self.layout.size
        self._scale = data.objective_scale
        lay = self.layout
        self._cones, self._relaxed = self._constraints()
        self._fb: tuple[NDArray[np.float64], NDArray[np.float64],
                        NDArray[np.float64]] | None = None
        self._failed_row = -1  # a row of Eq. 58 with nothing free that fails
        # restore_balance's least-squares inverse of Eq. 58's rows per set of pinned entries
        # (they depend on the free variables alone: shared with a solver `like` this one)
        self._pinned_inverses: dict[bytes, NDArray[np.float64]] = {}
        if (like is not None and like.data.force_balance is data.force_balance
                and like.layout.primary == self.layout.primary
                and np.array_equal(like.layout.T, self.layout.T)):
            self._pinned_inverses = like._pinned_inverses
        self._inconsistent = self._force_balance()
        equality = None if self._fb is None else self._fb[:2]
        k = data.factor.shape[0]
        r = data.factor / self._scale
        p_matrix, q_vector = r @ lay.T, r @ lay.c
        w_mass = data.weights.added_mass / self._scale / self._scale  # (scale² may underflow)
        mass_row = lay.T[data.mass_entries].sum(axis=0) * w_mass
        mass_offset = (float(lay.c[data.mass_entries].sum()) - data.original_mass) * w_mass
        #: The largest support load as a term of the objective (:mod:`.largest`), or ``None``:
        #: then the first stage's variables are ``(u, τ)``, its objective's factor one row more.
        self.largest = LargestLoad.of(data, lay, self._scale)
        self._norm_form = w_mass == 0 and (k > 0 or self.largest is not None)
        compressed = Compressed.of(p_matrix, q_vector)
        #: The objective's factor in the scaled variables, compressed to its rank (its root,
        #: ``‖P·u + q‖``, in units of the problem's scale): what a front's programs minimise.
        self.compressed = compressed
        self._dual_basis = compressed.basis if k else None
        sv, vt = compressed.singular_values, compressed.vt
        stage_p, stage_q, basis = compressed.P, compressed.q, self._dual_basis
        width = n
        if self.largest is not None:  # τ's row before the constant's (which squares drop)
            width = n + 1
            p_matrix, q_vector = _with_row(p_matrix, q_vector, k)
            stage_p, stage_q = _with_row(compressed.P, compressed.q, compressed.P.shape[0] - 1)
            mass_row = np.append(mass_row, 0.0)
            rank = compressed.P.shape[0] - 1
            basis = np.zeros((k + 1, rank + 2))
            if k:
                basis[:k, :rank] = compressed.basis[:, :rank]
                basis[:k, rank + 1] = compressed.basis[:, rank]
            basis[k, rank] = 1.0
            self._dual_basis = basis
        # The objective as the certificate sees it: the full factor.
        self._objective = ConvexObjective(P=p_matrix, q=q_vector, norm=self._norm_form,
                                          g=mass_row, g0=mass_offset)
        self._stage_equality = (equality if equality is None or self.largest is None
                                else (np.hstack([equality[0], np.zeros((equality[0].shape[0],
                                                                         1))]), equality[1]))
        self._stage_form = (width, stage_p, stage_q, mass_row)
        # The supports' loads (an engine's main bearings'), bounded or the largest weighed: a
        # cone per row each, the bound's last among the bounds' (:meth:`_constraints`).
        supports = data.regressors.supports
        bounded = data.support_bound is not None and supports is not None
        self._bound_cones = self._cones[len(self._cones) - supports.shape[0]:] if (
            bounded and supports is not None) else []
        self._base_cones = self._cones[: len(self._cones) - len(self._bound_cones)]
        #: The working set of the supports' rows the first stage carries (:mod:`.largest`),
        #: or ``None`` (no such rows: every cone).
        self._rows = (initial_rows(np.abs(supports @ data.x0)) if supports is not None and (
            bounded or self.largest is not None) else None)
        #: The first stage's program and its cones (the bounds', the largest load's epigraph
        #: over the working set), in the order the certificate reads their multipliers.
        self._stage_cones: list[Constraint] = []
        self._stage1 = self._stage_program(self._rows)
        # finalize's projections by margin, built when first needed
        self._projections: dict[float, ConicProgram] = {}
        # Tie-break. J is strictly convex in y = P·u, so every optimal design has the same y
        # (and, with mass penalised, the same total mass): fix them at the SOCP's values, in an
        # orthonormal basis of the directions they measure, and pick the design nearest the
        # preferred one. (Bounding J by the optimum instead leaves a thin shell that Clarabel
        # meets only "almost"; its violations, once repaired, cost more than the tie-break.)
        rows = []
        if k:
            rows = list(vt[: sv.size][sv > 1e-12 * sv.max(initial=0.0)])
        if w_mass:
            masses = lay.T[data.mass_entries].sum(axis=0)
            g = masses
            for v in rows:
                g = g - (v @ g) * v
            if np.linalg.norm(g) > 1e-12 * np.linalg.norm(masses):
                rows.append(g / np.linalg.norm(g))
        self._seen = np.array(rows).reshape(len(rows), n)
        fixed = [] if equality is None else [equality]
        if rows:
            fixed.append((self._seen, np.zeros(len(rows))))
        #: Whether the tie-break has a choice: its equations leave some design free (otherwise
        #: the optimum is unique, and the SOCP's is it).
        count = sum(e.shape[0] for e, _ in fixed)  # (fewer rows than variables: free)
        self._tie_free = count < n or (bool(fixed) and np.linalg.matrix_rank(
            np.vstack([e for e, _ in fixed])) < n)
        self._stage2_equality = ((np.vstack([e for e, _ in fixed]),
                                  np.concatenate([r for _, r in fixed])) if fixed else None)
        self._stage2 = ConicProgram(n, self._cones, objective="nearest",
                                    equality=self._stage2_equality)
        #: The tie-break's hold on the largest load at the first stage's optimum (cones in
        #: ``u``), set by :meth:`solve`; empty without that term.
        self._held: list[Constraint] = []

    def _stage_program(self, rows: NDArray[np.intp] | None) -> ConicProgram:
        """The first stage's program with the supports' ``rows`` (all where ``None``).

        The bounds, the bound on those rows' loads (``max_bearing_load``) and the largest
        load's epigraph over them (:mod:`.largest`).
        """
        width, p, q, g = self._stage_form
        n = self.layout.size

        def program_cones(room: float) -> list[Constraint]:
            bound = ([] if rows is None or not self._bound_cones
                     else [self._bound_cones[r] for r in rows])
            kept = (self._cones if rows is None else
                    [*self._base_cones, *(Constraint(c.kind, c.M, np.r_[c.m[0] - room, c.m[1:]])
                                          for c in bound)])
            return (kept if self.largest is None else
                    [*pad(kept, width), *self.largest.cones(width, n, rows)])

        # The certificate reads the program's multipliers against its cones as they are; the
        # solver is given the bound's a share of Clarabel's tolerance tighter, so that its
        # design meets the bound itself (finalize would move it off at a cost).
        self._stage_cones = program_cones(0.0)
        cones = program_cones(BOUND_ROOM)
        if self._norm_form:
            # In epigraph form, so that the norm's multiplier is the cone's dual.
            return ConicProgram(width, cones, equality=self._stage_equality, objective="norm",
                                P=p, q=q)
        # ‖P·u + q‖² + w_m·Δm, constants dropped
        return ConicProgram(width, cones, equality=self._stage_equality, objective="squares",
                            P=p[:-1], q=q[:-1], g=g)

    def _first_stage(self) -> tuple[StageReport, ConicSolution]:
        """The first stage solved: with the supports' working set, until its optimum breaks none.

        Each round's program a relaxation of the whole (:mod:`.largest`); the report's
        iterations and time those of every round.
        """
        supports = self.data.regressors.supports
        if self._rows is None or supports is None:
            return self._run(self._stage1, "convex")
        n = self.layout.size
        reports: list[StageReport] = []

        def solve(rows: NDArray[np.intp]) -> ConicSolution:
            if reports:  # (the first round's program is built already)
                self._stage1 = self._stage_program(rows)
            report, solution = self._run(self._stage1, "convex")
            reports.append(report)
            return solution

        def limits(solution: ConicSolution) -> tuple[NDArray[np.float64], float]:
            assert solution.u is not None
            loads = np.abs(supports @ self.layout.x(solution.u[:n]))  # N
            return loads, self.row_limit(None if self.largest is None else float(solution.u[n]))

        first, self._rows = over_working_set(self._rows, solve, limits)  # (a start as good
        # for the next solve)
        return replace(reports[-1], iterations=sum(r.iterations for r in reports),
                       time=sum(r.time for r in reports)), first

    def row_limit(self, tau: float | None) -> float:
        """The largest load a support's row may carry in a program, N.

        The bound (``max_bearing_load``), and the largest load's epigraph variable ``tau``
        (scaled: ``√w_L·L/s``) where the objective weighs it; ``inf`` without either.
        """
        limit = math.inf if self.data.support_bound is None else self.data.support_bound
        if tau is not None:
            limit = min(limit, tau * self._scale / math.sqrt(
                self.data.weights.largest_bearing_load))
        return limit

    @property
    def working_rows(self) -> NDArray[np.intp] | None:
        """The supports' rows a first stage starts from (:mod:`.largest`), or ``None``."""
        return self._rows

    @property
    def base_constraints(self) -> list[Constraint]:
        """:attr:`constraints` but the bound on the supports' loads."""
        return self._base_cones

    @property
    def bound_constraints(self) -> list[Constraint]:
        """The bound on the supports' loads, one cone per row (none without the bound)."""
        return self._bound_cones

    @property
    def constraints(self) -> list[Constraint]:
        """The bounds as cone constraints in the scaled variables (:meth:`_constraints`)."""
        return self._cones

    @property
    def equality(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """Eq. 58's rows that a free variable enters, ``(E, r)`` scaled, or ``None``."""
        return None if self._fb is None else self._fb[:2]

    def check_consistent(self) -> None:
        """Raise if a row of Eq. 58 that nothing free enters fails.

        The row itself is the diagnosis: its links, one of which must be let change (and a
        ``com_on_line`` that forbids what it asks); no bound widened within what is free helps.

        Raises
        ------
        InfeasibleError
            Naming the links to free.
        """
        if self._inconsistent:
            raise self._fixed_row_error()

    # -- building ------------------------------------------------------------------------------

    def _constraints(self, margin: float = 0.0, *, supports: bool = True
                     ) -> tuple[list[Constraint], list[str]]:
        """The bounds as cone constraints, each tightened by ``margin`` (relative, scaled units).

        ``supports``: with the bound on the supports' loads (``max_bearing_load``), if any.

        Returns the constraints (:class:`~.certificate.Constraint`, in the order their
        multipliers come back: the certificate evaluates them) and the links whose upper
        inertia bound is relaxed. A range narrower than twice the
        margin is kept as it is (its ends are what the designer gave).
        """
        data, lay = self.data, self.layout
        out: list[Constraint] = []
        relaxed: list[str] = []
        free = set(lay.primary)

        def entry(i: int, scale: float) -> tuple[NDArray[np.float64], float]:
            """``x[i]/scale`` as an affine function ``(a, a0)`` of the variables.

            A counterweight's own entry: less the kept link's.
            """
            return lay.T[i] / scale, float((lay.c[i] - data.offset[i]) / scale)

        def at_least(a: Affine, lo: float) -> None:  # a ≥ lo
            out.append(Constraint("nonneg", a[0][None, :], np.array([a[1] - lo])))

        def at_most(a: Affine, hi: float) -> None:  # a ≤ hi
            out.append(Constraint("nonneg", -a[0][None, :], np.array([hi - a[1]])))

        def norm_at_most(rows: list[Affine], rhs: Affine) -> None:  # ‖rows‖ ≤ rhs
            out.append(Constraint("soc", np.array([rhs[0]] + [a for a, _ in rows]),
                                  np.array([rhs[1]] + [a0 for _, a0 in rows])))

        # ‖rows‖²/den ≤ rhs: ‖(2·w, s − t)‖ ≤ s + t
        def quad_at_most(rows: list[Affine], den: Affine, rhs: Affine) -> None:
            norm_at_most([combine((2.0, a)) for a in rows] + [combine((1.0, den), (-1.0, rhs))],
                         combine((1.0, den), (1.0, rhs)))

        def combine(*terms: tuple[float, Affine]) -> Affine:
            """``Σ w·a`` of ``(w, a)`` pairs."""
            # (a sum of arrays, never of none: not the 0 that sum() starts from)
            return (sum(w * a[0] for w, a in terms),  # type: ignore[return-value]
                    float(sum(w * a[1] for w, a in terms)))

        def inside(lo: float, hi: float) -> tuple[float, float]:
            return (lo + margin, hi - margin) if hi - lo > 2 * margin else (lo, hi)

        for b in data.links:
            k = b.start
            mref, l, iref = b.mass_ref, b.length, b.inertia_ref
            m = entry(k, mref)
            # A counterweight that may be none keeps its cone's apex in the tightened set: its
            # bounds are tightened in proportion to its mass (none stays none).
            apex = b.offset is not None and b.mass[0] == 0
            if k in free:
                lo, hi = inside(b.mass[0] / mref, b.mass[1] / mref)
                at_least(m, 0.0 if apex else lo)
                at_most(m, hi)
            se, sf = entry(k + 1, mref * l), entry(k + 2, mref * l)
            centre = b.com_centre / l  # complex, in the link's frame
            if b.com_fixed is None:
                radius = b.radius / l
                radius = radius - margin if radius > 2 * margin else radius
                norm_at_most([combine((1.0, se), (-centre.real, m)),
                              combine((1.0, sf), (-centre.imag, m))], combine((radius, m)))
            if (k + 3) not in free:
                continue  # inert, or fixed inertia with a fixed centre of mass: nothing to ask
            j = entry(k + 3, iref)
            rho2 = (b.gyration / l) ** 2
            lo, hi = b.inertia[0] / iref, b.inertia[1] / iref
            lo_m = lo + margin if hi - lo > 2 * margin else lo
            hi_m = hi - margin if hi - lo > 2 * margin else hi
            if b.com_fixed is not None:
                inertia = combine((1.0, j), (-abs(b.com_fixed / l) ** 2, m))
                at_least(inertia, lo_m)
                if rho2:
                    at_least(combine((1.0, inertia), (-rho2, m)), margin)
                if math.isfinite(hi):
                    at_most(inertia, hi_m)
                continue
            if apex:  # ‖S‖²/m ≤ J − (ρ² + margin)·m (lo = 0)
                room = combine((1.0, j), (-(rho2 + margin), m))
                quad_at_most([se, sf], m, room)
            else:
                if lo > 0 or not rho2:  # ‖S‖²/m ≤ J − lo
                    quad_at_most([se, sf], m, (j[0], j[1] - lo_m))
                if rho2:  # ‖S‖²/m ≤ J − ρ²·m − margin
                    room = combine((1.0, j), (-rho2, m))
                    quad_at_most([se, sf], m, (room[0], room[1] - margin))
            if math.isfinite(hi):  # J − hi ≤ m·(R² − |c|²) + 2·c·S
                radius = b.radius / l
                cap = combine((radius**2 - abs(centre) ** 2, m), (2 * centre.real, se),
                              (2 * centre.imag, sf), (-1.0, j))
                at_least(cap, -hi_m)
                relaxed.append(b.name)
            if b.offset is not None:  # a counterweight's spread: J about p ≤ m·(2R² + ρ²)
                reach2 = b.counterweight_reach**2 / l**2
                spread = combine((1.0, j), (-2 * centre.real, se), (-2 * centre.imag, sf),
                                 (abs(centre) ** 2 - reach2 + margin, m))
                at_most(spread, 0.0)
        for b in data.rotor_links:
            k = b.rotor_entry
            if k in free:
                assert b.counter_rotor is not None
                scale = data.scales[k]
                lo, hi = inside(b.counter_rotor[0] / scale, b.counter_rotor[1] / scale)
                at_least(entry(k, scale), lo)
                at_most(entry(k, scale), hi)
        if data.sites is not None:  # |x_i| ≤ max_mr: in the scaled variables, ‖u_i‖ ≤ 1
            for i in data.sites.chosen:
                entries = range(data.size)[data.sites.entries(i)]
                bound = data.sites.sites[i].max_mr / data.scales[entries.start]
                norm_at_most([entry(k, data.scales[k]) for k in entries],
                             (np.zeros(lay.size), bound * (1 - margin) if margin < 0.5 else bound))
        support, rows = data.support_bound, data.regressors.supports
        if supports and support is not None and rows is not None:  # |load| ≤ bound, each sample
            a, a0 = rows @ lay.T / support, rows @ lay.c / support
            top = 1 - margin if margin < 0.5 else 1.0
            zero = np.zeros(lay.size)
            for r in range(rows.shape[0]):
                out.append(Constraint("soc", np.array([zero, a[r].real, a[r].imag]),
                                      np.array([top, a0[r].real, a0[r].imag])))
        return out, relaxed

    def box(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Bounds of each variable over the SOCP's feasible set (scaled; ``hi`` may be ∞).

        A mass between its bounds; a first moment within its disc at any allowed mass; an
        inertia about the frame's origin ``J = I + m·|s̄|²`` at least ``max(I_low, m·ρ²)``
        (plus ``m·|s̄|²`` for a fixed centre of mass) and at most ``I_high + m·(R + |c|)²``
        (the relaxed bound of :meth:`_constraints` allows no more), unbounded without
        ``I_high``; a counter-rotor between its bounds.
        """
        data, lay = self.data, self.layout
        lo = np.full(lay.size, -np.inf)
        hi = np.full(lay.size, np.inf)
        index = {entry: j for j, entry in enumerate(lay.primary)}
        for b in data.links:
            k = b.start
            m_lo, m_hi = b.mass
            ranges = {k: (m_lo, m_hi)}
            if b.com_fixed is None:
                for i, c in ((k + 1, b.com_centre.real), (k + 2, b.com_centre.imag)):
                    low, high = c - b.radius, c + b.radius
                    ranges[i] = (min(m_lo * low, m_hi * low), max(m_lo * high, m_hi * high))
            shift = data.offset
            for i, (low, high) in ranges.items():
                if i in index:
                    lo[index[i]] = (low + shift[i]) / data.scales[i]
                    hi[index[i]] = (high + shift[i]) / data.scales[i]
            if k + 3 in index:
                base = max(b.inertia[0], m_lo * b.gyration**2)
                reach = abs(b.com_fixed) if b.com_fixed is not None else (
                    abs(b.com_centre) + b.radius)
                if b.com_fixed is not None:
                    base += m_lo * reach**2
                scale = data.scales[k + 3]
                lo[index[k + 3]] = (base + shift[k + 3]) / scale
                hi[index[k + 3]] = (b.inertia[1] + m_hi * reach**2 + shift[k + 3]) / scale
        for b in data.rotor_links:
            if b.rotor_entry in index:
                assert b.counter_rotor is not None
                j = index[b.rotor_entry]
                lo[j], hi[j] = (v / data.scales[b.rotor_entry] for v in b.counter_rotor)
        if data.sites is not None:
            for i in data.sites.chosen:
                for k in range(data.size)[data.sites.entries(i)]:
                    bound = data.sites.sites[i].max_mr / data.scales[k]
                    lo[index[k]], hi[index[k]] = -bound, bound
        return lo, hi

    def _force_balance(self) -> bool:
        """Eq. 58's rows that involve a free variable (scaled); say whether a fixed row fails.

        Each row is scaled by the magnitude of its own terms at the design's scale (a row that
        involves only light links is not drowned by a heavy one's, as it would be by the
        total mass); a row whose free part is below rounding of its terms is fixed.
        """
        if self.data.force_balance is None:
            return False
        a, b = self.data.force_balance
        lay = self.layout
        terms = np.abs(a) @ np.abs(self.data.scales)  # each row's magnitude, kg
        at = a @ lay.T / terms[:, None]
        rhs = (b - a @ lay.c) / terms
        fixed_rows = self.data.force_balance_rows(lay.c)  # the rows with nothing free
        inconsistent = False
        keep = []
        for i in range(a.shape[0]):
            if np.max(np.abs(at[i]), initial=0.0) > 1e-13:
                keep.append(i)
            elif fixed_rows[i] > FORCE_BALANCE_TOLERANCE:
                inconsistent = True
                self._failed_row = i
        if keep:
            self._fb = (at[keep], rhs[keep], pseudo_inverse(at[keep]))
        return inconsistent

    # -- solving -------------------------------------------------------------------------------

    def _run(self, program: ConicProgram, name: str,
             **data: NDArray[np.float64]) -> tuple[StageReport, ConicSolution]:
        """Solve one of the programs; its report, and Clarabel's answer."""
        start = time.perf_counter()
        solution = solve_program(program, self.settings, **data)
        elapsed = time.perf_counter() - start
        ok = solution.u is not None
        report = StageReport(
            name=name,
            converged=ok,
            solver_status=solution.status,
            iterations=solution.iterations,
            time=elapsed,
            objective=(self.data.reduced_objective(
                self.layout.x(solution.u[: self.layout.size]))
                if solution.u is not None else math.nan),
        )
        return report, solution

    def solve(
        self, *, prefer: NDArray[np.float64] | None = None, tie_break: bool = True
    ) -> ConvexSolution:
        """Solve the SOCP (and the tie-break).

        Parameters
        ----------
        prefer
            Design vector the tie-break moves towards (default: the original design).
        tie_break
            Run the tie-break stage (otherwise the SOCP's own optimum is returned).

        Raises
        ------
        InfeasibleError
            If no design within the bounds meets force balance; the message names the bounds
            to widen and by how much.
        SolverError
            If Clarabel fails.
        """
        data, lay = self.data, self.layout
        self.check_consistent()
        report, first = self._first_stage()
        stages = [report]
        if first.u is None:
            raise self.infeasible(f"Clarabel: {report.solver_status} after "
                                   f"{report.iterations} iterations")
        u1 = first.u[: lay.size]  # (without the largest load's τ)
        x, tight = self.repair(u1)
        objective = data.reduced_objective(x)
        self._held = []
        if tie_break and lay.size:
            target = data.preferred if prefer is None else np.asarray(prefer, float)
            fixed = [] if self._fb is None else [self._fb[1]]
            probe = x
            stage2 = self._stage2
            if self.largest is not None:  # every optimum has the same largest load: held
                tau = max(float(first.u[lay.size]), self.largest.value(u1)) + TIE_HOLD
                self._held = self.largest.held(tau, self._rows)
                stage2 = ConicProgram(lay.size, [*self._cones, *self._held],
                                      objective="nearest", equality=self._stage2_equality)
            if self._tie_free:
                report2, second = self._run(
                    stage2, "tie-break", target=lay.u(target),
                    equality_rhs=np.concatenate([*fixed, self._seen @ u1]))
                stages.append(report2)
            if self._tie_free and second.u is not None:
                x2, tight2 = self.repair(second.u)
                objective2 = data.reduced_objective(x2)
                probe = x2
                # Only a feasible tie-break design replaces the SOCP's (an "almost solved"
                # one, repaired, can be cheaper by violating a bound).
                if not data.violations(x2) and data.within(objective2, objective, TIE_ACCEPT):
                    x, tight, objective = x2, tight2, objective2
            x, objective = self._without_small_counterweights(x, probe, u1, target, objective,
                                                              stages)
            x, objective = self.polish(x, target, objective)
            x = self.polish_sites(x)
        x = data.settle(x)  # the inert entries, for a crank whose speed changes
        x, feasible = self.finalize(x)
        if feasible and tie_break:
            x = self.without_idle_counterweights(x)
        lower = self._certified(first, x if feasible else None)
        return ConvexSolution(
            x=x,
            objective=data.objective(x),
            lower_bound=lower,
            relaxation_tight=tight,
            converged=feasible,
            stages=tuple(stages),
        )

    def _without_small_counterweights(
        self, x: NDArray[np.float64], probe: NDArray[np.float64], u1: NDArray[np.float64],
        target: NDArray[np.float64], objective: float, stages: list[StageReport],
    ) -> tuple[NDArray[np.float64], float]:
        """The design with the counterweights it barely uses taken off, where that costs nothing.

        A counterweight whose mass may be zero and that the optimum does without lies at the
        apex of its cone, which the interior-point solver approaches only to about the square
        root of its tolerance (a crank's 30 mg where none is needed). Those lighter than
        :data:`SMALL_COUNTERWEIGHT` of their link's mass are fixed at none and the tie-break
        solved again; its design replaces ``x`` where it is feasible and no worse
        (:data:`TIE_ACCEPT`). The small ones are those of ``probe``, the tie-break's design
        (whether it was kept or not: at the apex of a cone it may break a bound by the
        solver's accuracy).
        """
        data, lay = self.data, self.layout
        own = data.own(probe)
        small = [b for b in data.links
                 if b.offset is not None and b.mass[0] == 0 and not data.absent(b, own)
                 and own[b.start] <= SMALL_COUNTERWEIGHT * b.mass_ref]
        if not small:
            return x, objective
        rows, values = [], []
        for b in small:
            for i in range(b.start, b.start + 4):
                if np.any(lay.T[i]):  # (an inert entry is settled afterwards)
                    rows.append(lay.T[i] / data.scales[i])
                    values.append((data.offset[i] - lay.c[i]) / data.scales[i])
        equality = [np.array(rows)]
        rhs = [np.array(values)]
        if self._fb is not None:
            equality.insert(0, self._fb[0])
            rhs.insert(0, self._fb[1])
        if self._seen.shape[0]:
            equality.append(self._seen)
            rhs.append(self._seen @ u1)
        program = ConicProgram(lay.size, [*self._cones, *self._held], objective="nearest",
                               equality=(np.vstack(equality), np.concatenate(rhs)))
        report, solution = self._run(program, "counterweights off",
                                     target=lay.u(target))
        stages.append(report)
        if solution.u is None:
            return x, objective
        x2, _ = self.repair(solution.u)
        objective2 = data.reduced_objective(x2)
        if not data.violations(x2) and data.within(objective2, objective, TIE_ACCEPT):
            return x2, objective2
        return x, objective

    def _certified(self, first: ConicSolution, feasible: NDArray[np.float64] | None) -> float:
        """The certified lower bound on ``J`` from the SOCP's solution ``first``, (N·m)².

        Where it leaves the design's gap above :data:`CERTIFY_AGAIN` (Clarabel "almost solved"
        with a dual that is off by more than its tolerance: on another machine's arithmetic the
        Jansen leg's gap was 4e-6, beyond the certified 1e-6), the SOCP is solved again with
        each of :data:`ACCURACY_FALLBACKS` and the highest bound kept (every one is valid by
        weak duality), until one is tight.
        """
        data = self.data
        lower = self._lower_bound(first, feasible)
        if feasible is None:
            return lower
        objective = data.objective(feasible)
        for settings in ACCURACY_FALLBACKS:
            if data.gap(objective, lower) <= CERTIFY_AGAIN:
                break
            again = self._stage1.solve({**self.settings, **settings})
            if again.u is not None:
                lower = max(lower, self._lower_bound(again, feasible))
        return lower

    def _point(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """The first stage's variables at ``u``: ``u``, and its largest load's ``τ`` if any."""
        return u if self.largest is None else np.append(u, self.largest.value(u))

    def _lower_bound(self, solution: ConicSolution,
                     feasible: NDArray[np.float64] | None) -> float:
        """The certified lower bound on ``J`` from one solution of the SOCP, (N·m)².

        See :meth:`_bound`; the norm's multiplier from the epigraph's cone.
        """
        norm_dual = None
        if solution.epigraph_dual is not None and self._dual_basis is not None:
            # The Lagrangian is t − (μ·t + w·(P·u + q)): the norm's minorant is −w.
            norm_dual = -(self._dual_basis @ solution.epigraph_dual[1:])
        assert solution.u is not None
        return self._bound(solution.u, list(solution.duals), norm_dual, feasible)

    def _bound(self, u: NDArray[np.float64], multipliers: list[NDArray[np.float64]],
                     norm_dual: NDArray[np.float64] | None,
                     feasible: NDArray[np.float64] | None) -> float:
        """The certified lower bound on ``J``, (N·m)².

        By weak duality from the SOCP's solution ``u`` and its multipliers, repaired
        (:func:`.certificate.lower_bound`): valid whatever Clarabel's tolerances and status,
        and as tight as its dual is accurate. ``feasible`` (a design that meets every bound)
        bounds an inertia that has no upper bound on the objective's sublevel set. Where that
        certificate cannot be made (an unbounded direction of the wrong sign that the
        objective does not bound, a solution that is not finite), the bound that needs no
        solver: ``J ≥ 0``, or with added mass penalised ``J ≥ w_m·(Σ m_low − Σ m_original)``.
        """
        upper = None
        if feasible is not None:
            f = self._objective.value(self._point(self.layout.u(feasible)))
            upper = f + abs(f) + 1e-9  # above the optimum, whatever the design's rounding
        lo, hi = self.box()
        if self.largest is not None:  # τ at a minimiser: the largest load, within the box's
            # (and, for the norm, no more than the norm itself: at most a feasible design's)
            reach = self.largest.bound(lo, hi)
            if upper is not None and self._norm_form:
                reach = min(reach, upper)
            lo, hi = np.append(lo, 0.0), np.append(hi, reach)
        bound = lower_bound(self._objective, self._stage_cones, self._stage_equality, u,
                            multipliers, norm_dual, lo, hi, upper)
        scale = self._scale
        if bound is not None and self._norm_form:
            return (max(bound.value, 0.0) * scale) ** 2
        if bound is not None:
            return bound.value * scale**2
        data = self.data
        least = sum(b.mass[0] for b in data.links) - data.original_mass
        return data.weights.added_mass * least  # ‖K·x‖² ≥ 0 and every mass at least its least
