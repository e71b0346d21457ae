"""The loads along a fixed path as ``A·τ̈ + B·τ̇² + C`` against the core at the motion's states.

The second route: the motion's own states (its time law by the chain rule, a point's path by
inverse kinematics at each time) through the one core's inverse dynamics, as ``analyze`` runs
them, against the form's three coefficients at the same arguments with the law's ``τ̇``,
``τ̈``. And a planned motion's pace against its definition (its times from its rows, its rate
the derivative of its argument).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from planning.specs import carriage

from balancer.errors import SpecError
from balancer.linkage import trajectory
from balancer.mechanisms import mechanism_of
from balancer.model.motions import MotionSpec
from balancer.motion_analysis import frame_reactions
from balancer.planning.path_loads import load_rows, path_loads
from balancer.spec import load_design
from balancer.spec.reader import design_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize(("example", "gravity"), [("forbal2", (0.0, -9.81)),
                                                  ("three_rrr", (0.0, 0.0)),
                                                  ("fivebar_5r", (0.0, -9.81))])
def test_the_form_gives_the_cores_loads_along_the_motion(example, gravity):
    design = load_design(EXAMPLES / f"{example}.toml")
    mech = mechanism_of(design.mechanism)
    motion = design.motions[0]
    t = np.linspace(motion.start, motion.end, 57)
    tau, rate, acc = trajectory.time_argument(motion, t)
    loads = path_loads(mech, motion, tau, gravity)
    form = loads.at(rate**2, acc)
    state = trajectory.input_state(mech.structure, motion, t)
    reactions = frame_reactions(mech, mech.motion_at(state), gravity=gravity)
    _, direct = load_rows(mech.linkage.inputs, reactions)
    scale = np.max(np.abs(direct), axis=1, keepdims=True) + 1e-300
    assert np.max(np.abs(form - direct) / scale) < 1e-9


def test_a_carriage_s_shaking_force_is_its_mass_times_its_acceleration():
    design = design_from_dict(carriage())
    mech = mechanism_of(design.mechanism)
    motion = design.motions[0]
    tau = np.linspace(0.0, 1.0, 11)
    loads = path_loads(mech, motion, tau)
    p, d1, d2 = trajectory.path_at(motion, tau)
    x = loads.index("shaking_force_x")
    # F = −(M·ẍ) on the frame's side as the package signs it: A = ±M·x', B = ±M·x''
    sign = np.sign(loads.inertial[x][5] / d1[5, 0])
    assert np.allclose(loads.inertial[x], sign * 2.0 * d1[:, 0], rtol=1e-12, atol=1e-15)
    assert np.allclose(loads.centripetal[x], sign * 2.0 * d2[:, 0], rtol=1e-12, atol=1e-15)
    assert np.all(loads.static == 0.0) or np.max(np.abs(loads.static)) < 1e-15
    assert loads.mass == pytest.approx(2.5, rel=1e-15)


def _paced(rows):
    return MotionSpec(name="m", times=(0.0, 1.0), path=((0.0,), (1.0,)), law="spline",
                      along="x", pace=tuple(map(tuple, rows)))


def test_a_pace_runs_its_rows_with_constant_acceleration_between_them():
    rng = np.random.default_rng(43)
    tau = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, 9)), [1.0]])
    rate = rng.uniform(0.2, 2.0, tau.size)
    motion = _paced(np.column_stack([tau, rate]))
    knots = motion.pace_times
    at, r, a = trajectory.time_argument(motion, knots)
    assert np.allclose(at, tau, rtol=0, atol=1e-15) and np.allclose(r, rate, rtol=1e-14)
    # the rate is the argument's derivative and the acceleration the rate's (central
    # differences inside each interval, where the law is a parabola: exact to rounding)
    mid = 0.5 * (knots[:-1] + knots[1:])
    h = 1e-6 * np.diff(knots)
    plus, minus = (trajectory.time_argument(motion, mid + s * h) for s in (1, -1))
    centre = trajectory.time_argument(motion, mid)
    assert np.allclose((plus[0] - minus[0]) / (2 * h), centre[1], rtol=1e-8)
    assert np.allclose((plus[1] - minus[1]) / (2 * h), centre[2], rtol=1e-6)
    assert motion.duration == pytest.approx(float(np.sum(2 * np.diff(tau)
                                                         / (rate[:-1] + rate[1:]))), rel=1e-14)


@pytest.mark.parametrize(("rows", "words"), [
    ([[0.0, 1.0]], "at least two rows"),
    ([[0.0, 1.0], [0.5, -1.0], [1.0, 1.0]], "at least 0"),
    ([[0.0, 1.0], [0.6, 1.0], [0.5, 1.0], [1.0, 1.0]], "must increase"),
    ([[0.0, 1.0], [0.5, 0.0], [0.7, 0.0], [1.0, 1.0]], "at rest"),
    ([[0.0, 1.0], [0.9, 1.0]], "from 0 s to 1 s"),
    ([[0.0, 1.0, 2.0], [1.0, 1.0]], "each row"),
])
def test_a_bad_pace_is_refused_naming_the_key(rows, words):
    with pytest.raises(SpecError, match=words) as caught:
        _paced(rows)
    assert caught.value.key == "pace"
