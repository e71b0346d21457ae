"""The objective's scale: what a gap in ``J`` is measured against, and its rounding.

A solver's objective, its optimality gap and the rounding that blurs it are judged against the
problem's own scale of ``√J`` (:attr:`ObjectiveScale.objective_scale`: the original design's
RMS weighted shaking, or a share of what its inertias can produce where it is balanced already).
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from .objective_terms import ObjectiveTerms

#: Rounding of the objective relative to the rounding of one sum (:meth:`ObjectiveScale.rounding`).
ROUNDING_FACTOR = 64.0


#: A design whose shaking is below this share of what its inertias can produce
#: (:attr:`ObjectiveScale.inertial_scale`) is balanced already; the problem's scale is then
#: that share of the inertial scale, not the (vanishing) original figures.
BALANCED_SHARE = 1e-3


class ObjectiveScale(ObjectiveTerms):
    """The scale of a :class:`~.problem.NumericProblem`'s objective, and gaps measured by it."""

    def squares(self, x: NDArray[np.float64]) -> float:
        """``‖K·x‖² + w_L·L(x)²``: the objective's squares (all but the mass term), (N·m)²."""
        w = self.weights.largest_bearing_load
        return self.quadratic(x) + (w * self.largest_support_load(x) ** 2 if w else 0.0)

    @cached_property
    def objective_reference(self) -> float:
        """A positive scale of ``J``: ``‖K·x0‖² + w_L·L(x0)² + w_m·Σm_original``, (N·m)²."""
        value = self.squares(self.x0) + self.weights.added_mass * self.original_mass
        return value if value > 0 else 1.0

    @cached_property
    def inertial_scale(self) -> float:
        """The largest RMS a change of the parameters by their own scale makes, N·m.

        ``σ_max(R·diag(scales))`` (:attr:`scales`): what the links' inertias can produce, which
        does not vanish when the original design happens to be balanced; with the largest-load
        term, also ``√w_L`` times the largest row norm of the supports' rows so scaled (what a
        change by those scales makes of one support's load at one sample).
        """
        value = (float(np.linalg.norm(self.factor * self.scales, 2)) if self.factor.shape[0]
                 else 0.0)
        w, rows = self.weights.largest_bearing_load, self.regressors.supports
        if w and rows is not None:
            largest = float(np.max(np.linalg.norm(rows * self.scales, axis=1), initial=0.0))
            value = math.hypot(value, math.sqrt(w) * largest)
        return value

    @cached_property
    def objective_scale(self) -> float:
        """The problem's own scale of ``√J``, N·m: the original design's ``√(‖K·x0‖² + w_L·L²)``.

        It is the RMS of the original's weighted shaking (its RMS shaking moment for the
        default objective); for a design that is balanced already (below
        :data:`BALANCED_SHARE` of :attr:`inertial_scale`) that share of the inertial scale.
        Solvers scale their objective by it; optimality is judged against it.
        """
        value = max(math.sqrt(self.squares(self.x0)), BALANCED_SHARE * self.inertial_scale)
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
        eps = float(np.finfo(float).eps)
        blur = ROUNDING_FACTOR * eps * float(np.linalg.norm(np.abs(self.rows) @ np.abs(x)))
        w, rows = self.weights.largest_bearing_load, self.regressors.supports
        if w and rows is not None:  # (the largest load: a sum of terms as large as |S_r|·|x|)
            largest = float(np.max(np.abs(rows) @ np.abs(x), initial=0.0))
            blur = math.hypot(blur, ROUNDING_FACTOR * eps * math.sqrt(w) * largest)
        s = self.objective_scale
        if self.rms_form:
            return blur / s
        root = math.sqrt(max(self.squares(x), 0.0))
        mass = self.weights.added_mass * ROUNDING_FACTOR * eps * self.original_mass
        return (2 * root * blur + blur * blur + mass) / (s * s)

    def within(self, a: float, b: float, rel: float) -> bool:
        """Whether objective ``a`` exceeds ``b`` by at most ``rel`` of the problem's scale.

        In the sense of :meth:`gap`.
        """
        return self.gap(a, b) <= rel
