"""The convex program's variables: the design vector as an affine map of the free ones.

:class:`VariableMap` eliminates what is fixed (entries, centres of mass, inertias); the objective's
factor is compressed to its numerical rank (:class:`Compressed`) for the solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .problem import NumericProblem


@dataclass(frozen=True, eq=False)
class VariableMap:
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


def layout(data: NumericProblem) -> VariableMap:
    """The affine map from the free variables to the design vector (see :class:`VariableMap`)."""
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
        entry = b.rotor_entry
        assert b.counter_rotor is not None
        lo, hi = b.counter_rotor
        if data.inert[entry]:
            continue
        if lo < hi:
            new_variable(entry)
        else:
            c[entry] = lo
    if data.sites is not None:  # a chosen mass·radius's two entries; a kept one's values
        for i, site in enumerate(data.sites.sites):
            entries = range(size)[data.sites.entries(i)]
            if site.free:
                for entry in entries:
                    new_variable(entry)
            else:
                c[entries.start : entries.stop] = data.x0[entries.start : entries.stop]
    return VariableMap(c=c, T=rows[:, : len(primary)].copy(), primary=tuple(primary))


@dataclass(frozen=True, eq=False)
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
