"""A rotor at any ratio with eccentrics (:class:`balancer.linkage.rotors.Rotor`) against sympy.

The oracle writes the rotor as point masses on a disc turning about a fixed axis at ``k·θ(t)``
for a motion ``θ(t)`` of the link: the force and the moment about the origin on the frame from
``−d/dt`` of the momentum and angular momentum (plus the weights), the rocking couple from
DESIGN's sums, and the couple on the link from the energy (``τ·θ̇ = −d/dt(T + V)``). None of it
shares code with the rotor's closed forms.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from balancer.linkage import rotors
from balancer.linkage.rotors import Eccentric, Rotor

GRAVITY = (0.5, -9.81)
ROTOR = Rotor(ratio=-2.0, inertia=0.013, axis=complex(0.12, -0.05),
              eccentrics=(Eccentric(mr=0.004, angle=0.4, z=0.1, mass=0.3),
                          Eccentric(mr=0.002, angle=2.0, z=-0.08, mass=0.1)))


def _oracle(rotor: Rotor, times: np.ndarray):
    t = sp.symbols("t", real=True)
    theta = sp.Rational(3, 10) + sp.Rational(21, 10) * t + sp.Rational(7, 10) * sp.sin(
        sp.Rational(13, 10) * t)
    gx, gy = (sp.nsimplify(g) for g in GRAVITY)
    px, py = sp.nsimplify(rotor.axis.real), sp.nsimplify(rotor.axis.imag)
    k = sp.nsimplify(rotor.ratio)
    psi0 = k * theta
    own = sp.nsimplify(rotor.inertia)  # the disc about its axis, without the point masses
    h = 0
    fx = fy = mz = mx = my = 0
    potential = 0
    kinetic = 0
    for e in rotor.eccentrics:
        m = sp.nsimplify(e.mass)
        rho = sp.nsimplify(e.mr) / m
        own -= m * rho**2
        psi = psi0 + sp.nsimplify(e.angle)
        x, y = px + rho * sp.cos(psi), py + rho * sp.sin(psi)
        vx, vy = sp.diff(x, t), sp.diff(y, t)
        ax, ay = sp.diff(vx, t), sp.diff(vy, t)
        h += m * (x * vy - y * vx)
        fx += m * gx - m * ax
        fy += m * gy - m * ay
        mz += x * m * gy - y * m * gx
        z = sp.nsimplify(e.z)
        mx += z * (m * ay - m * gy)
        my += z * (m * gx - m * ax)
        potential += -m * (gx * x + gy * y)
        kinetic += m * (vx**2 + vy**2) / 2
    h += own * sp.diff(psi0, t)
    kinetic += own * sp.diff(psi0, t) ** 2 / 2
    mz += -sp.diff(h, t)
    omega = sp.diff(theta, t)
    couple = -sp.diff(kinetic + potential, t) / omega
    names = {"theta": theta, "omega": omega, "alpha": sp.diff(omega, t), "fx": fx, "fy": fy,
             "mz": mz, "mx": mx, "my": my, "couple": couple, "kinetic": kinetic, "h": h}
    out = {}
    for name, expr in names.items():
        f = sp.lambdify(t, expr, "numpy")
        out[name] = np.array([float(f(ti)) for ti in times])
    return out


def test_a_rotor_with_eccentrics_loads_the_frame_as_its_momentum_says():
    times = np.linspace(0.0, 3.0, 13)
    want = _oracle(ROTOR, times)
    state = (want["theta"], want["omega"], want["alpha"])
    force = ROTOR.shaking_force(*state, gravity=GRAVITY)
    moment = ROTOR.shaking_moment(*state, gravity=GRAVITY)
    rocking = ROTOR.rocking_couple(*state, gravity=GRAVITY)
    couple = ROTOR.link_couple(*state, gravity=GRAVITY)
    # sympy evaluates each expression to double precision; the closed forms round a few
    # operations: 1e-12 of each figure's scale.
    for got, key in ((force.real, "fx"), (force.imag, "fy"), (moment, "mz"),
                     (rocking.real, "mx"), (rocking.imag, "my"), (couple, "couple")):
        scale = float(np.max(np.abs(want[key])))
        assert scale > 0
        assert np.max(np.abs(got - want[key])) <= 1e-12 * scale, key
    energy = ROTOR.kinetic_energy(want["omega"])
    momentum = ROTOR.angular_momentum(want["theta"], want["omega"])
    # The axis is fixed: ½·J·ψ̇² (J about the axis, eccentrics included) is all of it.
    assert np.max(np.abs(energy - want["kinetic"])) <= 1e-12 * np.max(want["kinetic"])
    assert np.max(np.abs(momentum - want["h"])) <= 1e-12 * np.max(np.abs(want["h"]))


def test_a_counter_rotor_is_the_ratio_minus_one_rotor_on_its_pivot():
    rng = np.random.default_rng(20261127)
    theta, omega, alpha = rng.uniform(-5, 5, (3, 50))
    j = 0.37
    r = Rotor.counter(j, axis=complex(0.2, 0.1))
    assert not np.any(r.shaking_force(theta, omega, alpha, gravity=GRAVITY))
    assert np.array_equal(r.shaking_moment(theta, omega, alpha), rotors.moment(j, alpha))
    assert np.array_equal(r.shaking_moment(theta, omega, alpha), j * alpha)  # +J·α: DESIGN
    assert np.array_equal(r.link_couple(theta, omega, alpha), -j * alpha)
    # The frame's share: the whole change of momentum J·α less what the link gives, −J·α.
    assert np.allclose(rotors.ground_couple(j, alpha), 2 * j * alpha, rtol=0, atol=0)
    np.testing.assert_allclose(r.kinetic_energy(omega), 0.5 * j * omega**2, rtol=4e-16)


@pytest.mark.parametrize("ratio", [-2.0, -1.0, 1.0, 2.0, 3.0])
def test_a_shaft_at_ratio_k_shakes_at_the_pure_order_k(ratio):
    """DESIGN's orders: a shaft at ratio k makes a pure order |k|, forward if k > 0."""
    from balancer.orders import order_table

    n = 360
    theta = 2 * np.pi * np.arange(n) / n
    shaft = Rotor(ratio=ratio, inertia=0.01, eccentrics=(Eccentric(mr=0.003, angle=0.7),))
    force = shaft.shaking_force(theta, 100.0, 0.0)
    zero = np.zeros(n)
    table = order_table(force, zero, zero, zero)
    q = int(abs(ratio))
    amplitude = 0.003 * (ratio * 100.0) ** 2
    whirl = table[q].shaking_force
    assert (whirl.forward if ratio > 0 else whirl.backward) == pytest.approx(amplitude, rel=1e-12)
    other = whirl.backward if ratio > 0 else whirl.forward
    assert other == pytest.approx(0.0, abs=1e-12 * amplitude)
    for o in table:
        if o.order != q:
            assert math.hypot(o.shaking_force.forward, o.shaking_force.backward) <= \
                1e-12 * amplitude


def test_a_rotor_needs_a_ratio():
    with pytest.raises(ValueError, match="ratio"):
        Rotor(ratio=0.0, inertia=1.0)
