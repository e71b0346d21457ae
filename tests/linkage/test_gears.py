"""A gear pair in the core (:class:`balancer.linkage.constraints.Mesh`) against hand routes.

Two cranks geared at ratios of both signs, each with an offset mass: the driven crank's angle
is the ratio times the driver's; the mesh's Jacobian is its residual's derivative (central
differences) and its ``γ`` the residual's second derivative along the motion; the tooth force
is the driven crank's free body about its pivot; the frame's force and moment are the links'
momentum rates (an independent route: nothing of the joints); the motor's power is the rate of
the kinetic energy; the groups' route equals the global solve.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from balancer.errors import SpecError
from balancer.linkage.constraints import Mesh, pose_of
from balancer.linkage.dynamics import inverse_dynamics
from balancer.linkage.inputs import InputState
from balancer.linkage.kinematics import motion
from balancer.linkage.structure import Structure
from balancer.linkage.vectors import V
from balancer.model import Body, Gear, Link, Linkage

DRIVER = Link(mass=2.0, inertia=0.01, e=0.03, f=0.01)
DRIVEN = Link(mass=3.0, inertia=0.02, e=0.02, f=-0.01)
#: The driven crank's pivot, m, and its marker's place from it.
PIVOT = (0.2, 0.07)


def geared(ratio: float, driver_first: tuple[float, float] = (0.0, 0.0)) -> Linkage:
    """Crank ``a`` about ``O``, crank ``b`` about ``P`` turned by a gear at ``ratio``.

    ``driver_first``: crank a's frame origin is its pivot unless a point other than ``O``
    is first (here its marker, so that its origin moves).
    """
    return Linkage(
        points=(("O", driver_first), ("X", (0.05, 0.01)), ("P", PIVOT),
                ("Y", (PIVOT[0] - 0.01, PIVOT[1] + 0.05))),
        bodies=(Body(name="ground", points=("O", "P")),
                Body(name="a", points=("O", "X"), props=DRIVER),
                Body(name="b", points=("P", "Y"), props=DRIVEN)),
        inputs=("a",), gears=(Gear(name="gear", driver="a", driven="b", ratio=ratio),))


def about_pivot(link: Link, length: float) -> float:
    """A link's inertia about its first point, kg·m²."""
    return link.inertia + link.mass * (link.e**2 + link.f**2)


@pytest.mark.parametrize("ratio", [-1.0, -2.0, 2.0, 3.0, -3.0])
def test_driven_crank_and_tooth_force_by_hand(ratio: float) -> None:
    s = Structure.of(geared(ratio))
    assert [g.kind for g in s.groups] == ["input", "geared"]
    rng = np.random.default_rng(7)
    theta = rng.uniform(-3, 3, 9)
    omega, alpha = rng.uniform(-20, 20, 9), rng.uniform(-50, 50, 9)
    mo = motion(s, InputState.crank(theta, omega, alpha))
    np.testing.assert_allclose(mo.pose.angles[1] - s.ref_angle[1], ratio * (theta - s.ref_angle[0]),
                               atol=1e-12)
    np.testing.assert_allclose(mo.rate[1], ratio * omega, rtol=1e-13)
    np.testing.assert_allclose(mo.accel[1], ratio * alpha, rtol=1e-13)
    f = inverse_dynamics(s, mo)
    (mesh,) = s.meshes
    d = math.hypot(*PIVOT)
    u = complex(*PIVOT) / d
    rho_b = d / (ratio - 1)  # signed, along u from P
    # The driven crank's moment about its pivot: its inertia's, taken by the tooth at ρ_b·u.
    needed = about_pivot(DRIVEN, 0.05) * ratio * alpha
    tooth = needed / rho_b  # (ρ_b·u) × (λ·i·u) = ρ_b·λ on b
    force = f.teeth["gear"].x[:, 0] + 1j * f.teeth["gear"].y[:, 0]
    np.testing.assert_allclose(force, tooth * 1j * u, rtol=1e-12, atol=1e-12 * abs(tooth).max())
    # The driver: its own inertia's moment less the tooth's on it, −λ·t at ρ_a·u.
    torque = about_pivot(DRIVER, 0.05) * alpha + ratio * rho_b * tooth
    np.testing.assert_allclose(f.input_torques[0][:, 0], torque, rtol=1e-12,
                               atol=1e-12 * abs(torque).max())
    assert np.allclose(mesh.pitch_point.complex(), rho_b * ratio * u)


def _momentum_rates(s: Structure, mo: object) -> tuple[np.ndarray, np.ndarray]:
    """The links' ``Σ m·a_G`` and ``Σ (r_G × m·a_G + J·α)`` about the origin."""
    force = 0j
    moment = 0.0
    for k, body in enumerate(s.linkage.moving):
        link = body.props
        assert link is not None
        g = V(link.e, link.f)
        r = mo.pose.point(k, g)  # type: ignore[attr-defined]
        a = mo.point_acceleration(k, g)  # type: ignore[attr-defined]
        force = force + link.mass * (a.x + 1j * a.y)
        moment = moment + link.mass * (r.x * a.y - r.y * a.x) + link.inertia * mo.accel[k]  # type: ignore[attr-defined]
    return np.asarray(force), np.asarray(moment)


@pytest.mark.parametrize("ratio", [-1.0, 2.0])
@pytest.mark.parametrize("first", [(0.0, 0.0), (0.01, -0.02)])
def test_frame_loads_are_momentum_rates_and_power_is_energy_rate(
        ratio: float, first: tuple[float, float]) -> None:
    s = Structure.of(geared(ratio, first))
    rng = np.random.default_rng(11)
    theta, omega, alpha = rng.uniform(-3, 3, 8), rng.uniform(-20, 20, 8), rng.uniform(-50, 50, 8)
    mo = motion(s, InputState.crank(theta, omega, alpha))
    f = inverse_dynamics(s, mo)
    force, moment = _momentum_rates(s, mo)
    shaking = f.shaking_force.x[:, 0] + 1j * f.shaking_force.y[:, 0]
    scale = np.abs(force).max()
    np.testing.assert_allclose(shaking, -force, atol=1e-12 * scale)
    np.testing.assert_allclose(f.shaking_moment[:, 0], -moment, atol=1e-12 * np.abs(moment).max())
    # The frame's force is the sum of its pivots' reactions: the tooth is internal.
    total = sum(r.x[:, 0] + 1j * r.y[:, 0] for r in f.reactions.values())
    np.testing.assert_allclose(total, shaking, atol=1e-12 * scale)
    # The motor's power is the rate of the kinetic energy (central differences in time).
    def energy(t: float) -> np.ndarray:
        m = motion(s, InputState.crank(theta + omega * t + alpha * t * t / 2, omega + alpha * t))
        out = np.zeros(theta.size)
        for k, body in enumerate(s.linkage.moving):
            link = body.props
            assert link is not None
            v = m.point_velocity(k, V(link.e, link.f))
            out += 0.5 * link.mass * (v.x**2 + v.y**2) + 0.5 * link.inertia * m.rate[k] ** 2
        return out
    h = 1e-5
    rate = (energy(h) - energy(-h)) / (2 * h)
    power = f.input_torques[0][:, 0] * omega
    np.testing.assert_allclose(power, rate, rtol=1e-6, atol=1e-6 * np.abs(power).max())
    g = inverse_dynamics(s, mo, route="global")
    for a, b in zip(f.arrays(), g.arrays(), strict=True):
        assert np.allclose(np.asarray(a)[:, :1], np.asarray(b)[:, :1], rtol=1e-10,
                           atol=1e-10 * scale)


def test_mesh_jacobian_and_gamma_are_the_residuals_derivatives() -> None:
    s = Structure.of(geared(-2.0, (0.01, -0.02)))
    (mesh,) = s.meshes
    rng = np.random.default_rng(3)
    q = s.reference_coordinates() + rng.normal(0, 0.05, 6)
    pose = pose_of(q)
    rows = mesh.jacobian(pose)
    grad = np.zeros(6)
    for link, coeffs in rows:
        grad[3 * link : 3 * link + 3] += [float(c) for c in coeffs[0]]
    h = 1e-6
    fd = np.array([(float(mesh.residual(pose_of(q + h * e))[0])
                    - float(mesh.residual(pose_of(q - h * e))[0])) / (2 * h)
                   for e in np.eye(6)])
    np.testing.assert_allclose(grad, fd, atol=1e-9)
    # γ: along the motion, Φ_q·q̈ = γ where the motion keeps the residual at zero.
    mo = motion(s, InputState.crank(np.array([0.4]), np.array([7.0]), np.array([2.0])))
    residual = float(np.asarray(mesh.residual(mo.pose)[0]).ravel()[0])
    assert abs(residual) < 1e-15
    qdd = np.concatenate([[float(mo.acceleration[k].x[0]), float(mo.acceleration[k].y[0]),
                           float(mo.accel[k][0])] for k in range(2)])
    lhs = sum(float(np.dot(np.asarray([float(np.asarray(c).ravel()[0]) for c in coeffs[0]]),
                           qdd[3 * link : 3 * link + 3]))
              for link, coeffs in mesh.jacobian(mo.pose))
    gamma = float(np.asarray(mesh.gamma(mo.pose, list(mo.velocity), list(mo.rate))[0]).ravel()[0])
    assert lhs == pytest.approx(gamma, rel=1e-12, abs=1e-12)
    assert isinstance(mesh, Mesh)


@pytest.mark.parametrize(("field", "value", "key"), [
    ("ratio", 1.0, "mechanism.gears[1].ratio"),
    ("ratio", 0.0, "mechanism.gears[1].ratio"),
    ("driver", "b", "mechanism.gears[1].driver"),
    ("driven", "a", "mechanism.gears[1].driven"),
    ("driven", "nowhere", "mechanism.gears[1].driven"),
    ("name", "a,b", "mechanism.gears[1].name"),
    ("name", "x\ny", "mechanism.gears[1].name"),
])
def test_bad_gears_are_refused_by_key(field: str, value: object, key: str) -> None:
    good = geared(-1.0)
    gear = {"name": "gear", "driver": "a", "driven": "b", "ratio": -1.0, field: value}
    with pytest.raises(SpecError) as err:
        Linkage(points=good.points, bodies=good.bodies, inputs=good.inputs,
                gears=(Gear(**gear),))  # type: ignore[arg-type]
    assert err.value.key == key


def test_a_crank_turns_its_geared_links_at_whole_numbers_of_its_speed() -> None:
    """A cycle analysis samples one revolution: a gear at ½ (a motion of two revolutions) is
    refused by its key; a chain whose ratios multiply to a whole number is not."""
    good = geared(-1.0)
    with pytest.raises(SpecError) as err:
        Linkage(points=good.points, bodies=good.bodies, inputs=good.inputs,
                gears=(Gear(name="gear", driver="a", driven="b", ratio=0.5),))
    assert err.value.key == "mechanism.gears[1].ratio"
    assert "0.5 times the crank's speed" in str(err.value)
    third = Body(name="c", points=("R", "Z"), props=DRIVEN)
    chain = Linkage(points=(*good.points, ("R", (-0.2, 0.1)), ("Z", (-0.15, 0.1))),
                    bodies=(Body(name="ground", points=("O", "P", "R")), *good.bodies[1:],
                            third),
                    inputs=("a",), gears=(Gear(name="ab", driver="a", driven="b", ratio=-2.0),
                                          Gear(name="bc", driver="b", driven="c", ratio=-0.5)))
    s = Structure.of(chain)
    mo = motion(s, InputState.crank(np.array([0.3]), np.array([5.0])))
    assert mo.rate[2][0] == pytest.approx(5.0, rel=1e-14)
