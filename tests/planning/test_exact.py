"""The planner against the closed forms of a mass moved from rest to rest (issue 43).

A carriage of mass ``M`` moved ``D`` in ``T`` from rest to rest shakes its frame with ``M·a``.
The least RMS of ``a`` is the cubic's ``√12·D/T²``; the least peak the bang-bang's ``4·D/T²``.
The planner's optimum must reach each to its transcription's error, and that error must fall at
the scheme's order as the mesh is refined: second for a mean square (the trapezoid rule on a
smooth optimum), first for a peak (the bang-bang optimum is discontinuous in the acceleration,
which the pace holds constant between rows and the loads see from either side). The path is
the spec's Hermite cubic through two waypoints (not straight in its argument): what the planner
recovers is the motion, whatever the path's parametrisation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from planning.specs import DURATION, MASS, STROKE, carriage

from balancer.errors import SpecError
from balancer.mechanisms import mechanism_of
from balancer.model.plan import PlanSpec, PlanWeights
from balancer.planning import plan_motion
from balancer.planning.transcription import solve
from balancer.spec.reader import design_from_dict

RMS = math.sqrt(12.0) * MASS * STROKE / DURATION**2
PEAK = 4.0 * MASS * STROKE / DURATION**2
MESHES = (16, 32, 64, 128)


def _plans(measure: str, law: str = "cubic"):
    design = design_from_dict(carriage(law))
    mech = mechanism_of(design.mechanism)
    return [plan_motion(mech, design.motions[0],
                        PlanSpec(objective=PlanWeights(shaking_force=1.0), measure=measure,
                                 intervals=n)) for n in MESHES]


def _orders(errors: list[float]) -> np.ndarray:
    e = np.asarray(errors)
    return np.log2(e[:-1] / e[1:])


def test_the_least_rms_shaking_force_is_the_cubics_at_second_order():
    plans = _plans("rms")
    errors = [abs(math.sqrt(p.solution.objective) / RMS - 1.0) for p in plans]
    orders = _orders(errors)
    assert np.all(np.abs(orders - 2.0) < 0.25), orders
    assert errors[-1] < 1e-4
    for p in plans:  # the closed form is the plan's bound, and no motion beats it
        assert math.sqrt(p.bound) == pytest.approx(RMS, rel=1e-13)
        assert p.objective_after >= p.bound * (1 - 1e-12)
        assert p.certified


def test_the_least_peak_shaking_force_is_the_bang_bangs_at_first_order():
    plans = _plans("peak")
    errors = [abs(math.sqrt(p.solution.objective) / PEAK - 1.0) for p in plans]
    orders = _orders(errors)
    assert np.all(np.abs(orders - 1.0) < 0.2), orders
    for p in plans:
        assert math.sqrt(p.bound) == pytest.approx(PEAK, rel=1e-13)
        # the planned motion's own peak (the core along it) is the transcription's to O(h²)
        assert math.sqrt(p.objective_after) >= PEAK * (1 - 1e-12)


@pytest.mark.parametrize("law", ["cubic", "trapezoid"])
def test_the_optimum_does_not_depend_on_the_spec_s_own_law(law):
    # the law is the start, the path the same: one convex problem, one optimum
    spec = carriage(law)
    if law == "trapezoid":
        spec["motion"][0]["acc_time"] = 0.3
    design = design_from_dict(spec)
    p = plan_motion(mechanism_of(design.mechanism), design.motions[0],
                    PlanSpec(objective=PlanWeights(shaking_force=1.0), intervals=32))
    reference = _plans("rms")[1]
    assert p.solution.objective == pytest.approx(reference.solution.objective, rel=1e-8)
    steady = np.full(p.problem.loads.tau.size, (p.problem.span / p.problem.duration) ** 2)
    assert solve(p.problem, steady).objective == pytest.approx(p.solution.objective, rel=1e-8)


def test_a_path_of_many_waypoints_gets_an_interval_each_unless_asked():
    # a recorded motion (a table of 301 rows): its waypoints are the mesh's rows, so the
    # transcription's default intervals grow to its 300 segments; asked for fewer, it refuses
    spec = carriage("spline")
    times = np.linspace(0.0, DURATION, 301)
    spec["motion"][0].update(times=list(times),
                             path=[[STROKE * (3 * u**2 - 2 * u**3), 0.0] for u in times])
    design = design_from_dict(spec)
    mech = mechanism_of(design.mechanism)
    result = plan_motion(mech, design.motions[0],
                         PlanSpec(objective=PlanWeights(shaking_force=1.0)))
    assert result.problem.loads.tau.size == 301
    assert math.sqrt(result.solution.objective) == pytest.approx(RMS, rel=1e-3)
    with pytest.raises(SpecError, match="at least the path's segments"):
        plan_motion(mech, design.motions[0], PlanSpec(intervals=100))
