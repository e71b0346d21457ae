"""A motion's input states (:mod:`balancer.linkage.trajectory`), each figure by a second route.

The time laws against their closed forms and finite differences; the paths against scipy's
splines (``CubicHermiteSpline`` with the same slopes, ``CubicSpline`` periodic); the inverse
kinematics by the forward kinematics: the point it places must be on the path, with the path's
velocity and acceleration, to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import derivative_with_error
from linkage.several_inputs_specs import fivebar, linkage_of, three_rrr
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from balancer.errors import AssemblyError, SpecError
from balancer.linkage import kinematics, trajectory
from balancer.linkage.structure import Structure
from balancer.model.motions import MotionSpec

DIAMOND = ((0.1, 0.35), (0.13, 0.38), (0.16, 0.35), (0.13, 0.32), (0.1, 0.35))
TIMES = (0.0, 1.0, 2.2, 3.0, 4.0)


def motion(law: str, **more) -> MotionSpec:
    fields = {"name": law, "times": TIMES, "path": DIAMOND, "law": law, "samples": 101} | more
    if law == "trapezoid":
        fields.setdefault("acc_time", 0.5)
    return MotionSpec(**fields)


LAWS = ["trapezoid", "cubic", "quintic", "spline"]


@pytest.mark.parametrize("law", LAWS)
def test_the_time_law_runs_from_the_first_time_to_the_last(law):
    spec = motion(law)
    t = np.linspace(0.0, 4.0, 41)
    tau, rate, acc = trajectory.time_argument(spec, t)
    assert tau[0] == 0.0 and abs(tau[-1] - 4.0) <= 4e-15
    assert np.all(np.diff(tau) > 0)
    if law != "spline":  # rest to rest
        assert rate[0] == 0.0 and abs(rate[-1]) <= 1e-15
    for i in range(1, 40):
        if law == "trapezoid" and min(abs(t[i] - 0.5), abs(t[i] - 3.5)) < 0.01:
            continue  # (its rate has a kink where the acceleration ends: no derivative there)
        d1, e1 = derivative_with_error(lambda u: trajectory.time_argument(spec, np.array([u]))[0],
                                       t[i], h=1e-3)
        assert abs(d1[0] - rate[i]) <= e1 + 1e-12
        if law in ("cubic", "quintic", "spline"):  # (the trapezoid's is a step)
            d2, e2 = derivative_with_error(
                lambda u: trajectory.time_argument(spec, np.array([u]))[1], t[i], h=1e-3,
                scale=60.0)  # (the rate's terms: up to 60·u³ for the quintic's)
            assert abs(d2[0] - acc[i]) <= e2 + 1e-12


def test_the_trapezoid_is_the_forbal_controllers_law():
    # t_const = T − 2·ta, v_max = 2·d/(T + t_const), a_max = v_max/ta (their script, d = T)
    spec = motion("trapezoid", acc_time=0.5)
    big_t, ta = 4.0, 0.5
    v_max = 2 * big_t / (big_t + big_t - 2 * ta)
    a_max = v_max / ta
    t = np.array([0.25, 0.5, 2.0, 3.7])
    want = np.array([0.5 * a_max * 0.25**2, 0.5 * a_max * ta**2,
                     0.5 * a_max * ta**2 + v_max * (2.0 - ta),
                     a_max * ta**2 + v_max * (big_t - 2 * ta) - 0.5 * a_max * 0.3**2])
    tau, rate, _ = trajectory.time_argument(spec, t)
    assert np.allclose(tau, want, rtol=0, atol=1e-14)
    assert rate[2] == pytest.approx(v_max, abs=1e-15)


@pytest.mark.parametrize("law", LAWS)
def test_the_path_is_the_spline_through_the_waypoints(law):
    spec = motion(law)
    knots, values = np.array(TIMES), np.array(DIAMOND)
    if law == "spline":
        curve = CubicSpline(knots, values, bc_type="periodic")
    else:
        h = np.diff(knots)
        delta = np.diff(values, axis=0) / h[:, None]
        slopes = np.zeros_like(values)
        for i in range(1, len(knots) - 1):  # the three-point difference, written out
            slopes[i] = (h[i - 1] * delta[i] + h[i] * delta[i - 1]) / (h[i - 1] + h[i])
        curve = CubicHermiteSpline(knots, values, slopes)
    t = np.linspace(0.0, 4.0, 97)
    p, v, a = trajectory.path_values(spec, t)
    tau, rate, acc = trajectory.time_argument(spec, t)
    assert np.max(np.abs(p - curve(tau))) <= 1e-15
    assert np.max(np.abs(v - curve(tau, 1) * rate[:, None])) <= 1e-14
    want_a = curve(tau, 2) * rate[:, None] ** 2 + curve(tau, 1) * acc[:, None]
    assert np.max(np.abs(a - want_a)) <= 1e-13
    at_knots = trajectory.path_values(spec, trajectory.time_argument(spec, knots)[0] * 0
                                      + knots)[0] if law == "spline" else None
    if at_knots is not None:  # a spline's pace is its waypoints' own: through them at their times
        assert np.max(np.abs(at_knots - values)) <= 1e-15


OPEN = DIAMOND[:-1] + ((0.2, 0.3),)


@pytest.mark.parametrize("path", [DIAMOND, OPEN], ids=["closed: periodic", "open: clamped"])
def test_a_spline_is_periodic_where_closed_and_at_rest_at_its_ends_where_open(path):
    spec = motion("spline", path=path)
    knots, values = np.array(TIMES), np.array(path)
    curve = CubicSpline(knots, values, bc_type="periodic" if spec.closed else "clamped")
    t = np.linspace(0.0, 4.0, 97)
    p, v, a = trajectory.path_values(spec, t)
    assert np.max(np.abs(p - curve(t))) <= 1e-15
    assert np.max(np.abs(v - curve(t, 1))) <= 1e-14
    assert np.max(np.abs(a - curve(t, 2))) <= 1e-13
    if not spec.closed:
        assert np.all(v[[0, -1]] == 0.0)


@pytest.mark.parametrize("path", [DIAMOND, OPEN], ids=["closed", "open"])
def test_a_long_tables_spline_is_the_dense_solves(monkeypatch, path):
    # A table past DENSE_KNOTS takes SciPy's banded solve: the same slopes as the dense one.
    spec = motion("spline", path=path)
    dense = trajectory.path_values(spec, np.linspace(0.0, 4.0, 33))
    monkeypatch.setattr(trajectory, "DENSE_KNOTS", 2)
    banded = trajectory.path_values(spec, np.linspace(0.0, 4.0, 33))
    for x, y in zip(dense, banded, strict=True):
        assert np.max(np.abs(x - y)) <= 1e-13 * max(1.0, float(np.max(np.abs(x))))


@pytest.fixture(scope="module")
def five() -> Structure:
    return Structure.of(linkage_of(fivebar()))


@pytest.mark.parametrize("law", LAWS)
def test_the_inverse_kinematics_puts_the_point_on_its_path(five, law):
    spec = motion(law, point="E")
    state = trajectory.input_state(five, spec)
    mo = kinematics.motion(five, state)
    k, local = trajectory.marker(five, "E")
    p, v, a = trajectory.path_values(spec, trajectory.sample_times(spec))
    scale = five.length_scale()
    for got, want, what in ((mo.point(k, local), p, "position"),
                            (mo.point_velocity(k, local), v, "velocity"),
                            (mo.point_acceleration(k, local), a, "acceleration")):
        error = np.max(np.abs(np.column_stack([got.x, got.y]) - want))
        size = max(float(np.max(np.abs(want))), 1e-300)
        # Newton to 1e-13 of the length scale, rates by one 2×2 solve (condition ≤ 1e3)
        assert error <= (1e-13 * scale if what == "position" else 1e-12 * size), what
    # the inputs turn continuously along the path (no change of branch)
    steps = np.abs(np.diff(np.array(state.positions), axis=1))
    assert np.max(steps) <= 10 * np.max(np.abs(np.array(state.rates))) * spec.duration / 100


def test_the_inputs_own_path_is_their_change_from_the_reference(five):
    spec = MotionSpec(name="wave", times=(0.0, 0.5, 1.0), path=((0.0, 0.0), (0.2, -0.1),
                                                                (0.0, 0.0)), law="quintic")
    state = trajectory.input_state(five, spec)
    p, v, a = trajectory.path_values(spec, trajectory.sample_times(spec))
    for i, k in enumerate(five.inputs):
        assert np.array_equal(state.positions[i], p[:, i] + five.ref_angle[k])
        assert np.array_equal(state.rates[i], v[:, i])
        assert np.array_equal(state.accelerations[i], a[:, i])


def test_a_waypoint_out_of_reach_is_an_assembly_error(five):
    far = ((0.1, 0.35), (0.9, 0.9))
    spec = MotionSpec(name="far", times=(0.0, 1.0), path=far, point="E", law="cubic")
    with pytest.raises(AssemblyError, match="leaves the workspace at t = "):
        trajectory.input_state(five, spec)
    spec = MotionSpec(name="far", times=(0.0, 1.0), path=far[::-1], point="E", law="cubic")
    with pytest.raises(AssemblyError, match="first waypoint cannot be reached"):
        trajectory.input_state(five, spec)


def test_a_point_path_needs_two_inputs():
    s = Structure.of(linkage_of(three_rrr()))
    spec = motion("cubic", point="C1")
    with pytest.raises(SpecError, match="places two inputs; this linkage has 3"):
        trajectory.input_state(s, spec)


@pytest.mark.parametrize(("fields", "key", "match"), [
    ({"law": "bang"}, "law", "must be one of"),
    ({"law": "trapezoid", "acc_time": 2.5}, "acc_time", "at most half the duration"),
    ({"law": "trapezoid"}, "acc_time", "needs its acceleration time"),
    ({"law": "cubic", "acc_time": 0.5}, "acc_time", "trapezoid law's"),
    ({"times": (0.0, 1.0, 1.0, 3.0, 4.0)}, "times", "must increase"),
    ({"path": DIAMOND[:3]}, "path", "one waypoint per time"),
    ({"samples": 3}, "samples", "at least 8"),
])
def test_a_bad_motion_is_refused_naming_its_key(fields, key, match):
    with pytest.raises(SpecError, match=match) as caught:
        MotionSpec(**({"name": "m", "times": TIMES, "path": DIAMOND, "point": "E"} | fields))
    assert caught.value.key == key


def test_a_long_nearly_closed_table_is_periodic(monkeypatch):
    # A recorded loop whose last row is its first to 1e-13 (closed to 1e-12): made exactly
    # closed for the banded periodic solve, as for the dense one.
    spec = motion("spline", path=DIAMOND[:-1] + ((DIAMOND[0][0] + 1e-13, DIAMOND[0][1]),))
    assert spec.closed
    dense = trajectory.path_values(spec, np.linspace(0.0, 4.0, 9))
    monkeypatch.setattr(trajectory, "DENSE_KNOTS", 2)
    banded = trajectory.path_values(spec, np.linspace(0.0, 4.0, 9))
    assert np.max(np.abs(dense[0] - banded[0])) <= 1e-13


@pytest.mark.parametrize("law", LAWS)
def test_the_break_times_are_where_the_path_passes_its_waypoints(law):
    spec = motion(law)
    breaks = trajectory.break_times(spec)
    tau = trajectory.time_argument(spec, breaks)[0]
    inner = np.array(TIMES[1:-1])
    hits = [np.min(np.abs(tau - w)) for w in inner]
    assert max(hits) <= 1e-12  # each inner waypoint's time, through the law
    if law == "trapezoid":  # and where the acceleration ends and the deceleration starts
        assert np.min(np.abs(breaks - 0.5)) <= 1e-15 and np.min(np.abs(breaks - 3.5)) <= 1e-15
    assert np.all(np.diff(breaks) > 0) and breaks[0] > 0.0 and breaks[-1] < 4.0
