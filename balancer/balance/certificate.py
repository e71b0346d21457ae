"""A lower bound on the convex balancing program's optimum by weak duality, free of tolerances.

The second-order cone program of :mod:`.convex`, in its scaled variables ``u``, is

    minimise f(u)  subject to  M_i·u + m_i ∈ K_i (i = 1…m),  E·u = r,

with ``f`` the norm ``‖P·u + q‖`` (or ``‖P·u + q‖² + g·u + g0`` when added mass is penalised)
and each ``K_i`` the nonnegative reals (a bound) or a second-order cone (a centre of mass in its
disc; a realisable inertia, ``‖S‖²/m ≤ t`` as ``‖(2·S, m − t)‖ ≤ m + t``). For multipliers
``z_i`` in the (self-dual) cones, any ``ν`` and ``‖v‖ ≤ 1``, every feasible ``u`` has

    ‖P·u + q‖ ≥ v·(P·u + q) ≥ v·(P·u + q) − Σ z_i·(M_i·u + m_i) + ν·(E·u − r) = α + ρ·u

(for the sum of squares, ``‖w‖² ≥ 2·v·w − ‖v‖²`` with ``v`` the solution's residual). Over a
box ``[lo, hi]`` that holds a minimiser the optimum is therefore at least
``α + Σ_j min(ρ_j·lo_j, ρ_j·hi_j)``: a bound that holds whatever the solver's tolerances and
status — they only make ``ρ`` larger than zero and the bound less tight. Clarabel's dual
``(v, z, ν)``, projected onto the cones, leaves ``ρ`` at its dual residual (``1e-10``, ~1e-8
"almost solved"); the free ``ν`` and the multipliers of the active bounds are then refitted
(bounded least squares, :func:`lower_bound` and :mod:`.lsq`) to cancel what they can of it. (Not the
multipliers' own accuracy matters, but only this residual: a multiplier taken from the
primal point instead, e.g. ``v = ∇‖P·û + q‖``, is off by the primal error, which a flat
optimum leaves at the square root of the solver's tolerance.) Every choice of multipliers
gives a valid bound, so a few are tried and the highest kept: ``v`` the solver's or the
gradient at ``û`` (the solver's can be off by its tolerance in a direction the objective
barely sees), the inactive cones' multipliers as given or zero (at the solver's
complementarity tolerance they still pull an unbounded inertia's coefficient below zero).

The box comes from the bounds themselves (see :meth:`.convex.ConvexSolver.box`). An inertia
with no upper bound is bounded on the objective's sublevel set ``f ≤ U`` (``U`` the objective
of a feasible design) through the objective's own columns, when they have full rank;
otherwise its coefficient must be surely nonnegative, or no bound is given. The evaluation's
rounding is bounded too: sums are exactly rounded (``math.fsum``) and the bound is lowered by
``ε`` times the magnitudes of the products summed.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

from .lsq import bounded_lstsq, pinv

#: Equality constraints ``E·u = r``: ``(E, r)``.
Equality: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64]]

_EPS = float(np.finfo(float).eps)
#: Multiplier (relative to the largest) above which a bound counts as active when the
#: multipliers are refitted: an interior-point method leaves inactive ones at its
#: complementarity tolerance (1e-10 of the active ones or less).
ACTIVE_MULTIPLIER = 1e-7
#: ... and whose value at the solver's point is within this of its cone's boundary (scaled
#: units, relative to the constraint's size): it meets its active constraints to its
#: feasibility tolerance (1e-10, 1e-5 "almost solved").
ACTIVE_SLACK = 1e-4


@dataclass(frozen=True, eq=False)
class Constraint:
    """A cone constraint ``M·u + m ∈ K``.

    ``K`` is the nonnegative reals (``kind = "nonneg"``, one row) or the second-order cone
    ``{(t, w): ‖w‖ ≤ t}`` (``"soc"``).
    """

    kind: str
    M: NDArray[np.float64]
    m: NDArray[np.float64]

    def slack(self, u: NDArray[np.float64]) -> float:
        """How far ``M·u + m`` lies inside the cone, relative to its size (< 0: outside)."""
        s = self.M @ u + self.m
        if self.kind == "nonneg":
            return float(s[0]) / (1.0 + float(np.abs(self.M[0]) @ np.abs(u)))
        return (float(s[0]) - float(np.linalg.norm(s[1:]))) / (1.0 + abs(float(s[0])))

    def project(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """The nearest point of the (self-dual) cone to ``z``."""
        z = np.asarray(z, dtype=float).reshape(-1)
        if not np.isfinite(z).all():
            z = np.nan_to_num(z)
        if self.kind == "nonneg":
            return np.maximum(z, 0.0)
        t, w = z[0], z[1:]
        nw = float(np.linalg.norm(w))
        if nw <= -t:
            return np.zeros_like(z)
        if nw > t:
            t = (t + nw) / 2
            w = w * (t / nw)
            nw = float(np.linalg.norm(w))
        # inside the cone despite the rounding of the norm computed here
        out = np.empty(z.size)
        out[0] = max(t, nw * (1 + 4 * (w.size + 2) * _EPS))
        out[1:] = w
        return out


@dataclass(frozen=True, eq=False)
class ConvexObjective:
    """``f(u) = ‖P·u + q‖`` (``norm``), else ``‖P·u + q‖² + g·u + g0``."""

    P: NDArray[np.float64]
    q: NDArray[np.float64]
    norm: bool
    g: NDArray[np.float64]
    g0: float

    def value(self, u: NDArray[np.float64]) -> float:
        """``f(u)``."""
        r = self.P @ u + self.q
        if self.norm:
            return float(np.linalg.norm(r))
        return float(r @ r) + float(self.g @ u) + self.g0


@dataclass(frozen=True)
class Bound:
    """A certified lower bound on the program's optimum, in its own (scaled) units.

    Attributes
    ----------
    value
        No feasible ``u`` has ``f(u)`` below it.
    dual
        ``α + ρ·û`` at the solver's point (what the bound would be with ``ρ = 0``).
    residual
        ``‖ρ‖∞``.
    """

    value: float
    dual: float
    residual: float


def _sublevel_box(objective: ConvexObjective, lo: NDArray[np.float64], hi: NDArray[np.float64],
                  upper: float) -> NDArray[np.float64] | None:
    """``hi`` with the entries at ``∞`` bounded on ``{u in the box: f(u) ≤ upper}``.

    ``‖P_J·u_J‖ ≤ ‖P·u + q‖ + max over the rest of the box of ‖P_o·u_o + q‖``; with ``P_J``
    of full column rank, ``u_J = P_J⁺·(P_J·u_J)`` and ``|u_j| ≤ ‖row j of P_J⁺‖`` times that
    (``P_J⁺ = V·Σ⁻¹·Uᵀ``, each singular value lowered by the SVD's own rounding). ``None`` if
    it does not bound them.
    """
    free = ~np.isfinite(hi)
    P = objective.P
    if not P.shape[0] or not math.isfinite(upper):
        return None
    if objective.norm:
        radius = max(upper, 0.0)
    else:
        g = objective.g
        if np.any(g[free] != 0):
            return None
        low = float(np.sum(np.minimum(g[~free] * lo[~free], g[~free] * hi[~free])))
        radius = math.sqrt(max(upper - low - objective.g0, 0.0))
    po = P[:, ~free]
    mid, half = (lo[~free] + hi[~free]) / 2, (hi[~free] - lo[~free]) / 2
    rest = float(np.linalg.norm(po @ mid + objective.q)) + float(
        np.linalg.norm(po, axis=0) @ half)
    _, sv, vt = np.linalg.svd(P[:, free], full_matrices=False)
    safe = sv - 64 * _EPS * sv[0] * max(P.shape) if sv.size else sv  # the SVD's own rounding
    if sv.size < int(free.sum()) or not np.all(safe > 0):
        return _bounded_below_box(P[:, free], lo[free], radius + rest, hi, free)
    rows = np.sqrt(((vt / safe[:, None]) ** 2).sum(axis=0))  # ‖row j of P_J⁺‖
    out = np.array(hi, dtype=float)
    out[free] = (radius + rest) * rows * (1 + 1e-9)
    return out


def _bounded_below_box(pj: NDArray[np.float64], low: NDArray[np.float64], reach: float,
                       hi: NDArray[np.float64], free: NDArray[np.bool_]
                       ) -> NDArray[np.float64] | None:
    """:func:`_sublevel_box`'s bounds where ``P_J`` has not full column rank.

    Entries the objective sees only together (two counter-rotors' inertias of links that
    turn alike: equal columns) are each bounded by the objective's bound on their combination
    and the others' lower bounds. For each free ``j``, a combination ``λ`` of ``P_J``'s rows
    and ``μ ≥ 0`` with ``P_Jᵀ·λ − μ = e_j − r`` give, on ``‖P_J·u_J‖ ≤ reach`` and
    ``u_J ≥ low``, ``u_j ≤ b_j + r·u_J`` with ``b_j = ‖λ‖·reach − μ·low``. At any such
    point let ``M = max(L, max_k u_k)`` (``L`` the largest ``|low|``: ``|u_k| ≤ M``); then
    ``u_j ≤ b + ρ·M`` for ``b = max b_j`` and ``ρ = max ‖r‖₁`` (its rounding included), so
    ``M ≤ max(L, b/(1 − ρ))`` when ``ρ < 1``, and every ``u_j ≤ b + ρ·max(L, b/(1 − ρ))``.
    ``None`` if a lower bound is infinite or no such ``λ``, ``μ`` is found (a direction along
    which every entry may grow).
    """
    if not np.all(np.isfinite(low)):
        return None
    rows, count = pj.shape
    scale = max(float(np.max(np.abs(pj))), 1e-300)
    a = np.hstack([pj.T / scale, -np.eye(count)])  # in λ·scale, μ
    a = np.vstack([a, np.hstack([1e-6 * np.eye(rows), np.zeros((rows, count))])])
    lower = np.r_[np.full(rows, -np.inf), np.zeros(count)]
    upper = np.full(rows + count, np.inf)
    bounds, residuals = [], []
    for j in range(count):
        target = np.r_[np.eye(count)[j], np.zeros(rows)]
        fit = bounded_lstsq(a, target, lower, upper, tol=1e-14).x
        lam, mu = fit[:rows] / scale, np.maximum(fit[rows:], 0.0)
        terms = np.abs(pj.T * lam[None, :]).sum(axis=1) + mu + np.eye(count)[j]
        r = np.eye(count)[j] - (pj.T @ lam - mu)
        residuals.append(float(np.sum(np.abs(r)) + 64 * _EPS * np.sum(terms)))
        bounds.append(float(np.linalg.norm(lam)) * reach - float(mu @ low))
    rho = max(residuals)
    if not rho < 0.5:
        return None
    largest = float(np.max(np.abs(low), initial=0.0))
    b = max(bounds)
    top = b + rho * max(largest, b / (1 - rho))
    out = np.array(hi, dtype=float)
    out[free] = np.maximum(top, low) * (1 + 1e-9) + 1e-300
    return out


def lower_bound(objective: ConvexObjective, constraints: list[Constraint],
                equality: Equality | None, u: NDArray[np.float64], duals: list[NDArray[np.float64]],
                v: NDArray[np.float64] | None, lo: NDArray[np.float64],
                hi: NDArray[np.float64], upper: float | None) -> Bound | None:
    """The bound of the module docstring, or ``None`` where the box does not bound it.

    Parameters
    ----------
    objective, constraints, equality
        The program: ``f``, the cones, and ``(E, r)`` (or ``None``).
    u
        The solver's point ``û`` (for the sum of squares' tangent, and the refit's weights).
    duals
        The solver's multiplier of each constraint (projected onto its cone here).
    v
        The norm's multiplier (``‖v‖ ≤ 1`` is imposed here); ``None`` for the sum of squares.
    lo, hi
        A box every feasible point lies in (``hi`` may be ``inf``).
    upper
        The objective of a feasible design (or ``None``): bounds the entries with
        ``hi = ∞`` on the sublevel set, which holds every minimiser.
    """
    u = np.asarray(u, dtype=float)
    if not np.all(np.isfinite(u)):
        return None
    P, q = objective.P, objective.q
    # α and ρ are kept as the products they sum (summed exactly, math.fsum, at the end).
    # The objective's minorant v·(P·u + q) (norm), 2·v·(P·u + q) − ‖v‖² + g·u + g0 (squares).
    # For the norm, two choices of v, whichever bound is higher: the solver's multiplier, and
    # the gradient at û (the solver's multiplier can be off by its dual tolerance in a
    # direction the objective barely sees, which a far bound of the box multiplies).
    minorants: list[tuple[list[NDArray[np.float64]], list[NDArray[np.float64]]]] = []
    if objective.norm:
        r_hat = P @ u + q
        choices = [] if v is None else [np.nan_to_num(np.asarray(v, dtype=float))]
        if float(np.linalg.norm(r_hat)) > 0:
            choices.append(r_hat / float(np.linalg.norm(r_hat)))
        for vv in choices or [np.zeros(P.shape[0])]:
            # ‖v‖ ≤ 1 despite the rounding of the norm computed here
            vv = vv / (max(1.0, float(np.linalg.norm(vv))) * (1 + 8 * (vv.size + 1) * _EPS))
            minorants.append(([vv * q], [P * vv[:, None]]))
    else:
        vv = P @ u + q
        minorants.append(([2 * vv * q, -(vv * vv), np.array([objective.g0])],
                          [2 * P * vv[:, None], objective.g[None, :]]))
    # The cones' multipliers as the solver gives them, and with those of the inactive ones
    # (at its complementarity tolerance) set to zero: an inactive inertia cone's multiplier
    # still pulls the coefficient of an inertia with no upper bound below zero.
    zs = [c.project(z) for c, z in zip(constraints, duals, strict=True)]
    top = max((float(z[0]) for z in zs), default=0.0)
    active = [top > 0 and z[0] > ACTIVE_MULTIPLIER * top and c.slack(u) <= ACTIVE_SLACK
              for c, z in zip(constraints, zs, strict=True)]
    refit = _Refit(objective, constraints, equality, active, u, lo, hi, upper)
    stacked_m = np.concatenate([c.m for c in constraints]) if constraints else np.zeros(0)
    stacked_M = (np.vstack([c.M for c in constraints]) if constraints
                 else np.zeros((0, u.size)))
    best: Bound | None = None
    for zset in (zs, [z if a else np.zeros_like(z) for z, a in zip(zs, active, strict=True)]):
        z = np.concatenate(zset) if zset else np.zeros(0)
        cone_a, cone_r = -(z * stacked_m), -(stacked_M * z[:, None])
        for obj_a, obj_r in minorants:
            bound = refit(obj_a + [cone_a], obj_r + [cone_r])
            if bound is not None and (best is None or bound.value > best.value):
                best = bound
    return best


class _Refit:
    """The bound of :func:`lower_bound` for one choice of multipliers, refitted.

    What the choices share is built once: the refit's matrix (the active bounds' and the
    equalities' rows, weighted by the box around ``û``) and, when first needed, the box on the
    objective's sublevel set (:func:`_sublevel_box`).
    """

    def __init__(self, objective: ConvexObjective, constraints: list[Constraint],
                 equality: Equality | None, active: Sequence[bool], u: NDArray[np.float64],
                 lo: NDArray[np.float64], hi: NDArray[np.float64], upper: float | None) -> None:
        self.objective, self.u, self.lo, self.upper = objective, u, lo, upper
        self.hi = np.array(hi, dtype=float)
        finite = np.isfinite(self.hi)
        width = np.maximum(np.abs(lo - u), np.where(finite, np.abs(self.hi - u), 0.0))
        weight = np.where(finite, width, 1e3 * float(np.max(width, initial=1.0)))
        self.weight = np.maximum(weight, 1e-300)
        # Refit: ν free, and a nonnegative addition to each active bound's multiplier (both
        # terms vanish at û, so they cost the bound nothing there), to cancel what they can of
        # ρ. (The scalar part of an active cone's multiplier may grow too, keeping it in the
        # cone, but at the cost of its term at û: it did not pay.)
        columns: list[NDArray[np.float64]] = []
        offsets: list[float] = []
        for c, on in zip(constraints, active, strict=True):
            if c.kind == "nonneg" and on:
                columns.append(-c.M[0])
                offsets.append(-float(c.m[0]))
        signed = len(columns)
        if equality is not None:
            e, r = equality
            columns += list(e)
            offsets += list(-r)
        self.columns = np.array(columns).reshape(len(columns), u.size)
        self.offsets = np.array(offsets)
        self.matrix = self.columns.T * self.weight[:, None]
        self.lower = np.r_[np.zeros(signed), np.full(len(columns) - signed, -np.inf)]
        self.signed = signed
        # The unconstrained least-squares solution of every choice, as LAPACK's lstsq gives it
        # (singular values below ε of the largest dropped); where it keeps the active bounds'
        # additions ≥ 0 it is BVLS's answer too.
        self.inverse = pinv(self.matrix, rcond=_EPS) if columns else None
        self._box: list[NDArray[np.float64] | None] = []

    def box(self) -> NDArray[np.float64] | None:
        """:func:`_sublevel_box` of the program (computed once)."""
        if not self._box:
            upper = math.inf if self.upper is None else self.upper
            self._box.append(_sublevel_box(self.objective, self.lo, self.hi, upper))
        return self._box[0]

    def __call__(self, a_terms: list[NDArray[np.float64]], r_terms: list[NDArray[np.float64]]
                 ) -> Bound | None:
        """The bound for the products ``a_terms`` (of ``α``) and rows ``r_terms`` (of ``ρ``)."""
        extra_a: list[NDArray[np.float64]] = []
        extra_r: list[NDArray[np.float64]] = []
        if self.offsets.size:
            # The fit's target needs no exact sums: any multipliers give a valid bound.
            rho = np.vstack(r_terms).sum(axis=0)
            target = -rho * self.weight
            y = self.inverse @ target
            if not np.all(y[: self.signed] >= 0):
                y = bounded_lstsq(self.matrix, target, self.lower, np.inf, tol=1e-15,
                                  max_iter=500).x
            y = np.where(np.isfinite(y), y, 0.0)
            extra_a.append(y * self.offsets)
            extra_r.append(self.columns * y[:, None])
        return _finish(a_terms + extra_a, r_terms + extra_r, self.u, self.lo, self.hi,
                       self.box)


def _column_sums(rows: list[NDArray[np.float64]], n: int
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Exactly rounded sums of the columns of the stacked ``rows``, and of their magnitudes."""
    if not n or not rows:
        return np.zeros(n), np.zeros(n)
    stack = np.vstack([np.reshape(r, (-1, n)) for r in rows])
    sums = np.array([math.fsum(column) for column in stack.T.tolist()])
    return sums, np.abs(stack).sum(axis=0)


def _finish(a_terms: list[NDArray[np.float64]], r_terms: list[NDArray[np.float64]],
            u: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64],
            sublevel_box: Callable[[], NDArray[np.float64] | None]) -> Bound | None:
    """``α + Σ_j min(ρ_j·lo_j, ρ_j·hi_j)`` less the rounding of its evaluation.

    ``α`` and ``ρ`` are the exactly rounded sums of the products ``a_terms`` and of the
    columns of ``r_terms``; each product is off by at most ``ε/2`` of itself, each sum by
    ``ε/2`` of its value, and the box, computed from the bounds, is widened by ``4·ε`` of
    itself. ``sublevel_box()`` gives the box on the objective's sublevel set
    (:func:`_sublevel_box`).
    """
    a = np.concatenate([np.ravel(t) for t in a_terms]) if a_terms else np.zeros(0)
    alpha = math.fsum(a.tolist())
    rho, rmag = _column_sums(r_terms, u.size)
    if not (math.isfinite(alpha) and np.all(np.isfinite(rho)) and np.all(np.isfinite(rmag))):
        return None
    finite = np.isfinite(hi)
    # An unbounded entry whose coefficient is not surely ≥ 0 (beyond its rounding) needs a
    # finite bound: it could lower the bound without end.
    if np.any(~finite & (rho <= _EPS * (rmag + np.abs(rho)))):
        box = sublevel_box()
        if box is None:
            return None
        hi = box
        finite = np.isfinite(hi)
    lo = lo - 4 * _EPS * np.abs(lo)
    top = np.where(finite, hi + 4 * _EPS * np.abs(hi), lo)  # ρ ≥ 0 there: least at lo
    least = np.minimum(rho * lo, rho * top)
    extent = np.maximum(np.abs(lo), np.abs(top))
    bound = math.fsum([alpha, *least])
    allowance = _EPS * (float(np.abs(a).sum()) + abs(alpha) + float((rmag + np.abs(rho)) @ extent)
                        + float(np.abs(least).sum()) + abs(bound))
    bound -= 2 * allowance
    if not math.isfinite(bound):
        return None
    return Bound(value=bound, dual=alpha + float(rho @ u),
                 residual=float(np.max(np.abs(rho), initial=0.0)))
