"""The redesign problem in numbers: regressors, bounds, force balance, objective, feasibility.

**Inertial balancing only.** With the crank at constant speed every reaction, the shaking force,
the shaking moment and the driving torque are linear in the design vector of the mechanism's
layout (:class:`balancer.linkage.dynamics.Layout`: per link ``m``, ``m·e``, ``m·f`` and ``J``
about the frame's origin, then the counter-rotors' inertias). Applied loads are not (a force at
a centre of mass that the redesign moves), so the redesign balances the **inertial** shaking;
the loads stay on the links of the balanced design as they were.

The spec's side (:class:`~balancer.model.balance.BalanceProblem`, the ``[balance]`` schema)
becomes :class:`NumericProblem` by :func:`numeric_problem`: the regressors over the revolution
(:mod:`.regressors`), per-link bounds (:class:`~.bounds.LinkBounds`), the force-balance
conditions (:mod:`balancer.force_balance`), the objective, and the feasibility checks that the
optimisers and the tests rely on.

This module imports neither CVXPY nor CasADi.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..cycle import sample_angles
from ..errors import SpecError
from ..force_balance import SMALL_ROW, force_balance_conditions
from ..linkage.dynamics import TURNING
from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism
from ..model import Design
from ..model import MechanismModel as Model
from ..model.balance import BalanceProblem, Objective
from ..model.links import inertial_parameters, physical_parameters
from .bounds import LinkBounds, check_problem, resolve_link
from .lsq import bounded_lstsq
from .regressors import CycleRegressors, cycle_regressors, cycle_regressors_at

#: Relative tolerance of :meth:`NumericProblem.violations` for a solver's design (bounds and
#: force balance): ten times Clarabel's tolerance.
FEASIBILITY_TOLERANCE = 1e-9


#: Relative residual of a force-balance condition (against the size of its terms) that a
#: balanced design must meet: rounding, with room for the conditioning of the rows.
FORCE_BALANCE_TOLERANCE = 1e-12


#: Rounding of the objective relative to the rounding of one sum (:meth:`NumericProblem.rounding`).
ROUNDING_FACTOR = 64.0


#: The share of a row's raw terms that its size is at least: their rounding over the tolerance.
_RAW_SHARE = ROUNDING_FACTOR * float(np.finfo(float).eps) / FORCE_BALANCE_TOLERANCE


#: A bound met to this (relative, :meth:`NumericProblem.violations`) is met to rounding: the
#: physical values (:meth:`NumericProblem.physical`) then meet it exactly.
ROUNDING_TOLERANCE = 1e-12


#: A counterweight whose mass may be zero (``counterweight = { mass = [0, hi], … }``) and whose
#: own mass, first moments and inertia are all within this share of the link's scales (``m``,
#: ``m·l``, ``m·l²``) is none: the link is kept as it is (:meth:`NumericProblem.absent`). An
#: interior-point solver approaches a counterweight of no mass only as the apex of its cone, with
#: a centre of mass that the ratio of two vanishing first moments puts anywhere.
ABSENT = 1e-9


#: A design whose shaking is below this share of what its inertias can produce
#: (:attr:`NumericProblem.inertial_scale`) is balanced already; the problem's scale is then
#: that share of the inertial scale, not the (vanishing) original figures.
BALANCED_SHARE = 1e-3


def _bounded_least_squares(a: NDArray[np.float64], x: NDArray[np.float64],
                           entries: Sequence[int], lower: ArrayLike, upper: ArrayLike,
                           original: ArrayLike) -> NDArray[np.float64]:
    """Values of ``x[entries]`` within bounds minimising ``‖a·x‖²``, nearest ``original``.

    A light pull towards the original (1e-6 of the problem's scale) picks one among equally
    good choices.
    """
    lows, highs = np.asarray(lower, float), np.asarray(upper, float)
    values = np.asarray(original, float)
    free = lows < highs
    out = values.copy()
    if not free.any():
        return out
    x = np.array(x, dtype=float)
    x[list(entries)] = values  # the fixed ones at their value, the free ones solved for
    solved = [e for e, f in zip(entries, free, strict=True) if f]
    lows, highs, values = lows[free], highs[free], values[free]
    cols = a[:, solved]
    rest = a @ x - cols @ x[solved]
    scale = np.maximum(np.abs(values), 1.0)
    weight = 1e-6 * max(float(np.linalg.norm(cols)), 1e-300)
    lhs = np.vstack([cols * scale, weight * np.eye(len(solved))])
    rhs = np.concatenate([-rest, weight * values / scale])
    sol = bounded_lstsq(lhs, rhs, lows / scale, highs / scale, tol=1e-14)
    out[free] = np.clip(sol.x * scale, lows, highs)
    return out


@dataclass(frozen=True, kw_only=True)
class NumericProblem:
    """The redesign problem in numbers, built once by :func:`numeric_problem`.

    The objective is ``J(x) = ‖K·x‖² + w_m·(Σm − Σm_original)`` with ``K`` the weighted
    regressor rows (shaking moment, driving torque, shaking force) divided by ``√N``;
    :attr:`factor` ``R`` (from a QR factorisation of ``K``) has ``‖R·x‖ = ‖K·x‖`` and only as
    many rows as the design vector has entries, which is what the optimisers use.

    Attributes
    ----------
    problem
        The spec-side problem.
    mechanism
        The original design's mechanism.
    speed
        Crank speed, rad/s.
    theta1
        Sampled crank angles, rad.
    regressors
        The inertial shaking at those angles per unit entry (:class:`CycleRegressors`).
    links
        Resolved bounds of every moving link.
    x0
        Design vector of the original.
    rows
        ``K`` above, ``(rows, P)``, N·m.
    factor
        ``R`` above, upper triangular, N·m.
    force_balance
        ``(A, b)``: ``A·x = b`` is shaking-force balance
        (:func:`balancer.force_balance.force_balance_conditions`), or ``None`` when force
        balance is not imposed.
    inert
        Entries of ``x`` (inertias about the frames' origins, counter-rotors) that change
        nothing the objective measures: their regressor columns vanish (a crank's at constant
        speed: ``α1 = 0``). The optimisers leave them out; :meth:`settle` then gives them the
        value nearest the original's that the bounds allow.
    """

    problem: BalanceProblem
    mechanism: Mechanism
    speed: float
    theta1: NDArray[np.float64]
    regressors: CycleRegressors
    links: tuple[LinkBounds, ...]
    x0: NDArray[np.float64]
    rows: NDArray[np.float64]
    factor: NDArray[np.float64]
    force_balance: tuple[NDArray[np.float64], NDArray[np.float64]] | None
    inert: tuple[bool, ...]
    #: The regressors at rest under unit crank acceleration (``θ̇1 = 0``, ``θ̈1 = 1``) on the
    #: same angles, where they were computed with :attr:`regressors`
    #: (:attr:`acceleration_factor` computes them otherwise); what :attr:`acceleration_factor`
    #: uses, their shaking moment (their driving torque is NaN where the crank turns at the
    #: operating speed: not computed).
    unit_acceleration: CycleRegressors | None = None

    def with_problem(self, problem: BalanceProblem) -> NumericProblem:
        """The same design at the same operating point under another redesign problem.

        For new bounds (or other links free, another objective) without rebuilding what does
        not depend on them: the regressors, the force-balance conditions and the rows of
        :attr:`acceleration_factor` are kept; with the same objective weights also their
        reduction (:attr:`rows`, :attr:`factor`, :attr:`inert`) and the objective's scales.
        The result equals what :func:`numeric_problem` builds for the design with ``problem``
        as its ``[balance]``.

        Raises
        ------
        SpecError
            If ``problem`` is contradictory (:func:`check_problem`).
        """
        problem = _checked_problem(problem)
        mech = self.mechanism
        check_problem(problem, mech)
        links = tuple(resolve_link(mech, name, problem.link(name)) for name in mech.link_names)
        same_objective = problem.objective == self.problem.objective
        if same_objective:
            rows, factor, inert = self.rows, self.factor, self.inert
        else:
            rows, factor, inert = _reduced(self.regressors, problem.objective, links, self.size)
        fb = None
        if problem.force_balance:
            fb = self.force_balance if self.force_balance is not None else _force_balance(mech)
        new = replace(self, problem=problem, links=links, rows=rows, factor=factor,
                      force_balance=fb, inert=inert)
        kept = ["acceleration_factor", "scales", "original_mass"]
        if same_objective:
            kept += ["objective_reference", "inertial_scale", "objective_scale",
                     "original_objective"]
        if fb is not None and fb is self.force_balance:
            kept.append("_force_balance_sizes")
        for name in kept:  # cached properties that the new problem shares (made once)
            new.__dict__[name] = getattr(self, name)
        return new

    @property
    def linkage(self) -> Model:
        """The original design's model."""
        return self.mechanism.model

    @property
    def size(self) -> int:
        """Number of entries of the design vector ``P``."""
        return self.x0.size

    @property
    def samples(self) -> int:
        """Number of sampled crank angles ``N``."""
        return self.theta1.size

    @property
    def weights(self) -> Objective:
        """The objective's weights."""
        return self.problem.objective

    @cached_property
    def mass_entries(self) -> list[int]:
        """Positions of the links' masses in the design vector."""
        return [b.start for b in self.links]

    @cached_property
    def offset(self) -> NDArray[np.float64]:
        """The design vector's part that no bound concerns: the kept links' own entries.

        Zero except for a link with a counterweight, whose four entries hold the original
        link's (:attr:`LinkBounds.offset`).
        """
        out = np.zeros(self.size)
        for b in self.links:
            if b.offset is not None:
                out[b.entries] = b.offset
        return out

    @cached_property
    def _offset_values(self) -> list[float] | None:
        """:attr:`offset` as Python floats, or ``None`` where it is all zero (no counterweight)."""
        return self.offset.tolist() if self.offset.any() else None

    def own(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The entries the bounds concern: ``x`` less :attr:`offset` (a counterweight's own)."""
        return np.asarray(x, dtype=float) - self.offset

    def absent(self, b: LinkBounds, own: NDArray[np.float64] | list[float]) -> bool:
        """Whether link ``b``'s counterweight in ``own`` (:meth:`own`) is none at all.

        Only a counterweight whose mass may be zero; its own ``m``, ``m·e``, ``m·f`` and
        (unless it is :attr:`inert`, settled afterwards) ``J`` all within :data:`ABSENT` of the
        link's scales.
        """
        if b.offset is None or b.mass[0] > 0:
            return False
        k = b.start
        m, me, mf, j = (float(v) for v in own[k : k + 4])
        return (abs(m) <= ABSENT * b.mass_ref and abs(me) <= ABSENT * b.mass_ref * b.length
                and abs(mf) <= ABSENT * b.mass_ref * b.length
                and (self.inert[k + 3] or abs(j) <= ABSENT * b.inertia_ref))

    @cached_property
    def nullable(self) -> tuple[LinkBounds, ...]:
        """The links whose counterweight may be none (its mass may be zero).

        Those that :meth:`absent` can find without a counterweight; most problems have none.
        """
        return tuple(b for b in self.links if b.offset is not None and not b.mass[0] > 0)

    def without_absent(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                             NDArray[np.bool_]]:
        """``x`` with every counterweight that is none (:meth:`absent`) exactly none.

        Returns the design vector and the mask of the entries so set (to be kept by what
        restores Eq. 58 afterwards).
        """
        x = np.array(x, dtype=float)
        if not self.nullable:
            return x, np.zeros(self.size, dtype=bool)
        own = self.own(x)
        mask = np.zeros(self.size, dtype=bool)
        for b in self.links:
            if self.absent(b, own):
                x[b.entries] = self.offset[b.entries]
                mask[b.entries] = True
        return x, mask

    @cached_property
    def rotor_links(self) -> list[LinkBounds]:
        """The links that have a counter-rotor entry."""
        return [b for b in self.links if b.rotor is not None]

    @cached_property
    def original_mass(self) -> float:
        """Total mass of the original moving links, kg."""
        return self.linkage.total_mass

    @cached_property
    def scales(self) -> NDArray[np.float64]:
        """Typical magnitude of each entry of ``x``, for scaling the optimisers' variables.

        ``m``, ``m·l``, ``m·l``, ``m·l²`` per link (original mass); counter-rotors like their
        link's ``m·l²``.
        """
        out = np.ones(self.size)
        for b in self.links:
            m, l = b.mass_ref, b.length
            out[b.entries] = (m, m * l, m * l, m * l * l)
            if b.rotor is not None:
                out[b.rotor] = b.inertia_ref
        return out

    def total_mass(self, x: NDArray[np.float64]) -> float:
        """``Σm`` of a design vector, kg."""
        return float(np.sum(np.asarray(x)[self.mass_entries]))

    def quadratic(self, x: NDArray[np.float64]) -> float:
        """``‖K·x‖²``: the weighted mean squares, (N·m)²."""
        r = self.rows @ x
        return float(r @ r)

    def objective(self, x: NDArray[np.float64]) -> float:
        """``J(x)`` from the full regressor matrices, (N·m)² (see the module docstring)."""
        w = self.weights
        reg = self.regressors
        total = 0.0
        if w.shaking_moment:
            total += w.shaking_moment * float(np.mean((reg.shaking_moment @ x) ** 2))
        if w.driving_torque:
            total += w.driving_torque * float(np.mean((reg.driving_torque @ x) ** 2))
        if w.shaking_force or w.shaking_force_x or w.shaking_force_y:
            force = reg.shaking_force @ x
            wx = w.shaking_force + w.shaking_force_x
            wy = w.shaking_force + w.shaking_force_y
            total += wx * float(np.mean(force.real**2)) + wy * float(np.mean(force.imag**2))
        if w.rocking_couple:
            couple = reg.rocking_couple @ x
            total += w.rocking_couple * float(np.mean(couple.real**2 + couple.imag**2))
        if w.added_mass:
            total += w.added_mass * (self.total_mass(x) - self.original_mass)
        return total

    def reduced_objective(self, x: NDArray[np.float64]) -> float:
        """``J(x)`` through the factor: ``‖R·x‖² + w_m·(Σm − Σm_original)``, (N·m)².

        Equal to :meth:`objective` up to rounding, at a cost independent of the number of
        sampled angles: what the solvers' inner loops compare.
        """
        r = self.factor @ x
        total = float(r @ r)
        if self.weights.added_mass:
            total += self.weights.added_mass * (self.total_mass(x) - self.original_mass)
        return total

    @cached_property
    def original_objective(self) -> float:
        """``J`` of the original design, (N·m)²."""
        return self.objective(self.x0)

    @cached_property
    def objective_reference(self) -> float:
        """A positive scale of ``J``: ``‖K·x0‖² + w_m·Σm_original``, (N·m)²."""
        value = self.quadratic(self.x0) + self.weights.added_mass * self.original_mass
        return value if value > 0 else 1.0

    @cached_property
    def inertial_scale(self) -> float:
        """The largest RMS a change of the parameters by their own scale makes, N·m.

        ``σ_max(R·diag(scales))`` (:attr:`scales`): what the links' inertias can produce, which
        does not vanish when the original design happens to be balanced.
        """
        if not self.factor.shape[0]:
            return 0.0
        return float(np.linalg.norm(self.factor * self.scales, 2))

    @cached_property
    def objective_scale(self) -> float:
        """The problem's own scale of ``√J``, N·m: the original design's ``‖K·x0‖``.

        It is the RMS of the original's weighted shaking (its RMS shaking moment for the
        default objective); for a design that is balanced already (below
        :data:`BALANCED_SHARE` of :attr:`inertial_scale`) that share of the inertial scale.
        Solvers scale their objective by it; optimality is judged against it.
        """
        value = max(math.sqrt(self.quadratic(self.x0)), BALANCED_SHARE * self.inertial_scale)
        return value if value > 0 else 1.0

    @property
    def rms_form(self) -> bool:
        """Whether ``J`` is a mean square (no mass term): then compared through ``√J``, N·m."""
        return not self.weights.added_mass

    def gap(self, objective: float, lower_bound: float) -> float:
        """The gap of ``objective`` to ``lower_bound``, relative to :attr:`objective_scale`.

        ``(√J − √J_low)/s`` for a mean-square objective (its RMS over the problem's scale, so
        that a zero optimum is judged as finely as any other), else ``(J − J_low)/s²``.
        Dimensionless.
        """
        s = self.objective_scale
        if self.rms_form:
            return (math.sqrt(max(objective, 0.0)) - math.sqrt(max(lower_bound, 0.0))) / s
        return (objective - lower_bound) / (s * s)

    def rounding(self, x: NDArray[np.float64]) -> float:
        """How much rounding can blur the objective at ``x``, in the units of :meth:`gap`.

        The weighted mean squares ``‖K·x‖`` are sums of terms as large as ``|K|·|x|``
        (entry by entry); their rounding is ε times that, and the regressors' own rounding
        (from the kinematics) about as much again: :data:`ROUNDING_FACTOR`·ε·``‖|K|·|x|‖``.
        Tiny for most designs; for links of very different masses (whose terms cancel), large
        enough that no claim of optimality finer than it can be made.
        """
        eps = np.finfo(float).eps
        blur = ROUNDING_FACTOR * eps * float(np.linalg.norm(np.abs(self.rows) @ np.abs(x)))
        s = self.objective_scale
        if self.rms_form:
            return blur / s
        root = math.sqrt(max(self.quadratic(x), 0.0))
        mass = self.weights.added_mass * ROUNDING_FACTOR * eps * self.original_mass
        return (2 * root * blur + blur * blur + mass) / (s * s)

    def within(self, a: float, b: float, rel: float) -> bool:
        """Whether objective ``a`` exceeds ``b`` by at most ``rel`` of the problem's scale.

        In the sense of :meth:`gap`.
        """
        return self.gap(a, b) <= rel

    @cached_property
    def acceleration_factor(self) -> NDArray[np.float64]:
        """Shaking moment per unit crank acceleration at rest, reduced: ``(P, P)``, N·m/(rad/s²).

        The regressors at ``(θ1, θ̇1 = 0, θ̈1 = 1)`` on the sampled angles, divided by ``√N``
        (``A``), as their triangular factor ``R`` (``‖R·x‖ = ‖A·x‖``, the root mean square of
        that shaking moment), so that settling costs the same at any number of samples. The
        objective, at constant speed, does not see what the crank's rotary inertia does when
        the speed changes; this does.
        """
        reg = self.unit_acceleration or cycle_regressors(self.mechanism, self.theta1, 0.0, 1.0)
        rows = reg.shaking_moment / math.sqrt(self.theta1.size)
        # (R alone: numpy's stubs say qr gives a QRResult whatever its mode.)
        return cast("NDArray[np.float64]", np.linalg.qr(rows, mode="r"))

    def settle(self, x: NDArray[np.float64], *, for_motion: bool = True) -> NDArray[np.float64]:
        """Give the :attr:`inert` entries their values.

        With ``for_motion`` false they just take the allowed value nearest the original's (all
        that a check of the objective or the constraints needs); otherwise:

        Nothing the objective or a constraint measures depends on them. An inertia about a
        centre of mass keeps the allowed value nearest the original's (a designer's crankshaft
        or flywheel is not shrunk behind their back). A counter-rotor is chosen, within its
        bounds, to minimise the mean square of the shaking moment per unit crank acceleration
        (:attr:`acceleration_factor`): what a change of crank speed (start-up, fluctuation, free
        motion) makes the frame feel; among equally good choices the one nearest the original.
        With Berkof's conditions met this gives the crank the counter-rotor that completes the
        balance for every motion.
        """
        x = np.array(x, dtype=float)
        own = self.own(x).tolist()
        offset = self._offset_values or [0.0] * self.size
        entries, lower, upper, original = [], [], [], []
        for b in self.links:
            k = b.start
            if not self.inert[k + 3]:
                continue
            m, me, mf = own[k], own[k + 1], own[k + 2]
            if self.absent(b, own):  # no counterweight: none of its inertia either
                x[k + 3] = self.offset[k + 3]
                continue
            if not m > 0:  # nothing to settle
                continue
            q = (me * me + mf * mf) / m
            lo = max(b.inertia[0], m * b.gyration**2)
            shift = offset[k + 3]
            # A counterweight's inertia nearest its least (it has no original).
            kept = lo if b.offset is not None else min(max(b.original.inertia, lo), b.inertia[1])
            entries.append(k + 3)
            lower.append(lo + q + shift)
            upper.append(b.inertia[1] + q + shift)
            original.append(kept + q + shift)
        for b in self.rotor_links:
            if self.inert[b.rotor_entry] and b.counter_rotor is not None:
                lo, hi = b.counter_rotor
                entries.append(b.rotor_entry)
                lower.append(lo)
                upper.append(hi)
                original.append(min(max(b.original.counter_rotor, lo), hi))
        if not entries:
            return x
        x[entries] = original
        if not for_motion:
            return x
        a = self.acceleration_factor
        lower_a, upper_a, original_a = (np.array(v, dtype=float) for v in (lower, upper,
                                                                             original))
        rotor_entries = {b.rotor for b in self.rotor_links}
        rotors = np.array([i in rotor_entries for i in entries])
        if rotors.any():
            idx = [e for e, r in zip(entries, rotors, strict=True) if r]
            x[idx] = _bounded_least_squares(a, x, idx, lower_a[rotors], upper_a[rotors],
                                            original_a[rotors])
        return x

    def physical(self, x: NDArray[np.float64]) -> dict[str, tuple[float, float, float, float,
                                                                   float]]:
        """Each link's ``(m, e, f, I, counter-rotor)`` of design vector ``x``, in its bounds.

        ``m``, ``e = m·e/m``, ``f = m·f/m``, ``I = J − m·(e² + f²)``; an inertia within
        rounding of the original's is the original's. Each value is then put into its bounds
        exactly (:meth:`clamp`): the conversion rounds, and a designer's spec must hold what
        the problem promised. How far that moved anything is the caller's to check
        (:meth:`clamp_distance`).
        """
        out = {}
        own_x = self.own(x)
        for b in self.links:
            rotor = float(x[b.rotor]) if b.rotor is not None else 0.0
            if self.absent(b, own_x) or (b.offset is not None and b.mass[0] == 0
                                         and not own_x[b.start] > 0):
                # no counterweight (none, or no mass where none is allowed: its mass put into
                # its bounds is 0, and a body of no mass has no centre): the link as it is
                original = b.original
                out[b.name] = (original.mass, original.e, original.f, original.inertia, rotor)
                continue
            if b.offset is not None:  # the counterweight in its bounds, added to the link
                own = physical_parameters(x[b.entries] - self.offset[b.entries])
                m, e, f, inertia, rotor = self.clamp(b, *own, rotor)
                if (m, e, f, inertia) == own:  # in its bounds: the link's values as they are
                    out[b.name] = (*physical_parameters(x[b.entries]), rotor)
                    continue
                # (Through the counterweight's own values only when a bound moved it: a
                # counterweight that nearly cancels the link's first moment loses digits of
                # the sum on the way.)
                total = np.add(inertial_parameters(m, e, f, inertia), b.offset)
                out[b.name] = (*physical_parameters(total), rotor)
                continue
            m, e, f, inertia = physical_parameters(x[b.entries])
            if abs(inertia - b.original.inertia) <= 1e-12 * b.inertia_ref:
                inertia = b.original.inertia  # only roundoff from J − m·s²
            out[b.name] = self.clamp(b, m, e, f, inertia, rotor)
        return out

    @staticmethod
    def clamp(b: LinkBounds, m: float, e: float, f: float, inertia: float,
              rotor: float) -> tuple[float, float, float, float, float]:
        """Physical values of one link put exactly into its bounds ``b``.

        Mass into its range; the centre of mass onto the disc (radially) or to its fixed
        place; the inertia into ``[max(I_low, m·ρ²), I_high]``, a counterweight's also under
        its spread (:attr:`LinkBounds.counterweight_reach`: at most ``m·(reach² − |c̄ − p|²)``);
        the counter-rotor into its range. A bound derived by arithmetic (a distance, ``m·ρ²``)
        is met with a margin of a few units in the last place, so that it holds whichever way a
        reader rounds it.
        """
        ulps = 8 * 2.0**-52
        m = min(max(m, b.mass[0]), b.mass[1])
        if b.com_fixed is not None:
            e, f = b.com_fixed.real, b.com_fixed.imag
        elif b.on_line:
            e, f = min(max(e, b.line_span[0]), b.line_span[1]), 0.0
        else:
            e, f = NumericProblem._onto_disc(b.com_centre, b.radius, e, f)
        least = m * b.gyration**2 * (1 + ulps)
        most = b.inertia[1]
        if b.offset is not None:  # a counterweight's spread
            spread = m * (b.counterweight_reach**2 - abs(complex(e, f) - b.com_centre) ** 2)
            most = min(most, max(spread * (1 - ulps), least))
        if least > most:
            least = most
        inertia = min(max(inertia, b.inertia[0], least), most)
        if b.counter_rotor is not None:
            rotor = min(max(rotor, b.counter_rotor[0]), b.counter_rotor[1])
        return m, e, f, inertia, rotor

    @staticmethod
    def _onto_disc(centre: complex, radius: float, e: float, f: float) -> tuple[float, float]:
        """``(e, f)`` moved radially onto the disc ``|s̄ − centre| ≤ radius`` if outside it.

        Judged on the coordinates as stored: ``centre + d`` rounds to the spacing of the
        coordinates, which for a small disc far from the frame's origin (a ``com_about`` at the
        far joint) is far coarser than the radius's last digits, so the point is pulled in by
        that spacing until the stored coordinates are inside. The bound is met with 8 units in
        the last place of the radius to spare (a reader's subtraction ``e − c`` rounds relative
        to the distance, its ``hypot`` to a unit or so). A radius below the coordinates'
        spacing leaves the centre itself.
        """
        limit = radius * (1 - 8 * 2.0**-52)
        d = complex(e, f) - centre
        if abs(d) <= limit:
            return e, f
        target = limit
        for _ in range(8):  # one pull by twice the rounding suffices; more is a safeguard
            if target <= 0:
                break
            d *= target / abs(d)
            p = centre + d
            e, f = p.real, p.imag
            if abs(complex(e, f) - centre) <= limit:
                return e, f
            target -= 2 * float(np.spacing(max(abs(e), abs(f))))
        return centre.real, centre.imag

    def clamp_distance(self, x: NDArray[np.float64]) -> float:
        """How far :meth:`physical` moved ``x`` to put it in its bounds, relative.

        The largest change of an entry over its scale (:attr:`scales`).
        """
        return float(np.max(np.abs(self.vector_of(self.physical(x)) - x) / self.scales))

    def vector_of(self, physical: Mapping[str, tuple[float, float, float, float, float]]
                  ) -> NDArray[np.float64]:
        """The design vector of physical values (as from :meth:`physical`)."""
        x = np.zeros(self.size)
        for b in self.links:
            m, e, f, inertia, rotor = physical[b.name]
            x[b.entries] = inertial_parameters(m, e, f, inertia)
            if b.rotor is not None:
                x[b.rotor] = rotor
        return x

    def linkage_of(self, x: NDArray[np.float64]) -> Model:
        """The mechanism's model with design vector ``x`` (loads kept from the original links).

        Physical values from :meth:`physical`, in their bounds exactly.
        """
        links = {}
        values = self.physical(x)
        for b in self.links:
            m, e, f, inertia, rotor = values[b.name]
            links[b.name] = replace(
                b.original, mass=m, e=e, f=f, inertia=inertia, counter_rotor=rotor
            )
        return self.linkage.with_links(links)

    def violations(self, x: NDArray[np.float64], tol: float = FEASIBILITY_TOLERANCE) -> list[str]:
        """The constraints that ``x`` breaks by more than ``tol`` (relative), as text.

        Bounds are compared on the scale of the link (``m``, ``l``, ``m·l²``); force balance
        per condition against the size of its terms (:meth:`force_balance_rows`), at
        ``max(tol, FORCE_BALANCE_TOLERANCE)``. An empty list means ``x`` is a feasible design.
        """
        out = []
        own = self.own(x).tolist()  # Python floats: the same arithmetic, a scalar at a time
        for b in self.links:
            k = b.start
            m, me, mf, j = own[k : k + 4]
            whose = b.name if b.offset is None else f"{b.name}'s counterweight"
            if self.absent(b, own):
                continue  # none added: the link as it is
            if not m > 0:
                out.append(f"{whose}: mass {m:.6g} kg is not positive")
                continue
            l, mref, iref = b.length, b.mass_ref, b.inertia_ref
            if m < b.mass[0] - tol * mref or m > b.mass[1] + tol * mref:
                out.append(f"{b.bound_key('mass')}: {m:.9g} kg outside [{b.mass[0]:.9g}, "
                           f"{b.mass[1]:.9g}]")
            com = complex(me, mf) / m
            if b.on_line and abs(com.imag) > tol * l:
                out.append(f"{b.key}.com_on_line: centre of mass {com.imag:.3g} m off the line")
            if b.com_fixed is not None:
                if abs(com - b.com_fixed) > tol * l:
                    out.append(f"{b.name}: centre of mass moved by {abs(com - b.com_fixed):.3g} m")
            elif abs(com - b.com_centre) > b.radius + tol * l:
                out.append(
                    f"{b.bound_key('com_radius')}: centre of {whose} "
                    f"{abs(com - b.com_centre):.9g} m from {b.about} (at most "
                    f"{b.com_radius:.9g})"
                )
            inertia = j - (me * me + mf * mf) / m
            lo = max(b.inertia[0], m * b.gyration**2)
            if inertia < lo - tol * iref or inertia > b.inertia[1] + tol * iref:
                out.append(
                    f"{whose}: inertia {inertia:.9g} kg·m² outside [{lo:.9g}, {b.inertia[1]:.9g}]"
                )
            if b.offset is not None:  # its spread (LinkBounds.counterweight_reach)
                p = b.com_centre
                about_p = j - 2 * (p.real * me + p.imag * mf) + m * abs(p) ** 2
                if about_p > m * b.counterweight_reach**2 + tol * iref:
                    out.append(f"{whose}: second moment {about_p:.9g} kg·m² about {b.about} "
                               f"beyond m·(2R² + ρ²) = {m * b.counterweight_reach**2:.9g}")
        for b in self.rotor_links:
            value = float(x[b.rotor_entry])
            if b.counter_rotor is None:
                if abs(value) > tol * b.inertia_ref:
                    out.append(f"{b.name}: has no counter-rotor, got {value:.6g} kg·m²")
                continue
            lo, hi = b.counter_rotor
            scale = max(b.inertia_ref, hi)
            if value < lo - tol * scale or value > hi + tol * scale:
                out.append(
                    f"{b.key}.counter_rotor: {value:.9g} kg·m² outside [{lo:.9g}, {hi:.9g}]"
                )
        residual = self.force_balance_residual(x)
        if residual > max(tol, FORCE_BALANCE_TOLERANCE):
            out.append(f"force balance: residual {residual:.3g} of its terms")
        return out

    def force_balance_residual(self, x: NDArray[np.float64]) -> float:
        """Largest residual of the force-balance conditions relative to their terms' size.

        See :meth:`force_balance_rows`. 0 when force balance is not imposed.
        """
        return float(np.max(self.force_balance_rows(x), initial=0.0))

    @cached_property
    def _force_balance_sizes(self) -> tuple[NDArray[np.float64], ...]:
        """What :meth:`force_balance_rows` needs of ``(A, b)`` alone.

        ``|A|``, the indicator ``(P, links)`` of each link's entries (a link's terms are
        combined before their magnitude is taken), each row's :data:`SMALL_ROW` floor, and
        ``|b|``.
        """
        assert self.force_balance is not None, "where force balance is imposed"
        a, rhs = self.force_balance
        by_link = np.zeros((self.size, len(self.links)))
        for j, b in enumerate(self.links):
            by_link[b.entries, j] = 1.0
        return np.abs(a), by_link, SMALL_ROW * (np.abs(a) @ self.scales), np.abs(rhs)

    def force_balance_rows(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each condition's residual relative to the size of its terms.

        ``|A_i·x − b_i| / s_i``. The size ``s_i`` is the sum over links of the magnitude of
        each link's contribution (a link's terms combined first: a heavy link whose centre of
        mass sits on its pivot contributes nothing, exactly, and must not hide a light link's
        unbalance); it is at least :data:`ROUNDING_FACTOR`·ε/:data:`FORCE_BALANCE_TOLERANCE`
        times the raw terms ``Σ_j |A_ij·x_j|`` (their rounding, which no design can beat) and
        :data:`SMALL_ROW` of the row at the parameters' scales. Under a counterweight an entry
        is the sum of the kept link's and the counterweight's (:attr:`offset`), whose rounding
        is that of both: its raw term is ``|A_ij|·(|x_j − offset_j| + |offset_j|)`` (a
        counterweight that cancels the kept link's first moment, as a slider-crank's rod
        must have ``m·f = 0``, leaves a sum of rounding).
        """
        if self.force_balance is None:
            return np.zeros(0)
        a, rhs = self.force_balance
        x = np.asarray(x, dtype=float)
        abs_a, by_link, floor, abs_rhs = self._force_balance_sizes
        if self._offset_values is None:  # no counterweight: |x − 0| + |0| is |x|, exactly
            raw = abs_a @ np.abs(x) + abs_rhs
        else:
            offset = self.offset
            raw = abs_a @ (np.abs(x - offset) + np.abs(offset)) + abs_rhs
        combined = np.abs((a * x) @ by_link).sum(axis=1) + abs_rhs
        size = np.maximum(np.maximum(combined, _RAW_SHARE * raw), floor)
        residual = np.abs(a @ x - rhs)
        if floor.all():  # every row has a positive size
            return residual / size
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(size > 0, residual / size, residual)


def numeric_problem(design: Design) -> NumericProblem:
    """Build the numeric redesign problem of a design spec once.

    For the same design under other bounds, :meth:`NumericProblem.with_problem` reuses what
    does not depend on them.

    Raises
    ------
    SpecError
        If the spec has no ``[balance]`` or no ``[operation]`` section, or the problem is
        contradictory (see :func:`check_problem`).
    AssemblyError
        If the crank cannot turn a full revolution.
    """
    problem = _checked_problem(design.balance)
    if design.operation is None:
        raise SpecError(
            "missing required key: the balancing objective is evaluated at the operating speed",
            key="operation.speed",
        )
    mech = mechanism_of(design.mechanism)
    check_problem(problem, mech)
    mech.require_full_revolution("balancing")
    speed = design.operation.speed
    angles = sample_angles(design.operation.samples)
    # (At unit crank acceleration too, for the counter-rotors' settling: in the same pass;
    # its shaking moment alone is used, so its driving torque at rest is not computed.)
    reg, unit = cycle_regressors_at(mech, angles, [(speed, 0.0), (0.0, 1.0)],
                                    torque_at_rest=not abs(speed) > TURNING)
    links = tuple(resolve_link(mech, name, problem.link(name)) for name in mech.link_names)
    rows, factor, inert = _reduced(reg, problem.objective, links, mech.layout.size)
    return NumericProblem(
        problem=problem,
        mechanism=mech,
        speed=speed,
        theta1=angles,
        regressors=reg,
        links=links,
        x0=mech.parameters(),
        rows=rows,
        factor=factor,
        force_balance=_force_balance(mech) if problem.force_balance else None,
        inert=inert,
        unit_acceleration=unit,
    )


def _checked_problem(problem: object) -> BalanceProblem:
    """``problem`` if it is a redesign problem; :class:`SpecError` if there is none."""
    if problem is None:
        raise SpecError("missing required table: the redesign problem ([balance])",
                        key="balance")
    if not isinstance(problem, BalanceProblem):
        raise TypeError(f"design.balance must be a BalanceProblem, not {type(problem).__name__}")
    return problem


def _force_balance(mech: Mechanism) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(A, b)`` of shaking-force balance.

    From :func:`~balancer.force_balance.force_balance_conditions`.
    """
    conditions = force_balance_conditions(mech)
    return conditions.matrix, np.zeros(conditions.count)


def _reduced(reg: CycleRegressors, w: Objective, links: tuple[LinkBounds, ...], p: int
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[bool, ...]]:
    """The objective's rows ``K``, their triangular factor ``R`` and the inert entries.

    ``K`` stacks the weighted regressor rows divided by ``√N`` (see :class:`NumericProblem`);
    an entry is inert where its column of ``R`` vanishes (to ``1e-12`` of the largest).
    """
    n = reg.shaking_moment.shape[0]
    blocks = []
    if w.shaking_moment:
        blocks.append(math.sqrt(w.shaking_moment) * reg.shaking_moment)
    if w.driving_torque:
        blocks.append(math.sqrt(w.driving_torque) * reg.driving_torque)
    wx, wy = w.shaking_force + w.shaking_force_x, w.shaking_force + w.shaking_force_y
    if wx:
        blocks.append(math.sqrt(wx) * reg.shaking_force.real)
    if wy:
        blocks.append(math.sqrt(wy) * reg.shaking_force.imag)
    if w.rocking_couple:
        blocks += [math.sqrt(w.rocking_couple) * reg.rocking_couple.real,
                   math.sqrt(w.rocking_couple) * reg.rocking_couple.imag]
    rows = np.vstack(blocks) / math.sqrt(n) if blocks else np.zeros((0, p))
    factor = (cast("NDArray[np.float64]", np.linalg.qr(rows, mode="r"))  # R alone (as above)
              if blocks else np.zeros((0, p)))
    norms = np.linalg.norm(factor, axis=0) if blocks else np.zeros(p)
    threshold = 1e-12 * max(float(norms.max(initial=0.0)), 1e-300)
    candidates = {b.start + 3 for b in links} | {b.rotor for b in links if b.rotor is not None}
    inert = tuple(i in candidates and norms[i] <= threshold for i in range(p))
    return rows, factor, inert
