"""A solver's design made exactly feasible: bounds met exactly, force balance to rounding.

Interior-point solvers meet their constraints to a tolerance; a designer's spec must hold what
the problem promised. :class:`Repairs` holds the convex solver's ways from a solver's point to a
design that does (:class:`~.convex.ConvexSolver` inherits them): restoring Eq. 58 by the least
change, moving broken bounds onto their limits with Eq. 58 kept, projecting onto the bounds
tightened by a margin, polishing free entries back to the preferred design, and taking off
counterweights that the optimum does not need.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .certificate import Constraint
from .conic import ConicProgram
from .feasibility import FORCE_BALANCE_TOLERANCE, ROUNDING_TOLERANCE
from .lsq import pinv as pseudo_inverse
from .problem import NumericProblem

#: :meth:`Repairs.polish` puts a parameter back at its preferred value where the objective
#: is worse by at most this of the problem's scale than the design's before polishing: far
#: inside the certified 1e-6 and the tie-break's 1e-8, and far above what a parameter that the
#: objective does not see moves it by (rounding).
POLISH_ACCEPT = 1e-10
#: A counterweight that may be none is taken off (:meth:`Repairs.polish`,
#: :meth:`Repairs.without_idle_counterweights`) where the objective without it exceeds the
#: objective with it by at most this of the problem's scale: "no worse" to rounding.
TAKE_OFF_ACCEPT = 1e-12

if TYPE_CHECKING:
    from .variables import VariableMap

#: Inward margin of the bounds (scaled units) in the final projection (:meth:`finalize`): a
#: hundred times Clarabel's feasibility tolerance, so that its solution lies inside the bounds.
MARGIN = 1e-8
#: Inward distance (of a link's mass, of its length) at which the active-set correction
#: (:meth:`Repairs.onto_active`) puts each bound it moves a design onto: far above the
#: rounding of the physical values (``ε``), far below any tolerance.
ACTIVE_INSIDE = 1e-12
#: Eq. 58's residual, relative to its terms (:meth:`NumericProblem.force_balance_rows`), at
#: which a design meets it to rounding: a few ε for the few products in each row.
EQ58_ROUNDING = 16 * float(np.finfo(float).eps)
_EPS = float(np.finfo(float).eps)


#: A mass·radius within this share of its bound is held by it (:meth:`Repairs.polish_sites`).
ACTIVE_SHARE = 1e-6
#: Singular values of the objective's factor below this share of the largest are rounding
#: (:meth:`Repairs.polish_sites`).
RANK_TOLERANCE = 1e-12


def _norm(v: NDArray[np.float64]) -> float:
    """The 2-norm of a real vector, as ``numpy.linalg.norm`` computes it: ``√(v·v)``."""
    return math.sqrt(float(v.dot(v)))


class Repairs:
    """The repairs of a convex solver's designs (see the module docstring).

    Mixed into :class:`~.convex.ConvexSolver`, whose problem, variables, force-balance rows
    and programs they use.
    """

    data: NumericProblem
    layout: VariableMap
    settings: dict[str, Any]
    _fb: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]] | None
    _pinned_inverses: dict[bytes, NDArray[np.float64]]
    _projections: dict[float, ConicProgram]

    def _constraints(self, margin: float = 0.0, *, supports: bool = True
                     ) -> tuple[list[Constraint], list[str]]:
        """The bounds as cone constraints tightened by ``margin`` (the solver's)."""
        raise NotImplementedError

    def finalize(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], bool]:
        """The design ``x`` made exactly feasible: bounds met exactly, Eq. 58 to rounding.

        Solvers meet bounds to their tolerance. First Eq. 58 is restored by the least change
        of the free variables; if a bound is still broken by more than rounding
        (:data:`~balancer.balance.feasibility.ROUNDING_TOLERANCE`: a designer's spec must hold
        what the problem promised, and :meth:`NumericProblem.physical` removes only rounding), the
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
        # A counterweight that is none stays none: the projection's margin would put it off
        # its cone's apex (a few milligrams at its pivot that change nothing).
        _, was_none = data.without_absent(x)
        for margin in (MARGIN, 1e-2 * MARGIN, 0.0):  # a thin feasible set takes a smaller one
            u = self._project(lay.u(x), margin)
            if u is None:
                continue
            candidates = [self._clip_and_pin(self.restore_balance(u)), self.onto_active(u)]
            if was_none.any():
                kept = lay.x(u)
                kept[was_none] = x[was_none]
                candidates.insert(0, self._clip_and_pin(self.restore_balance(lay.u(kept))))
            for candidate in candidates:
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
                    g = abs(d) - b.radius * m  # ≤ 0 inside, kg·m
                    inside = min(ACTIVE_INSIDE * l, b.radius / 4) * m
                    broken = broken or g > 0
                    if (g > -inside / 2 or (k, "com") in taken) and abs(d) > 0:
                        taken.add((k, "com"))
                        n = d / abs(d)
                        grad = (-(n.real * b.com_centre.real + n.imag * b.com_centre.imag)
                                - b.radius, n.real, n.imag)
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
            xp = data.built(x)
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
                if abs(d) > m * b.radius:
                    d *= m * b.radius / abs(d) * (1 - 4 * 2.0**-52)
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
                x[b.rotor_entry] = min(max(x[b.rotor_entry], b.counter_rotor[0]),
                                       b.counter_rotor[1])
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
        accuracy (a mass of 2.10001 kg where nothing asks it to leave 2.1; "almost solved", on
        another machine's arithmetic, the Jansen leg's j at 0.5400003 kg for 0.54); each free
        entry of ``x`` is set to its preferred value where that keeps every constraint and the
        objective no worse (to :data:`POLISH_ACCEPT` of the problem's scale from the objective
        before polishing: the changes do not add up; better where the preferred value is a bound
        that the interior-point solver held the entry off). First each counterweight that
        may be none is taken off whole where that keeps every constraint and makes the
        objective no worse.
        """
        data, lay = self.data, self.layout
        start = objective
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
            if data.within(jt, objective, TAKE_OFF_ACCEPT) and not data.violations(xt):
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
            if not data.within(jt, start, POLISH_ACCEPT):  # (better: a bound it was held off)
                continue
            if not data.violations(xt):
                u, x, objective, pinned = trial, xt, jt, trial_pinned
        return x, objective

    def polish_sites(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """``x`` with its mass·radius sites off their bounds solved for exactly, the rest kept.

        Where its bound does not hold a site, the objective is a least-squares problem in it:
        solved by a factorisation its residual is rounding, where the interior-point iterate
        leaves what those masses can cancel at the square root of its tolerance. The
        least-norm solution in the scaled variables (as the tie-break chooses); kept only if
        every site stays within its bound and the objective is no worse.
        """
        data = self.data
        sites = data.sites
        if sites is None:
            return x
        x = np.asarray(x, dtype=float)
        free = np.zeros(data.size, dtype=bool)
        for i in sites.chosen:
            if abs(sites.vector(x, i)) < (1 - ACTIVE_SHARE) * sites.sites[i].max_mr:
                free[sites.entries(i)] = True
        if not free.any():
            return x
        scaled = data.factor[:, free] * data.scales[free]
        rhs = -(data.factor[:, ~free] @ x[~free])
        solved, *_ = np.linalg.lstsq(scaled, rhs, rcond=RANK_TOLERANCE)
        candidate = x.copy()
        candidate[free] = solved * data.scales[free]
        if sites.violations(candidate, 0.0) or data.violations(candidate):
            return x
        return candidate if data.reduced_objective(candidate) <= data.reduced_objective(x) else x

    def without_idle_counterweights(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The exactly feasible design ``x`` without the counterweights that do nothing in it.

        :meth:`polish` takes off the counterweights that may be none where the objective is no
        worse without them, but before :meth:`finalize` meets the bounds exactly; what one
        bought there may be no more than a bound met to the solver's tolerance, which
        finalize's exact design gives back (redesign campaign, seed 40, problem 1169: a
        rocker's 4.6 kg counterweight 4e-7 m from its fixed pivot, worth 1.3e-12 of the
        scale while the rocker's inertia sat 5.5e-11 kg·m² below its bound, worth nothing
        once there). Each such counterweight is taken off the finalized design where the
        design without it, settled and finalized, is exactly feasible and its objective no
        worse (:data:`TAKE_OFF_ACCEPT`).
        """
        data = self.data
        if not data.nullable:
            return x
        objective = data.objective(x)
        for b in data.nullable:
            if data.absent(b, data.own(x)):
                continue
            trial = np.array(x, dtype=float)
            trial[b.entries] = data.offset[b.entries]
            xt, exact = self.finalize(data.settle(trial))
            if not (exact and data.absent(b, data.own(xt))):
                continue
            jt = data.objective(xt)
            if data.within(jt, objective, TAKE_OFF_ACCEPT):
                x, objective = xt, jt
        return x

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
        if not data.nullable:
            return u
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
        feasibility check that follows decides. A counterweight that is none
        (:meth:`NumericProblem.absent`) stays none: its entries are kept too.
        """
        u = np.array(u, dtype=float)
        if self._fb is None:
            return u
        at, rhs, pinv = self._fb
        if self.data.nullable:  # (without a counterweight that may be none: nothing to keep)
            _, none = self.data.without_absent(self.layout.x(u))
            if none.any():
                kept = none[list(self.layout.primary)]
                pinned = kept if pinned is None else (pinned | kept)
        free = None if pinned is None or not pinned.any() else ~pinned
        if free is not None and not free.any():
            return u
        if free is not None:
            key = free.tobytes()
            if key not in self._pinned_inverses:  # the same few patterns recur: keep them
                self._pinned_inverses[key] = pseudo_inverse(at[:, free])
            pinv = self._pinned_inverses[key]
        residual = at @ u - rhs
        size = _norm(residual)
        # The correction's own rounding (the rows' conditioning times ε) leaves a residual
        # above rounding of the terms: refine while it shrinks (one or two more steps).
        for _ in range(4):
            if free is None:
                trial = u - pinv @ residual
            else:
                trial = u.copy()
                trial[free] -= pinv @ residual
            trial_residual = at @ trial - rhs
            trial_size = _norm(trial_residual)
            if not trial_size < size:
                break
            u, residual, size = trial, trial_residual, trial_size
        return u

    def repair(self, u: NDArray[np.float64]) -> tuple[NDArray[np.float64], bool]:
        """The design of solver variables ``u``, with the solver's small violations removed.

        Clarabel meets the constraints to its tolerance (``1e-10``, or ~``1e-5`` when it stops
        "almost solved"). First the least change of ``u`` restores Eq. 58 to rounding (it moves
        the design by about Clarabel's tolerance). A design that then meets every bound to
        :data:`~balancer.balance.feasibility.FEASIBILITY_TOLERANCE` is kept as it is; otherwise
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
                    if abs(d) > m * b.radius:
                        d *= m * b.radius / abs(d)
                        s = m * b.com_centre + d
                        u[index[k + 1]] = (s.real + shift[k + 1]) / data.scales[k + 1]
                        u[index[k + 2]] = (s.imag + shift[k + 2]) / data.scales[k + 2]
            for b in data.rotor_links:
                entry = b.rotor_entry
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
