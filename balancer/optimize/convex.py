"""Convex balancing: a second-order cone program in the inertial parameters (CVXPY + Clarabel).

With the crank at constant speed the shaking moment, driving torque and shaking force are
linear in the design vector ``x`` (:data:`balancer.inverse.PARAMETER_NAMES`), Eq. 45–54, and
force balance is four linear equations (Eq. 58). Per link, with ``S = (m·e, m·f)`` and ``c`` the
position of ``com_about`` in the link frame (0 for the first joint, ``l`` for the second):

- mass bounds ``m_low ≤ m ≤ m_high``;
- centre of mass in a disc: ``‖S − m·c‖ ≤ m·R`` (a second-order cone);
- realisable inertia about the centre of mass ``I = J − ‖S‖²/m``:
  ``‖S‖²/m ≤ J − max(I_low, m·ρ²)`` (``quad_over_lin``, a rotated cone);
- an upper inertia bound ``I ≤ I_high`` on a link whose centre of mass may move is not convex
  (``J − I_high ≤ ‖S‖²/m``); it is replaced by its convex envelope over the disc,
  ``J − I_high ≤ m·(R² − c²) + 2·c·m·e`` (valid because ``|s̄ − c| ≤ R``), and
  :attr:`ConvexSolution.relaxation_tight` says whether the optimum met the exact bound;
- counter-rotor bounds; fixed entries are eliminated (a fixed centre of mass makes
  ``S = m·s̄``, a fixed inertia with it ``J = I + m·|s̄|²``: both linear).

Objective: ``‖K·x‖`` (the root of the weighted mean squares, minimised as a norm so that a zero
optimum is reached accurately), or ``‖K·x‖² + w_m·Δm`` when mass is penalised; ``K`` is
compressed to its 14-column triangular factor ``R``.

Two stages: the SOCP gives the optimum (the lower bound); then, because the optimum is usually
not unique (the crank's inertia and counter-rotor do nothing at constant speed, the shaking
moment sees only the difference of the rocker's inertia and its counter-rotor, and complete
balance leaves a whole family of couplers), a **tie-break** picks, among the designs within
``1e-8`` (relative) of the optimum, the one nearest the original in scaled parameters.

An infeasible problem (force balance cannot be met within the bounds) is diagnosed by an elastic
(phase-1) problem with a slack on each bound and raises :class:`InfeasibleError` naming the
bounds to widen and the values that would do.

Variables are scaled per link (kg by the original mass, kg·m by ``m·l``, kg·m² by ``m·l²``) and
the objective by the original design's; both problems are built once per
:class:`~balancer.problem.NumericProblem` with parameters, so re-solving is cheap.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError
from ..problem import DEFAULT_ABOUT, JOINTS, NumericProblem
from .result import InfeasibleError, StageReport

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
#: The tie-break keeps the objective within ``TIE_RELATIVE·optimum + TIE_ABSOLUTE·original``.
TIE_RELATIVE = 1e-8
TIE_ABSOLUTE = 1e-10
#: A slack of the elastic problem above this (in scaled units) names a bound to widen.
SLACK_TOLERANCE = 1e-7

_SOLVED = ("optimal", "optimal_inaccurate")


@dataclass(frozen=True)
class Layout:
    """The design vector as an affine map of the free variables: ``x = c + T·u``.

    Fixed entries sit in ``c``; a fixed centre of mass makes ``m·e``, ``m·f`` multiples of
    ``m``; a fixed inertia with a fixed centre of mass makes ``J = I + m·|s̄|²``. Inert entries
    (see :attr:`NumericProblem.inert`) are left at 0 and settled afterwards. Each variable is
    one entry of ``x`` divided by its scale.

    Attributes
    ----------
    c
        Constant part, ``(14,)``.
    T
        ``(14, n)``.
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
    c = np.zeros(14)
    rows = np.zeros((14, 14))  # rows[i] = coefficients of x[i] on the variables (max 14)
    primary: list[int] = []

    def new_variable(entry: int) -> None:
        rows[entry, len(primary)] = scales[entry]
        primary.append(entry)

    for b in data.links:
        k = 4 * b.index
        if b.mass[0] < b.mass[1]:
            new_variable(k)
        else:
            c[k] = b.mass[0]
        if b.com_fixed is None:
            new_variable(k + 1)
            new_variable(k + 2)
        else:
            for i, part in ((k + 1, b.com_fixed.real), (k + 2, b.com_fixed.imag)):
                c[i] = part * c[k]
                rows[i] = part * rows[k]
        if data.inert[k + 3]:
            pass
        elif b.inertia_fixed and b.com_fixed is not None:
            s2 = abs(b.com_fixed) ** 2
            c[k + 3] = b.inertia[0] + s2 * c[k]
            rows[k + 3] = s2 * rows[k]
        else:
            new_variable(k + 3)
    for entry, b in ((12, data.links[0]), (13, data.links[2])):
        assert b.counter_rotor is not None
        lo, hi = b.counter_rotor
        if data.inert[entry]:
            continue
        if lo < hi:
            new_variable(entry)
        else:
            c[entry] = lo
    return Layout(c=c, T=rows[:, : len(primary)].copy(), primary=tuple(primary))


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
        The SOCP's optimum: no feasible design does better (to Clarabel's tolerance), (N·m)².
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
    """

    def __init__(self, data: NumericProblem, *, settings: dict | None = None) -> None:
        self.data = data
        self.settings = {**CLARABEL_SETTINGS, **(settings or {})}
        self.layout = layout(data)
        n = self.layout.size
        self._u = cp.Variable(n, name="u")
        self._scale = data.objective_scale
        lay = self.layout
        x = lay.c + lay.T @ self._u
        constraints, self._relaxed = self._constraints(x)
        self._inconsistent = self._force_balance(x, constraints)
        k = data.factor.shape[0]
        self._P = cp.Parameter((k, n), name="P") if k else None
        self._q = cp.Parameter(k, name="q") if k else None
        w_mass = data.weights.added_mass / self._scale**2
        mass_term = (x[0] + x[4] + x[8] - data.original_mass) * w_mass if w_mass else 0.0
        self._norm_form = w_mass == 0
        if k:
            residual = self._P @ self._u + self._q
            if self._norm_form:
                value = cp.norm(residual)
            else:
                value = cp.sum_squares(residual) + mass_term
        else:
            value = mass_term
        self._value = value
        self._stage1 = cp.Problem(cp.Minimize(value), constraints)
        self._bound = cp.Parameter(name="bound")
        self._prefer = cp.Parameter(n, name="prefer")
        self._stage2 = cp.Problem(
            cp.Minimize(cp.sum_squares(self._u - self._prefer)),
            [*constraints, value <= self._bound],
        )
        self._set_objective_data()

    # -- building ------------------------------------------------------------------------------

    def _set_objective_data(self) -> None:
        if self._P is None:
            return
        r = self.data.factor / self._scale
        self._P.value = r @ self.layout.T
        self._q.value = r @ self.layout.c

    def _constraints(self, x) -> tuple[list, list[str]]:
        data, lay = self.data, self.layout
        out: list = []
        relaxed: list[str] = []
        free = set(lay.primary)
        for b in data.links:
            k = 4 * b.index
            mref, l, iref = b.mass_ref, b.length, b.inertia_ref
            m = x[k] / mref
            if k in free:
                out += [m >= b.mass[0] / mref, m <= b.mass[1] / mref]
            se, sf = x[k + 1] / (mref * l), x[k + 2] / (mref * l)
            centre = b.com_centre / l
            if b.com_fixed is None:
                out.append(cp.norm(cp.hstack([se - centre * m, sf])) <= (b.com_radius / l) * m)
            if (k + 3) not in free:
                continue  # inert, or fixed inertia with a fixed centre of mass: nothing to ask
            j = x[k + 3] / iref
            rho2 = (b.gyration / l) ** 2
            lo, hi = b.inertia[0] / iref, b.inertia[1] / iref
            if b.com_fixed is not None:
                inertia = j - m * abs(b.com_fixed / l) ** 2
                out.append(inertia >= lo)
                if rho2:
                    out.append(inertia >= rho2 * m)
                if math.isfinite(hi):
                    out.append(inertia <= hi)
                continue
            q = cp.quad_over_lin(cp.hstack([se, sf]), m)
            if lo > 0 or not rho2:
                out.append(q <= j - lo)
            if rho2:
                out.append(q <= j - rho2 * m)
            if math.isfinite(hi):
                radius = b.com_radius / l
                out.append(j - hi <= m * (radius**2 - centre**2) + 2 * centre * se)
                relaxed.append(b.name)
        for entry, b in ((12, data.links[0]), (13, data.links[2])):
            if entry in free:
                assert b.counter_rotor is not None
                scale = data.scales[entry]
                out += [x[entry] / scale >= b.counter_rotor[0] / scale,
                        x[entry] / scale <= b.counter_rotor[1] / scale]
        return out, relaxed

    def _force_balance(self, x, constraints: list) -> bool:
        """Add Eq. 58 (rows that involve a free variable); say whether a fixed row fails."""
        if self.data.force_balance is None:
            return False
        a, b = self.data.force_balance
        mtot = self.data.original_mass
        lay = self.layout
        at = a @ lay.T[:12] / mtot
        rhs = (b - a @ lay.c[:12]) / mtot
        inconsistent = False
        keep = []
        for i in range(a.shape[0]):
            if np.max(np.abs(at[i]), initial=0.0) > 1e-14:
                keep.append(i)
            elif abs(rhs[i]) > 1e-12:
                inconsistent = True
        if keep:
            constraints.append(at[keep] @ self._u == rhs[keep])
        return inconsistent

    # -- solving -------------------------------------------------------------------------------

    def _run(self, problem: cp.Problem, name: str) -> tuple[StageReport, bool]:
        start = time.perf_counter()
        try:
            problem.solve(solver=cp.CLARABEL, **self.settings)
            status = str(problem.status)
        except cp.error.SolverError as exc:  # numerical failure inside Clarabel
            status = f"solver error: {exc}"
        elapsed = time.perf_counter() - start
        ok = status in _SOLVED and self._u.value is not None
        stats = problem.solver_stats
        iterations = int(stats.num_iters) if stats is not None and stats.num_iters else 0
        objective = self.data.objective(self.layout.x(self._u.value)) if ok else math.nan
        report = StageReport(
            name=name,
            converged=ok,
            solver_status=status,
            iterations=iterations,
            time=elapsed,
            objective=objective,
        )
        return report, ok

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
        if self._inconsistent:
            raise self.diagnose()
        report, ok = self._run(self._stage1, "convex")
        stages = [report]
        if not ok:
            if report.solver_status.startswith("infeasible"):
                raise self.diagnose()
            raise SolverError(
                f"the convex balancing problem could not be solved (Clarabel: "
                f"{report.solver_status} after {report.iterations} iterations)"
            )
        u = np.array(self._u.value)
        value = float(self._stage1.value)
        if self._P is not None and self._norm_form:
            lower = (value * self._scale) ** 2  # the norm ‖R·x‖ was minimised
        else:
            lower = value * self._scale**2
        if tie_break and lay.size:
            target = data.x0 if prefer is None else np.asarray(prefer, float)
            self._prefer.value = lay.u(target)
            self._bound.value = value + TIE_RELATIVE * abs(value) + TIE_ABSOLUTE
            report2, ok2 = self._run(self._stage2, "tie-break")
            stages.append(report2)
            if ok2:
                u = np.array(self._u.value)
        x = lay.x(u)
        tight = True
        for name in self._relaxed:
            b = next(b for b in data.links if b.name == name)
            k = 4 * b.index
            inertia = x[k + 3] - (x[k + 1] ** 2 + x[k + 2] ** 2) / x[k]
            if inertia > b.inertia[1] + 1e-9 * b.inertia_ref:
                tight = False
                x[k + 3] += b.inertia[1] - inertia  # move into the bound: feasible
        x = data.settle(x)
        return ConvexSolution(
            x=x,
            objective=data.objective(x),
            lower_bound=lower,
            relaxation_tight=tight,
            converged=True,
            stages=tuple(stages),
        )

    # -- infeasibility -------------------------------------------------------------------------

    def diagnose(self) -> InfeasibleError:
        """The elastic (phase-1) problem: which bounds to widen so that force balance is met.

        Every bound on the masses and centres of mass gets a nonnegative slack (a fixed mass or
        centre of mass too, at ten times the weight: widening a bound is preferred to freeing
        a fixed quantity); the weighted sum of the slacks is minimised subject to Eq. 58.
        The nonzero slacks name the bounds; the design found gives the values that suffice
        together.
        """
        data = self.data
        mtot = data.original_mass
        m = cp.Variable(3)
        s = cp.Variable((3, 2))
        slacks: list[tuple[cp.Variable, str, float]] = []
        cons: list = []

        def slack(kind: str, weight: float) -> cp.Variable:
            t = cp.Variable(nonneg=True)
            slacks.append((t, kind, weight))
            return t

        x_parts = []
        for b in data.links:
            i, mref, l = b.index, b.mass_ref, b.length
            fixed_mass = b.mass[0] == b.mass[1]
            w = 10.0 if fixed_mass else 1.0
            cons += [
                m[i] >= b.mass[0] / mref - slack(f"{i}:mass-low", w),
                m[i] <= b.mass[1] / mref + slack(f"{i}:mass-high", w),
                m[i] >= 1e-2 * b.mass[0] / mref,
            ]
            if b.com_fixed is None:
                cons.append(
                    cp.norm(s[i] - cp.hstack([b.com_centre / l * m[i], 0.0]))
                    <= b.com_radius / l * m[i] + slack(f"{i}:com", 1.0)
                )
            else:
                e0, f0 = b.com_fixed.real / l, b.com_fixed.imag / l
                cons.append(
                    cp.norm(s[i] - cp.hstack([e0 * m[i], f0 * m[i]]))
                    <= slack(f"{i}:com-fixed", 10.0)
                )
            x_parts += [m[i] * mref, s[i, 0] * mref * l, s[i, 1] * mref * l, 0.0]
        assert data.force_balance is not None
        a, rhs = data.force_balance
        x12 = cp.hstack(x_parts)
        cons.append(a @ x12 / mtot == rhs / mtot)
        objective = cp.Minimize(sum(w * t for t, _, w in slacks))
        problem = cp.Problem(objective, cons)
        try:
            problem.solve(solver=cp.CLARABEL, **self.settings)
        except cp.error.SolverError as exc:
            return InfeasibleError(f"force balance cannot be met within the bounds ({exc})")
        if problem.status not in _SOLVED:
            return InfeasibleError(
                "force balance cannot be met within the bounds (the elastic problem failed: "
                f"{problem.status})"
            )
        needed = []
        for t, kind, _ in slacks:
            if t.value is None or t.value <= SLACK_TOLERANCE:
                continue
            i, what = kind.split(":")
            b = data.links[int(i)]
            mi = float(m.value[int(i)]) * b.mass_ref
            com = complex(*(s.value[int(i)] * b.mass_ref * b.length)) / mi
            if what == "mass-low":
                if b.mass[0] == b.mass[1]:
                    needed.append((f"{b.key}.mass", _down(mi), b.mass[0], "kg", "allow"))
                else:
                    needed.append((f"{b.key}.mass", _down(mi), b.mass[0], "kg", "low"))
            elif what == "mass-high":
                if b.mass[0] == b.mass[1]:
                    needed.append((f"{b.key}.mass", _up(mi), b.mass[1], "kg", "allow"))
                else:
                    needed.append((f"{b.key}.mass", _up(mi), b.mass[1], "kg", "high"))
            elif what == "com":
                distance = abs(com - b.com_centre)
                needed.append((f"{b.key}.com_radius", _up(distance), b.com_radius, "m", "least"))
            else:
                about = DEFAULT_ABOUT[b.name]
                centre = 0.0 if about == JOINTS[b.name][0] else b.length
                distance = abs(com - centre)
                needed.append((f"{b.key}.com_radius", _up(distance), None, "m", about))
        if not needed:
            return InfeasibleError(
                "the convex solver reported the balancing problem infeasible, but a design "
                "within the bounds meets force balance: numerical trouble (try other bounds)"
            )
        parts = []
        for key, value, current, unit, how in needed:
            if how == "least":
                parts.append(f"{key} must be at least {value:.4g} {unit} (is {current!r})")
            elif how == "high":
                parts.append(f"{key} must allow up to {value:.4g} {unit} (is at most {current!r})")
            elif how == "low":
                parts.append(
                    f"{key} must allow down to {value:.4g} {unit} (is at least {current!r})"
                )
            elif how == "allow":
                parts.append(f"{key} must allow {value:.4g} {unit} (fixed at {current!r})")
            else:
                parts.append(
                    f"{key} must be at least {value:.4g} {unit} about {how} (the centre of mass "
                    "is fixed now)"
                )
        message = "force balance cannot be met within the bounds: " + "; ".join(parts)
        return InfeasibleError(
            message, needed=tuple((k, v, c, u) for k, v, c, u, _ in needed)
        )


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
