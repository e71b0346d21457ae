"""The transcription's optimum against CVXPY's (Clarabel), the same convex program in its form.

CVXPY's disciplined form of the problem of :mod:`balancer.planning.transcription`, written
independently from its docstring: unknowns ``bₖ`` and ``yₖ ≤ √bₖ``; each interval's weighted
sum of squares over ``yₖ + yₖ₊₁`` (``quad_over_lin``), its duration ``2·Δτ/(yₖ + yₖ₊₁)``
(``inv_pos``) summed to at most ``T``. At the optimum ``y = √b`` (both decrease in ``y``), so
its value is the transcription's optimum. An interval ending at a waypoint sees the path's
piece before it (its curvature jumps there).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balancer.mechanisms import mechanism_of
from balancer.model.plan import PlanSpec, PlanWeights
from balancer.planning import plan_motion
from balancer.spec import load_design

#: A few seconds of optimisation: the full suite's, not the fast lane's.
pytestmark = pytest.mark.slow

cp = pytest.importorskip("cvxpy")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _cvxpy_optimum(problem) -> float:
    at = problem.loads
    to = at.left if at.left is not None else at  # (an interval's end: the piece it arrives on)
    dtau = np.diff(at.tau)
    count = at.tau.size
    b = cp.Variable(count, nonneg=True)
    y = cp.Variable(count, nonneg=True)
    a = cp.multiply(b[1:] - b[:-1], 1.0 / (2.0 * dtau))
    rows = [i for i, w in enumerate(problem.weights) if w > 0]
    # (scaled to an objective of order one at a constant pace, for the conic solver)
    steady = np.full(count, (problem.span / problem.duration) ** 2)
    unit = np.sqrt(problem.objective(steady))
    terms, times = [], []
    for k in range(count - 1):
        sides = []
        for i in rows:
            root = np.sqrt(problem.weights[i]) / unit
            sides += [root * (at.inertial[i, k] * a[k] + at.centripetal[i, k] * b[k]
                              + at.static[i, k]),
                      root * (to.inertial[i, k + 1] * a[k] + to.centripetal[i, k + 1] * b[k + 1]
                              + to.static[i, k + 1])]
        # Δt/2·Σ(L²) = Δτ·Σ L²/(yₖ + yₖ₊₁)
        terms.append(dtau[k] * cp.quad_over_lin(cp.hstack(sides), y[k] + y[k + 1]))
        times.append(2.0 * dtau[k] * cp.inv_pos(y[k] + y[k + 1]))
    constraints = [y <= cp.sqrt(b), cp.sum(cp.hstack(times)) <= problem.duration]
    if problem.periodic:
        constraints.append(b[0] == b[-1])
    program = cp.Problem(cp.Minimize(cp.sum(cp.hstack(terms)) / problem.duration), constraints)
    program.solve(solver=cp.CLARABEL)
    assert program.status == cp.OPTIMAL
    return float(program.value) * unit**2


@pytest.mark.parametrize(("example", "weights"), [
    ("forbal2", PlanWeights(shaking_moment=1.0)),
    ("three_rrr", PlanWeights(shaking_force=1.0, torque=0.5)),
    ("fivebar_5r", PlanWeights(shaking_moment=1.0, shaking_force_x=0.3)),
])
def test_the_transcription_s_optimum_is_cvxpy_s(example, weights):
    design = load_design(EXAMPLES / f"{example}.toml")
    plan = plan_motion(mechanism_of(design.mechanism), design.motions[0],
                       PlanSpec(objective=weights, intervals=24))
    assert plan.certified
    oracle = _cvxpy_optimum(plan.problem)
    assert plan.solution.objective == pytest.approx(oracle, rel=1e-7)  # (Clarabel: 1e-8)


def test_where_a_faster_motion_shakes_less_the_plan_is_local_and_the_convex_one_bounds_it():
    # The 3-RRR stood up in a vertical plane, its shaking force weighed: the frame carries the
    # weights, and a motion that ends early carries them for less of the time it counts — the
    # duration held, the problem is not convex; the convex relaxation's optimum (CVXPY's) is a
    # lower bound of the plan's
    design = load_design(EXAMPLES / "three_rrr.toml")
    plan = plan_motion(mechanism_of(design.mechanism), design.motions[0],
                       PlanSpec(objective=PlanWeights(shaking_force=1.0, torque=0.5),
                                intervals=24), gravity=(0.0, -9.81))
    assert not plan.certified
    assert plan.planned.duration == pytest.approx(design.motions[0].duration, rel=1e-9)
    oracle = _cvxpy_optimum(plan.problem)
    assert oracle <= plan.solution.objective * (1 + 1e-9)


def test_the_weights_constant_part_leaves_the_least_shaking_force_s_time_law():
    # the weights add a constant to the shaking force: its mean square grows by their square
    # whatever the time law, so the optimal pace is the one without gravity (and global)
    design = load_design(EXAMPLES / "forbal2.toml")
    mech = mechanism_of(design.mechanism)
    spec = PlanSpec(objective=PlanWeights(shaking_moment=0.0, shaking_force=1.0), intervals=40)
    plain = plan_motion(mech, design.motions[0], spec)
    heavy = plan_motion(mech, design.motions[0], spec, gravity=(0.0, -9.81))
    assert heavy.certified and plain.certified
    assert heavy.planned.duration == pytest.approx(plain.planned.duration, rel=1e-12)
    rates = np.asarray(heavy.planned.pace)[:, 1], np.asarray(plain.planned.pace)[:, 1]
    # (an optimum to IPOPT's 1e-10 of its objective: its variables to about the square root)
    assert np.max(np.abs(rates[0] - rates[1])) <= 1e-4 * np.max(rates[1])
