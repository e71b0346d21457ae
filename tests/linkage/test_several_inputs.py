"""The general core with several inputs: a 5R five-bar (two inputs, a closed-form dyad) and a
3-RRR planar parallel manipulator (three inputs, a numeric group of four links).

Each figure against a route that shares nothing with the one under test but the model:
velocities and accelerations against finite differences of the positions along a smooth
motion of the inputs (with their error bound, :func:`helpers.derivative_with_error`); the
inputs' torques against the energy balance ``Σ τ_i·ω_i = dT/dt`` (no gravity, no loads: the
motors' power is the kinetic energy's rate, by finite differences of ``T``); the forces on the
frame against the momentum theorems (``F = −dP/dt``, ``M = −dL_O/dt`` by finite differences);
and the groups' route against the global ``3n × 3n`` solve (:func:`global_kinetostatics`).
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from helpers import derivative_with_error
from linkage.several_inputs_specs import (
    crank_rocker,
    crank_slider,
    fivebar,
    linkage_of,
    three_rrr,
)

from balancer.errors import SpecError
from balancer.linkage import dynamics, kinematics
from balancer.linkage.inputs import InputState
from balancer.linkage.structure import Structure
from balancer.linkage.vectors import V
from balancer.model import Linkage
from balancer.spec.reader import design_from_dict
from balancer.spec.writer import dumps_design

#: Relative tolerance between two formulations of the same figure (each a few linear solves
#: of condition well below 1e4 at the sampled states: ≈ 1e4·64·ε ≈ 1.4e-10 per solve).
RTOL = 1e-9


CASES = {"fivebar": fivebar, "3-RRR": three_rrr, "crank and slide": crank_slider}


@pytest.fixture(params=sorted(CASES))
def case(request) -> tuple[Linkage, Structure]:
    linkage = linkage_of(CASES[request.param]())
    return linkage, Structure.of(linkage)


#: The inputs' motion: θ_i(t) = θ_i,ref + a_i·sin(w_i·t + φ_i) (rad, t in s); the amplitudes
#: by the number of inputs (the 3-RRR's platform turns several times faster than its cranks:
#: it keeps well inside its workspace).
AMPLITUDES = {2: (0.25, 0.2), 3: (0.08, 0.06, 0.07)}
RATE, PHASE = (3.0, 5.0, 4.0), (0.3, -0.7, 1.1)


def state_at(structure: Structure, t: np.ndarray | float) -> InputState:
    t = np.atleast_1d(np.asarray(t, dtype=float))
    ref = list(structure.input_references)
    m = len(ref)
    a, w, p = (np.array(x[:m]) for x in (AMPLITUDES[m], RATE, PHASE))
    # (along a slide, m: a fifth of the amplitude in rad, 0.04 m on a 0.4 m linkage)
    a = a * np.array([0.2 if d.position_unit == "m" else 1.0 for d in structure.drivers])
    arg = w[:, None] * t[None, :] + p[:, None]
    return InputState.of(np.array(ref)[:, None] + a[:, None] * np.sin(arg),
                         a[:, None] * w[:, None] * np.cos(arg),
                         -a[:, None] * w[:, None] ** 2 * np.sin(arg))


TIMES = np.linspace(0.0, 1.2, 7)


def test_the_structure_has_a_group_per_input_then_the_rest(case):
    linkage, s = case
    assert s.inputs == tuple(s.index(name) for name in linkage.inputs)
    kinds = [g.kind for g in s.groups]
    assert kinds[: len(s.inputs)] == ["slide" if d.position_unit == "m" else "input"
                                      for d in s.drivers]
    assert [g.driver.index for g in s.groups[: len(s.inputs)]] == list(range(len(s.inputs)))
    expected = "RRR" if len(s.inputs) == 2 else "numeric"
    assert kinds[len(s.inputs):] == [expected]
    # the reference pose is the motion at the reference inputs, to rounding
    at_ref = kinematics.positions(s, InputState.of([[x] for x in s.input_references]))
    q = s.reference_coordinates()
    scale = s.length_scale()
    for k in range(s.size):
        assert abs(at_ref.origins[k].x[0] - q[3 * k]) <= 1e-12 * scale
        assert abs(at_ref.origins[k].y[0] - q[3 * k + 1]) <= 1e-12 * scale
        assert abs(math.remainder(at_ref.angles[k][0] - q[3 * k + 2], 2 * math.pi)) <= 1e-12


def test_the_joints_close_along_the_motion(case):
    _, s = case
    pose = kinematics.positions(s, state_at(s, TIMES))
    scale = s.length_scale()
    for c in s.constraints:
        for r, kind in zip(c.residual(pose), c.row_kinds, strict=True):
            assert np.all(np.isfinite(r))
            assert np.max(np.abs(r)) <= 1e-12 * (scale if kind == "length" else 1.0)


#: The finite differences' step, s.
STEP = 1e-3


def _along(s: Structure, of):
    """``t → of(motion)[..., at t]`` at every time the differences at :data:`TIMES` ask for,
    from one motion over all of them (``of`` gives arrays whose last axis is the states)."""
    times = sorted({t + k * h for t in TIMES for h in (STEP, 2 * STEP) for k in range(-3, 4)})
    values = np.asarray(of(kinematics.motion(s, state_at(s, np.array(times)))))
    table = {t: values[..., i] for i, t in enumerate(times)}
    return lambda t: table[t]


def _coordinates(s: Structure, origins, angles) -> np.ndarray:
    return np.array([x for k in range(s.size) for x in (origins[k].x, origins[k].y, angles[k])])


def test_rates_and_accelerations_are_the_positions_derivatives(case):
    _, s = case
    mo = kinematics.motion(s, state_at(s, TIMES))
    positions = _along(s, lambda m: _coordinates(s, m.pose.origins, m.pose.angles))
    rates = _along(s, lambda m: _coordinates(s, m.velocity, m.rate))
    want_v = _coordinates(s, mo.velocity, mo.rate)
    want_a = _coordinates(s, mo.acceleration, mo.accel)
    for i, t in enumerate(TIMES):
        fd_v, err_v = derivative_with_error(positions, t, h=STEP)
        fd_a, err_a = derivative_with_error(rates, t, h=STEP)
        v, a = want_v[:, i], want_a[:, i]
        assert np.max(np.abs(fd_v - v)) <= err_v + 1e-12 * np.max(np.abs(v))
        assert np.max(np.abs(fd_a - a)) <= err_a + 1e-12 * np.max(np.abs(a))
        assert err_v <= 1e-6 * np.max(np.abs(v))  # (a bound that can tell)
        assert err_a <= 1e-6 * np.max(np.abs(a))


def _kinetic_energy(linkage: Linkage, s: Structure, mo: kinematics.Motion) -> np.ndarray:
    """``T = Σ ½·m·|v_G|² + ½·J_G·ω²`` (J about the centre of mass), J per state."""
    total = np.zeros(mo.count)
    for k, name in enumerate(s.names):
        link = linkage.link(name)
        v = mo.point_velocity(k, V(link.e, link.f))
        total += 0.5 * link.mass * (v.x ** 2 + v.y ** 2) + 0.5 * link.inertia * mo.rate[k] ** 2
    return total


def _momenta(linkage: Linkage, s: Structure, mo: kinematics.Motion) -> np.ndarray:
    """Linear momentum (x, y) and angular momentum about the origin, per state."""
    px, py, lz = (np.zeros(mo.count) for _ in range(3))
    for k, name in enumerate(s.names):
        link = linkage.link(name)
        r, v = mo.point(k, V(link.e, link.f)), mo.point_velocity(k, V(link.e, link.f))
        px += link.mass * v.x
        py += link.mass * v.y
        lz += link.mass * (r.x * v.y - r.y * v.x) + link.inertia * mo.rate[k]
    return np.array([px, py, lz])


@pytest.mark.parametrize("route", ["groups", "global"])
def test_the_inputs_torques_supply_the_kinetic_energys_rate(case, route):
    linkage, s = case
    state = state_at(s, TIMES)
    forces = dynamics.inverse_dynamics(s, kinematics.motion(s, state), linkage, route=route)
    assert len(forces.input_torques) == len(s.inputs)
    each = np.array([np.asarray(tau)[:, 0] * w for tau, w in
                     zip(forces.input_torques, state.rates, strict=True)])
    energy = _along(s, lambda m: _kinetic_energy(linkage, s, m))
    for i, t in enumerate(TIMES):
        rate, err = derivative_with_error(energy, t, h=STEP)
        assert abs(each[:, i].sum() - rate) <= err + RTOL * np.max(np.abs(each[:, i]))


def test_the_frame_feels_the_momentums_rate(case):
    linkage, s = case
    forces = dynamics.inverse_dynamics(s, kinematics.motion(s, state_at(s, TIMES)), linkage)
    momenta = _along(s, lambda m: _momenta(linkage, s, m))
    for i, t in enumerate(TIMES):
        rate, err = derivative_with_error(momenta, t, h=STEP)
        got = np.array([forces.shaking_force.x[i, 0], forces.shaking_force.y[i, 0],
                        forces.shaking_moment[i, 0]])
        # the frame feels minus the momentum's rate (no weights, no loads)
        assert np.max(np.abs(got + rate)) <= err + RTOL * np.max(np.abs(rate))


def test_the_groups_and_the_global_solve_agree(case):
    linkage, s = case
    mo = kinematics.motion(s, state_at(s, TIMES))
    a = dynamics.inverse_dynamics(s, mo, linkage, gravity=(0.0, -9.81))
    b = dynamics.inverse_dynamics(s, mo, linkage, gravity=(0.0, -9.81), route="global")
    for x, y in zip(a.arrays(), b.arrays(), strict=True):
        scale = max(float(np.max(np.abs(x))), 1e-300)
        assert np.max(np.abs(np.asarray(x) - np.asarray(y))) <= RTOL * scale


def test_one_input_spelled_as_a_list_is_the_crank():
    spec = crank_rocker()
    one = linkage_of(spec)
    listed = dict(spec, mechanism={**spec["mechanism"], "inputs": ["crank"]})
    del listed["mechanism"]["input"]
    two = linkage_of(listed)
    assert one == two and one.input == "crank"
    s = Structure.of(one)
    theta = np.linspace(0.0, 2 * np.pi, 9)
    mo = kinematics.motion(s, InputState.crank(theta, 3.0, 0.5))
    assert np.array_equal(mo.theta1, theta) and np.all(mo.omega1 == 3.0)
    forces = dynamics.inverse_dynamics(s, mo, one)
    assert forces.driving_torque is forces.input_torques[0]


def test_the_spec_writes_several_inputs_back():
    design = design_from_dict(fivebar())
    text = dumps_design(design)
    assert 'inputs = ["left", "right"]' in text
    again = design_from_dict(tomllib.loads(text))
    assert again.mechanism == design.mechanism


def test_a_count_of_inputs_that_is_not_the_mobility_is_refused():
    one = fivebar()
    one["mechanism"]["inputs"] = ["left"]
    with pytest.raises(SpecError, match="2 degrees of freedom, not 1") as caught:
        Structure.of(linkage_of(one))
    assert caught.value.key == "mechanism"
    four = fivebar()
    four["links"]["upper_left"]["points"] = ["C", "E", "D"]  # the upper links welded: 1 DOF
    del four["links"]["upper_right"]
    four["mechanism"]["points"]["D"] = [0.22, 0.18]
    four["links"]["right"]["points"] = ["B", "D"]
    with pytest.raises(SpecError, match=r"1 degrees of freedom, not 2: .* one per input "
                                        r"\(left, right\)"):
        Structure.of(linkage_of(four))


def test_inputs_that_name_a_link_twice_or_the_ground_are_refused():
    for inputs, match in ((["left", "left"], "names a link twice"),
                          (["left", "ground"], "must name a moving link"),
                          (["left", "upper_left"], "must be a ground point")):
        spec = fivebar()
        spec["mechanism"]["inputs"] = inputs
        with pytest.raises(SpecError, match=match) as caught:
            linkage_of(spec)
        assert caught.value.key == "mechanism.inputs"
    both = fivebar()
    both["mechanism"]["input"] = "left"
    with pytest.raises(SpecError, match="not both"):
        linkage_of(both)


def test_a_state_for_another_count_of_inputs_is_refused():
    s = Structure.of(linkage_of(fivebar()))
    with pytest.raises(ValueError, match="1 inputs; the linkage has 2"):
        kinematics.motion(s, InputState.crank([0.0]))
    with pytest.raises(ValueError, match="not one"):
        _ = kinematics.motion(s, state_at(s, TIMES)).theta1
