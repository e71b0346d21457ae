"""Plane vectors as pairs of real values, and small dense linear solves over many at once.

A :class:`V` holds ``x`` and ``y`` of any type that supports arithmetic: floats, numpy arrays
(one entry per crank angle) or CasADi symbols; :class:`Ops` supplies the few functions that
differ between them. The equations of the linkage are written once against these and evaluated
with numpy (vectorised) or CasADi (compiled).

:func:`solve` solves ``A·X = B`` for many small systems at once (one per crank angle).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True, slots=True)
class V:
    """A plane vector ``(x, y)``; the components may be floats, arrays or symbols."""

    x: Any
    y: Any

    def __add__(self, other: V) -> V:
        return V(self.x + other.x, self.y + other.y)

    def __sub__(self, other: V) -> V:
        return V(self.x - other.x, self.y - other.y)

    def __neg__(self) -> V:
        return V(-self.x, -self.y)

    def __mul__(self, k: Any) -> V:
        return V(self.x * k, self.y * k)

    __rmul__ = __mul__

    def __truediv__(self, k: Any) -> V:
        return V(self.x / k, self.y / k)

    def dot(self, other: V) -> Any:
        """Scalar product."""
        return self.x * other.x + self.y * other.y

    def cross(self, other: V) -> Any:
        """Z-component of ``self × other``."""
        return self.x * other.y - self.y * other.x

    def perp(self) -> V:
        """The vector turned by +90° (``J·v``, ``i·v`` for a complex number)."""
        return V(-self.y, self.x)

    def rotated(self, c: Any, s: Any) -> V:
        """The vector turned by the angle whose cosine and sine are ``c`` and ``s``."""
        return V(c * self.x - s * self.y, s * self.x + c * self.y)

    def norm2(self) -> Any:
        """Squared length."""
        return self.x * self.x + self.y * self.y

    @staticmethod
    def of(z: complex) -> V:
        """From a complex number."""
        return V(z.real, z.imag)

    @staticmethod
    def of_array(z) -> V:
        """From a complex array (real and imaginary parts as arrays)."""
        z = np.asarray(z)
        return V(z.real.astype(float), z.imag.astype(float))

    def complex(self):
        """As a complex number (numpy: a complex array)."""
        return self.x + 1j * self.y


class Ops:
    """Elementary functions of numpy arrays (the default) or, in :class:`CasadiOps`, symbols."""

    sqrt = staticmethod(np.sqrt)
    sin = staticmethod(np.sin)
    cos = staticmethod(np.cos)
    atan2 = staticmethod(np.arctan2)

    @staticmethod
    def where(condition: Any, a: Any, b: Any) -> Any:
        """``a`` where ``condition`` holds, else ``b``."""
        return np.where(condition, a, b)

    @staticmethod
    def solve(a: list[list[Any]], b: list[list[Any]]) -> list[list[Any]]:
        """``X`` with ``A·X = B``; ``A`` is k×k, ``B`` k×m, entries arrays over the systems."""
        return solve(a, b)


NUMPY = Ops()


def _stack(rows: list[list[Any]], n: int) -> NDArray[np.float64]:
    out = np.empty((len(rows), len(rows[0]), n))
    for i, row in enumerate(rows):
        for j, value in enumerate(row):
            out[i, j] = value
    return out


def solve(a: list[list[Any]], b: list[list[Any]]) -> list[list[NDArray[np.float64]]]:
    """Solve ``A·X = B`` for many systems at once (LAPACK's LU with partial pivoting).

    Parameters
    ----------
    a
        ``k`` rows of ``k`` entries, each a float or an array of shape ``(n,)`` (one value per
        system).
    b
        ``k`` rows of ``m`` entries, likewise.

    Returns
    -------
    list of list of numpy.ndarray
        ``X`` as ``k`` rows of ``m`` arrays of shape ``(n,)``; a singular system gives NaN
        (the caller tests what it needs).
    """
    n = 1
    for row in (*a, *b):
        for value in row:
            n = max(n, np.size(value))
    k, m = len(a), len(b[0])
    am = _stack(a, n).transpose(2, 0, 1)
    bm = _stack(b, n).transpose(2, 0, 1)
    try:
        x = np.linalg.solve(am, bm)
    except np.linalg.LinAlgError:  # some system singular: solve the others, NaN for those
        x = np.full((n, k, m), np.nan)
        ok = np.abs(np.linalg.det(am)) > 0
        if ok.any():
            x[ok] = np.linalg.solve(am[ok], bm[ok])
    return [[x[:, i, c] for c in range(m)] for i in range(k)]
