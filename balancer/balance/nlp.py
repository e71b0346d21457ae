"""Nonlinear balancing in the designer's own parameters (CasADi + IPOPT).

Decision vector (scaled; only what may change): per link, in the mechanism's order,
``m/m_ref`` (kg), ``e/l`` and ``f/l`` (centre of mass in the link frame, m), ``I/(m_ref·l²)``
(inertia about the centre of mass, kg·m²); then the counter-rotor inertias of the links on a
ground pivot over their link's ``m_ref·l²`` (kg·m²). Fixed quantities are constants; inert ones
(see :attr:`balancer.balance.problem.NumericProblem.inert`) are left out and settled
afterwards.

The objective is the same ``J`` as the convex problem's, written through the inertial
parameters ``π(p) = (m, m·e, m·f, I + m·(e² + f²))``
(:func:`balancer.model.links.inertial_parameters`) and the factor ``R`` of the regressors:
``J = ‖R·π‖² + w_m·Δm``. Constraints: force balance (bilinear equalities in these variables),
the centre of mass in its disc ``|s̄ − c|² ≤ R²``, ``I ≥ m·ρ²``, and simple bounds — an upper
inertia bound is exact here, which is where this formulation can beat the convex relaxation.

IPOPT is built once per problem (:class:`NlpSolver`) and started from the convex optimum (a
primal warm start). CasADi stops IPOPT at a SIGINT and returns normally (status
``NonIpopt_Exception_Thrown``, and a warning on stderr): :meth:`NlpSolver.solve` raises
:class:`KeyboardInterrupt` instead (:func:`balancer.interrupts.checked`), without the warning.
"""

from __future__ import annotations

import contextlib
import io
import math
import sys
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .. import interrupts
from ..model.links import inertial_parameters, physical_parameters
from .problem import NumericProblem
from .result import StageReport

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca

#: IPOPT's options, in one place: quiet and tight. The start is the convex optimum (a primal
#: warm start); IPOPT's own warm-start mode, which also wants multipliers that the convex
#: problem does not give in these variables, stalled on the degenerate optimum of complete
#: balancing (300 iterations without convergence), so the defaults for μ and the bound push
#: are kept: 15–30 iterations, a few milliseconds, on PB1 and PB2.
IPOPT_OPTIONS: dict[str, object] = {
    "print_time": False,
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-12,
    "ipopt.acceptable_tol": 1e-9,
    "ipopt.constr_viol_tol": 1e-12,
    "ipopt.max_iter": 300,
}

#: With a bound on the supports' loads (``max_bearing_load``), the NLP started from a design
#: holds only the samples where that design's load is at least this share of the bound (the
#: bound's Hessian over every sample is costly to build); its design is kept only if it meets
#: the bound at every sample (:meth:`~balancer.balance.feasibility.Feasibility.violations`).
NEAR_BOUND = 0.5

_CONVERGED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
_INFEASIBLE = ("Infeasible_Problem_Detected", "Restoration_Failed")


@dataclass(frozen=True, kw_only=True, eq=False)
class NlpSolution:
    """IPOPT's answer.

    Attributes
    ----------
    x
        Design vector (inert entries settled).
    objective
        ``J(x)``, (N·m)².
    status
        ``"optimal"`` (IPOPT converged: a local optimum), ``"infeasible"`` or ``"failed"``.
    feasible
        Whether ``x`` meets every bound and force balance (checked, not taken from IPOPT).
    stage
        The solver run.
    """

    x: NDArray[np.float64]
    objective: float
    status: str
    feasible: bool
    stage: StageReport


class NlpSolver:
    """The balancing NLP of a redesign problem, built once and solved from given starts.

    Parameters
    ----------
    data
        The numeric problem.
    options
        IPOPT/CasADi options to override :data:`IPOPT_OPTIONS`.
    """

    def __init__(self, data: NumericProblem, *, options: dict[str, Any] | None = None,
                 start: NDArray[np.float64] | None = None) -> None:
        import casadi as ca  # heavy: only where symbols are built
        self.data = data
        self.options = {**IPOPT_OPTIONS, **(options or {})}
        self._names: list[tuple[int, str]] = []  # (link index or entry, kind) per variable
        lbx: list[float] = []
        ubx: list[float] = []
        symbols: list[ca.SX] = []
        g: list[ca.SX] = []
        lbg: list[float] = []
        ubg: list[float] = []
        varying: set[int] = set()  # entries of x that can change
        # the design vector, in the layout's order
        parts: list[ca.SX | float] = [0.0] * data.size
        m: ca.SX | float  # a link's physical values: variables, or fixed
        e: ca.SX | float
        f: ca.SX | float
        inertia: ca.SX | float

        def variable(name: str, lo: float, hi: float, tag: tuple[int, str]) -> ca.SX:
            s = ca.SX.sym(name)
            symbols.append(s)
            lbx.append(lo)
            ubx.append(hi)
            self._names.append(tag)
            return s

        for b in data.links:
            k, mref, l, iref = b.start, b.mass_ref, b.length, b.inertia_ref
            if b.mass[0] < b.mass[1]:
                m = mref * variable(
                    f"m{b.index}", b.mass[0] / mref, b.mass[1] / mref, (b.index, "m")
                )
                varying.update((k, k + 1, k + 2))
            else:
                m = b.mass[0]
            if b.on_line:  # on the link's line: f = 0, e within the disc's chord
                lo, hi = b.line_span
                e = l * variable(f"e{b.index}", lo / l, hi / l, (b.index, "e"))
                f = 0.0
                varying.add(k + 1)
            elif b.com_fixed is None:
                c, r = b.com_centre / l, b.radius / l
                e = l * variable(f"e{b.index}", c.real - r, c.real + r, (b.index, "e"))
                f = l * variable(f"f{b.index}", c.imag - r, c.imag + r, (b.index, "f"))
                g.append((e / l - c.real) ** 2 + (f / l - c.imag) ** 2)
                lbg.append(-math.inf)
                ubg.append(r * r)
                varying.update((k + 1, k + 2))
            else:
                e, f = b.com_fixed.real, b.com_fixed.imag
            if data.inert[k + 3] or b.inertia_fixed:
                # (An inert one is settled afterwards; a counterweight has no original.)
                kept = b.original.inertia if b.offset is None else b.inertia[0]
                inertia = kept if data.inert[k + 3] else b.inertia[0]
            else:
                inertia = iref * variable(
                    f"I{b.index}", b.inertia[0] / iref, b.inertia[1] / iref, (b.index, "I")
                )
                if b.gyration > 0 and b.mass[0] < b.mass[1]:
                    g.append((inertia - m * b.gyration**2) / iref)
                    lbg.append(0.0)
                    ubg.append(math.inf)
                elif b.gyration > 0:
                    lbx[-1] = max(lbx[-1], b.mass[0] * b.gyration**2 / iref)
                if b.offset is not None:  # its spread (LinkBounds.counterweight_reach)
                    p = b.com_centre
                    g.append((inertia + m * ((e - p.real) ** 2 + (f - p.imag) ** 2)
                              - m * b.counterweight_reach**2) / iref)
                    lbg.append(-math.inf)
                    ubg.append(0.0)
            # A counterweight's variables are its own; the link's entries add the kept link's.
            shift = (0.0,) * 4 if b.offset is None else b.offset
            parts[k : k + 4] = [p + d for p, d in zip(inertial_parameters(m, e, f, inertia),
                                                       shift, strict=True)]
        for b in data.rotor_links:
            entry = b.rotor_entry
            assert b.counter_rotor is not None
            lo, hi = b.counter_rotor
            scale = data.scales[entry]
            if data.inert[entry] or lo == hi:
                parts[entry] = lo
            else:
                parts[entry] = scale * variable(f"Jc{entry}", lo / scale, hi / scale,
                                                (entry, "Jc"))
        if data.sites is not None:  # a chosen mass·radius within its disc; a kept one as it is
            for i, site in enumerate(data.sites.sites):
                entries = range(data.size)[data.sites.entries(i)]
                if not site.free:
                    for k in entries:
                        parts[k] = float(data.x0[k])
                    continue
                bound = site.max_mr / data.scales[entries.start]
                re, im = (data.scales[k] * variable(f"x{k}", -bound, bound, (k, "mr"))
                          for k in entries)
                parts[entries.start], parts[entries.start + 1] = re, im
                g.append((re * re + im * im) / data.scales[entries.start] ** 2)
                lbg.append(-math.inf)
                ubg.append(bound * bound)
        pi = ca.vertcat(*parts)
        support, rows = data.support_bound, data.regressors.supports
        if support is not None and rows is not None:  # |load|² ≤ bound² at every sample
            # (the entries that are numbers folded into one column: a graph as small as the
            # variables, not as the design vector)
            if start is not None:  # the rows near the bound at the start: a working set
                near = np.abs(rows @ np.asarray(start, float)) >= NEAR_BOUND * support
                rows = rows[near]
            fixed = [i for i, part in enumerate(parts) if isinstance(part, float)]
            moving = [i for i, part in enumerate(parts) if not isinstance(part, float)]
            known = rows[:, fixed] @ np.array([parts[i] for i in fixed], dtype=float) / support
            scaled = rows[:, moving] / support
            unknown = ca.vertcat(*(parts[i] for i in moving))
            re = ca.mtimes(ca.DM(scaled.real), unknown) + ca.DM(known.real)
            im = ca.mtimes(ca.DM(scaled.imag), unknown) + ca.DM(known.imag)
            g.append(re * re + im * im)
            lbg += [-math.inf] * rows.shape[0]
            ubg += [1.0] * rows.shape[0]
        if data.force_balance is not None:
            a, rhs = data.force_balance
            terms = np.abs(a) @ np.abs(data.scales)  # each condition by its own size
            residual = (ca.mtimes(ca.DM(a / terms[:, None]), pi) - ca.DM(rhs / terms))
            for i in range(a.shape[0]):
                if any(a[i, j] != 0 for j in varying):
                    g.append(residual[i])
                    lbg.append(0.0)
                    ubg.append(0.0)
        scale = data.objective_scale
        value: ca.SX | float = 0
        if data.factor.shape[0]:
            weighted = ca.mtimes(ca.DM(data.factor / scale), pi)
            value = ca.sumsqr(weighted)
        if data.weights.added_mass:
            value = value + data.weights.added_mass / scale**2 * (
                sum(pi[i] for i in data.mass_entries) - data.original_mass
            )
        v = ca.vertcat(*symbols)
        self._pi = ca.Function("pi", [v], [pi])
        self._lbx = np.array(lbx)
        self._ubx = np.array(ubx)
        self._lbg = np.array(lbg)
        self._ubg = np.array(ubg)
        # As many equations (Eq. 58's rows) as variables leave IPOPT nothing to improve on the
        # convex optimum, and CasADi would say on stderr that the NLP is overconstrained.
        # The largest main-bearing load as an objective (an engine's, whose program is convex
        # and exact: its convex optimum is global) is not written here: nothing to improve.
        equations = int(np.sum(self._lbg == self._ubg))
        self._solver = None if (equations >= len(symbols)
                                or data.weights.largest_bearing_load) else ca.nlpsol(
            "balance", "ipopt", {"x": v, "f": value, "g": ca.vertcat(*g)}, self.options
        )

    @property
    def size(self) -> int:
        """Number of decision variables."""
        return len(self._names)

    @property
    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Lower and upper bounds of the scaled decision vector (``±inf`` where none)."""
        return self._lbx.copy(), self._ubx.copy()

    def start(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The scaled decision vector for design vector ``x``, clipped into the bounds."""
        data = self.data
        own = data.own(x)
        # A counterweight of no mass has no centre: it starts at its disc's centre.
        # (a held link as it is: it may have no mass, an engine's crankshaft on its axis)
        physical = [(b.original.mass, b.original.e, b.original.f, b.original.inertia)
                    if not b.listed
                    else (0.0, b.com_centre.real, b.com_centre.imag, 0.0) if data.absent(b, own)
                    else physical_parameters(own[b.entries]) for b in data.links]
        out = []
        for index, kind in self._names:
            if kind in ("Jc", "mr"):
                out.append(x[index] / data.scales[index])
                continue
            b = data.links[index]
            m, e, f, inertia = physical[index]
            out.append(
                {
                    "m": m / b.mass_ref,
                    "e": e / b.length,
                    "f": f / b.length,
                    "I": inertia / b.inertia_ref,
                }[kind]
            )
        v = np.clip(np.array(out, float), self._lbx, self._ubx)
        for i, (index, kind) in enumerate(self._names):  # pull the centre of mass into its disc
            if kind == "e" and not data.links[index].on_line:
                b = data.links[index]
                c, r = b.com_centre / b.length, b.radius / b.length
                d = math.hypot(v[i] - c.real, v[i + 1] - c.imag)
                if d > r:
                    v[i] = c.real + (v[i] - c.real) * r / d
                    v[i + 1] = c.imag + (v[i + 1] - c.imag) * r / d
        return v

    def design(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """The design vector ``x`` of a scaled decision vector (inert entries settled)."""
        return self.data.settle(np.array(self._pi(v)).ravel())

    def solve(self, x_start: NDArray[np.float64]) -> NlpSolution | None:
        """Run IPOPT from design vector ``x_start`` (normally the convex optimum).

        ``None`` where the problem leaves no freedom beyond its equations (nothing to solve),
        or its objective weighs the largest main-bearing load (an engine's: the convex program
        is exact, its optimum global).
        """
        if self._solver is None:
            return None
        data = self.data
        v0 = self.start(np.asarray(x_start, float))
        t0 = time.perf_counter()
        said = io.StringIO()  # CasADi's messages: dropped if it was interrupted
        with interrupts.checked(), contextlib.redirect_stderr(said):
            sol = self._solver(x0=v0, lbx=self._lbx, ubx=self._ubx, lbg=self._lbg,
                               ubg=self._ubg)
        sys.stderr.write(said.getvalue())
        elapsed = time.perf_counter() - t0
        stats = self._solver.stats()
        word = str(stats.get("return_status", "unknown"))
        x = self.design(np.array(sol["x"]).ravel())
        feasible = not data.violations(x)
        if word in _CONVERGED:
            status = "optimal"
        elif word in _INFEASIBLE:
            status = "infeasible"
        else:
            status = "failed"
        objective = data.objective(x)
        stage = StageReport(
            name="nlp",
            converged=word in _CONVERGED,
            solver_status=word,
            iterations=int(stats.get("iter_count", 0)),
            time=elapsed,
            objective=objective,
        )
        return NlpSolution(x=x, objective=objective, status=status, feasible=feasible, stage=stage)
