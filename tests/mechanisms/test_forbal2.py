"""The shipped Forbal-2 example (``examples/forbal2.toml``) against the authors' own files.

Vyas & Bottin, "Forbal: Force Balanced 2-5 Degree of Freedom Robot Manipulator Built from a Five
Bar Linkage" (arXiv 2509.03119, 2025); repository yjvyas/forbal. The figures typed in here are
theirs, read from ``forbal_description/urdf/forbal2.xacro`` and ``forbal2.urdf.xacro`` (the
inertials, the counter rings), ``forbal_controllers/config/forbal2.yaml`` (the joint limits) and
``forbal_controllers/src/forbal2.cpp`` (the inverse kinematics): never from the spec, which is
checked against them.

- The spec loads; its structure has mobility 2: the two motors' links as input groups, then the
  RRR dyad of links 12 and 22.
- Each link's mass, centre and inertia are the URDF's inertial combined with its steel ring
  (and link 22 with the end effector), computed here from the raw numbers.
- Along every motion: the parallelogram holds (link 22 ∥ link 11, link 12 ∥ link 21), the tip
  is on the motion's path, the inputs stay within the workspace and joint 22 within its limits;
  along the diamond the inputs are those of the authors' closed-form inverse kinematics.
- Over the workspace grid the total centre of mass is the closed form of the links' first
  moments; it stays within ``(|K11| + |K21|)/M`` of the motors' axis, 1.28 mm (1.27 mm measured;
  the counter rings cancel the first moments along the links to the data's rounding, not the
  small ones across them).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from balancer.linkage import kinematics, trajectory
from balancer.linkage.inputs import InputState
from balancer.linkage.structure import Structure
from balancer.linkage.vectors import V
from balancer.model.motions import MotionSpec
from balancer.spec import load_design

SPEC = Path(__file__).resolve().parents[2] / "examples" / "forbal2.toml"

# -- the authors' data (yjvyas/forbal) -------------------------------------------------------

#: Every link between joints (forbal2.xacro's joint origins; forbal2.yaml's link_length), and
#: the end-effector tip beyond link 22's joint with link 12 (forbal2.yaml's ee_length), m.
LENGTH, EE_LENGTH = 0.2, 0.025
#: The motors' axis in the world's x–z plane (joint11's and joint21's origins), m.
AXIS = (0.01616, 0.2275)
#: The reference pose: their constant command's joint coordinates, rad.
Q11, Q21 = 0.6, 0.7
#: URDF inertials in the plane: mass (kg), centre (x, z) in the link's frame (m), iyy (kg·m²).
URDF = {
    "link11": (0.29281186, (-0.00489125, 0.00230041), 0.00512981),
    "link12": (0.09554154, (0.12256792, 0.00211240), 0.00040772),
    "link21": (0.29126576, (-0.01196349, 0.00180672), 0.00539388),
    "link22": (0.15367895, (-0.02274975, 0.00189109), 0.00263097),
}
#: The end effector's inertial, in its frame 0.2 m along link 22 (x, z), and its iyy.
EE = (0.04366081, (0.01099440, 0.00000028), 0.00001407)
#: The steel counter rings (forbal2.urdf.xacro's ringmass): mass (kg) at x = −0.2 m on the link.
RINGS = {"link11": 0.02982881, "link21": 0.32560040, "link22": 0.08713178}
RING_RADII = (0.0032, 0.02)   # m, inner and outer
#: Joint limits (forbal2.xacro; the yaml allows q21 up to 1.28), rad.
LIMITS = {"q11": (-1.25, 1.45), "q21": (-1.5, 1.25), "q22": (0.3, 2.9)}


def _parts(name: str) -> list[tuple[float, tuple[float, float], float]]:
    """A link's parts as built: its URDF inertial, its ring (axial inertia m·(r₁² + r₂²)/2),
    and on link 22 the end effector; each (mass, centre (e, f), inertia about the centre)."""
    parts = [URDF[name]]
    if name == "link22":
        m, (x, z), iyy = EE
        parts.append((m, (LENGTH + x, z), iyy))
    if name in RINGS:
        m = RINGS[name]
        parts.append((m, (-0.2, 0.0), m * (RING_RADII[0] ** 2 + RING_RADII[1] ** 2) / 2))
    return parts


def combined(name: str) -> tuple[float, float, float, float]:
    """The link's mass, centre (e, f) and inertia about that centre, from its parts."""
    parts = _parts(name)
    mass = math.fsum(m for m, _, _ in parts)
    e = math.fsum(m * c[0] for m, c, _ in parts) / mass
    f = math.fsum(m * c[1] for m, c, _ in parts) / mass
    inertia = math.fsum(i + m * ((c[0] - e) ** 2 + (c[1] - f) ** 2) for m, c, i in parts)
    return mass, e, f, inertia


def their_inverse_kinematics(x: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """forbal2.cpp's ``inverse_kinematics`` (in double precision): (q11, q21) of a tip (x, z)."""
    l, le = LENGTH, EE_LENGTH
    xd, zd = x - AXIS[0], z - AXIS[1]
    reach = np.hypot(xd, zd)
    theta_e0 = np.arctan(zd / xd)
    beta = np.arccos((l**2 + (l + le) ** 2 - reach**2) / (2 * l * (l + le)))
    gamma = np.arccos((reach**2 + l**2 - (l + le) ** 2) / (2 * l * reach))
    q21 = gamma + theta_e0
    q11 = (math.pi - beta) - q21
    return q11, q21


def wrapped(angle: np.ndarray) -> np.ndarray:
    """An angle's principal value, rad."""
    return np.angle(np.exp(1j * np.asarray(angle)))


# -- fixtures --------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def design():
    return load_design(SPEC)


@pytest.fixture(scope="module")
def structure(design):
    return Structure.of(design.mechanism)


@pytest.fixture(scope="module")
def motions(design, structure):
    """Each motion's sampled times, path, input states and motion."""
    out = {}
    for spec in design.motions:
        times = trajectory.sample_times(spec)
        path, _, _ = trajectory.path_values(spec, times)
        state = trajectory.input_state(structure, spec)
        out[spec.name] = (spec, path, state, kinematics.motion(structure, state))
    return out


def _angles(structure, pose) -> dict[str, np.ndarray]:
    return {name: np.asarray(pose.angles[structure.index(name)]) for name in structure.names}


# -- the spec and its structure -----------------------------------------------------------------


def test_the_spec_loads_as_two_inputs_and_an_rrr_dyad(design, structure):
    assert design.mechanism.inputs == ("link11", "link21")
    assert [m.name for m in design.motions] == ["diamond", "circle", "figure-eight"]
    assert all(m.samples == 400 and m.point == "E" for m in design.motions)
    rows = sum(c.rows for c in structure.constraints)
    assert 3 * structure.size - rows == 2
    kinds = [(tuple(structure.names[k] for k in g.links), g.kind) for g in structure.groups]
    assert kinds == [(("link11",), "input"), (("link21",), "input"),
                     (("link12", "link22"), "RRR")]
    # the compound hinge O: both motors' links pinned to the ground there, each driven from it
    assert sorted(structure.point_links["O"]) == sorted(
        [-1, structure.index("link11"), structure.index("link21")])


def test_the_reference_pose_is_their_constant_command(design, structure):
    points = dict(design.mechanism.point_positions)   # complex, m
    assert points["O"] == complex(*AXIS)
    ref = dict(zip(structure.names, structure.ref_angle, strict=True))
    # θ11 = −q11, θ21 = q21; the parallelogram's other two sides parallel to them
    for name, angle in (("link11", -Q11), ("link21", Q21), ("link12", Q21), ("link22", -Q11)):
        assert ref[name] == pytest.approx(angle, abs=1e-15)
    for a, b in (("O", "A"), ("O", "B"), ("A", "C"), ("B", "C")):
        assert abs(points[b] - points[a]) == pytest.approx(LENGTH, rel=1e-15)
    k = structure.index("link22")
    tip = structure.local[(k, "E")]
    assert tip.x == pytest.approx(LENGTH + EE_LENGTH, rel=1e-15)
    assert abs(tip.y) < 1e-16


@pytest.mark.parametrize("name", ["link11", "link12", "link21", "link22"])
def test_each_link_is_the_urdf_inertial_with_its_ring(design, name):
    link = next(b for b in design.mechanism.moving if b.name == name).props
    mass, e, f, inertia = combined(name)
    assert link.mass == pytest.approx(mass, rel=1e-12)
    assert link.e == pytest.approx(e, rel=1e-12)
    assert link.f == pytest.approx(f, rel=1e-12)
    assert link.inertia == pytest.approx(inertia, rel=1e-12)


def test_the_workspace_is_their_joint_limits(design):
    w = design.workspace
    # θ11 − θ11_ref = −(q11 − Q11), θ21 − θ21_ref = q21 − Q21
    low, high = LIMITS["q11"]
    assert (w.range_of("link11").low, w.range_of("link11").high) == pytest.approx(
        (-(high - Q11), -(low - Q11)), abs=1e-15)
    low, high = LIMITS["q21"]
    assert (w.range_of("link21").low, w.range_of("link21").high) == pytest.approx(
        (low - Q21, high - Q21), abs=1e-15)
    # joint 22 at B: θ22 − θ21 = −q22, from its reference −(Q11 + Q21)
    (joint,) = w.joints
    low, high = LIMITS["q22"]
    assert joint.name == "B"
    assert (joint.low, joint.high) == pytest.approx(
        (-(high - Q11 - Q21), -(low - Q11 - Q21)), abs=1e-15)


# -- the motions --------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["diamond", "circle", "figure-eight"])
def test_a_motion_keeps_the_parallelogram_and_its_path(motions, structure, design, name):
    spec, path, state, mo = motions[name]
    angles = _angles(structure, mo.pose)
    assert np.max(np.abs(wrapped(angles["link22"] - angles["link11"]))) <= 1e-12
    assert np.max(np.abs(wrapped(angles["link12"] - angles["link21"]))) <= 1e-12
    k, local = trajectory.marker(structure, "E")
    tip = mo.point(k, local)
    assert np.max(np.hypot(tip.x - path[:, 0], tip.y - path[:, 1])) <= 1e-12
    # the waypoints are the authors' (their spline passes them at the waypoints' times)
    assert (path[0, 0], path[0, 1]) == pytest.approx(spec.path[0], abs=1e-15)
    # within the workspace: each input's change, and joint 22's, within its range
    w = design.workspace
    for i, input_name in enumerate(design.mechanism.inputs):
        change = state.positions[i] - structure.ref_angle[structure.index(input_name)]
        r = w.range_of(input_name)
        assert r.low <= change.min() and change.max() <= r.high, input_name
    ref = dict(zip(structure.names, structure.ref_angle, strict=True))
    joint = (angles["link22"] - angles["link21"]) - (ref["link22"] - ref["link21"])
    (limit,) = w.joints
    assert limit.low <= joint.min() and joint.max() <= limit.high
    # and in their joint coordinates, within their limits
    q11, q21 = -angles["link11"], angles["link21"]
    for q, (low, high) in ((q11, LIMITS["q11"]), (q21, LIMITS["q21"]),
                           (q11 + q21, LIMITS["q22"])):
        assert low <= q.min() and q.max() <= high


def test_the_waypoints_are_their_commands(design):
    """forbal2_commands_trapezoid.txt: the diamond as written; the circle's 41 points 9° apart
    on radius 0.05 m about (0.30, 0.22), to their 9 digits; the figure of eight's 17 points 45°
    apart on two ellipses (0.05 m across, 0.025 m up) about (0.26, 0.225) and (0.26, 0.175)."""
    motions = {m.name: m for m in design.motions}
    diamond = motions["diamond"]
    assert diamond.times == (0.0, 1.0, 2.0, 3.0, 4.0)
    assert diamond.path == ((0.22, 0.22), (0.32, 0.32), (0.42, 0.22), (0.32, 0.12), (0.22, 0.22))
    circle = motions["circle"]
    k = np.arange(41)
    assert circle.times == pytest.approx(0.2 * k, abs=1e-15)
    at = math.pi + np.radians(9.0) * k
    want = np.column_stack([0.30 + 0.05 * np.cos(at), 0.22 + 0.05 * np.sin(at)])
    assert np.max(np.abs(np.array(circle.path) - want)) <= 5e-10
    eight = motions["figure-eight"]
    k = np.arange(17)
    assert eight.times == pytest.approx(0.25 * k, abs=1e-15)
    at = -math.pi / 2 + np.radians(45.0) * k   # from the bottom of the upper ellipse
    upper = k <= 8
    want = np.column_stack([0.26 + 0.05 * np.cos(at),
                            np.where(upper, 0.225 + 0.025 * np.sin(at),
                                     0.175 - 0.025 * np.sin(at))])
    assert np.max(np.abs(np.array(eight.path) - want)) <= 1e-15
    assert all(m.law == "trapezoid" and m.acc_time == 0.5 for m in design.motions)


def test_the_diamond_is_their_inverse_kinematics(motions):
    spec, path, state, _ = motions["diamond"]
    q11, q21 = their_inverse_kinematics(path[:, 0], path[:, 1])
    assert np.max(np.abs(-state.positions[0] - q11)) <= 1e-10
    assert np.max(np.abs(state.positions[1] - q21)) <= 1e-10
    assert spec.law == "trapezoid" and spec.acc_time == 0.5


def test_the_time_law_is_their_controllers():
    """forbal2.cpp's trapezoid: ``s(t)`` over the path length ``d``, then ``τ = s·T/d``; the
    length cancels, so ``τ(t)`` is the trapezoid of ``τ`` itself; their spline's inner slopes
    (tk::spline's ``cspline_hermite``) the three-point difference of unequal steps."""
    total, acc = 4.0, 0.5
    spec = MotionSpec(name="m", times=(0.0, 1.0, 2.5, 4.0),
                      path=((0.0, 0.0), (1.0, 2.0), (3.0, -1.0), (2.0, 0.5)),
                      law="trapezoid", acc_time=acc)
    t = np.linspace(0.0, total, 81)
    d = 0.37   # any length
    t_const = total - 2 * acc
    v_max = 2 * d / (total + t_const)
    a_max = v_max / acc
    s = np.where(t <= acc, 0.5 * a_max * t**2,
                 np.where(t <= acc + t_const, 0.5 * a_max * acc**2 + v_max * (t - acc),
                          a_max * acc**2 + v_max * t_const - 0.5 * a_max * (total - t) ** 2))
    tau, _, _ = trajectory.time_argument(spec, t)
    assert np.max(np.abs(tau - s * total / d)) <= 1e-14
    # tk::spline's b[i] = −h/(hl(hl+h))·y[i−1] + (h−hl)/(hl·h)·y[i] + hl/(h(hl+h))·y[i+1]
    y, x = np.asarray(spec.path), np.asarray(spec.times)
    theirs = []
    for i in (1, 2):
        h, hl = x[i + 1] - x[i], x[i] - x[i - 1]
        theirs.append(-h / (hl * (hl + h)) * y[i - 1] + (h - hl) / (hl * h) * y[i]
                      + hl / (h * (hl + h)) * y[i + 1])
    # ours at those waypoints: dp/dτ = ṗ/τ̇ where τ = 1.0 and 2.5, both in the constant-rate
    # phase, τ/T = (u − a/2)/(1 − a) with a = acc/T
    a = acc / total
    u = a / 2 + (1 - a) * x[1:3] / total
    _, velocity, _ = trajectory.path_values(spec, u * total)
    assert np.max(np.abs(velocity * (1 - a) - np.array(theirs))) <= 1e-13


# -- force balance over the workspace -----------------------------------------------------------


def _first_moments() -> tuple[np.ndarray, np.ndarray, float]:
    """K11, K21 (kg·m, in the frames of links 11 and 21) and the total mass: the centre of mass
    is ``O + (R(θ11)·K11 + R(θ21)·K21)/M`` for the parallelogram (links 22 ∥ 11, 12 ∥ 21)."""
    mass = {name: combined(name) for name in URDF}
    first = {name: np.array([m * e, m * f]) for name, (m, e, f, _) in mass.items()}
    along = np.array([LENGTH, 0.0])
    k11 = first["link11"] + mass["link12"][0] * along + first["link22"]
    k21 = first["link21"] + mass["link22"][0] * along + first["link12"]
    return k11, k21, math.fsum(m for m, _, _, _ in mass.values())


def test_the_counter_rings_balance_the_links_along_their_lines():
    k11, k21, _ = _first_moments()
    # the first moments along links 11 and 21 cancel to the data's rounding (masses and
    # centres to 1e-8): 2.7e-9 and 8.2e-10 kg·m
    assert abs(k11[0]) <= 1e-8 and abs(k21[0]) <= 1e-8
    # across them they do not: the URDF's centres lie off the links' lines by up to 2.3 mm
    assert abs(k11[1]) > 1e-4 and abs(k21[1]) > 1e-4


def test_the_centre_of_mass_stays_near_the_motors_axis_over_the_workspace(design, structure):
    w = design.workspace
    r11, r21 = w.range_of("link11"), w.range_of("link21")
    g11, g21 = np.meshgrid(np.linspace(r11.low, r11.high, w.samples),
                           np.linspace(r21.low, r21.high, w.samples))
    i11, i21 = structure.index("link11"), structure.index("link21")
    theta11 = structure.ref_angle[i11] + g11.ravel()
    theta21 = structure.ref_angle[i21] + g21.ravel()
    with np.errstate(all="ignore"):  # the grid passes the folded pose (θ11 = θ21) once
        pose = kinematics.positions(structure, InputState.of([theta11, theta21]))
    angles = _angles(structure, pose)
    ref = dict(zip(structure.names, structure.ref_angle, strict=True))
    joint = (angles["link22"] - angles["link21"]) - (ref["link22"] - ref["link21"])
    (limit,) = w.joints
    kept = np.isfinite(joint) & (limit.low <= joint) & (joint <= limit.high)
    assert 500 < kept.sum() < theta11.size   # the box's corners fold the parallelogram
    # within joint 22's limits, every grid state is the parallelogram
    assert np.max(np.abs(wrapped(angles["link22"] - angles["link11"])[kept])) <= 1e-12
    assert np.max(np.abs(wrapped(angles["link12"] - angles["link21"])[kept])) <= 1e-12
    # the centre of mass from the package's poses and the spec's links ...
    total, cx, cy = 0.0, 0.0, 0.0
    for k, body in enumerate(design.mechanism.moving):
        link = body.props
        at = pose.point(k, V(link.e, link.f))
        total += link.mass
        cx, cy = cx + link.mass * at.x, cy + link.mass * at.y
    cx, cy = (cx / total)[kept], (cy / total)[kept]
    # ... is the closed form from the authors' numbers
    k11, k21, mass = _first_moments()
    assert total == pytest.approx(mass, rel=1e-12)
    c11, s11 = np.cos(theta11[kept]), np.sin(theta11[kept])
    c21, s21 = np.cos(theta21[kept]), np.sin(theta21[kept])
    x = AXIS[0] + (c11 * k11[0] - s11 * k11[1] + c21 * k21[0] - s21 * k21[1]) / mass
    y = AXIS[1] + (s11 * k11[0] + c11 * k11[1] + s21 * k21[0] + c21 * k21[1]) / mass
    assert np.max(np.hypot(cx - x, cy - y)) <= 1e-12
    # so it stays within (|K11| + |K21|)/M = 1.28 mm of the motors' axis (1.27 mm measured;
    # its positions over the grid span 2.35 mm)
    bound = (np.linalg.norm(k11) + np.linalg.norm(k21)) / mass
    assert np.max(np.hypot(cx - AXIS[0], cy - AXIS[1])) <= bound * (1 + 1e-9)
    assert bound < 1.3e-3
