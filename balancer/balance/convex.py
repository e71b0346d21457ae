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
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError
from .certificate import Constraint, Objective, lower_bound
from .conic import SOLVED, ConicProgram, ConicSolution
from .problem import FORCE_BALANCE_TOLERANCE, ROUNDING_TOLERANCE, NumericProblem
from .result import InfeasibleError, StageReport

if TYPE_CHECKING:
    import cvxpy as cp

#: Clarabel's settings for every solve here (tight: the zero optimum of complete balancing
#: must be reached to ~1e-10 of the original shaking moment).
CLARABEL_SETTINGS: dict[str, float | int] = {
    "tol_gap_abs": 1e-10,
    "tol_gap_rel": 1e-10,
    "tol_feas": 1e-10,
    "tol_infeas_abs": 1e-10,
    "tol_infeas_rel": 1e-10,
    "tol_ktratio": 1e-8,
    "max_iter": 200,
}
#: The tie-break's design replaces the SOCP's if it is feasible and its objective is no worse
#: by more than this, relative to the problem's scale (:meth:`NumericProblem.within`).
TIE_ACCEPT = 1e-8
#: Inward margin of the bounds (scaled units) in the final projection (:meth:`finalize`): a
#: hundred times Clarabel's feasibility tolerance, so that its solution lies inside the bounds.
MARGIN = 1e-8
#: Inward distance (of a link's mass, of its length) at which the active-set correction
#: (:meth:`ConvexSolver.onto_active`) puts each bound it moves a design onto: far above the
#: rounding of the physical values (``ε``), far below any tolerance.
ACTIVE_INSIDE = 1e-12
#: Eq. 58's residual, relative to its terms (:meth:`NumericProblem.force_balance_rows`), at
#: which a design meets it to rounding: a few ε for the few products in each row.
EQ58_ROUNDING = 16 * float(np.finfo(float).eps)
_EPS = float(np.finfo(float).eps)
#: A counterweight whose mass may be zero and that the optimum gives less than this share of
#: its link's mass is tried at none (:meth:`ConvexSolver._without_small_counterweights`).
SMALL_COUNTERWEIGHT = 1e-3
#: A slack of the elastic problem above this (in scaled units) names a bound to widen.
SLACK_TOLERANCE = 1e-7
#: How far beyond its bound (relative to the bound's scale) the value a bound needs alone
#: must lie to be evidence (:meth:`ConvexSolver.diagnose`): ten times Clarabel's tolerance
#: (1e-10, scaled units) on that value.
NEEDED_TOLERANCE = 1e-9



@dataclass(frozen=True)
class Layout:
    """The design vector as an affine map of the free variables: ``x = c + T·u``.

    Fixed entries sit in ``c``; a fixed centre of mass makes ``m·e``, ``m·f`` multiples of
    ``m``; a fixed inertia with a fixed centre of mass makes ``J = I + m·|s̄|²``. Inert entries
    (see :attr:`NumericProblem.inert`) are left at 0 (a kept link's under a counterweight: at
    its own, the counterweight's at 0) and settled afterwards. Each variable is
    one entry of ``x`` divided by its scale.

    Attributes
    ----------
    c
        Constant part, ``(P,)``.
    T
        ``(P, n)``.
    primary
        The entry of ``x`` each variable stands for.
    """

    c: NDArray[np.float64]
    T: NDArray[np.float64]
    primary: tuple[int, ...]

    @property
    def size(self) -> int:
        """Number of free variables ``n``."""
        return self.T.shape[1]

    def x(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """``c + T·u``."""
        return self.c + self.T @ u

    def u(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The variables that stand for ``x``'s entries."""
        return np.array([x[i] / self.T[i, j] for j, i in enumerate(self.primary)])


def layout(data: NumericProblem) -> Layout:
    """The affine map from the free variables to the design vector (see :class:`Layout`)."""
    scales = data.scales
    size = data.size
    c = np.zeros(size)
    rows = np.zeros((size, size))  # rows[i] = coefficients of x[i] on the variables
    primary: list[int] = []

    def new_variable(entry: int) -> None:
        rows[entry, len(primary)] = scales[entry]
        primary.append(entry)

    for b in data.links:
        k = b.start
        if b.mass[0] < b.mass[1]:
            new_variable(k)
        else:
            c[k] = b.mass[0] + data.offset[k]
        if b.com_fixed is None:
            new_variable(k + 1)
            if not b.on_line:  # on the link's line, m·f stays 0
                new_variable(k + 2)
        else:
            for i, part in ((k + 1, b.com_fixed.real), (k + 2, b.com_fixed.imag)):
                c[i] = part * c[k]
                rows[i] = part * rows[k]
        if data.inert[k + 3]:
            # Left to settle; under a counterweight at the kept link's own (the counterweight's
            # nil): at 0 it would be an inertia of −J₀, never none (NumericProblem.absent).
            c[k + 3] = data.offset[k + 3]
        elif b.inertia_fixed and b.com_fixed is not None:
            s2 = abs(b.com_fixed) ** 2
            c[k + 3] = b.inertia[0] + s2 * c[k]
            rows[k + 3] = s2 * rows[k]
        else:
            new_variable(k + 3)
    for b in data.rotor_links:
        entry = b.rotor
        assert b.counter_rotor is not None
        lo, hi = b.counter_rotor
        if data.inert[entry]:
            continue
        if lo < hi:
            new_variable(entry)
        else:
            c[entry] = lo
    return Layout(c=c, T=rows[:, : len(primary)].copy(), primary=tuple(primary))


@dataclass(frozen=True)
class Compressed:
    """An objective's factor ``‖P·u + q‖`` compressed to its numerical rank, for the solver.

    ``R·T`` has as many rows as the design vector but rank only as large as the shaking's
    harmonic content (6 for the crank-shaper against 22 rows); rows of rounding (1e-16 of the
    others) inside a second-order cone spoil its equilibration, and Clarabel stalled "almost
    solved" at 1e-10. ``‖P·u + q‖² = ‖Σ₁·V₁ᵀ·u + U₁ᵀ·q‖² + ‖U₂ᵀ·q‖²``, dropping only singular
    values of rounding: :attr:`P` and :attr:`q` are the kept rows and one last row
    ``(0, ‖U₂ᵀ·q‖)``. A multiplier ``w`` of those rows is ``basis·w`` in the full factor's
    rows (the rows kept, and the direction of ``q``'s part in the rest).
    """

    P: NDArray[np.float64]
    q: NDArray[np.float64]
    basis: NDArray[np.float64]
    singular_values: NDArray[np.float64]
    vt: NDArray[np.float64]

    @classmethod
    def of(cls, p: NDArray[np.float64], q: NDArray[np.float64]) -> Compressed:
        """The compression of ``‖p·u + q‖`` (``p`` of shape ``(k, n)``)."""
        k, n = p.shape
        if k:
            u_left, sv, vt = np.linalg.svd(p, full_matrices=True)
        else:
            u_left, sv, vt = np.zeros((0, 0)), np.zeros(0), np.zeros((0, n))
        eps = np.finfo(float).eps
        rank = int(np.sum(sv > 16 * eps * max(p.shape) * sv.max(initial=0.0)))
        rest = u_left[:, rank:].T @ q
        q_rest = float(np.linalg.norm(rest))
        rest_dir = u_left[:, rank:] @ (rest / q_rest) if q_rest > 0 else np.zeros(k)
        return cls(P=np.vstack([sv[:rank, None] * vt[:rank], np.zeros((1, n))]),
                   q=np.append(u_left[:, :rank].T @ q, q_rest),
                   basis=np.column_stack([u_left[:, :rank], rest_dir]),
                   singular_values=sv, vt=vt)


@dataclass(frozen=True, kw_only=True)
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


class ConvexSolver:
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

    def __init__(self, data: NumericProblem, *, settings: dict | None = None,
                 like: ConvexSolver | None = None) -> None:
        self.data = data
        self.settings = {**CLARABEL_SETTINGS, **(settings or {})}
        self.layout = layout(data)
        n = self.layout.size
        self._scale = data.objective_scale
        lay = self.layout
        self._cones, self._relaxed = self._constraints()
        self._fb: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
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
        self._norm_form = w_mass == 0 and k > 0
        # The objective as the certificate sees it: the full factor.
        self._objective = Objective(P=p_matrix, q=q_vector, norm=self._norm_form,
                                    g=mass_row, g0=mass_offset)
        compressed = Compressed.of(p_matrix, q_vector)
        self._dual_basis = compressed.basis if k else None
        sv, vt = compressed.singular_values, compressed.vt
        if self._norm_form:
            # In epigraph form, so that the norm's multiplier is the cone's dual.
            self._stage1 = ConicProgram(n, self._cones, equality=equality, objective="norm",
                                        P=compressed.P, q=compressed.q)
        else:  # ‖P·u + q‖² + w_m·Δm, constants dropped
            self._stage1 = ConicProgram(n, self._cones, equality=equality, objective="squares",
                                        P=compressed.P[:-1], q=compressed.q[:-1], g=mass_row)
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
        self._stage2 = ConicProgram(
            n, self._cones, objective="nearest",
            equality=(np.vstack([e for e, _ in fixed]), np.concatenate([r for _, r in fixed]))
            if fixed else None)

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

    def _constraints(self, margin: float = 0.0) -> tuple[list[Constraint], list[str]]:
        """The bounds as cone constraints, each tightened by ``margin`` (relative, scaled units).

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

        def at_least(a, lo: float) -> None:  # a ≥ lo
            out.append(Constraint("nonneg", a[0][None, :], np.array([a[1] - lo])))

        def at_most(a, hi: float) -> None:  # a ≤ hi
            out.append(Constraint("nonneg", -a[0][None, :], np.array([hi - a[1]])))

        def norm_at_most(rows, rhs) -> None:  # ‖rows‖ ≤ rhs, each an affine (a, a0)
            out.append(Constraint("soc", np.array([rhs[0]] + [a for a, _ in rows]),
                                  np.array([rhs[1]] + [a0 for _, a0 in rows])))

        def quad_at_most(rows, den, rhs) -> None:  # ‖rows‖²/den ≤ rhs: ‖(2·w, s − t)‖ ≤ s + t
            norm_at_most([combine((2.0, a)) for a in rows] + [combine((1.0, den), (-1.0, rhs))],
                         combine((1.0, den), (1.0, rhs)))

        def combine(*terms) -> tuple[NDArray[np.float64], float]:
            """``Σ w·a`` of ``(w, a)`` pairs."""
            return (sum(w * a[0] for w, a in terms),  # type: ignore[return-value]
                    float(sum(w * a[1] for w, a in terms)))

        def inside(lo: float, hi: float) -> tuple[float, float]:
            return (lo + margin, hi - margin) if hi - lo > 2 * margin else (lo, hi)

        for b in data.links:
            k = b.start
            mref, l, iref = b.mass_ref, b.length, b.inertia_ref
            m = entry(k, mref)
            if k in free:
                lo, hi = inside(b.mass[0] / mref, b.mass[1] / mref)
                at_least(m, lo)
                at_most(m, hi)
            se, sf = entry(k + 1, mref * l), entry(k + 2, mref * l)
            centre = b.com_centre / l  # complex, in the link's frame
            if b.com_fixed is None:
                radius = b.com_radius / l
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
            if lo > 0 or not rho2:  # ‖S‖²/m ≤ J − lo
                quad_at_most([se, sf], m, (j[0], j[1] - lo_m))
            if rho2:  # ‖S‖²/m ≤ J − ρ²·m − margin
                room = combine((1.0, j), (-rho2, m))
                quad_at_most([se, sf], m, (room[0], room[1] - margin))
            if math.isfinite(hi):  # J − hi ≤ m·(R² − |c|²) + 2·c·S
                radius = b.com_radius / l
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
            k = b.rotor
            if k in free:
                assert b.counter_rotor is not None
                scale = data.scales[k]
                lo, hi = inside(b.counter_rotor[0] / scale, b.counter_rotor[1] / scale)
                at_least(entry(k, scale), lo)
                at_most(entry(k, scale), hi)
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
                    low, high = c - b.com_radius, c + b.com_radius
                    ranges[i] = (min(m_lo * low, m_hi * low), max(m_lo * high, m_hi * high))
            shift = data.offset
            for i, (low, high) in ranges.items():
                if i in index:
                    lo[index[i]] = (low + shift[i]) / data.scales[i]
                    hi[index[i]] = (high + shift[i]) / data.scales[i]
            if k + 3 in index:
                base = max(b.inertia[0], m_lo * b.gyration**2)
                reach = abs(b.com_fixed) if b.com_fixed is not None else (
                    abs(b.com_centre) + b.com_radius)
                if b.com_fixed is not None:
                    base += m_lo * reach**2
                scale = data.scales[k + 3]
                lo[index[k + 3]] = (base + shift[k + 3]) / scale
                hi[index[k + 3]] = (b.inertia[1] + m_hi * reach**2 + shift[k + 3]) / scale
        for b in data.rotor_links:
            if b.rotor in index:
                assert b.counter_rotor is not None
                j = index[b.rotor]
                lo[j], hi[j] = (v / data.scales[b.rotor] for v in b.counter_rotor)
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
            self._fb = (at[keep], rhs[keep], np.linalg.pinv(at[keep]))
        return inconsistent

    # -- solving -------------------------------------------------------------------------------

    def _run(self, program: ConicProgram, name: str,
             **data: NDArray[np.float64]) -> tuple[StageReport, ConicSolution]:
        """Solve one of the programs; its report, and Clarabel's answer."""
        start = time.perf_counter()
        solution = program.solve(self.settings, **data)
        elapsed = time.perf_counter() - start
        ok = solution.u is not None
        report = StageReport(
            name=name,
            converged=ok,
            solver_status=solution.status,
            iterations=solution.iterations,
            time=elapsed,
            objective=self.data.reduced_objective(self.layout.x(solution.u)) if ok else math.nan,
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
        report, first = self._run(self._stage1, "convex")
        stages = [report]
        if first.u is None:
            raise self.infeasible(f"Clarabel: {report.solver_status} after "
                                   f"{report.iterations} iterations")
        u1 = first.u
        multipliers = list(first.duals)
        norm_dual = None
        if first.epigraph_dual is not None and self._dual_basis is not None:
            # The Lagrangian is t − (μ·t + w·(P·u + q)): the norm's minorant is −w.
            norm_dual = -(self._dual_basis @ first.epigraph_dual[1:])
        x, tight = self.repair(u1)
        objective = data.reduced_objective(x)
        if tie_break and lay.size:
            target = data.x0 if prefer is None else np.asarray(prefer, float)
            fixed = [] if self._fb is None else [self._fb[1]]
            report2, second = self._run(self._stage2, "tie-break", target=lay.u(target),
                                        equality_rhs=np.concatenate([*fixed, self._seen @ u1]))
            stages.append(report2)
            probe = x
            if second.u is not None:
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
        x = data.settle(x)  # the inert entries, for a crank whose speed changes
        x, feasible = self.finalize(x)
        lower = self._lower_bound(u1, multipliers, norm_dual, x if feasible else None)
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
        program = ConicProgram(lay.size, self._cones, objective="nearest",
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

    def _lower_bound(self, u: NDArray[np.float64], multipliers: list[NDArray[np.float64]],
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
            f = self._objective.value(self.layout.u(feasible))
            upper = f + abs(f) + 1e-9  # above the optimum, whatever the design's rounding
        equality = None if self._fb is None else self._fb[:2]
        lo, hi = self.box()
        bound = lower_bound(self._objective, self._cones, equality, u, multipliers, norm_dual,
                            lo, hi, upper)
        scale = self._scale
        if bound is not None and self._norm_form:
            return (max(bound.value, 0.0) * scale) ** 2
        if bound is not None:
            return bound.value * scale**2
        data = self.data
        least = sum(b.mass[0] for b in data.links) - data.original_mass
        return data.weights.added_mass * least  # ‖K·x‖² ≥ 0 and every mass at least its least

    def _fixed_row_error(self) -> InfeasibleError:
        """A condition of Eq. 58 that nothing free enters, and fails: name its links."""
        data = self.data
        rows = data.force_balance_rows(self.layout.c)
        a, _ = data.force_balance
        i = self._failed_row
        names = [b.name for b in data.links if np.any(a[i, b.start : b.start + 3])]
        keys = " or ".join(f"balance.{n}" for n in names)
        lines = [b.key for b in data.links if b.on_line and b.name in names]
        if lines:
            keys += (f"; {', '.join(k + '.com_on_line' for k in lines)} keeps a centre of "
                     "mass on its link's line, which this condition does not allow")
        return InfeasibleError(
            f"force balance cannot be met within the bounds: a condition of Eq. 58 among the "
            f"{', '.join(names)} fails by {rows[i]:.3g} of its terms and nothing in it may "
            f"change; let a mass or a centre of mass change ({keys})")

    def infeasible(self, why: str) -> SolverError:
        """The error for an SOCP that could not be solved: diagnosed infeasibility, or not."""
        diagnosis = self.diagnose() if self.data.force_balance is not None else None
        if diagnosis is not None:
            return diagnosis
        return SolverError(f"the convex balancing problem could not be solved ({why}), though "
                           "a design within the bounds meets force balance: numerical trouble")

    def finalize(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], bool]:
        """The design ``x`` made exactly feasible: bounds met exactly, Eq. 58 to rounding.

        Solvers meet bounds to their tolerance. First Eq. 58 is restored by the least change
        of the free variables; if a bound is still broken by more than rounding
        (:data:`~balancer.balance.problem.ROUNDING_TOLERANCE`: a designer's spec must hold what the
        problem promised, and :meth:`NumericProblem.physical` removes only rounding), the
        broken bounds are met as equations together with Eq. 58 (:meth:`onto_active`: a move
        of the size of the violations). Failing that, ``x`` is projected, as the least change
        in scaled variables, onto the bounds tightened by :data:`MARGIN`, with Eq. 58 as
        equalities, and Eq. 58 restored again (a change of ~Clarabel's tolerance, inside the
        margin), or the bounds met as equations from there. Returns the design and whether it
        is exactly feasible.
        """
        data, lay = self.data, self.layout
        x = self._clip_inertias(self.balanced(np.asarray(x, float)))
        exact = self._exact(x)
        if exact is not None:
            return exact, True
        if not lay.size:
            return x, False
        inert = [i for i in range(data.size) if data.inert[i]]

        def exact_of(u: NDArray[np.float64] | None) -> NDArray[np.float64] | None:
            if u is None:
                return None
            x2 = lay.x(u)
            x2[inert] = x[inert]  # settled already; the solvers here do not see them
            return self._exact(self._clip_inertias(x2))

        exact = exact_of(self.onto_active(lay.u(x)))
        if exact is not None:
            return exact, True
        for margin in (MARGIN, 1e-2 * MARGIN, 0.0):  # a thin feasible set takes a smaller one
            u = self._project(lay.u(x), margin)
            if u is None:
                continue
            for candidate in (self._clip_and_pin(self.restore_balance(u)),
                              self.onto_active(u)):
                exact = exact_of(candidate)
                if exact is not None:
                    return exact, True
        return x, False

    def onto_active(self, u: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """Solver variables ``u`` moved onto the bounds they break, with Eq. 58 kept.

        Each mass bound and centre-of-mass disc that ``u`` breaks (or meets within
        :data:`ACTIVE_INSIDE`) becomes one equation, putting the design that far inside it;
        they are solved with Eq. 58 by Gauss–Newton steps of least change in the scaled
        variables, and a bound once taken stays taken. (Clipping a centre of mass onto its
        disc and holding both its coordinates asks two conditions for one bound: with a thin
        feasible set, e.g. a mass that must lie within 1e-9 of the least that allows force
        balance, Eq. 58 then cannot be restored by what is left.) ``None`` if no design that
        meets the bounds and Eq. 58 (to rounding) is reached in a few steps.
        """
        data, lay = self.data, self.layout
        if not lay.size:
            return None
        index = {entry: j for j, entry in enumerate(lay.primary)}
        u = np.array(u, dtype=float)
        taken: set[tuple[int, str]] = set()
        for _ in range(8):
            x = data.own(lay.x(u))  # what the bounds concern
            rows: list[NDArray[np.float64]] = []
            values: list[float] = []
            broken = False
            for b in data.links:
                k, mref, l = b.start, b.mass_ref, b.length
                m = x[k]
                if k in index:
                    lo, hi = b.mass
                    inside = min(ACTIVE_INSIDE * mref, (hi - lo) / 4)
                    broken = broken or not lo <= m <= hi
                    if m > hi - inside / 2 or m < lo + inside / 2 or (k, "mass") in taken:
                        taken.add((k, "mass"))
                        target = min(max(m, lo + inside), hi - inside)
                        rows.append(lay.T[k] / mref)
                        values.append((target - m) / mref)
                if b.com_fixed is None and m > 0:
                    d = complex(x[k + 1], x[k + 2]) - m * b.com_centre
                    g = abs(d) - b.com_radius * m  # ≤ 0 inside, kg·m
                    inside = min(ACTIVE_INSIDE * l, b.com_radius / 4) * m
                    broken = broken or g > 0
                    if (g > -inside / 2 or (k, "com") in taken) and abs(d) > 0:
                        taken.add((k, "com"))
                        n = d / abs(d)
                        grad = (-(n.real * b.com_centre.real + n.imag * b.com_centre.imag)
                                - b.com_radius, n.real, n.imag)
                        rows.append(np.asarray(grad) @ lay.T[k:k + 3] / (mref * l))
                        values.append((-inside - g) / (mref * l))
            residual = 0.0
            if self._fb is not None:
                at, rhs, _ = self._fb
                r = at @ u - rhs
                residual = float(np.max(np.abs(r), initial=0.0))
                rows.extend(at)
                values.extend(-r)
            if (not broken and data.force_balance_residual(lay.x(u))
                    <= FORCE_BALANCE_TOLERANCE):
                return u
            if not rows:
                return None
            step = np.linalg.lstsq(np.array(rows), np.array(values), rcond=None)[0]
            if not np.all(np.isfinite(step)):
                return None
            u = u + step
            if not taken and residual == 0.0:
                return None
        return None

    def _exact(self, x: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The design of ``x``'s physical values, in their bounds exactly, with Eq. 58 kept.

        :meth:`NumericProblem.physical` moves values that overshoot a bound by rounding onto
        it; that can cost Eq. 58 its last digits, which the other free variables restore (the
        ones moved onto a bound stay there in the rounds that follow); repeated until both
        hold and Eq. 58 is met to the rounding of its terms, or a few rounds have passed (a
        move of rounding size each time); the design with the least residual is kept.
        ``None`` if none meets both.
        """
        data, lay = self.data, self.layout
        inert = [i for i in range(data.size) if data.inert[i]]
        best: tuple[float, NDArray[np.float64]] | None = None
        pinned = np.zeros(lay.size, dtype=bool)
        for _ in range(4):
            xp = data.vector_of(data.physical(x))
            residual = data.force_balance_residual(xp)
            if (residual <= FORCE_BALANCE_TOLERANCE
                    and not data.violations(xp, tol=ROUNDING_TOLERANCE)
                    and (best is None or residual < best[0])):
                best = (residual, xp)
            if best is not None and best[0] <= EQ58_ROUNDING or not lay.size:
                break
            up = lay.u(xp)
            # The entries the conversion moved by more than its own rounding (onto a bound),
            # in this round or an earlier one: they stay.
            moved = np.abs(xp - x) > 8 * _EPS * np.maximum(np.abs(x), np.abs(xp))
            pinned = pinned | moved[list(lay.primary)]
            x = lay.x(self.restore_balance(up, pinned))
            x[inert] = xp[inert]
            x = self._clip_inertias(x)
        return None if best is None else best[1]

    def _clip_and_pin(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """Masses and centres of mass that overshoot their bounds put on them.

        Eq. 58 is then restored by the other free variables (the ones put on a bound stay).
        """
        data, lay = self.data, self.layout
        u = np.array(u, dtype=float)
        index = {entry: j for j, entry in enumerate(lay.primary)}
        pinned = np.zeros(u.size, dtype=bool)
        shift = data.offset
        x = data.own(lay.x(u))
        for b in data.links:
            k = b.start
            if k in index:
                m = min(max(x[k], b.mass[0]), b.mass[1])
                if m != x[k]:
                    u[index[k]] = (m + shift[k]) / data.scales[k]
                    pinned[index[k]] = True
            if b.on_line:
                x = data.own(lay.x(u))
                lo, hi = b.line_span
                s_x = min(max(x[k + 1], x[k] * lo), x[k] * hi)
                if s_x != x[k + 1]:
                    u[index[k + 1]] = s_x / data.scales[k + 1]
                    pinned[index[k + 1]] = True
            elif b.com_fixed is None:
                x = data.own(lay.x(u))
                m, d = x[k], complex(x[k + 1], x[k + 2]) - x[k] * b.com_centre
                if abs(d) > m * b.com_radius:
                    d *= m * b.com_radius / abs(d) * (1 - 4 * 2.0**-52)
                    s_ = m * b.com_centre + d
                    u[index[k + 1]] = (s_.real + shift[k + 1]) / data.scales[k + 1]
                    u[index[k + 2]] = (s_.imag + shift[k + 2]) / data.scales[k + 2]
                    pinned[[index[k + 1], index[k + 2]]] = True
        return self.restore_balance(u, pinned) if pinned.any() else u

    def _clip_inertias(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Inertias and counter-rotors moved into their bounds (they are not in Eq. 58)."""
        data = self.data
        x = np.array(x, dtype=float)
        for b in data.rotor_links:
            if b.counter_rotor is not None:
                x[b.rotor] = min(max(x[b.rotor], b.counter_rotor[0]), b.counter_rotor[1])
        own = data.own(x)
        for b in data.links:  # inert ones too: a move of the mass or centre of mass shifts I
            k = b.start
            if data.absent(b, own) or not own[k] > 0:  # (no mass: no centre to clip about)
                continue
            q = (own[k + 1] ** 2 + own[k + 2] ** 2) / own[k]
            low = max(b.inertia[0], own[k] * b.gyration**2)
            inertia = own[k + 3] - q
            if not low <= inertia <= b.inertia[1]:
                shift = data.offset[k + 3]
                x[k + 3] = min(max(inertia, low), b.inertia[1]) + q + shift
                while x[k + 3] - shift - q < low:  # rounding in J − q
                    x[k + 3] = np.nextafter(x[k + 3], np.inf)
        return x

    def _project(self, u0: NDArray[np.float64], margin: float) -> NDArray[np.float64] | None:
        """The least change of ``u0`` (scaled) into the bounds tightened by ``margin``.

        With Eq. 58 as equalities; ``None`` if that set is empty or Clarabel fails.
        """
        if margin not in self._projections:
            constraints, _ = self._constraints(margin=margin)
            self._projections[margin] = ConicProgram(
                self.layout.size, constraints, objective="nearest",
                equality=None if self._fb is None else self._fb[:2])
        return self._projections[margin].solve(self.settings, target=u0).u

    def polish(
        self, x: NDArray[np.float64], target: NDArray[np.float64], objective: float
    ) -> tuple[NDArray[np.float64], float]:
        """Put back, one by one, the free parameters the optimum does not care about.

        The tie-break moves towards the preferred design only to the interior-point solver's
        accuracy (a mass of 2.10001 kg where nothing asks it to leave 2.1); each free entry of
        ``x`` is set to its preferred value where that keeps every constraint and the objective
        (to 1e-12 relative). First each counterweight that may be none is taken off whole where
        that keeps every constraint and makes the objective no worse.
        """
        data, lay = self.data, self.layout
        u = lay.u(x)
        preferred = lay.u(target)
        pinned = np.zeros(u.size, dtype=bool)  # entries put back: Eq. 58 may not move them
        primary = list(lay.primary)
        for b in data.links:  # a counterweight that may be none, taken off whole
            if b.offset is None or b.mass[0] > 0 or data.absent(b, data.own(x)):
                continue
            trial_x = lay.x(u)
            trial_x[b.entries] = data.offset[b.entries]
            none = np.zeros(data.size, dtype=bool)
            none[b.entries] = True
            trial_pinned = pinned | none[primary]
            trial = self.restore_balance(lay.u(trial_x), trial_pinned)
            xt = data.settle(lay.x(trial), for_motion=False)
            jt = data.reduced_objective(xt)
            # (no worse: a counterweight whose removal lowers J was an artefact, e.g. the
            # apex of its cone approached with an inertia of the solver's tolerance)
            if data.within(jt, objective, 1e-12) and not data.violations(xt):
                u, x, objective, pinned = trial, xt, jt, trial_pinned
        for j in range(u.size):
            if u[j] == preferred[j]:
                pinned[j] = True
                continue
            trial = u.copy()
            trial[j] = preferred[j]
            trial_pinned = pinned.copy()
            trial_pinned[j] = True
            trial = self.restore_balance(trial, trial_pinned)
            xt = data.settle(lay.x(trial), for_motion=False)
            jt = data.reduced_objective(xt)
            if not (data.within(jt, objective, 1e-12) and data.within(objective, jt, 1e-12)):
                continue
            if not data.violations(xt):
                u, x, objective, pinned = trial, xt, jt, trial_pinned
        return x, objective

    def balanced(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Design vector ``x`` (another solver's, e.g. IPOPT's) with Eq. 58 met to rounding.

        The least change of the free variables does it (:meth:`restore_balance`); the entries
        that are not free variables are kept.
        """
        lay = self.layout
        x = np.array(x, dtype=float)
        if not lay.size:
            return x
        u = lay.u(x)
        return x + lay.T @ (self.drop_absent(self.restore_balance(u)) - u)

    def drop_absent(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """Solver variables ``u`` with every counterweight that is none exactly none.

        A counterweight whose mass may be zero is approached by the interior-point solver only
        as the apex of its cone (:meth:`NumericProblem.absent`); it is set to nothing and
        Eq. 58 restored by the other free variables.
        """
        data, lay = self.data, self.layout
        x, mask = data.without_absent(lay.x(u))
        if not mask.any():
            return u
        return self.restore_balance(lay.u(x), mask[list(lay.primary)])

    def restore_balance(
        self, u: NDArray[np.float64], pinned: NDArray[np.bool_] | None = None
    ) -> NDArray[np.float64]:
        """Solver variables ``u`` moved the least to meet Eq. 58 to rounding.

        The move is the least in the scaled variables; the ``pinned`` entries are kept.
        Interior-point solvers meet the force balance to their tolerance (Clarabel's 1e-10,
        IPOPT's 1e-12 in scaled units); this puts the shaking force at rounding level. Where
        the unpinned entries cannot restore a row, the least-squares correction is made and the
        feasibility check that follows decides.
        """
        u = np.array(u, dtype=float)
        if self._fb is None:
            return u
        at, rhs, pinv = self._fb
        free = None if pinned is None or not pinned.any() else ~pinned
        if free is not None and not free.any():
            return u
        if free is not None:
            key = free.tobytes()
            if key not in self._pinned_inverses:  # the same few patterns recur: keep them
                self._pinned_inverses[key] = np.linalg.pinv(at[:, free])
            pinv = self._pinned_inverses[key]
        residual = at @ u - rhs
        size = np.linalg.norm(residual)
        # The correction's own rounding (the rows' conditioning times ε) leaves a residual
        # above rounding of the terms: refine while it shrinks (one or two more steps).
        for _ in range(4):
            if free is None:
                trial = u - pinv @ residual
            else:
                trial = u.copy()
                trial[free] -= pinv @ residual
            trial_residual = at @ trial - rhs
            trial_size = np.linalg.norm(trial_residual)
            if not trial_size < size:
                break
            u, residual, size = trial, trial_residual, trial_size
        return u

    def repair(self, u: NDArray[np.float64]) -> tuple[NDArray[np.float64], bool]:
        """The design of solver variables ``u``, with the solver's small violations removed.

        Clarabel meets the constraints to its tolerance (``1e-10``, or ~``1e-5`` when it stops
        "almost solved"). First the least change of ``u`` restores Eq. 58 to rounding (it moves
        the design by about Clarabel's tolerance). A design that then meets every bound to
        :data:`~balancer.balance.problem.FEASIBILITY_TOLERANCE` is kept as it is; otherwise
        masses and counter-rotors are clipped into their bounds and centres of mass pulled into
        their
        discs, Eq. 58 restored again (alternating twice), and each inertia about the centre of
        mass put into its bounds (inertias do not enter Eq. 58). Returns the design vector
        (inert entries settled) and whether the convex relaxation was tight: an upper inertia
        bound overshot by more than ``1e-6`` relative is a relaxation that was not tight, and
        the design moved into it is feasible but possibly not optimal.
        """
        data, lay = self.data, self.layout
        u = np.array(u, dtype=float)
        index = {entry: j for j, entry in enumerate(lay.primary)}
        u = self.drop_absent(self.restore_balance(u))  # Eq. 58 to rounding
        # Met to the feasibility tolerance: leave the solver's design alone (a "repair" of a
        # 1e-12 violation would cost more objective than it is worth at a zero optimum).
        rounds = 2 if data.violations(data.settle(lay.x(u), for_motion=False)) else 0
        shift = data.offset
        for _ in range(rounds):
            for b in data.links:
                k = b.start
                if k in index:
                    j = index[k]
                    u[j] = np.clip(u[j], (b.mass[0] + shift[k]) / data.scales[k],
                                   (b.mass[1] + shift[k]) / data.scales[k])
                if b.on_line:
                    x = data.own(lay.x(u))
                    lo, hi = b.line_span
                    u[index[k + 1]] = min(max(x[k + 1], x[k] * lo), x[k] * hi) \
                        / data.scales[k + 1]
                elif b.com_fixed is None:
                    x = data.own(lay.x(u))
                    m, d = x[k], complex(x[k + 1], x[k + 2]) - x[k] * b.com_centre
                    if abs(d) > m * b.com_radius:
                        d *= m * b.com_radius / abs(d)
                        s = m * b.com_centre + d
                        u[index[k + 1]] = (s.real + shift[k + 1]) / data.scales[k + 1]
                        u[index[k + 2]] = (s.imag + shift[k + 2]) / data.scales[k + 2]
            for b in data.rotor_links:
                entry = b.rotor
                if entry in index:
                    assert b.counter_rotor is not None
                    lo, hi = (v / data.scales[entry] for v in b.counter_rotor)
                    u[index[entry]] = np.clip(u[index[entry]], lo, hi)
            u = self.restore_balance(u)
        x = lay.x(u)
        own = data.own(x)
        tight = True
        for b in data.links:
            k = b.start
            if data.inert[k + 3] or (k + 3) not in index or data.absent(b, own):
                continue
            if not own[k] > 0:  # a counterweight at its cone's apex: no centre to clip about
                continue
            q = (own[k + 1] ** 2 + own[k + 2] ** 2) / own[k]
            inertia = own[k + 3] - q
            if inertia > b.inertia[1] * (1 + 1e-6) + 1e-9 * b.inertia_ref:
                tight = False
            low = max(b.inertia[0], own[k] * b.gyration**2)
            if rounds and not low <= inertia <= b.inertia[1]:
                x[k + 3] = min(max(inertia, low), b.inertia[1]) + q + shift[k + 3]
        return data.settle(x, for_motion=False), tight

    # -- infeasibility -------------------------------------------------------------------------

    def _bound_constraints(self, m, s, tau, slack=None, skip=None) -> list:
        """Eq. 58 and the bounds on masses and centres of mass (what force balance meets).

        In scaled variables ``m[i] = m_i/m_ref``, ``s[i] = S_i/(m_ref·l)``. ``tau`` multiplies
        every constant (1, or a variable for the Charnes–Cooper form of a ratio); ``slack``
        (a function of a group name) relaxes each group; ``skip`` names a group left out.
        Groups are ``(i, kind)`` with kind ``mass-low``, ``mass-high``, ``com`` (the disc of a
        listed radius) or ``com-fixed`` (a centre of mass that may not move).
        """
        import cvxpy as cp

        data = self.data

        def relax(group):
            return 0.0 if slack is None else slack(group)

        cons: list = []
        parts: list = [0.0] * data.size  # the design vector, in the layout's order
        for b in data.links:
            i, mref, l = b.index, b.mass_ref, b.length
            if skip != (i, "mass-low"):
                cons.append(m[i] >= b.mass[0] / mref * tau - relax((i, "mass-low")))
            if skip != (i, "mass-high"):
                cons.append(m[i] <= b.mass[1] / mref * tau + relax((i, "mass-high")))
            cons.append(m[i] >= 0.1 * b.mass[0] / mref * tau)
            if b.com_fixed is None:
                group = (i, "com")
                c = b.com_centre / l
                lhs = cp.norm(s[i] - cp.hstack([c.real * m[i], c.imag * m[i]]))
                rhs = b.com_radius / l * m[i]
            else:
                group = (i, "com-fixed")
                lhs = cp.norm(
                    s[i] - cp.hstack([b.com_fixed.real / l * m[i], b.com_fixed.imag / l * m[i]])
                )
                rhs = 0.0
            if skip != group:
                cons.append(lhs <= rhs + relax(group))
            if b.on_line:
                cons.append(s[i, 1] == 0)
            shift = data.offset[b.start : b.start + 3]  # a kept link's own, under a counterweight
            parts[b.start : b.start + 3] = [m[i] * mref + shift[0] * tau,
                                            s[i, 0] * mref * l + shift[1] * tau,
                                            s[i, 1] * mref * l + shift[2] * tau]
        assert data.force_balance is not None
        a, rhs_fb = data.force_balance
        terms = np.abs(a) @ np.abs(data.scales)  # each row by its own magnitude
        cons.append((a / terms[:, None]) @ cp.hstack(parts) == rhs_fb / terms * tau)
        return cons

    def diagnose(self) -> InfeasibleError | None:
        """Which bounds to widen so that force balance can be met, and to what.

        First each bound alone (a mass bound, a centre-of-mass radius; a fixed mass or centre
        of mass too): with every other bound kept, the value it needs is computed exactly (the
        least radius by the Charnes–Cooper form of ``‖S − m·c‖/m``, a mass by a linear
        objective; only a solve that Clarabel calls "optimal" counts: one that stops "almost
        solved" meets its constraints only to ~1e-5, and a program infeasible by 1e-7, as
        these are when the problem is, looks solved to that). In exact arithmetic every bound
        tells the same: the problem is feasible exactly when each needs no more than it
        allows. Each value is off by Clarabel's tolerance, so a bound is evidence only beyond
        :data:`NEEDED_TOLERANCE` (of its scale) either side of it: one that allows that much
        more than it needs makes the problem feasible; otherwise one that needs that much more
        than it allows makes it infeasible, whatever the others say within the tolerance (a
        heavy link's fixed centre of mass may need to move only 1e-11 m where a light link
        lacks 1e-7 of its mass; and no design moves a fixed value at all). The bounds to
        widen are reported, those the spec already gives as ranges first, smallest relative change
        first. If no bound alone was solved, an elastic (phase-1) problem puts a nonnegative
        slack on every bound (ten times the weight on a fixed quantity; slacks in common
        units: kg over the total mass, kg·m over the total mass times the longest link) and
        minimises their weighted sum subject to Eq. 58; its nonzero slacks name the bounds,
        and its design the values that suffice together. (Only force balance can make the
        problem infeasible: every other condition is met by some inertia, and
        :func:`~balancer.balance.bounds.check_problem` has rejected empty ranges.) Returns
        ``None`` when no bound needs widening (the problem is feasible), or when no value lies
        beyond the tolerance (undecided: the problem is no more than that far from feasible).
        """
        data = self.data
        groups = []
        for b in data.links:
            groups += [(b.index, "mass-low"), (b.index, "mass-high")]
            groups.append((b.index, "com" if b.com_fixed is None else "com-fixed"))
        ranked = []
        infeasible = solved = False
        for group in groups:
            value = self._needed(group)
            if value is None:
                continue
            solved = True
            i, kind = group
            b = data.links[i]
            lo, hi = b.mass
            excess = self._excess(b, kind, value)
            if excess < -NEEDED_TOLERANCE:
                return None  # with every bound kept, force balance is met: feasible
            infeasible = infeasible or excess > NEEDED_TOLERANCE
            if excess <= 0:
                continue
            if kind == "mass-high":
                ranked.append((lo == hi, value / hi - 1, group, value))
            elif kind == "mass-low":
                ranked.append((lo == hi, 1 - value / lo, group, value))
            elif kind == "com":
                ranked.append((False, (value - b.com_radius) / b.length, group, value))
            else:
                ranked.append((True, value / b.length, group, value))
        if not solved:
            return self._elastic()
        if not infeasible or not ranked:
            return None  # feasible, or undecided within Clarabel's tolerance
        ranked.sort(key=lambda item: item[:2])
        best = [r for r in ranked if r[0] == ranked[0][0]][:3]
        # A fixed centre of mass is reported as the radius to give about the default point.
        best = [(*r[:3], self._radius_about_default(r[2], r[3])) if r[2][1] == "com-fixed"
                else r for r in best]
        items, parts = zip(*(self._describe(g, v) for _, _, g, v in best), strict=True)
        message = "force balance cannot be met within the bounds: " + ", or ".join(parts)
        return InfeasibleError(message, needed=tuple(items), jointly=False)

    def _elastic(self) -> InfeasibleError | None:
        """The phase-1 problem of :meth:`diagnose`, for when no single bound suffices."""
        import cvxpy as cp

        data = self.data
        mtot = data.original_mass
        moment_unit = mtot * max(b.length for b in data.links)
        m = cp.Variable(len(data.links))
        s = cp.Variable((len(data.links), 2))
        slacks: dict[tuple[int, str], tuple[cp.Variable, float]] = {}

        def slack(group: tuple[int, str]) -> cp.Variable:
            b = data.links[group[0]]
            if group[1].startswith("mass"):
                fixed = b.mass[0] == b.mass[1]
                weight = (10.0 if fixed else 1.0) * b.mass_ref / mtot
            else:
                weight = (10.0 if group[1] == "com-fixed" else 1.0) * b.mass_ref * b.length
                weight /= moment_unit
            t = cp.Variable(nonneg=True)
            slacks[group] = (t, weight)
            return t

        cons = self._bound_constraints(m, s, 1.0, slack=slack)
        problem = cp.Problem(cp.Minimize(sum(w * t for t, w in slacks.values())), cons)
        try:
            _solve(problem, self.settings)
        except cp.error.SolverError as exc:
            return InfeasibleError(f"force balance cannot be met within the bounds ({exc})")
        if problem.status not in SOLVED:
            return InfeasibleError(
                "force balance cannot be met within the bounds (the elastic problem failed: "
                f"{problem.status})"
            )
        support = [g for g, (t, _) in slacks.items() if t.value > SLACK_TOLERANCE]
        if not support:
            return None  # a design within the bounds meets force balance
        items, parts = [], []
        for i, kind in support:
            b = data.links[i]
            mi = float(m.value[i]) * b.mass_ref
            com = complex(*(s.value[i] * b.mass_ref * b.length)) / mi
            value = mi if kind.startswith("mass") else abs(com - (
                b.com_centre if kind == "com" else self._about(b)))
            item, text = self._describe((i, kind), value)
            items.append(item)
            parts.append(text)
        message = "force balance cannot be met within the bounds: " + "; ".join(parts)
        return InfeasibleError(message + " (together)", needed=tuple(items), jointly=True)

    @staticmethod
    def _excess(b, kind: str, value: float) -> float:
        """How far the value a bound group needs (:meth:`_needed`) lies beyond its bound.

        Relative to the bound's scale (the link's mass or length); ``≤ 0``: within it.
        """
        if kind == "mass-high":
            return (value - b.mass[1]) / b.mass_ref
        if kind == "mass-low":
            return (b.mass[0] - value) / b.mass_ref
        if kind == "com":
            return (value - b.com_radius) / b.length
        return value / b.length  # a fixed centre of mass: how far it must move

    def _centre(self, b, kind: str) -> complex:
        """Where a centre-of-mass group's value is measured from (local, m).

        A radius's ``com_about``; for a fixed centre of mass, the fixed centre itself: the
        value is then how far it must move, which is what makes the problem infeasible (the
        radius a designer would give, about the link's default point, is :meth:`_about`'s).
        """
        if kind == "com":
            return b.com_centre
        return b.com_fixed

    def _about(self, b) -> complex:
        """The link's default ``com_about`` point (local, m)."""
        return self.data.mechanism.structure.local[(b.index, b.default_about)].complex()

    def _needed(self, group: tuple[int, str], centre: complex | None = None) -> float | None:
        """The exact bound group ``group`` needs with every other bound kept.

        For a centre of mass, its least distance from ``centre`` (default :meth:`_centre`).
        ``None`` if that program is infeasible too, or Clarabel did not solve it accurately.
        """
        import cvxpy as cp

        i, kind = group
        b = self.data.links[i]
        m = cp.Variable(len(self.data.links))
        s = cp.Variable((len(self.data.links), 2))
        if kind.startswith("com"):
            tau = cp.Variable(nonneg=True)  # Charnes–Cooper: scale everything so that m_i = 1
            cons = self._bound_constraints(m, s, tau, skip=group)
            cons.append(m[i] == 1.0)
            centre = (self._centre(b, kind) if centre is None else centre) / b.length
            objective = cp.Minimize(cp.norm(s[i] - cp.hstack([centre.real, centre.imag])))
            scale = b.length  # ‖S/m − c‖ in metres
        else:
            cons = self._bound_constraints(m, s, 1.0, skip=group)
            sign = 1.0 if kind == "mass-high" else -1.0
            objective = cp.Minimize(sign * m[i])
            scale = sign * b.mass_ref
        problem = cp.Problem(objective, cons)
        try:
            _solve(problem, self.settings)
        except cp.error.SolverError:
            return None
        if problem.status != "optimal":  # "almost solved": its value is not to be trusted
            return None
        return float(problem.value) * scale

    def _radius_about_default(self, group: tuple[int, str], move: float) -> float:
        """The least ``com_radius`` about the default point that a fixed centre of mass needs.

        Its least distance from that point with every other bound kept; where that program
        is not solved accurately, the fixed centre's distance from it plus how far it must
        move (a radius that suffices).
        """
        b = self.data.links[group[0]]
        value = self._needed(group, centre=self._about(b))
        return value if value is not None else abs(b.com_fixed - self._about(b)) + move

    def _describe(
        self, group: tuple[int, str], value: float
    ) -> tuple[tuple[str, float, float | None, str], str]:
        """``(key, needed, current, unit)`` and the words for one bound to widen."""
        i, kind = group
        b = self.data.links[i]
        if kind in ("mass-high", "mass-low"):
            key = b.bound_key("mass")
            high = kind == "mass-high"
            v = _up(value) if high else _down(value)
            current = b.mass[1] if high else b.mass[0]
            if b.mass[0] == b.mass[1]:
                words = f"{key} must allow {v:.4g} kg (fixed at {current!r})"
            elif high and b.gyration > 0 and b.mass[1] == b.inertia[1] / b.gyration**2:
                words = (f"{key} must allow up to {v:.4g} kg (is at most {current:.6g}: "
                         f"{b.key}.inertia ≤ {b.inertia[1]:.6g} kg·m² with min_gyration "
                         f"{b.gyration:.6g} m caps it at I/ρ²)")
            elif high:
                words = f"{key} must allow up to {v:.4g} kg (is at most {current!r})"
            else:
                words = f"{key} must allow down to {v:.4g} kg (is at least {current!r})"
            return (key, v, current, "kg"), words
        key = b.bound_key("com_radius")
        v = _up(value)
        if kind == "com":
            return (key, v, b.com_radius, "m"), (
                f"{key} must be at least {v:.4g} m (is {b.com_radius!r})"
            )
        about = b.default_about
        return (key, v, None, "m"), (
            f"{key} must be given, at least {v:.4g} m about {about} (the centre of mass is "
            "fixed now)"
        )


def _solve(problem: cp.Problem, settings: dict) -> None:
    """Solve with Clarabel; an inaccurate solution is judged by its status, not a warning.

    (A run stopped at its iteration limit can leave iterates of 1e155, whose objective CVXPY
    evaluates: that overflow is no news either.)
    """
    with warnings.catch_warnings(), np.errstate(over="ignore", invalid="ignore"):
        warnings.filterwarnings("ignore", message="Solution may be inaccurate")
        problem.solve(solver="CLARABEL", **settings)


def _up(x: float, digits: int = 4) -> float:
    """``x`` rounded up to ``digits`` significant digits (a bound that surely suffices)."""
    if x <= 0:
        return 0.0
    scale = 10 ** (digits - 1 - math.floor(math.log10(x)))
    return math.ceil(x * scale * (1 - 1e-12)) / scale


def _down(x: float, digits: int = 4) -> float:
    """``x`` rounded down to ``digits`` significant digits."""
    if x <= 0:
        return 0.0
    scale = 10 ** (digits - 1 - math.floor(math.log10(x)))
    return math.floor(x * scale * (1 + 1e-12)) / scale
