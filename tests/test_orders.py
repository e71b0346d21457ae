"""The order table against routes that share no code with it.

The tool's orders come from one FFT (:mod:`balancer.orders`). Here: a direct discrete Fourier
sum over the cycle's CSV columns (cosines and sines summed by hand), and the identities of
DESIGN.md's "Orders": a purely reciprocating force has equal forward and backward halves, a
force turning with the crank no backward part, a shaft at ratio k a pure order |k|, order 0 the
signed mean; a cycle of two revolutions has half orders.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from balancer.cycle import cycle_analysis
from balancer.orders import HIGHEST_ORDER, order_table
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parent.parent / "balancer" / "examples"
EPS = float(np.finfo(float).eps)


def _direct(values: np.ndarray, theta: np.ndarray, q: float) -> complex:
    """``(1/N)·Σ_k x_k·exp(−i·q·θ_k)`` summed term by term (no FFT)."""
    total = 0j
    for x, t in zip(values.tolist(), theta.tolist(), strict=True):
        total += x * complex(math.cos(q * t), -math.sin(q * t))
    return total / len(theta)


@pytest.mark.parametrize("name", ["meijaard2020", "engine", "quick_return", "jansen_leg"])
def test_the_orders_are_the_direct_fourier_sums_of_the_csv_columns(name):
    design = load_design(EXAMPLES / f"{name}.toml")
    op = design.operation
    analysis = cycle_analysis(design.mechanism, op.speed, op.samples)
    names, cols = analysis.columns()
    col = dict(zip(names, cols, strict=True))
    theta = analysis.theta1
    n = theta.size
    force = col["shaking_force_x"] + 1j * col["shaking_force_y"]
    couple = col["rocking_couple_x"] + 1j * col["rocking_couple_y"]
    # A sum of N terms of size up to max|x| is exact to about N·eps·max|x| (both routes).
    def tol(x):
        return 4 * n * EPS * float(np.max(np.abs(x)))

    assert len(analysis.orders) == HIGHEST_ORDER + 1
    for order in analysis.orders:
        q = order.order
        for values, whirl in ((force, order.shaking_force), (couple, order.rocking_couple)):
            fwd, bwd = _direct(values, theta, q), _direct(values, theta, -q)
            if q == 0:
                assert whirl.x == pytest.approx(fwd.real, abs=tol(values))
                assert whirl.y == pytest.approx(fwd.imag, abs=tol(values))
                assert whirl.forward == pytest.approx(abs(fwd), abs=tol(values))
                assert whirl.backward == 0.0
                continue
            assert whirl.forward == pytest.approx(abs(fwd), abs=tol(values))
            assert whirl.backward == pytest.approx(abs(bwd), abs=tol(values))
            for part, amp in ((values.real, whirl.x), (values.imag, whirl.y)):
                assert amp == pytest.approx(2 * abs(_direct(part, theta, q)), abs=tol(part))
        for key in ("shaking_moment", "driving_torque"):
            got = getattr(order, key)
            c = _direct(col[key], theta, q)
            want = c.real if q == 0 else 2 * abs(c)
            assert got == pytest.approx(want, abs=tol(col[key])), (q, key)


def test_a_reciprocating_force_whirls_both_ways_by_halves():
    theta = 2 * np.pi * np.arange(360) / 360
    direction = np.exp(0.7j)
    force = 5.0 * np.cos(3 * theta + 0.4) * direction + 2.0 * np.cos(theta) * direction
    zero = np.zeros(theta.size)
    table = order_table(force, zero, zero, zero)
    tol = 1e-13 * 5
    for q, amplitude in ((1, 2.0), (3, 5.0)):
        w = table[q].shaking_force
        assert w.forward == pytest.approx(amplitude / 2, abs=tol)
        assert w.backward == pytest.approx(amplitude / 2, abs=tol)
        assert math.hypot(w.x, w.y) == pytest.approx(amplitude, abs=tol)  # along one line
    for q in (0, 2, 4, 5, 6, 7, 8):
        assert table[q].shaking_force.forward == pytest.approx(0.0, abs=tol)


def test_a_force_turning_with_the_crank_has_no_backward_part_and_a_shaft_a_pure_order():
    theta = 2 * np.pi * np.arange(720) / 720
    zero = np.zeros(theta.size)
    # A crank's unbalance turns with it (order 1 forward); a shaft at ratio k = −2 against it.
    force = 3.0 * np.exp(1j * (theta + 0.2)) + 4.0 * np.exp(-2j * (theta - 0.3))
    table = order_table(force, zero, zero, zero)
    tol = 1e-13 * 4
    assert table[1].shaking_force.forward == pytest.approx(3.0, abs=tol)
    assert table[1].shaking_force.backward == pytest.approx(0.0, abs=tol)
    assert table[2].shaking_force.forward == pytest.approx(0.0, abs=tol)
    assert table[2].shaking_force.backward == pytest.approx(4.0, abs=tol)
    # Each component of a circle of radius A is a cosine of amplitude A.
    assert table[1].shaking_force.x == pytest.approx(3.0, abs=tol)
    assert table[1].shaking_force.y == pytest.approx(3.0, abs=tol)


def test_order_zero_is_the_signed_mean_and_scalars_their_peak_amplitude():
    theta = 2 * np.pi * np.arange(90) / 90
    moment = -1.5 + 2.5 * np.sin(2 * theta + 1.0)
    torque = 0.25 - 0.5 * np.cos(8 * theta)
    zero = np.zeros(theta.size, complex)
    table = order_table(zero + (1 - 2j), zero, moment, torque)
    assert table[0].shaking_moment == pytest.approx(-1.5, abs=1e-14)
    assert table[0].driving_torque == pytest.approx(0.25, abs=1e-14)
    assert table[0].shaking_force.x == pytest.approx(1.0) and table[0].shaking_force.y == -2.0
    assert table[0].shaking_force.forward == pytest.approx(math.sqrt(5))
    assert table[2].shaking_moment == pytest.approx(2.5, abs=1e-13)
    assert table[8].driving_torque == pytest.approx(0.5, abs=1e-13)


def test_a_cycle_of_two_revolutions_has_half_orders_and_no_order_above_half_the_samples():
    theta = 2 * np.pi * np.arange(2 * 36) / 36  # 36 samples per revolution, 720°
    zero = np.zeros(theta.size)
    torque = np.cos(theta / 2) + 0.5 * np.cos(1.5 * theta)
    table = order_table(zero.astype(complex), zero, zero, torque, revolutions=2)
    assert [o.order for o in table] == [j / 2 for j in range(17)]
    assert table[1].driving_torque == pytest.approx(1.0, abs=1e-13)  # order ½
    assert table[3].driving_torque == pytest.approx(0.5, abs=1e-13)  # order 1½
    few = order_table(np.ones(10, complex), np.zeros(10), np.zeros(10), np.zeros(10))
    assert [o.order for o in few] == [0, 1, 2, 3, 4, 5]  # none above N/2 = 5
    # At N/2 a cosine's amplitude is |X|/N and its two whirls cannot be told apart.
    nyquist = np.cos(np.pi * np.arange(10))
    last = order_table(nyquist.astype(complex), np.zeros(10), nyquist, np.zeros(10))[5]
    assert last.shaking_moment == pytest.approx(1.0)
    assert last.shaking_force.forward == pytest.approx(0.5)
    assert last.shaking_force.backward == pytest.approx(0.5)


def _four_stroke():
    """The shipped engine with a four-stroke gas table (period 4π): firing near top dead
    centre, nothing over the exhaust and intake revolution."""
    from dataclasses import replace

    from balancer.model import GasForce

    design = load_design(EXAMPLES / "engine.toml")
    engine = design.mechanism
    angles = (0.0, 0.3, 0.8, 1.6, 2.6, 3.4, 6.0, 9.0, 11.5, 12.3)
    force = (-4000.0, -5000.0, -3000.0, -1200.0, -300.0, -50.0, 0.0, -20.0, -400.0, -2500.0)
    gas = GasForce(angles=angles, values=force, period=4 * math.pi)
    return replace(engine, gas_force=gas), design.operation.speed


def test_a_four_stroke_is_analysed_over_720_degrees_with_half_orders():
    engine, speed = _four_stroke()
    analysis = cycle_analysis(engine, speed, 360)
    assert analysis.revolutions == 2 and analysis.samples == 720
    assert analysis.theta1[-1] == pytest.approx(4 * math.pi * 719 / 720)
    assert [o.order for o in analysis.orders] == [j / 2 for j in range(17)]
    assert analysis.orders[1].driving_torque > 0  # order ½: the firing every other turn
    # The same engine with the table read as one revolution's: whole orders only.
    from dataclasses import replace
    two = replace(engine, gas_force=replace(engine.gas_force, period=2 * math.pi * 1.999))
    assert cycle_analysis(two, speed, 360).revolutions == 1


def test_a_four_strokes_mean_torque_is_its_gas_work_over_the_cycle():
    """Energy: at constant speed the drive's mean torque over 720° is −(gas work)/(4π), the work
    ∮ F·dx on the piston from the closed-form stroke x(θ) by quadrature (inertia and the
    shaking do no net work over a cycle)."""
    engine, speed = _four_stroke()
    r, big_l, e = engine.lengths

    def work(n: int) -> float:
        theta = np.linspace(0.0, 4 * np.pi, n + 1)
        s = r * np.sin(theta) - e
        dx = -r * np.sin(theta) - s * r * np.cos(theta) / np.sqrt(big_l**2 - s**2)
        f = np.asarray(engine.gas_force.at(theta), float)
        values = f * dx
        return float(np.sum(values[:-1]) * (4 * np.pi / n))  # periodic: the rectangle rule

    w1, w2 = work(40_000), work(80_000)
    means = [cycle_analysis(engine, speed, n).orders[0].driving_torque for n in (360, 720)]
    want = -w2 / (4 * np.pi)
    tol = 10 * (abs(w1 - w2) / (4 * np.pi) + abs(means[0] - means[1])) + 1e-12 * abs(want)
    assert means[1] == pytest.approx(want, abs=tol)
    assert tol < 1e-6 * abs(want)  # a bound worth the name
