"""Why a redesign problem is infeasible, and which bounds to widen to what (CVXPY).

Force balance cannot be met within the bounds: the value each bound needs alone (its own conic
program with every other bound kept) names the bounds that suffice alone; failing that, an
elastic (phase-1) problem with a slack on each bound names those to widen together. The only
use of CVXPY in the package; :class:`Diagnosis` is mixed into :class:`~.convex.ConvexSolver`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import SolverError
from .bounds import LinkBounds
from .certificate import Constraint
from .conic import SOLVED, ConicProgram
from .problem import NumericProblem
from .result import InfeasibleError

if TYPE_CHECKING:
    import cvxpy as cp

    from .variables import VariableMap

#: A slack of the elastic problem above this (in scaled units) names a bound to widen.
SLACK_TOLERANCE = 1e-7
#: How far beyond its bound (relative to the bound's scale) the value a bound needs alone
#: must lie to be evidence (:meth:`Diagnosis.diagnose`): ten times Clarabel's tolerance
#: (1e-10, scaled units) on that value.
NEEDED_TOLERANCE = 1e-9


class Diagnosis:
    """The infeasibility diagnosis of a convex solver (see the module docstring)."""

    data: NumericProblem
    layout: VariableMap
    settings: dict[str, Any]
    _failed_row: int

    def _constraints(self, margin: float = 0.0, *, supports: bool = True
                     ) -> tuple[list[Constraint], list[str]]:
        """The bounds as cone constraints (the solver's)."""
        raise NotImplementedError

    def _fixed_row_error(self) -> InfeasibleError:
        """A condition of Eq. 58 that nothing free enters, and fails: name its links."""
        data = self.data
        rows = data.force_balance_rows(self.layout.c)
        assert data.force_balance is not None  # a row of it failed
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
        """The error for an SOCP that could not be solved: diagnosed infeasibility, or not.

        With a bound on the supports' loads (``max_bearing_load``), the least bound any design
        within the other bounds meets, where it is above the spec's.
        """
        diagnosis = self.diagnose() if self.data.force_balance is not None else None
        if diagnosis is not None:
            return diagnosis
        bound = self.data.support_bound
        if bound is not None:
            least = self.least_support_load()
            if least is not None and least > bound * (1 - 1e-9):
                words = self.data.mechanism.presentation.support_words
                return InfeasibleError(
                    f"no design within the other bounds keeps every {words} at or below "
                    f"{bound:.6g} N: the least largest load is {least:.6g} N "
                    "(balance.max_bearing_load)",
                    needed=(("balance.max_bearing_load", least, bound, "N"),))
        return SolverError(f"the convex balancing problem could not be solved ({why}), though "
                           "a design within the bounds meets force balance: numerical trouble")

    def least_support_load(self) -> float | None:
        """The least largest support load any design within the other bounds has, N.

        ``min t`` with ``|load_r(x)| ≤ t`` at every sample and support and every other cone of
        the program (Clarabel); ``None`` if it fails.
        """
        data, lay = self.data, self.layout
        rows = data.regressors.supports
        bound = data.support_bound
        if rows is None or bound is None:
            return None
        n = lay.size
        others, _ = self._constraints(supports=False)
        cones = [Constraint(c.kind, np.hstack([c.M, np.zeros((c.M.shape[0], 1))]), c.m)
                 for c in others]
        a, a0 = rows @ lay.T / bound, rows @ lay.c / bound
        top = np.zeros(n + 1)
        top[n] = 1.0
        for r in range(rows.shape[0]):
            cones.append(Constraint("soc", np.array([top, np.append(a[r].real, 0.0),
                                                     np.append(a[r].imag, 0.0)]),
                                    np.array([0.0, a0[r].real, a0[r].imag])))
        program = ConicProgram(n + 1, cones, objective="squares", P=np.zeros((0, n + 1)),
                               q=np.zeros(0), g=top)
        solution = program.solve(self.settings)
        return None if solution.u is None else float(solution.u[n]) * bound

    def _bound_constraints(self, m: cp.Variable, s: cp.Variable, tau: float | cp.Variable,
                           slack: Callable[[tuple[int, str]], cp.Variable] | None = None,
                           skip: tuple[int, str] | None = None) -> list[cp.Constraint]:
        """Eq. 58 and the bounds on masses and centres of mass (what force balance meets).

        In scaled variables ``m[i] = m_i/m_ref``, ``s[i] = S_i/(m_ref·l)``. ``tau`` multiplies
        every constant (1, or a variable for the Charnes–Cooper form of a ratio); ``slack``
        (a function of a group name) relaxes each group; ``skip`` names a group left out.
        Groups are ``(i, kind)`` with kind ``mass-low``, ``mass-high``, ``com`` (the disc of a
        listed radius) or ``com-fixed`` (a centre of mass that may not move).
        """
        import cvxpy as cp

        data = self.data

        def relax(group: tuple[int, str]) -> float | cp.Variable:
            return 0.0 if slack is None else slack(group)

        cons: list[cp.Constraint] = []
        # the design vector, in the layout's order
        parts: list[float | cp.Expression] = [0.0] * data.size
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
                rhs = b.radius / l * m[i]
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
        groups: list[tuple[int, str]] = []
        for b in data.links:
            groups += [(b.index, "mass-low"), (b.index, "mass-high")]
            groups.append((b.index, "com" if b.com_fixed is None else "com-fixed"))
        ranked: list[tuple[bool, float, tuple[int, str], float]] = []
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
                ranked.append((False, (value - b.radius) / b.length, group, value))
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
        # (solved: CVXPY has given every variable its value)
        support = [g for g, (t, _) in slacks.items()
                   if t.value is not None and t.value > SLACK_TOLERANCE]
        if not support:
            return None  # a design within the bounds meets force balance
        items: list[tuple[str, float, float | None, str]] = []
        parts: list[str] = []
        assert m.value is not None and s.value is not None  # solved
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
    def _excess(b: LinkBounds, kind: str, value: float) -> float:
        """How far the value a bound group needs (:meth:`_needed`) lies beyond its bound.

        Relative to the bound's scale (the link's mass or length); ``≤ 0``: within it.
        """
        if kind == "mass-high":
            return (value - b.mass[1]) / b.mass_ref
        if kind == "mass-low":
            return (b.mass[0] - value) / b.mass_ref
        if kind == "com":
            return (value - b.radius) / b.length
        return value / b.length  # a fixed centre of mass: how far it must move

    def _centre(self, b: LinkBounds, kind: str) -> complex:
        """Where a centre-of-mass group's value is measured from (local, m).

        A radius's ``com_about``; for a fixed centre of mass, the fixed centre itself: the
        value is then how far it must move, which is what makes the problem infeasible (the
        radius a designer would give, about the link's default point, is :meth:`_about`'s).
        """
        if kind == "com":
            return b.com_centre
        assert b.com_fixed is not None  # the group of a fixed centre of mass
        return b.com_fixed

    def _about(self, b: LinkBounds) -> complex:
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
        if value is not None:
            return value
        assert b.com_fixed is not None  # the group of a fixed centre of mass
        return abs(b.com_fixed - self._about(b)) + move

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
            elif high and b.room_written("mass") is not None:
                words = (f"{key} must allow up to {v:.4g} kg (is at most {current:.6g}: the "
                         f"most its part's room holds, {b.part_key}, of the "
                         f"{b.room_written('mass')!r} written)")
            elif high:
                words = f"{key} must allow up to {v:.4g} kg (is at most {current!r})"
            else:
                words = f"{key} must allow down to {v:.4g} kg (is at least {current!r})"
            return (key, v, current, "kg"), words
        key = b.bound_key("com_radius")
        v = _up(value)
        if kind == "com":
            written = b.room_written("com_radius")
            if written is not None:  # the part's room narrowed what the spec wrote
                return (key, v, b.com_radius, "m"), (
                    f"{key} must be at least {v:.4g} m (is {b.com_radius:.6g}: the reach of "
                    f"its part's room, {b.part_key}, within the {written!r} written)"
                )
            return (key, v, b.com_radius, "m"), (
                f"{key} must be at least {v:.4g} m (is {b.com_radius!r})"
            )
        about = b.default_about
        return (key, v, None, "m"), (
            f"{key} must be given, at least {v:.4g} m about {about} (the centre of mass is "
            "fixed now)"
        )


def _solve(problem: cp.Problem, settings: dict[str, Any]) -> None:
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
