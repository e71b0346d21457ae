"""Bounded least squares (balancer.balance.lsq) against SciPy's lsq_linear, its oracle."""

from __future__ import annotations

import numpy as np
import pytest

from balancer.balance.lsq import bounded_lstsq


def _problems():
    """Random dense problems of the balancing's sizes: box bounds, sign bounds, free entries."""
    rng = np.random.default_rng(20260101)
    for k in range(60):
        m, n = int(rng.integers(3, 30)), int(rng.integers(1, 12))
        A = rng.standard_normal((m, n)) * np.exp(rng.uniform(-3, 3, n))
        if k % 5 == 0 and n > 2:
            A[:, -1] = A[:, 0] - A[:, 1]  # rank-deficient: the active set's lstsq still exact
        b = rng.standard_normal(m) * 10.0
        kind = k % 3
        if kind == 0:  # a box around zero, partly one-sided
            lower = -rng.uniform(0.01, 1.0, n)
            upper = rng.uniform(0.01, 1.0, n)
            upper[rng.uniform(size=n) < 0.2] = np.inf
        elif kind == 1:  # the certificate's refit: some entries ≥ 0, the rest free
            signed = int(rng.integers(0, n + 1))
            lower = np.r_[np.zeros(signed), np.full(n - signed, -np.inf)]
            upper = np.full(n, np.inf)
        else:  # the settling's: a box away from zero
            lower = rng.uniform(-2.0, 1.0, n)
            upper = lower + rng.uniform(0.1, 2.0, n)
        yield A, b, lower, upper


@pytest.mark.parametrize("tol", [1e-14, 1e-10])
def test_the_same_minimiser_as_scipys_bvls(tol):
    from scipy.optimize import lsq_linear

    for A, b, lower, upper in _problems():
        fit = bounded_lstsq(A, b, lower, upper, tol=tol, max_iter=500)
        ref = lsq_linear(A, b, bounds=(lower, upper), method="bvls", tol=tol, max_iter=500)
        # The same steps, so the same rounding (and a variable an ulp beyond the bound it
        # met set to it).
        assert np.array_equal(fit.x, np.clip(ref.x, lower, upper))
        assert fit.optimality == pytest.approx(ref.optimality, rel=0, abs=0)


def test_the_minimiser_meets_its_optimality_conditions():
    # Karush–Kuhn–Tucker: within the bounds; the gradient g = Aᵀ(A·x − b) zero on a free
    # entry and pointing out of the box on a bound one — to the rounding of forming g,
    # 64·ε·‖A‖·(‖A‖·‖x‖ + ‖b‖) (a few dozen ulps of the products summed). An entry that a
    # step x + α·(z − x) brought to its bound may stop an ulp or so of the iterates' size
    # short of it (4·ε·‖x‖∞; seen: 2.2e-16 above a lower bound 0, on one machine's BLAS and
    # SciPy's lsq_linear alike): it is on the bound.
    eps = np.finfo(float).eps
    for A, b, lower, upper in _problems():
        fit = bounded_lstsq(A, b, lower, upper, tol=1e-14, max_iter=500)
        x = fit.x
        assert np.all(x >= lower) and np.all(x <= upper)
        g = A.T @ (A @ x - b)
        norm = np.linalg.norm(A, 2)
        rounding = 64 * eps * norm * (norm * np.linalg.norm(x) + np.linalg.norm(b))
        near = 4 * eps * np.max(np.abs(x))
        at_lower, at_upper = x - lower <= near, upper - x <= near
        free = ~(at_lower | at_upper)
        assert np.all(np.abs(g[free]) <= rounding)
        assert np.all(g[at_lower] >= -rounding) and np.all(g[at_upper] <= rounding)
        assert fit.status in ("unconstrained", "optimal", "stalled")


def test_inside_the_bounds_it_is_the_least_squares_solution():
    A = np.array([[1.0, 0.0], [0.0, 2.0], [1.0, 1.0]])
    b = np.array([1.0, 2.0, 2.0])
    fit = bounded_lstsq(A, b, -10.0, 10.0)
    assert fit.status == "unconstrained"
    assert np.array_equal(fit.x, np.linalg.lstsq(A, b, rcond=-1)[0])
    with pytest.raises(ValueError, match="below its upper"):
        bounded_lstsq(A, b, [0.0, 1.0], [1.0, 1.0])
