"""The plan's limits: each input's speed, acceleration and load held at the transcription's
rows, active where they bind, checked on the planned motion by the core (its states and loads
at the pace's rows, from either side), and the spec's [plan] written and read back."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.linkage import trajectory
from balancer.mechanisms import mechanism_of
from balancer.model.plan import InputLimits, PlanSpec, PlanWeights
from balancer.motion_analysis import frame_reactions
from balancer.planning import plan_motion
from balancer.planning.path_loads import load_rows
from balancer.spec import dumps_design, load_design, loads_design

#: A few seconds of optimisation: the full suite's, not the fast lane's.
pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _sides(mech, motion):
    """The inputs' states and loads at the pace's rows, from the interval after and before."""
    knots = np.asarray(motion.pace_times)
    out = []
    for t in (knots[:-1], knots[1:] - 1e-12 * (knots[-1] - knots[0])):
        state = trajectory.input_state(mech.structure, motion, t)
        reactions = frame_reactions(mech, mech.motion_at(state), gravity=(0.0, 0.0))
        _, loads = load_rows(mech.linkage.inputs, reactions)
        out.append((state, loads))
    return out


@pytest.mark.parametrize("kind", ["max_speed", "max_acceleration", "max_torque"])
def test_a_binding_limit_is_held_and_reached(kind):
    design = load_design(EXAMPLES / "forbal2.toml")
    mech = mechanism_of(design.mechanism)
    base = replace(design.plan, intervals=60)
    free = plan_motion(mech, design.motions[0], base)
    # the free plan's largest value of the kind on link21, and a limit at 80 % of it
    index = mech.linkage.inputs.index("link21")
    sides = _sides(mech, free.planned)

    def largest(sides) -> float:
        values = []
        for state, loads in sides:
            values.append({"max_speed": state.rates, "max_acceleration": state.accelerations,
                           "max_torque": loads[5:]}[kind][index])
        return float(np.max(np.abs(np.concatenate(values))))

    limit = 0.8 * largest(sides)
    limited = plan_motion(mech, design.motions[0],
                          replace(base, **{kind: InputLimits(each=(("link21", limit),))}))
    reached = largest(_sides(mech, limited.planned))
    assert reached <= limit * (1 + 1e-7)
    assert reached >= limit * (1 - 1e-6)  # it binds
    assert limited.objective_after >= free.objective_after * (1 - 1e-9)
    assert limited.certified


def test_limits_that_cannot_be_met_in_the_duration_are_refused():
    design = load_design(EXAMPLES / "forbal2.toml")
    spec = replace(design.plan, intervals=24, max_speed=InputLimits(every=0.05))
    from balancer.errors import SolverError

    with pytest.raises(SolverError, match="lengthen the duration"):
        plan_motion(mechanism_of(design.mechanism), design.motions[0], spec)


def test_the_plan_is_written_and_read_back():
    design = load_design(EXAMPLES / "forbal2.toml")
    spec = PlanSpec(motion="circle", name="circle fast", duration=6.0, measure="peak",
                    objective=PlanWeights(shaking_moment=0.0, torque=2.0, rocking_couple=1.0),
                    intervals=64, max_speed=InputLimits(every=3.0),
                    max_torque=InputLimits(each=(("link11", 0.5), ("link21", 0.7))))
    again = loads_design(dumps_design(replace(design, plan=spec)))
    assert again.plan == spec
