"""The largest support load as an objective term, in epigraph form for the convex programs.

``[balance.objective] largest_bearing_load = w_L`` adds ``w_L·L(x)²`` to ``J``, with
``L(x) = max_r |S_r·x|`` the largest main-bearing load over the bearings and samples (the rows
``S`` of :attr:`~.regressors.CycleRegressors.supports`, complex: a load's x and y parts). The
convex program carries it as one more variable ``τ`` (scaled: ``τ = √w_L·L/s`` in units of the
problem's scale ``s``) with a second-order cone per row,

    ‖(Re, Im)(a_r·u + a0_r)‖ ≤ τ,   a = √w_L·S·T/s,  a0 = √w_L·S·c/s,

(``x = T·u + c``, the solver's variables ``u``) and one more row ``(0, …, 0, 1)`` in the
objective's factor: ``‖P·u + q‖² + τ²``, whose least value has ``τ = L``. The term is strictly
increasing in ``τ``, so every minimiser has the same ``τ``; a tie-break among them holds
``|a_r·u + a0_r| ≤ τ̂`` (:meth:`LargestLoad.held`).

The rows are thousands (every bearing at every sample) and nearly parallel: with all of them
— this term's, or a bound's on the same loads (``max_bearing_load``) — Clarabel stops "almost
solved", its multipliers too rough for a certificate. So a first stage carries a working set
of them (:func:`initial_rows`), solved again with the rows its optimum breaks added
(:func:`broken_rows`) until it breaks none. Each program is a relaxation of the whole one
(fewer constraints): its certified bound holds for the whole.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .certificate import Constraint
from .conic import ConicSolution
from .problem import NumericProblem
from .variables import VariableMap

#: Rows a working set starts with or takes at once, at most (the largest loads first).
BATCH = 64
#: Rows within this share of the largest load start a working set.
NEAR = 0.9
#: A row is broken where its load exceeds its limit by this much of it (and 1e-12 of the
#: largest load): below the rounding a design is held to
#: (:data:`~.feasibility.ROUNDING_TOLERANCE`), so that the whole program's bounds hold.
BROKEN = 1e-12
#: Working-set rounds at most (each adds rows; all of them in the last resort).
ROUNDS = 12


@dataclass(frozen=True, eq=False)
class LargestLoad:
    """The largest-load term in a convex program's scaled variables (module docstring).

    Attributes
    ----------
    a, a0
        ``(R, n)`` and ``(R,)``, complex: ``|a_r·u + a0_r| = √w_L·|S_r·x|/s``.
    """

    a: NDArray[np.complex128]
    a0: NDArray[np.complex128]

    @classmethod
    def of(cls, data: NumericProblem, lay: VariableMap, scale: float) -> LargestLoad | None:
        """The term of ``data``'s objective in ``lay``'s variables over ``scale``, or ``None``."""
        weight, rows = data.weights.largest_bearing_load, data.regressors.supports
        if not weight or rows is None:
            return None
        k = math.sqrt(weight) / scale
        return cls(a=k * (rows @ lay.T), a0=k * (rows @ lay.c))

    def value(self, u: NDArray[np.float64]) -> float:
        """``τ`` of ``u``: ``max_r |a_r·u + a0_r|`` (``√w_L·L(x)/s``)."""
        return float(np.max(np.abs(self.a @ u + self.a0), initial=0.0))

    @property
    def count(self) -> int:
        """The number of rows (supports × samples)."""
        return int(self.a.shape[0])

    def cones(self, width: int, column: int, rows: NDArray[np.intp] | None = None
              ) -> list[Constraint]:
        """``|a_r·u + a0_r| ≤ y[column]`` for a program of ``width`` whose first ``n`` are ``u``.

        For the rows ``rows`` (all where ``None``).
        """
        n = self.a.shape[1]
        out = []
        for r in range(self.count) if rows is None else rows:
            m = np.zeros((3, width))
            m[0, column] = 1.0
            m[1, :n], m[2, :n] = self.a[r].real, self.a[r].imag
            out.append(Constraint("soc", m, np.array([0.0, self.a0[r].real, self.a0[r].imag])))
        return out

    def held(self, tau: float, rows: NDArray[np.intp] | None = None) -> list[Constraint]:
        """``|a_r·u + a0_r| ≤ tau`` in ``u`` alone (a tie-break's hold on the optimum's ``τ``).

        For the rows ``rows`` (all where ``None``).
        """
        zero = np.zeros(self.a.shape[1])
        return [Constraint("soc", np.array([zero, self.a[r].real, self.a[r].imag]),
                           np.array([tau, self.a0[r].real, self.a0[r].imag]))
                for r in (range(self.count) if rows is None else rows)]

    def bound(self, lo: NDArray[np.float64], hi: NDArray[np.float64]) -> float:
        """The largest ``τ`` of any ``u`` in the box ``[lo, hi]`` (∞ where it is unbounded).

        ``|a_r·u + a0_r| ≤ |a0_r| + Σ_j |a_rj|·max(|lo_j|, |hi_j|)``: the box's bound on the
        epigraph variable at a minimiser (where ``τ`` is the largest load), which the
        certificate needs.
        """
        reach = np.maximum(np.abs(lo), np.abs(hi))
        seen = np.abs(self.a) > 0
        if np.any(~np.isfinite(reach) & np.any(seen, axis=0)):
            return math.inf
        reach = np.where(np.isfinite(reach), reach, 0.0)
        return float(np.max(np.abs(self.a0) + np.abs(self.a) @ reach, initial=0.0))


def initial_rows(loads: NDArray[np.float64]) -> NDArray[np.intp]:
    """A working set to start from: the rows whose loads are near the largest.

    Those within :data:`NEAR` of it, the :data:`BATCH` largest at most.
    """
    near = np.flatnonzero(loads >= NEAR * float(np.max(loads, initial=0.0)))
    return np.sort(near[np.argsort(-loads[near])][:BATCH]).astype(np.intp)


def broken_rows(loads: NDArray[np.float64], limit: float, rows: NDArray[np.intp],
                last: bool = False) -> NDArray[np.intp]:
    """The working set ``rows`` with the rows whose ``loads`` break ``limit`` added.

    Broken: above ``limit`` by :data:`BROKEN` of it (and 1e-12 of the largest load). The
    :data:`BATCH` largest of them (every one where ``last``); ``rows`` as it is where none is.
    """
    top = float(np.max(loads, initial=0.0))
    broken = np.setdiff1d(np.flatnonzero(loads > limit * (1 + BROKEN) + 1e-12 * top), rows)
    if not last:
        broken = broken[np.argsort(-loads[broken])][:BATCH]
    return np.union1d(rows, broken).astype(np.intp)


def over_working_set(rows: NDArray[np.intp], solve: Callable[[NDArray[np.intp]], ConicSolution],
                     limits: Callable[[ConicSolution], tuple[NDArray[np.float64], float]]
                     ) -> tuple[ConicSolution, NDArray[np.intp]]:
    """A program solved over a working set of the supports' rows until it breaks none.

    ``solve(rows)`` solves the program with ``rows``; ``limits(solution)`` gives the loads of
    every row at its point and the limit they must keep. Each round adds the rows broken
    (:func:`broken_rows`; every one in the last of :data:`ROUNDS`). Returns the last solution
    and its rows.
    """
    solution = solve(rows)
    for round_ in range(ROUNDS):
        if solution.u is None:
            break
        loads, limit = limits(solution)
        more = broken_rows(loads, limit, rows, last=round_ == ROUNDS - 1)
        if more.size == rows.size:
            break
        rows = more
        solution = solve(rows)
    return solution, rows


def pad(constraints: list[Constraint], width: int) -> list[Constraint]:
    """Constraints in ``n`` variables as constraints of a program of ``width`` (zeros after)."""
    out = []
    for c in constraints:
        m = np.zeros((c.M.shape[0], width))
        m[:, : c.M.shape[1]] = c.M
        out.append(Constraint(c.kind, m, c.m))
    return out


__all__ = ["LargestLoad", "broken_rows", "initial_rows", "over_working_set", "pad"]
