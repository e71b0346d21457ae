"""Cumulative Gauss–Kronrod quadrature (balancer.simulation.quadrature) against exact integrals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from balancer.errors import SolverError
from balancer.simulation.quadrature import GAUSS, KRONROD, NODES, cumulative, partial_weights


def test_the_rules_are_gauss_and_kronrod():
    # The Gauss part: numpy's 7-point Gauss–Legendre nodes and weights (Golub–Welsch), another
    # route to the same constants, to a few roundings.
    x, w = np.polynomial.legendre.leggauss(7)
    assert np.allclose(NODES[1::2], x, rtol=0, atol=1e-15)
    assert np.allclose(GAUSS[1::2], w, rtol=0, atol=1e-15)
    assert np.all(GAUSS[::2] == 0)
    # Exactness: Gauss integrates monomials to degree 13, Kronrod to degree 22 (3·7 + 1), each
    # to the rounding of its sum (15 terms of at most 1): 1e-14 absolute.
    for degree in range(23):
        exact = 2.0 / (degree + 1) if degree % 2 == 0 else 0.0
        assert abs(KRONROD @ NODES**degree - exact) < 1e-14, degree
        if degree <= 13:
            assert abs(GAUSS @ NODES**degree - exact) < 1e-14, degree
    # ... and not beyond: the pair measures an error that exists.
    assert abs(GAUSS @ NODES**14 - 2 / 15) > 1e-6
    assert abs(KRONROD @ NODES**24 - 2 / 25) > 1e-12


def _smooth(t):
    return np.column_stack([np.sin(3 * t) ** 2 * np.cos(t), 0.5 + np.cos(7 * t)])


def _smooth_integral(t):
    # ∫ sin²(3t)·cos t = sin t/2 − (sin 7t/7 + sin 5t/5)/4 ;  ∫ 0.5 + cos 7t = t/2 + sin 7t/7
    return np.column_stack([np.sin(t) / 2 - (np.sin(7 * t) / 7 + np.sin(5 * t) / 5) / 4,
                            t / 2 + np.sin(7 * t) / 7])


@pytest.mark.parametrize("outputs", [2, 3, 50, 501])
@pytest.mark.parametrize("rtol", [1e-6, 1e-10])
def test_cumulative_integrals_at_every_time(outputs, rtol):
    times = np.linspace(0.2, 9.0, outputs)
    atol = 1e-3 * rtol
    got = cumulative(_smooth, times, rtol=rtol, atol=atol, max_width=0.5)
    exact = _smooth_integral(times) - _smooth_integral(times[:1])
    # Each panel's error within atol + rtol·|W| (W ≤ 5 here): the sum over the panels bounds
    # the global error; the antiderivative's own rounding is far below it.
    bound = got.panels * (atol + rtol * np.max(np.abs(exact), axis=0))
    assert np.all(np.abs(got.values - exact) <= bound)
    assert got.values.shape == (outputs, 2) and np.all(got.values[0] == 0)
    assert got.panels >= math.ceil(8.8 / 0.5) and got.evaluations >= 15 * got.panels
    # The times fall inside the panels: asking for more of them adds no panels of their own.
    assert got.panels <= 2 * cumulative(_smooth, times[[0, -1]], rtol=rtol, atol=atol,
                                        max_width=0.5).panels


def test_the_partial_weights_integrate_the_interpolant():
    # ∫₋₁ᵘ of the degree-14 interpolant through the 15 nodes is exact for monomials up to
    # degree 14 (the integral (u^(d+1) − (−1)^(d+1))/(d + 1), another route), to the rounding
    # of sums of 15 weights below 2 in size; at u = 1 it is the Kronrod rule. Its tail (the
    # Legendre terms of degree 13 and 14) is nothing for a polynomial of degree 12, the
    # integral of P13 or P14 itself for those, (P_n+1 − P_n−1)/(2n + 1), and zero at u = ±1.
    legendre = np.polynomial.legendre
    u = np.linspace(-1.0, 1.0, 41)
    w_k, w_tail = partial_weights(u)
    for degree in range(15):
        exact = (u ** (degree + 1) - (-1.0) ** (degree + 1)) / (degree + 1)
        assert np.max(np.abs(w_k @ NODES**degree - exact)) < 1e-14, degree
        if degree <= 12:
            assert np.max(np.abs(w_tail @ NODES**degree)) < 1e-13, degree
    for n in (13, 14):
        p_n = legendre.legval(NODES, np.eye(15)[n])
        exact = (legendre.legval(u, np.eye(16)[n + 1]) - legendre.legval(u, np.eye(16)[n - 1]))
        assert np.max(np.abs(w_tail @ p_n - exact / (2 * n + 1))) < 1e-13, n
    assert np.max(np.abs(w_k[-1] - KRONROD)) < 1e-15
    assert np.max(np.abs(w_tail[[0, -1]])) < 1e-13 and np.max(np.abs(w_k[0])) < 1e-15


def test_a_narrow_peak_is_found_by_halving():
    # A Lorentzian 1e-3 wide in a first panel 100 times as wide: the rules miss it at first;
    # halving where they disagree finds it, and nowhere else.
    def peak(t):
        return (1.0 / (1.0 + ((t - 0.3137) / 1e-3) ** 2))[:, None]

    times = np.array([0.0, 0.05, 0.1, 1.0])
    got = cumulative(peak, times, rtol=1e-11, atol=1e-15)
    exact = 1e-3 * (np.arctan((times - 0.3137) / 1e-3) - math.atan(-0.3137 / 1e-3))
    assert np.all(np.abs(got.values[:, 0] - exact) <= got.panels * (1e-15 + 1e-11 * exact[-1]))
    assert got.panels > 10  # refined around the peak ...
    assert got.evaluations < 15 * 400  # ... only there


def test_an_integrand_that_is_not_finite_is_an_error():
    def bad(t):
        return np.where(t > 0.5, np.nan, 1.0)[:, None]

    # Named where it first is not finite: the first node beyond 0.5 of the one panel [0, 1].
    with pytest.raises(SolverError, match=r"power is not finite at t = 0\.60389"):
        cumulative(bad, np.linspace(0, 1, 5), rtol=1e-9, atol=1e-12)


def test_one_time_integrates_nothing():
    got = cumulative(_smooth, np.array([3.0]), rtol=1e-9, atol=1e-12)
    assert got.values.shape == (1, 2) and np.all(got.values == 0) and got.panels == 0


def test_an_integrand_that_halving_does_not_resolve_stops_within_a_budget():
    # Linkage fuzz campaign, seed 4444, case 141: a driven motion starting at a dead point
    # (the torque singular there) doubled its failing panels each round, a minute and more of
    # a simulate that looked hung. An integrand whose estimates do not fall with halving
    # (here an oscillation far finer than any panel reached) is an error after
    # MAX_REFINED panels per first panel (and EXTRA_REFINED more) have been made.
    from balancer.simulation.quadrature import EXTRA_REFINED, MAX_REFINED

    calls = []

    def rough(t):
        calls.append(t.size)
        return np.sin(1e12 * t)[:, None]

    with pytest.raises(SolverError, match="did not converge"):
        cumulative(rough, np.linspace(0.0, 1.0, 11), rtol=1e-10, atol=1e-12, max_width=0.5)
    budget = 2 + MAX_REFINED * 2 + EXTRA_REFINED + 2 * (MAX_REFINED * 2 + EXTRA_REFINED)
    assert sum(calls) <= 15 * budget


def test_panels_end_at_the_breaks_of_a_jump():
    # A step at t = 0.3: its integral is exact from the first panels when one ends there; a
    # panel across the step is halved round after round instead.
    def step(t):
        return np.where(t < 0.3, 1.0, 3.0)[:, None]

    times = np.linspace(0.0, 1.0, 11)
    exact = np.where(times < 0.3, times, 0.3 + 3.0 * (times - 0.3))
    broken = cumulative(step, times, rtol=1e-12, atol=1e-14, breaks=[0.3])
    assert np.max(np.abs(broken.values[:, 0] - exact)) <= 1e-14
    whole = cumulative(step, times, rtol=1e-12, atol=1e-14)
    assert broken.evaluations < whole.evaluations / 3
