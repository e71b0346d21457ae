"""The objective's terms: its least-squares rows, their triangular factor, its value.

``J(x) = ‖K·x‖² + w_m·(Σm − Σm_original) + w_L·L(x)²``: :func:`objective_rows` stacks the
weighted regressor rows of each mean-square term of ``[balance.objective]`` (shaking moment,
driving torque, shaking force, rocking couple, main-bearing load; an engine's unbalance,
``w_U·Σ (|x_i|·ω²)²`` over its chosen mass·radius sites) into ``K`` and factors it;
``L(x) = max_r |S_r·x|`` is the largest main-bearing load over the bearings and samples (the
rows ``S`` of :attr:`~.regressors.CycleRegressors.supports`; the min–max term, which the convex
program carries in epigraph form, :mod:`.convex`). :class:`ObjectiveTerms` evaluates ``J`` from
the full regressors (:meth:`ObjectiveTerms.objective`) or through the factor
(:meth:`ObjectiveTerms.reduced_objective`).
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..model.balance import Objective
from ..quantities import squared_parts
from .bounds import LinkBounds
from .problem_data import ProblemData
from .regressors import CycleRegressors
from .sites import Sites


def objective_rows(reg: CycleRegressors, w: Objective, links: tuple[LinkBounds, ...], p: int,
                   sites: Sites | None = None
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[bool, ...]]:
    """The objective's rows ``K``, their triangular factor ``R`` and the inert entries.

    ``K`` stacks the weighted regressor rows, each block divided by the square root of its
    number of rows (``√N``: a mean square; see :class:`ProblemData`), and the unbalance's
    ``√w_U·ω²`` on each chosen site's entries (a sum of squares); an entry is inert where
    its column of ``R`` vanishes (to ``1e-12`` of the largest).
    """
    blocks = [math.sqrt(term.weight) * part / math.sqrt(part.shape[0]) for term in w.terms
              for part in squared_parts(term.name, lambda key: getattr(reg, key))]
    if w.unbalance and sites is not None:
        chosen = np.flatnonzero(sites.chosen_entries(p))
        block = np.zeros((chosen.size, p))
        block[np.arange(chosen.size), chosen] = math.sqrt(w.unbalance) * sites.speed**2
        blocks.append(block)
    rows = np.vstack(blocks) if blocks else np.zeros((0, p))
    factor = (cast("NDArray[np.float64]", np.linalg.qr(rows, mode="r"))  # R alone (as above)
              if blocks else np.zeros((0, p)))
    norms = np.linalg.norm(factor, axis=0) if blocks else np.zeros(p)
    threshold = 1e-12 * max(float(norms.max(initial=0.0)), 1e-300)
    candidates = {b.start + 3 for b in links} | {b.rotor for b in links if b.rotor is not None}
    inert = tuple(i in candidates and norms[i] <= threshold for i in range(p))
    return rows, factor, inert


class ObjectiveTerms(ProblemData):
    """The objective of a :class:`~.problem.NumericProblem`: its value at a design vector."""

    def quadratic(self, x: NDArray[np.float64]) -> float:
        """``‖K·x‖²``: the weighted mean squares, (N·m)²."""
        r = self.rows @ x
        return float(r @ r)

    def objective(self, x: NDArray[np.float64]) -> float:
        """``J(x)`` from the full regressor matrices, (N·m)² (see the module docstring)."""
        w = self.weights
        reg = self.regressors
        total = 0.0
        loads: dict[str, NDArray[np.number]] = {}

        def at_x(key: str) -> NDArray[np.number]:  # each load at x once (its parts share it)
            if key not in loads:
                loads[key] = getattr(reg, key) @ x
            return loads[key]

        for term in w.terms:
            for part in squared_parts(term.name, at_x):
                total += term.weight * float(np.mean(part**2))
        if w.added_mass:
            total += w.added_mass * (self.total_mass(x) - self.original_mass)
        if w.unbalance and self.sites is not None:
            total += w.unbalance * self.sites.unbalance(x) ** 2
        if w.largest_bearing_load:
            total += w.largest_bearing_load * self.largest_support_load(x) ** 2
        return total

    def largest_support_load(self, x: NDArray[np.float64]) -> float:
        """``L(x)``: the largest support load (an engine's main bearing's) at ``x``, N.

        Over every support and sample (the rows of the regressors' ``supports``); 0 where the
        problem has none.
        """
        rows = self.regressors.supports
        return 0.0 if rows is None else float(np.max(np.abs(rows @ x), initial=0.0))

    def reduced_objective(self, x: NDArray[np.float64]) -> float:
        """``J(x)`` through the factor: ``‖R·x‖² + w_m·(Σm − Σm_original)``, (N·m)².

        Equal to :meth:`objective` up to rounding, at a cost independent of the number of
        sampled angles (but for the largest-load term's ``w_L·L(x)²``, which needs every
        sample): what the solvers' inner loops compare.
        """
        r = self.factor @ x
        total = float(r @ r)
        w = self.weights
        if w.added_mass:
            total += w.added_mass * (self.total_mass(x) - self.original_mass)
        if w.largest_bearing_load:
            total += w.largest_bearing_load * self.largest_support_load(x) ** 2
        return total

    @cached_property
    def original_objective(self) -> float:
        """``J`` of the original design, (N·m)²."""
        return self.objective(self.x0)
