"""A planned motion as the other verbs read it: its loads the planner's, proved by simulation.

The planner's loads at its mesh (the form ``A·τ̈ + B·τ̇² + C`` with the pace's rates and
accelerations) against the core along the planned motion at the pace's times; the planned
motion driven in the multibody formulation (its motors' work by quadrature, the energy balance)
against both; the written spec read back; a one-input linkage's revolution, periodic at the
same mean speed, and the analytic case of a balanced rotor (its least torque the constant
speed's, zero).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from linkage.several_inputs_specs import crank_rocker

from balancer.api import simulate_motion
from balancer.api.planning import path_of, plan, planned_design
from balancer.cycle import cycle_analysis
from balancer.linkage import trajectory
from balancer.mechanisms import mechanism_of
from balancer.model.plan import InputLimits, PlanSpec, PlanWeights
from balancer.motion_analysis import frame_reactions, motion_analysis
from balancer.planning import revolution
from balancer.planning.path_loads import load_rows
from balancer.spec import dumps_design, load_design, loads_design
from balancer.spec.reader import design_from_dict

#: A few seconds of optimisation: the full suite's, not the fast lane's.
pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def forbal():
    design = load_design(EXAMPLES / "forbal2.toml")
    return design, plan(design, settings=PlanSpec(intervals=60))


def test_the_planned_motion_s_loads_are_the_planner_s(forbal):
    design, result = forbal
    mech = mechanism_of(design.mechanism)
    problem, rate2 = result.problem, result.solution.rate2
    start, end = problem.sides(rate2)  # each interval's loads at its first and last row
    knots = np.asarray(result.planned.pace_times)
    # (an interval's end a hair before its last row: the piece of the path it runs on, whose
    # curvature at a waypoint is not the next piece's)
    before = knots[1:] - 1e-12 * (knots[-1] - knots[0])
    for mine, times in ((start, knots[:-1]), (end, before)):
        state = trajectory.input_state(mech.structure, result.planned, times)
        reactions = frame_reactions(mech, mech.motion_at(state), gravity=(0.0, 0.0))
        _, core = load_rows(mech.linkage.inputs, reactions)
        scale = np.max(np.abs(core), axis=1, keepdims=True) + 1e-300
        assert np.max(np.abs(mine - core) / scale) < 1e-9


def test_the_planned_motion_simulated_gives_the_planner_s_loads(forbal):
    design, result = forbal
    run = simulate_motion(planned_design(design, result), result.planned.name,
                          method="multibody")
    assert run.energy_error < 1e-9
    after = result.after.reactions
    for ours, theirs in ((run.reactions.shaking_moment, after.shaking_moment),
                         (run.reactions.shaking_force, after.shaking_force),
                         *zip(run.reactions.torques, after.torques, strict=True)):
        scale = np.max(np.abs(theirs))
        assert np.max(np.abs(ours - theirs)) <= 1e-9 * scale


def test_the_written_spec_reads_the_planned_motion_back(forbal):
    design, result = forbal
    text = dumps_design(planned_design(design, result))
    again = loads_design(text)
    assert again.motion(result.planned.name) == result.planned
    assert 'along = "diamond"' in text
    # written again, the plan replaces its motion rather than adding a second one
    twice = planned_design(again, result)
    assert [m.name for m in twice.motions].count(result.planned.name) == 1


def _one_input(**links) -> dict:
    spec = crank_rocker()
    spec["operation"] = {"speed": 12.0}
    for name, values in links.items():
        spec["links"][name].update(values)
    return spec


def test_a_revolution_is_planned_periodic_at_the_same_mean_speed():
    design = design_from_dict(_one_input())
    result = plan(design, settings=PlanSpec(objective=PlanWeights(torque=1.0), intervals=48))
    assert result.path.along == "revolution" and result.path.periodic
    assert result.planned.duration == pytest.approx(2 * math.pi / 12.0, rel=1e-12)
    rows = np.asarray(result.planned.pace)
    assert rows[0, 1] == pytest.approx(rows[-1, 1], rel=1e-12)
    change = np.asarray(result.after.changes[0])
    assert change[-1] - change[0] == pytest.approx(2 * math.pi, rel=1e-12)
    assert result.objective_after < result.objective_before


def test_a_balanced_rotor_s_least_torque_is_the_constant_speed_s():
    # every link's centre of mass on its pivot... a crank alone cannot carry the others; here
    # the coupler and rocker weigh nothing, the crank's centre is on its pivot: the torque is
    # J·θ̈, zero at constant speed
    spec = _one_input(crank={"com": {"e": 0.0, "f": 0.0}},
                      coupler={"mass": 1e-12, "inertia": 1e-14},
                      rocker={"mass": 1e-12, "inertia": 1e-14})
    design = design_from_dict(spec)
    result = plan(design, settings=PlanSpec(objective=PlanWeights(torque=1.0), intervals=32))
    rate = np.asarray(result.planned.pace)[:, 1]
    assert np.max(np.abs(rate - 1.0)) < 1e-6
    assert path_of(design, None).name == "revolution"


def test_a_revolution_at_its_constant_pace_is_the_cycle_analysis():
    # the paper's four-bar (its closed-form type): its revolution as a motion at the constant
    # pace against the cycle analysis at the same crank angles (the seed's own route)
    design = load_design(EXAMPLES / "meijaard2020.toml")
    mech = mechanism_of(design.mechanism)
    speed = design.operation.speed
    along = motion_analysis(mech, revolution(speed, samples=361),
                            gravity=design.operation.gravity)
    cycle = cycle_analysis(design.mechanism, speed, 360, gravity=design.operation.gravity)
    assert mech.structure.input_references == (0.0,)
    np.testing.assert_allclose(np.asarray(along.state.positions[0])[:-1], cycle.theta1,
                               rtol=0, atol=1e-13)
    for ours, theirs in ((along.reactions.shaking_moment, cycle.reactions.shaking_moment),
                         (along.reactions.shaking_force, cycle.reactions.shaking_force),
                         (along.reactions.torques[0], cycle.reactions.driving_torque)):
        scale = np.max(np.abs(theirs))
        assert np.max(np.abs(np.asarray(ours)[:-1] - theirs)) <= 1e-10 * scale


def test_the_paper_s_four_bar_planned_and_proved_by_simulation(tmp_path):
    design = load_design(EXAMPLES / "meijaard2020.toml")
    settings = PlanSpec(objective=PlanWeights(shaking_moment=1.0, torque=0.1), intervals=80,
                        max_speed=InputLimits(every=15.0))
    result = plan(design, settings=settings)
    assert result.certified and result.objective_after < result.objective_before
    written = loads_design(dumps_design(planned_design(design, result)))
    run = simulate_motion(written, result.planned.name, method="multibody")
    assert run.energy_error < 1e-9
    scale = np.max(np.abs(result.after.reactions.shaking_moment))
    assert np.max(np.abs(run.reactions.shaking_moment
                         - result.after.reactions.shaking_moment)) <= 1e-9 * scale
    assert np.max(np.abs(run.state.rates[0])) <= 15.0 * (1 + 1e-6)
