"""Numerical helpers for tests: finite differences and the error bounds tolerances come from.

Every tolerance in the tests is derived from what it compares, never from what one machine
printed:

- rounding: :data:`ROUNDING` (a few dozen operations, each within ε) times the magnitude of
  the terms a value is computed from, times the condition number where one enters;
- two formulations evaluated at the same state: 1e-9 relative (DESIGN.md, "How we know it is
  right"), at states filtered away from singular positions so that their condition is bounded;
- finite differences: :func:`derivative_with_error` (truncation estimated by halving the step,
  rounding bounded);
- simulations: :func:`integration_bound`, amplified along a free motion by :func:`growth`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

#: Machine epsilon of double precision.
EPS = float(np.finfo(float).eps)

#: Rounding allowance, relative to the magnitude of the terms a value is computed from: a few
#: dozen floating-point operations (elementary functions within an ulp or two), whose errors
#: add at worst linearly. Multiply by the condition number where the value comes through the
#: position analysis or a linear solve.
ROUNDING = 64 * EPS

_D1 = np.array([-1, 9, -45, 0, 45, -9, 1]) / 60.0
_D2 = np.array([2, -27, 270, -490, 270, -27, 2]) / 180.0


def _difference(f: Callable[[float], np.ndarray], t: float, h: float, order: int):
    """The difference quotient and the largest magnitude of the values it is made of."""
    weights = _D1 if order == 1 else _D2
    values = [np.asarray(f(t + k * h)) for k in range(-3, 4)]
    total = sum(w * v for w, v in zip(weights, values, strict=True) if w != 0)
    return total / (h**order), max(float(np.max(np.abs(v))) for v in values)


def derivative(
    f: Callable[[float], np.ndarray], t: float = 0.0, h: float = 3e-4, order: int = 1
) -> np.ndarray:
    """Seven-point central difference of ``f`` at ``t`` (first or second derivative).

    Truncation error is O(h⁶): ``h⁶·f⁽⁷⁾/140`` for the first derivative, ``h⁶·f⁽⁸⁾/560`` for the
    second; with ``h = 3e-4``, ``h⁶/140 ≈ 5e-24``, but ``f⁽⁷⁾`` of a linkage's motion can be
    large (a short link turning fast): :func:`derivative_with_error` estimates it. Rounding:
    each value's relative error δ gives ``Σ|wₖ|·δ·max|f|/hᵒʳᵈᵉʳ`` (``1.8·δ·|f|/h`` for the first
    derivative; ``6.0·δ·|f|/h²`` for the second, 2e-7·|f| at δ = 16ε: use it with care).
    """
    return _difference(f, t, h, order)[0]


def derivative_with_error(
    f: Callable[[float], np.ndarray],
    t: float = 0.0,
    h: float = 3e-4,
    order: int = 1,
    scale: float | None = None,
) -> tuple[np.ndarray, float]:
    """:func:`derivative` and a bound on its error (absolute, in the units of the derivative).

    Truncation: the same difference with step ``2h`` has ``2⁶ = 64`` times the leading error,
    so ``|D(2h) − D(h)|/63`` estimates ``D(h)``'s (Richardson); twice that is taken. Rounding:
    each value carries at most :data:`ROUNDING` relative to the magnitude of the terms it is
    computed from (``scale``; by default the values' own largest magnitude, which is right
    unless they come from terms that cancel), hence ``Σ|wₖ|·ROUNDING·scale/hᵒʳᵈᵉʳ``.
    """
    weights = _D1 if order == 1 else _D2
    fine, magnitude = _difference(f, t, h, order)
    coarse, _ = _difference(f, t, 2 * h, order)
    truncation = float(np.max(np.abs(coarse - fine))) / (2**6 - 1)
    terms = magnitude if scale is None else max(scale, magnitude)
    rounding = ROUNDING * float(np.sum(np.abs(weights))) * terms / h**order
    return fine, 2 * truncation + rounding


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
    That is all for a first integral (``T − T0 − W``: its error does not grow with the motion)
    and for a motion that does not amplify errors; a free motion does (an error of its energy
    shifts its phase more and more): quantities along it take :meth:`Growth.bound`.
    """
    return float(sum(tr.steps * tr.rtol for tr in trajectories))


def drift_bound(trajectory, lengths) -> tuple[float, float]:
    """Bounds on the loop-closure drift before projection: position (m), velocity (m/s).

    The state is projected after every step, so the drift is one step's local error seen
    through the loop closure: angles within ``rtol·Θ + atol`` (Θ the largest angle, at least
    1 rad: attitudes and joint coordinates are of that order), rates within ``rtol·Ω + atol``,
    and the closure ``Σ lₖ·e^{iθₖ}`` and its rate change by ``Σl`` times those (the rate also by
    ``ω·δθ``); twice it for the joint-coordinate formulation, whose residuals difference two
    joints' errors.
    """
    tr = trajectory
    total = float(sum(lengths[:3]))
    theta = max(float(np.max(np.abs(tr.theta))), 1.0)
    omega = float(np.max(np.abs(tr.omega)))
    angle = tr.rtol * theta + tr.atol
    rate = tr.rtol * omega + tr.atol
    return 2 * total * angle, 2 * total * (rate + omega * angle)


@dataclass(frozen=True)
class Growth:
    """How much a motion amplifies an error of its state (see :func:`growth`)."""

    reference: object
    perturbed: tuple
    delta: float

    def change(self, quantity: Callable) -> float:
        """Largest change of ``quantity(trajectory)`` over the run per unit relative change of
        the initial state, summed over the two directions (in the quantity's units)."""
        ref = np.asarray(quantity(self.reference))
        return sum(float(np.max(np.abs(np.asarray(quantity(p)) - ref)))
                   for p in self.perturbed) / self.delta

    def bound(self, quantity: Callable, *trajectories) -> float:
        """Bound on the difference of ``quantity`` between ``trajectories`` of this motion, in
        its units: :meth:`change` times their :func:`integration_bound`."""
        return self.change(quantity) * integration_bound(*trajectories)


def growth(simulate, linkage, settings, delta: float | None = None, reference=None,
           **kw) -> Growth:
    """The motion's amplification of errors, from two runs with a perturbed initial state.

    An error committed at one step is carried by the motion like a perturbation of the initial
    state: a free motion shears it into a phase error that grows with time. Each step's local
    error is within ``rtol`` relative to the state, of magnitudes Θ (the angles, at least
    1 rad) and Ω (the rates) over the run, so its effect on a quantity is at most ``rtol``
    times the quantity's change per unit relative perturbation of the initial crank angle (by
    ``delta·Θ``) plus that of its rate (by ``delta·Ω``) — :meth:`Growth.change`. A
    perturbation at t = 0 has the longest time to grow, so its largest change over the run
    bounds the effect of one made later.

    ``delta`` is by default 100 times the reference's own :func:`integration_bound` (at least
    1e-6): the response is then the motion's, not the runs' own errors (≤ 1 % of it), and
    still linear.

    ``simulate(linkage, settings, **kw)`` makes the runs (any formulation that can make this
    motion; the growth is the motion's, not the formulation's); ``reference``, if given, is
    the unperturbed one already made that way.
    """
    if reference is None:
        reference = simulate(linkage, settings, **kw)
    kw.setdefault("outputs", reference.t.size)  # the same output times as the reference
    if delta is None:
        delta = max(1e-6, 100 * integration_bound(reference))
    theta = max(float(np.max(np.abs(reference.theta))), 1.0)
    omega = float(np.max(np.abs(reference.omega)))
    perturbed = (
        simulate(linkage, replace(settings, theta1=settings.theta1 + delta * theta), **kw),
        simulate(linkage, replace(settings, omega1=settings.omega1 + delta * omega), **kw),
    )
    return Growth(reference=reference, perturbed=perturbed, delta=delta)


def rank_rows(rows: np.ndarray) -> np.ndarray:
    """Rows with the same ``‖rows·x‖`` for every x, only as many as their rank.

    (N samples of a few harmonics have rank ~6; rows of rounding inside a cone stall Clarabel
    "almost solved".) The singular values dropped are 1e-12 of the largest: a change of
    1e-24 relative in the squared norm.
    """
    _, sv, vt = np.linalg.svd(rows, full_matrices=False)
    keep = sv > 1e-12 * sv[0]
    return sv[keep, None] * vt[keep]


def least_rms_moment_by_cvxpy(design, extra=None, rows=None) -> float:
    """The least RMS shaking moment of a redesign problem, formulated apart from the optimiser.

    A CVXPY program written from the spec's bounds in the links' inertial parameters (scaled
    per entry): each listed link's mass range, its centre of mass in its disc
    (``‖S − m·c‖ ≤ R·m``), its inertia about the centre of mass at least ``m·ρ²``
    (``‖S‖²/m ≤ J − ρ²·m``), unlisted links fixed, counter-rotor ranges, force balance
    ``A·x = b``; ``extra(x, data)`` adds constraints; ``rows(data)`` gives the rows whose mean
    square is minimised instead of the shaking moment's. The product instead assembles
    Clarabel's standard form in its own scaled variables from its own constraint builder.
    """
    import math

    import cvxpy as cp

    from balancer.balance.problem import numeric_problem

    data = numeric_problem(design)
    y = cp.Variable(data.size)  # x scaled per entry (kg, kg·m, kg·m²), for the solver
    x = cp.multiply(data.scales, y)
    cons = []
    for b in data.links:
        k = b.start
        m, s, j = x[k], x[k + 1 : k + 3], x[k + 3]
        if not b.listed:
            cons.append(x[b.entries] == data.x0[b.entries])
            continue
        c = np.array([b.com_centre.real, b.com_centre.imag])
        cons += [m >= b.mass[0], m <= b.mass[1], cp.norm(s - m * c) <= b.com_radius * m,
                 cp.quad_over_lin(s, m) <= j - b.gyration**2 * m]
    for b in data.rotor_links:
        lo, hi = b.counter_rotor
        cons += [x[b.rotor] >= lo, x[b.rotor] <= hi]
    a, rhs = data.force_balance
    cons.append(a @ x == rhs)
    if extra is not None:
        cons += extra(x, data)
    moment = rank_rows(data.regressors.shaking_moment if rows is None else rows(data))
    scale = float(np.linalg.norm(moment @ data.x0))
    problem = cp.Problem(cp.Minimize(cp.norm(moment @ x) / scale), cons)
    # Tolerances 1e-9, else 1e-8 where that stalls (as 1e-10 does): both far below the
    # comparisons' 1e-6.
    for tol in (1e-9, 1e-8):
        with warnings.catch_warnings():  # ("may be inaccurate": the status says so)
            warnings.simplefilter("ignore", UserWarning)
            problem.solve(solver=cp.CLARABEL, tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol)
        if problem.status == "optimal":
            break
    assert problem.status == "optimal"
    return float(problem.value) * scale / math.sqrt(data.samples)
