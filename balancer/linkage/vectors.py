"""Plane vectors as pairs of real values, and small dense linear solves over many at once.

A :class:`V` holds ``x`` and ``y`` of any type that supports arithmetic: floats, numpy arrays
(one entry per crank angle) or CasADi symbols; :class:`Ops` supplies the few functions that
differ between them. The equations of the linkage are written once against these and evaluated
with numpy (vectorised) or CasADi (compiled).

:class:`Factor` solves ``A·X = B`` for many small systems at once (one per crank angle),
exploiting their structure.

The seeds' closed forms write plane vectors as complex numbers ``x + i·y``: their scalar and
cross products are :func:`inner` and :func:`cross` (:func:`cross_scalar` for single numbers).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: A value of the linkage's equations: a float, a numpy array (one entry per crank angle, or
#: ``(N, C)``) or a CasADi symbol — whatever arithmetic and :class:`Ops` accept. The equations
#: are written once against all three, so their values are typed no closer than this.
Num: TypeAlias = Any
#: A dense solve of symbols ``dense(block, columns)``: ``X`` with ``A·X = B``, ``A`` ``k×k`` and
#: ``B`` ``k×m`` as lists of rows (:meth:`balancer.linkage.symbols.CasadiOps.factor`).
DenseSolve: TypeAlias = Callable[[list[list[Num]], list[list[Num]]], list[list[Num]]]


@dataclass(frozen=True, slots=True)
class V:
    """A plane vector ``(x, y)``; the components may be floats, arrays or symbols."""

    x: Num
    y: Num

    def __add__(self, other: V) -> V:
        return V(self.x + other.x, self.y + other.y)

    def __sub__(self, other: V) -> V:
        return V(self.x - other.x, self.y - other.y)

    def __neg__(self) -> V:
        return V(-self.x, -self.y)

    def __mul__(self, k: Num) -> V:
        return V(self.x * k, self.y * k)

    __rmul__ = __mul__

    def __truediv__(self, k: Num) -> V:
        return V(self.x / k, self.y / k)

    def dot(self, other: V) -> Num:
        """Scalar product."""
        return self.x * other.x + self.y * other.y

    def cross(self, other: V) -> Num:
        """Z-component of ``self × other``."""
        return self.x * other.y - self.y * other.x

    def perp(self) -> V:
        """The vector turned by +90° (``J·v``, ``i·v`` for a complex number)."""
        return V(-self.y, self.x)

    def rotated(self, c: Num, s: Num) -> V:
        """The vector turned by the angle whose cosine and sine are ``c`` and ``s``.

        A component that is the float 0.0 (a point on a link's axis) costs nothing.
        """
        x, y = self.x, self.y
        if isinstance(y, float) and y == 0.0:
            return V(c * x, s * x)
        if isinstance(x, float) and x == 0.0:
            return V(-(s * y), c * y)
        return V(c * x - s * y, s * x + c * y)

    def norm2(self) -> Num:
        """Squared length."""
        return self.x * self.x + self.y * self.y

    @staticmethod
    def of(z: complex) -> V:
        """From a complex number."""
        return V(z.real, z.imag)

    @staticmethod
    def of_array(z: ArrayLike) -> V:
        """From a complex array (real and imaginary parts as arrays)."""
        a = np.asarray(z)
        return V(a.real.astype(float), a.imag.astype(float))

    def complex(self) -> Num:
        """As a complex number (numpy: a complex array)."""
        return self.x + 1j * self.y


class Ops:
    """Elementary functions of numpy arrays (the default) or, in :class:`CasadiOps`, symbols."""

    @staticmethod
    def sqrt(x: Num) -> Num:
        """Square root."""
        return np.sqrt(x)

    @staticmethod
    def sin(x: Num) -> Num:
        """Sine."""
        return np.sin(x)

    @staticmethod
    def cos(x: Num) -> Num:
        """Cosine."""
        return np.cos(x)

    @staticmethod
    def atan2(y: Num, x: Num) -> Num:
        """The angle of ``(x, y)``, rad."""
        return np.arctan2(y, x)

    @staticmethod
    def where(condition: Num, a: Num, b: Num) -> Num:
        """``a`` where ``condition`` holds, else ``b``."""
        return np.where(condition, a, b)

    @staticmethod
    def factor(a: list[list[Num]]) -> Factor:
        """``A`` (k×k, entries floats or arrays over the systems) factored for its solves."""
        return Factor(a)


NUMPY = Ops()
#: Where the equations take their elementary functions: an :class:`Ops` (:data:`NUMPY`, or a
#: program's own) or an :class:`Ops` class itself (:class:`~.symbols.CasadiOps`, whose
#: functions are static).
OpsLike: TypeAlias = Ops | type[Ops]


def _is_zero(v: Num) -> bool:
    return isinstance(v, float) and v == 0.0


def _times(m: Num, x: Num) -> Num:
    """``m·x``, structural zeros kept as the float 0.0 (an ``(N,)`` ``m`` spans ``(N, C)``)."""
    if _is_zero(m) or _is_zero(x):
        return 0.0
    if isinstance(m, np.ndarray) and isinstance(x, np.ndarray) and m.ndim < x.ndim:
        m = m.reshape(m.shape + (1,) * (x.ndim - m.ndim))
    return m * x


def _plus(a: Num, b: Num) -> Num:
    """``a + b`` with structural zeros kept."""
    if _is_zero(b):
        return a
    if _is_zero(a):
        return b
    return a + b


def _minus(a: Num, b: Num) -> Num:
    """``a − b`` with structural zeros kept."""
    if _is_zero(b):
        return a
    if _is_zero(a):
        return -b
    return a - b


def _reciprocal(v: Num) -> Num:
    """``1/v``: NaN where a float or an array is zero; a symbol's as it is."""
    if isinstance(v, float | np.ndarray):
        v = np.asarray(v, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return 1.0 / np.where(v == 0, np.nan, v)
    return 1.0 / v


class _BatchLU:
    """LU with partial pivoting of many small dense systems, vectorised over the systems.

    Entries are arrays ``(N,)``; the pivot row of each column is chosen per system (the
    largest magnitude, found by pairwise exchanges), so that this is LAPACK's ``getrf`` run
    on every system at once — a few dozen vector operations instead of one call per system.
    """

    @np.errstate(divide="ignore", invalid="ignore")
    def __init__(self, block: list[list[Num]], n: int) -> None:
        k = len(block)
        a = [[np.broadcast_to(np.asarray(v, dtype=float), (n,)).copy() for v in row]
             for row in block]
        self.swaps: list[list[tuple[int, NDArray[np.bool_]]]] = []
        self.lower: list[list[tuple[int, NDArray[np.float64]]]] = []
        for p in range(k):
            swaps = []
            for i in range(p + 1, k):
                bigger = np.abs(a[i][p]) > np.abs(a[p][p])
                if bigger.any():
                    for j in range(p, k):
                        a[p][j], a[i][j] = (np.where(bigger, a[i][j], a[p][j]),
                                            np.where(bigger, a[p][j], a[i][j]))
                    swaps.append((i, bigger))
            self.swaps.append(swaps)
            pivot = np.where(a[p][p] == 0, np.nan, a[p][p])
            lower = []
            for i in range(p + 1, k):
                m = a[i][p] / pivot
                for j in range(p + 1, k):
                    a[i][j] = a[i][j] - m * a[p][j]
                lower.append((i, m))
            self.lower.append(lower)
        self.upper = a
        self.diagonal = [1.0 / a[p][p] for p in range(k)]

    @np.errstate(divide="ignore", invalid="ignore")
    def solve(self, b: list[Num]) -> list[Num]:
        """``x`` with ``A·x = b``; ``b`` a list of ``k`` entries (``(N,)`` or ``(N, C)``)."""
        k = len(b)
        y = list(b)
        for p in range(k):
            for i, bigger in self.swaps[p]:
                mask = bigger if np.ndim(y[p]) <= 1 and np.ndim(y[i]) <= 1 else bigger[:, None]
                y[p], y[i] = np.where(mask, y[i], y[p]), np.where(mask, y[p], y[i])
            for i, m in self.lower[p]:
                y[i] = _minus(y[i], _times(m, y[p]))
        x: list[Num] = [0.0] * k
        for p in reversed(range(k)):
            acc = y[p]
            for j in range(p + 1, k):
                acc = _minus(acc, _times(self.upper[p][j], x[j]))
            x[p] = _times(self.diagonal[p], acc)
        return x


class Factor:
    """``A`` of many small systems factored once, to solve ``A·X = B`` for several ``B``.

    The entries of ``A`` are floats (the same in every system) or arrays ``(N,)``. Gaussian
    elimination takes its pivots among the constant non-zero entries first — in the
    constraints' Jacobians in absolute coordinates, the ``±1`` of a pin's translations, the
    ``1`` of an angle — whose multipliers are bounded by the other entries (lengths and
    direction cosines): the ``(x, y)`` of a dyad's links drop out exactly and only a 2×2 in
    its angles is left, as in the textbook's closed forms. That dense remainder is solved by
    its explicit inverse (up to 2×2) or by LU with partial pivoting (:class:`_BatchLU`).
    Floats that are exactly zero are skipped throughout, so the work is that of the
    structure's non-zeros: a few vector operations per system instead of a LAPACK call each.
    The pivot order depends only on which entries are constant, never on the arrays' values.

    A singular system (zero determinant of the remainder) gives NaN or ±inf in its
    solution; the caller tests what it needs.
    """

    @np.errstate(divide="ignore", invalid="ignore")
    def __init__(self, a: list[list[Num]], dense: DenseSolve | None = None) -> None:
        k = len(a)
        rows = [list(row) for row in a]
        live_rows, live_cols = list(range(k)), list(range(k))
        self.steps: list[tuple[int, int, Num, list[tuple[int, Num]]]] = []
        while True:
            best, size = None, 0.0
            for i in live_rows:
                for j in live_cols:
                    v = rows[i][j]
                    if isinstance(v, float) and abs(v) > size:
                        best, size = (i, j), abs(v)
            if best is None:
                break
            i, j = best
            live_rows.remove(i)
            live_cols.remove(j)
            pivot = rows[i][j]
            updates = []
            for r in live_rows:
                f = rows[r][j]
                if _is_zero(f):
                    continue
                m = f / pivot
                for c in live_cols:
                    rows[r][c] = _minus(rows[r][c], _times(m, rows[i][c]))
                rows[r][j] = 0.0
                updates.append((r, m))
            self.steps.append((i, j, pivot, updates))
        self.rows = rows
        self.rest_rows, self.rest_cols = live_rows, live_cols
        block = [[rows[i][j] for j in live_cols] for i in live_rows]
        self.inverse: list[list[Num]] | None = None
        self.dense: _BatchLU | None = None
        self.symbolic: tuple[DenseSolve, list[list[Num]]] | None = None
        if len(block) == 1:
            (a11,), = block
            self.inverse = [[_reciprocal(a11)]]
        elif len(block) == 2:
            (a11, a12), (a21, a22) = block
            inv = _reciprocal(_minus(_times(a11, a22), _times(a12, a21)))
            self.inverse = [[_times(a22, inv), _times(a12, -inv)],
                            [_times(a21, -inv), _times(a11, inv)]]
        elif len(block) > 2:
            if not all(isinstance(v, float | np.ndarray) for row in block for v in row):
                if dense is None:
                    raise NotImplementedError("a dense remainder of symbols")
                self.symbolic = (dense, block)  # ``dense(block, columns)`` solves it
            else:
                n = max(np.size(v) for row in block for v in row)
                self.dense = _BatchLU(block, n)

    @np.errstate(divide="ignore", invalid="ignore")
    def solve(self, b: list[list[Num]]) -> list[list[Num]]:
        """``X`` with ``A·X = B``.

        ``B`` is ``k`` rows of ``m`` entries (floats, ``(N,)`` or ``(N, C)`` arrays); ``X``
        likewise.
        """
        rhs = [list(row) for row in b]
        width = len(rhs[0])
        for i, _, _, updates in self.steps:
            for r, m in updates:
                for c in range(width):
                    rhs[r][c] = _minus(rhs[r][c], _times(m, rhs[i][c]))
        x: list[list[Num]] = [[0.0] * width for _ in self.rows]
        if self.inverse is not None:
            for jj, j in enumerate(self.rest_cols):
                for c in range(width):
                    acc: Num = 0.0
                    for ii, i in enumerate(self.rest_rows):
                        acc = _plus(acc, _times(self.inverse[jj][ii], rhs[i][c]))
                    x[j][c] = acc
        elif self.symbolic is not None:
            dense, block = self.symbolic
            sol = dense(block, [[rhs[i][c] for c in range(width)] for i in self.rest_rows])
            for jj, j in enumerate(self.rest_cols):
                for c in range(width):
                    x[j][c] = sol[jj][c]
        elif self.dense is not None:
            for c in range(width):
                sol = self.dense.solve([rhs[i][c] for i in self.rest_rows])
                for jj, j in enumerate(self.rest_cols):
                    x[j][c] = sol[jj]
        for i, j, pivot, _ in reversed(self.steps):
            for c in range(width):
                acc = rhs[i][c]
                for col, v in enumerate(self.rows[i]):
                    if col != j and not _is_zero(v):
                        acc = _minus(acc, _times(v, x[col][c]))
                x[j][c] = acc / pivot if not _is_zero(acc) else 0.0
        return x


# -- plane vectors as complex numbers (the seeds' closed forms) --------------------------------


def inner(x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
    """Scalar product ``⟨x̄, ȳ⟩ = Re(x*·y)`` of plane vectors given as complex numbers."""
    x = np.asarray(x)
    y = np.asarray(y)
    return x.real * y.real + x.imag * y.imag


def cross(x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
    """Z-component of ``x × y`` for plane vectors given as complex numbers (``Im(x*·y)``)."""
    x = np.asarray(x)
    y = np.asarray(y)
    return x.real * y.imag - x.imag * y.real


def cross_scalar(x: complex, y: complex) -> float:
    """:func:`cross` of two Python complex numbers, without numpy's per-call cost.

    The formulations' right-hand sides call it thousands of times per simulation.
    """
    return x.real * y.imag - x.imag * y.real


def as_1d(x: ArrayLike) -> NDArray[np.float64]:
    """``x`` as a one-dimensional float array (a number as an array of one)."""
    a = np.asarray(x, dtype=float)
    return a.reshape(-1) if a.ndim else a.reshape(1)
