"""Numerical helpers for tests: finite differences accurate enough to test to ~1e-10."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

_D1 = np.array([-1, 9, -45, 0, 45, -9, 1]) / 60.0
_D2 = np.array([2, -27, 270, -490, 270, -27, 2]) / 180.0


def derivative(
    f: Callable[[float], np.ndarray], t: float = 0.0, h: float = 3e-4, order: int = 1
) -> np.ndarray:
    """Seven-point central difference of ``f`` at ``t`` (first or second derivative).

    Truncation error is O(h⁶): ``h⁶·f⁽⁷⁾/140`` for the first derivative, ``h⁶·f⁽⁸⁾/560`` for the
    second. With ``h = 3e-4`` and smooth functions of unit scale that is ~1e-27·f⁽⁷⁾, so that
    even near a dead point (large high derivatives) it stays small; rounding contributes
    ~1e-12·|f| to a first derivative.
    """
    weights = _D1 if order == 1 else _D2
    values = [f(t + k * h) for k in range(-3, 4)]
    total = sum(w * v for w, v in zip(weights, values, strict=True) if w != 0)
    return total / (h**order)


def rel_err(a, b, scale=None) -> float:
    """Largest absolute difference relative to the largest magnitude (or ``scale``)."""
    a = np.asarray(a)
    b = np.asarray(b)
    s = scale if scale is not None else max(np.max(np.abs(a)), np.max(np.abs(b)), 1e-300)
    return float(np.max(np.abs(a - b)) / s)


def integration_bound(*trajectories) -> float:
    """A bound on the relative global error of simulated trajectories, from their tolerances.

    DOP853 keeps each step's local error within ``rtol`` relative to the state (``atol`` is
    chosen far below ``rtol`` times the states' scale in these tests). Without damping the local
    errors add up over the steps, so after ``n`` steps a relative global error of ``n·rtol``;
    two independent trajectories differ by at most the sum of their bounds. Quantities quadratic
    in the rates (kinetic energy) take twice it: a relative error ε in a rate changes them by 2ε.
    """
    return float(sum(tr.steps * tr.rtol for tr in trajectories))
