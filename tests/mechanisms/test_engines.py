"""Engines (``type = "engine"``) against routes written here, sharing no code with the tool.

DESIGN.md, "Engines and multi-plane machines". The tool builds an engine as a general linkage of
slider-cranks on one crankshaft and solves it with its general core; here every reference is
written from the slider-crank's closed form, in each cylinder's own axes and turned into the
global ones:

- the crank pin ``P = r·e^{iα}`` with ``α = θ1 + phase − bank`` (axes along the cylinder), the
  piston pin ``W = s + i·offset``, ``s = r·cos α + D``, ``D = √(l² − h²)``, ``h = offset −
  r·sin α``, so that ``W − P = D + i·h``; the rod's centre of mass ``P + (e + i·f)(W − P)/l``,
  its angle ``bank + atan2(h, D)``; every rate and acceleration differentiated by hand (at
  constant speed ``d/dt = ω·d/dα``): exact, so the comparisons are at 1e-9 relative;
- the loads on the frame from momentum alone: the shaking force ``Σ −m·a`` (plus each rotating
  mass·radius' ``mr·k²ω²·e^{i(kθ1 + phase)}``), the rocking couple ``Mx + i·My = Σ i·z·(−m·a)``
  (DESIGN's ``Mx = Σ z·m·a_y``, ``My = −Σ z·m·a_x`` without outside loads), the shaking moment
  ``−dH_z/dt = −Σ (m·r × a + I·φ̈)`` (a shaft's eccentric: ``at × F``), and the driving torque
  from the power ``τ·ω = dT/dt − P_gas`` with ``P_gas = (p − p_crankcase)·dV/dt``;
- the harmonic coefficients ``A_n`` of the piston's acceleration by the trapezoid rule over the
  period (spectrally accurate: the integrand is analytic in a strip of half-width
  ``acosh(1/λ)``, so ``N`` points leave an aliasing error of order ``e^{−N·acosh(1/λ)}``,
  nothing at N = 256);
- the gas pressure from scipy's periodic cubic spline, the indicated work by Gauss–Legendre
  quadrature on each interval of the table.

"Zero to rounding" is measured against the scale of the terms that cancel (a cylinder's inertia
force ``m·r·ω²``, or that times the largest distance for a couple) with :data:`ZERO`: the tool's
samples come through the general core's position analysis and a linear solve (condition of a
slider-crank's Jacobian some ``l/(l − r − |offset|)`` < 10 here), sums of a few dozen terms each
within :data:`helpers.ROUNDING`, and then a DFT over ``N ≤ 1440`` samples (``N·ε`` at most):
:data:`ZERO` below, 4.6e-13.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest
from helpers import EPS, ROUNDING, derivative_with_error
from scipy.interpolate import CubicSpline

from balancer.cycle import cycle_analysis
from balancer.formulations import make
from balancer.linkage import rotors
from balancer.linkage.vectors import V
from balancer.mechanisms import geometry, mechanism_of
from balancer.mechanisms.engine.model import (
    BalanceShaft,
    Crankshaft,
    Cylinder,
    Engine,
    GasCycle,
    Mass,
)
from balancer.model import Design, Link, Operation
from balancer.simulation import simulate
from balancer.spec import dumps_design, load_design, loads_design

EXAMPLES = Path(__file__).resolve().parents[2] / "balancer" / "examples"

#: Exact routes against the tool: DESIGN.md's 1e-9 relative.
EXACT = 1e-9
#: Zero to rounding, relative to the scale of the terms that cancel: ROUNDING (64 ε) per sample
#: times the condition of the position analysis and linear solve (below 10 here: rods at least
#: three cranks long), plus the DFT's N·ε over at most N = 1440 samples.
CONDITION = 10
ZERO = CONDITION * ROUNDING + 1440 * EPS


# -- the independent route: one slider-crank in closed form ---------------------------------


@dataclass
class Kinematics:
    """One cylinder over the sampled angles (global axes, complex x + i·y)."""

    pin: np.ndarray          # crank pin P
    pin_acc: np.ndarray
    wrist: np.ndarray        # piston pin W
    wrist_vel: np.ndarray
    wrist_acc: np.ndarray
    com: np.ndarray          # rod's centre of mass
    com_vel: np.ndarray
    com_acc: np.ndarray
    spin: np.ndarray         # rod's angular velocity
    spin_acc: np.ndarray     # rod's angular acceleration
    ds: np.ndarray           # ds/dθ1, s the piston pin's place along the axis


def slider_crank(theta: np.ndarray, speed: float, *, crank: float, rod: float, offset: float,
                 phase_deg: float, bank_deg: float, e: float, f: float) -> Kinematics:
    """The closed-form slider-crank of the module's docstring, rates differentiated by hand."""
    r, l = crank, rod
    u = complex(math.cos(math.radians(bank_deg)), math.sin(math.radians(bank_deg)))
    alpha = theta + math.radians(phase_deg) - math.radians(bank_deg)
    ca, sa = np.cos(alpha), np.sin(alpha)
    h, h1, h2 = offset - r * sa, -r * ca, r * sa                 # h and its α-derivatives
    d = np.sqrt(l * l - h * h)
    g = h * r * ca                                               # −h·h'
    g1 = -r * r * ca * ca - h * r * sa
    d1 = g / d
    d2 = g1 / d - g * g / d**3
    s1 = -r * sa + d1
    s2 = -r * ca + d2
    pin = r * np.exp(1j * alpha)                                 # in the cylinder's axes
    k = complex(e, f) / l
    w2 = speed * speed
    return Kinematics(
        pin=u * pin, pin_acc=u * (-w2 * pin),
        wrist=u * (r * ca + d + 1j * offset), wrist_vel=u * (speed * s1),
        wrist_acc=u * (w2 * s2),
        com=u * (pin + k * (d + 1j * h)),
        com_vel=u * speed * (1j * pin + k * (d1 + 1j * h1)),
        com_acc=u * w2 * (-pin + k * (d2 + 1j * h2)),
        spin=speed * (h1 * d - h * d1) / (l * l),
        spin_acc=w2 * (h2 * d - h * d2) / (l * l),
        ds=s1)


def cross(a, b):
    """``a × b`` (z component) of vectors given as complex numbers."""
    return (np.conj(a) * b).imag


@dataclass
class Loads:
    """What the engine does to its frame, by the module docstring's momentum sums."""

    force: np.ndarray
    couple: np.ndarray
    moment: np.ndarray
    torque: np.ndarray           # driving torque, inertia only (no gas)
    scale_force: float           # the largest single body's force amplitude
    scale_moment: float          # the largest single term of the moment sum


def momentum_loads(engine: Engine, theta: np.ndarray, speed: float) -> Loads:
    """Shaking force, rocking couple, shaking moment and (inertia) driving torque."""
    rod, mp = engine.rod, engine.piston
    force = np.zeros(theta.size, complex)
    couple = np.zeros(theta.size, complex)
    moment = np.zeros(theta.size)
    power = np.zeros(theta.size)
    big_f = big_m = 0.0
    for c in engine.cylinders:
        # (on a geared crankshaft k = ±1 about ā: its own angle k·θ1 at the rate k·ω)
        k, at = engine.shaft_ratio(c.crankshaft), engine.shaft_axis(c.crankshaft)
        kin = slider_crank(k * theta, k * speed, crank=c.crank, rod=c.rod, offset=c.offset,
                           phase_deg=c.phase_deg, bank_deg=c.bank_deg, e=rod.e, f=rod.f)
        for m, pos, vel, acc in ((mp, at + kin.wrist, kin.wrist_vel, kin.wrist_acc),
                                 (rod.mass, at + kin.com, kin.com_vel, kin.com_acc)):
            force += -m * acc
            couple += 1j * c.z * (-m * acc)
            term = m * cross(pos, acc)
            moment -= term
            power += m * (np.conj(vel) * acc).real
            big_f = max(big_f, float(np.max(np.abs(m * acc))))
            big_m = max(big_m, float(np.max(np.abs(term))))
        moment -= rod.inertia * kin.spin_acc
        power += rod.inertia * kin.spin * kin.spin_acc
        big_m = max(big_m, float(np.max(np.abs(rod.inertia * kin.spin_acc))))
    for shaft in engine.shafts:  # each crankshaft's masses, at its ratio about its axis
        k, at = engine.shaft_ratio(shaft), engine.shaft_axis(shaft)
        for mass in engine.shaft_masses(shaft):
            f = mass.mr * speed**2 * np.exp(1j * (k * theta + math.radians(mass.phase_deg)))
            force += f
            couple += 1j * mass.z * f
            moment += cross(at, f)
            big_f = max(big_f, mass.mr * speed**2)
            big_m = max(big_m, abs(at) * mass.mr * speed**2)
    for shaft in engine.balance_shafts:
        k = shaft.ratio
        at = complex(*shaft.at)
        for ecc in shaft.eccentrics:
            f = ecc.mr * (k * speed) ** 2 * np.exp(1j * (k * theta + math.radians(ecc.phase_deg)))
            force += f
            couple += 1j * ecc.z * f
            moment += cross(at, f)
            big_f = max(big_f, ecc.mr * (k * speed) ** 2)
            big_m = max(big_m, abs(at) * ecc.mr * (k * speed) ** 2)
    return Loads(force=force, couple=couple, moment=moment, torque=power / speed,
                 scale_force=big_f, scale_moment=big_m)


def harmonic_coefficients(lam: float, orders=(1, 2, 4, 6), n: int = 256) -> dict[int, float]:
    """``A_n`` of ``x''/(r·ω²) = −Σ A_n·cos(n·α)`` for the in-line slider-crank, ``λ = r/l``.

    ``x = r·cos α + √(l² − r²·sin²α)`` from the crank's axis, so
    ``x''/(rω²) = −cos α − λ·(cos 2α/q + λ²·sin²2α/(4q³))``, ``q = √(1 − λ²·sin²α)``; the
    coefficients by the trapezoid rule over ``n`` equally spaced angles (see the module's
    docstring for why that is exact to rounding).
    """
    alpha = 2 * np.pi * np.arange(n) / n
    q = np.sqrt(1 - (lam * np.sin(alpha)) ** 2)
    acc = -np.cos(alpha) - lam * (np.cos(2 * alpha) / q
                                  + lam**2 * np.sin(2 * alpha) ** 2 / (4 * q**3))
    return {k: float(-2 * np.mean(acc * np.cos(k * alpha))) for k in orders}


def order(analysis, q: float):
    """The analysis' entry of order ``q``."""
    (entry,) = [o for o in analysis.orders if o.order == q]
    return entry


def random_rod(rng: np.random.Generator, length: float) -> Link:
    """A rod with its centre of mass on its line (``f = 0``) and any inertia."""
    m = float(rng.uniform(0.3, 0.8))
    e = float(rng.uniform(0.2, 0.45)) * length
    return Link(mass=m, inertia=m * float(rng.uniform(0.2, 0.4) * length) ** 2, e=e, f=0.0)


def flat_four(rng: np.random.Generator, *, bank_deg: float, crank=0.043, rod=0.1435,
              **kw) -> Engine:
    """A flat-plane in-line four (pins 0°, 180°, 180°, 0°) in planes symmetric about z = 0."""
    pitch = float(rng.uniform(0.08, 0.1))
    cylinders = tuple(Cylinder(z=pitch * (k - 1.5), phase_deg=p, bank_deg=bank_deg, crank=crank,
                               rod=rod, bore=0.086)
                      for k, p in enumerate((0.0, 180.0, 180.0, 0.0)))
    return Engine(cylinders=cylinders, rod=random_rod(rng, rod),
                  piston=float(rng.uniform(0.3, 0.6)), **kw)


def reciprocating_mass(engine: Engine) -> float:
    """``m_rec = m_piston + m_rod·e/l`` (the rod's small-end share; its centre on its line)."""
    return engine.piston + engine.rod.mass * engine.rod.e / engine.cylinders[0].rod


# -- 1. the harmonic coefficients --------------------------------------------------------------


def test_the_two_term_series_for_A2_is_only_the_start_of_the_exact_coefficient():
    """A2 = λ + λ³/4 + 15λ⁵/128 + (35/512)·λ⁷ + (735/16384)·λ⁹ + …, every term positive.

    The terms come from expanding √(1 − λ²sin²α) (coefficients −1/2, −1/8, −1/16, −5/128,
    −7/256, −21/1024 of x¹…x⁶) and sin^{2n}α's cos 2α coefficient ``−C(2n, n−1)/2^{2n−1}``;
    times −4 from the second derivative. At λ = 0.3 the series to λ⁵ falls short by the λ⁷ and
    λ⁹ terms (1.58e-5: the series is not exact), leaving less than the λ¹¹ term, 5.6e-8, and
    the rest (each term under a third of the last), 1e-7 in all.
    """
    lam = 0.3
    a = harmonic_coefficients(lam)
    assert a[1] == pytest.approx(1.0, abs=1e-15)
    series = lam + lam**3 / 4 + 15 * lam**5 / 128
    missing = 35 * lam**7 / 512 + 735 * lam**9 / 16384
    short = a[2] - series
    assert 1.5e-5 < short  # the series is NOT exact: it misses 1.6e-5 at λ = 0.3
    assert 0 < short - missing < 1e-7
    # A4 = −(λ³/4 + 3λ⁵/16) − …, A6 = 9λ⁵/128 + …: the next terms are O(λ⁷), under 1e-4 here
    assert abs(a[4] + lam**3 / 4 + 3 * lam**5 / 16) < 1e-4
    assert abs(a[6] - 9 * lam**5 / 128) < 1e-4
    # and as λ → 0 the series' shortfall shrinks as λ⁷: by 2⁷ per halving, corrected by the λ⁹
    # term's share ((735/16384)/(35/512)·λ² = 0.656·λ²: 5.9% at λ = 0.3, 1.5% at 0.15); the
    # λ¹¹ term's (0.464·λ⁴: 0.38% at 0.3) and the later ones' move it less than 0.5%
    small = harmonic_coefficients(lam / 2)[2] - (lam / 2 + (lam / 2) ** 3 / 4
                                                 + 15 * (lam / 2) ** 5 / 128)
    ratio = (1 + 0.656 * (lam / 2) ** 2) / (1 + 0.656 * lam**2)
    assert small == pytest.approx(short / 128 * ratio, rel=5e-3)


@pytest.mark.parametrize("seed", [1, 2])
def test_a_flat_four_shakes_at_orders_two_and_four_by_the_exact_coefficients(seed):
    """Order 2 is 4·m_rec·r·ω²·A2, order 4 is 4·m_rec·r·ω²·|A4|; odd orders vanish.

    With the rod's centre on its line at e, its centre's acceleration is
    (1 − e/l)·a_pin + (e/l)·a_piston: the pin's share turns with the crank (order 1 only), the
    rest reciprocates with the piston; the flat-plane crank's pins 0°, 180°, 180°, 0° put the
    four cylinders' even orders in phase and cancel the odd ones (their primaries sum to zero).
    A reciprocating force whirls both ways by halves. The rod's inertia is arbitrary: it adds
    no force. The DFT over 360 samples aliases orders 358, 362 into order 2: e^{−358·1.9}, none.
    """
    rng = np.random.default_rng(2026 + seed)
    bank = float(rng.uniform(0, 360))
    engine = flat_four(rng, bank_deg=bank)
    c = engine.cylinders[0]
    speed = float(rng.uniform(300, 700))
    analysis = cycle_analysis(engine, speed, 360)
    a = harmonic_coefficients(c.crank / c.rod)
    unit = 4 * reciprocating_mass(engine) * c.crank * speed**2
    one = unit / 4
    u = np.exp(1j * math.radians(bank))
    for q, coefficient in ((2, a[2]), (4, abs(a[4]))):
        w = order(analysis, q).shaking_force
        want = unit * coefficient
        assert w.forward + w.backward == pytest.approx(want, rel=EXACT), q
        assert w.forward == pytest.approx(w.backward, rel=EXACT), q
        assert w.x == pytest.approx(want * abs(u.real), abs=EXACT * want), q
        assert w.y == pytest.approx(want * abs(u.imag), abs=EXACT * want), q
    for q in (1, 3):
        w = order(analysis, q).shaking_force
        assert max(w.forward, w.backward) <= ZERO * one, q


# -- 2. the in-line six -----------------------------------------------------------------------


@pytest.mark.parametrize("phases", [(0, 120, 240, 240, 120, 0), (0, 240, 120, 120, 240, 0)])
def test_an_inline_six_has_no_free_force_or_couple_below_order_six(phases):
    """No shaking force at orders 1–5, 7, 8, no rocking couple at any order; order 6 exact.

    The throws at multiples of 120° make Σ e^{i·q·phase} vanish unless 3 | q, and a
    cylinder's reciprocating force has order 1 and even orders only, so of orders 1 … 8 only 6
    is left: 6·m_rec·r·ω²·|A6|. The mirror-symmetric planes (z_k = −z_{7−k}, equal phases)
    cancel every couple. Zero is measured against one cylinder's inertia force (times the
    farthest plane for the couple).
    """
    rng = np.random.default_rng(2026)
    pitch = 0.1
    crank, length = 0.045, 0.15
    cylinders = tuple(Cylinder(z=pitch * (k - 2.5), phase_deg=float(p), bank_deg=90.0,
                               crank=crank, rod=length) for k, p in enumerate(phases))
    engine = Engine(cylinders=cylinders, rod=random_rod(rng, length), piston=0.5)
    speed = 500.0
    analysis = cycle_analysis(engine, speed, 360)
    one = (engine.piston + engine.rod.mass) * crank * speed**2
    for entry in analysis.orders:
        w, rc = entry.shaking_force, entry.rocking_couple
        assert max(rc.forward, rc.backward) <= ZERO * one * 2.5 * pitch, entry.order
        if entry.order == 6:
            a6 = harmonic_coefficients(crank / length)[6]
            assert w.forward + w.backward == pytest.approx(
                6 * reciprocating_mass(engine) * crank * speed**2 * abs(a6), rel=EXACT)
        else:
            assert max(w.forward, w.backward) <= ZERO * one, entry.order


# -- 3. the 90° V-twin ------------------------------------------------------------------------


def test_a_ninety_degree_v_twin_on_one_pin_has_a_primary_that_a_counterweight_cancels():
    """The primary is a pure forward whirl (m_rec + 2·m_rod·(1 − e/l))·r·ω², along the pin.

    Cylinder k's reciprocating primary is m_rec·r·ω²·cos(θ1 + φ − b_k)·e^{i·b_k} =
    (m_rec·r·ω²/2)·(e^{i(θ1 + φ)} + e^{−i(θ1 + φ)}·e^{2i·b_k}); with b_2 = b_1 + 90° the
    backward halves cancel (e^{2i·b_1} + e^{2i·b_2} = 0) and the forward halves add to
    m_rec·r·ω²·e^{i(θ1 + φ)}: a force of constant size turning with the pin. The rods' big-end
    shares, m_rod·(1 − e/l) each, turn with the pin too. So one counterweight of
    mr = r·(m_rec + 2·m_rod·(1 − e/l)) opposite the pin, in the cylinders' plane, cancels the
    whole of order 1, force and couple (not m_rec·r alone: that leaves the rods' big ends).
    """
    rng = np.random.default_rng(2026)
    crank, length = 0.04, 0.13
    phase = float(rng.uniform(0, 360))
    bank = float(rng.uniform(0, 360))
    plane = 0.02
    cylinders = tuple(Cylinder(z=plane, phase_deg=phase, bank_deg=b, crank=crank, rod=length)
                      for b in (bank, bank + 90.0))
    engine = Engine(cylinders=cylinders, rod=random_rod(rng, length), piston=0.4)
    speed = 600.0
    rod = engine.rod
    rotating = 2 * rod.mass * (1 - rod.e / length)
    primary = (reciprocating_mass(engine) + rotating) * crank * speed**2
    w = order(cycle_analysis(engine, speed, 360), 1).shaking_force
    assert w.forward == pytest.approx(primary, rel=EXACT)
    assert w.backward <= ZERO * primary
    assert w.x == pytest.approx(primary, rel=EXACT)  # a circle: both components' amplitude
    assert w.y == pytest.approx(primary, rel=EXACT)

    def countered(mr: float):
        weight = Mass(mr=mr, phase_deg=phase + 180.0, z=plane, label="counterweight")
        balanced = Engine(cylinders=cylinders, rod=rod, piston=engine.piston,
                          crankshaft=Crankshaft(inertia=0.01, masses=(weight,)))
        return order(cycle_analysis(balanced, speed, 360), 1)

    first = countered((reciprocating_mass(engine) + rotating) * crank)
    for whirl, scale in ((first.shaking_force, primary), (first.rocking_couple, primary * plane)):
        assert max(whirl.forward, whirl.backward) <= ZERO * scale
    # m_rec·r alone cancels the reciprocating primary and leaves the big ends turning
    first = countered(reciprocating_mass(engine) * crank)
    assert first.shaking_force.forward == pytest.approx(rotating * crank * speed**2, rel=EXACT)
    assert first.shaking_force.backward <= ZERO * primary


# -- 4. Lanchester shafts ---------------------------------------------------------------------


@pytest.mark.parametrize("bank", [90.0, None])
def test_lanchester_shafts_cancel_order_two_and_leave_order_four(bank):
    """Two shafts at ±2× with mr = m_rec·r·A2/2 cancel the flat four's order 2; 4 unchanged.

    The order-2 force is 4·m_rec·r·ω²·A2·cos(2θ1 − 2b)·e^{ib} = 2·m_rec·r·ω²·A2·
    (e^{i(2θ1 − b)} + e^{−i(2θ1 − 3b)}); a shaft at ratio k shakes with mr·k²ω²·e^{i(kθ1 + ψ)},
    so mr = m_rec·r·A2/2 at ψ = 180° − b (ratio +2) and ψ = 180° + 3b (ratio −2) cancel it:
    upright (b = 90°) both at 90°, as examples/inline_four.toml has them. The shafts add order 2
    only, so order 4 is the engine's without them.
    """
    rng = np.random.default_rng(2027)
    bank = float(rng.uniform(0, 360)) if bank is None else bank
    plain = flat_four(rng, bank_deg=bank)
    c = plain.cylinders[0]
    a2 = harmonic_coefficients(c.crank / c.rod)[2]
    mr = reciprocating_mass(plain) * c.crank * a2 / 2
    shafts = (BalanceShaft(ratio=2, at=(-0.07, -0.1), inertia=4e-4,
                           eccentrics=(Mass(mr=mr, phase_deg=180.0 - bank),)),
              BalanceShaft(ratio=-2, at=(0.07, -0.1), inertia=4e-4,
                           eccentrics=(Mass(mr=mr, phase_deg=180.0 + 3 * bank),)))
    shafted = Engine(cylinders=plain.cylinders, rod=plain.rod, piston=plain.piston,
                     balance_shafts=shafts)
    speed = 628.3185307179587
    before, after = (cycle_analysis(e, speed, 360) for e in (plain, shafted))
    scale = 4 * reciprocating_mass(plain) * c.crank * speed**2
    w = order(before, 2).shaking_force
    assert w.forward + w.backward == pytest.approx(scale * a2, rel=EXACT)
    w = order(after, 2).shaking_force
    assert max(w.forward, w.backward) <= ZERO * scale
    rc = order(after, 2).rocking_couple
    assert max(rc.forward, rc.backward) <= ZERO * scale * 0.15
    four_before, four_after = order(before, 4).shaking_force, order(after, 4).shaking_force
    for key in ("x", "y", "forward", "backward"):
        assert getattr(four_after, key) == pytest.approx(getattr(four_before, key),
                                                         abs=ZERO * scale), key


# -- 5. the engine as separate slider-cranks --------------------------------------------------


def random_engine(rng: np.random.Generator, n: int) -> Engine:
    """``n`` cylinders with their own lengths, offsets, banks, planes; masses; one shaft."""
    cylinders = []
    for k in range(n):
        crank = float(rng.uniform(0.03, 0.05))
        offset = float(rng.uniform(-0.3, 0.3)) * crank
        cylinders.append(Cylinder(
            z=float(rng.uniform(-0.15, 0.15)),
            phase_deg=float(360 * k / n + rng.uniform(-20, 20)),
            bank_deg=float(rng.uniform(0, 360)), crank=crank,
            rod=float(rng.uniform(3.0, 4.0)) * crank, offset=offset))
    length = min(c.rod for c in cylinders)
    rod = Link(mass=float(rng.uniform(0.3, 0.8)), inertia=float(rng.uniform(1e-3, 3e-3)),
               e=float(rng.uniform(0.2, 0.5)) * length, f=float(rng.uniform(-0.1, 0.1)) * length)
    masses = tuple(Mass(mr=float(rng.uniform(0.0, 0.02)), phase_deg=float(rng.uniform(0, 360)),
                        z=float(rng.uniform(-0.15, 0.15))) for _ in range(3))
    shaft = BalanceShaft(ratio=int(rng.choice([-2, -1, 1, 2, 3])),
                         at=(float(rng.uniform(-0.1, 0.1)), float(rng.uniform(-0.1, 0.1))),
                         inertia=float(rng.uniform(0, 1e-3)),
                         eccentrics=tuple(Mass(mr=float(rng.uniform(0.0, 0.005)),
                                               phase_deg=float(rng.uniform(0, 360)),
                                               z=float(rng.uniform(-0.15, 0.15)))
                                          for _ in range(2)))
    return Engine(cylinders=tuple(cylinders), rod=rod, piston=float(rng.uniform(0.3, 0.6)),
                  crankshaft=Crankshaft(inertia=0.02, masses=masses), balance_shafts=(shaft,))


@pytest.mark.parametrize("n, seed", [(3, 1), (3, 2), (6, 3), (2, 4)])
def test_an_engine_shakes_as_the_sum_of_its_slider_cranks(n, seed):
    """Shaking force, rocking couple, shaking moment and driving torque, sample by sample.

    The reference is the module docstring's momentum sums over closed-form slider-cranks with
    offsets, banks and lengths of their own, the rod's centre off its line, masses on the
    crankshaft in several planes and a shaft with eccentrics in two: exact, so 1e-9 of each
    quantity's largest sample.
    """
    rng = np.random.default_rng(2026 * seed)
    engine = random_engine(rng, n)
    speed = float(rng.uniform(200, 700))
    analysis = cycle_analysis(engine, speed, 720)
    want = momentum_loads(engine, analysis.theta1, speed)
    r = analysis.reactions
    for got, ref in ((r.shaking_force, want.force), (r.rocking_couple, want.couple),
                     (r.shaking_moment, want.moment), (r.driving_torque, want.torque)):
        scale = float(np.max(np.abs(ref)))
        assert scale > 0
        assert np.max(np.abs(got - ref)) <= EXACT * scale


# -- 6. gas -----------------------------------------------------------------------------------


def example_gas() -> GasCycle:
    """The pressure table of examples/inline_four.toml, read as plain TOML (not by the tool)."""
    data = tomllib.loads((EXAMPLES / "inline_four.toml").read_text())["gas"]
    return GasCycle(crank_angle_deg=tuple(data["crank_angle_deg"]),
                    pressure=tuple(data["pressure"]), crankcase=data["crankcase"])


def pressure_spline(engine: Engine) -> CubicSpline:
    """The periodic cubic spline through the table, over the angle from firing (rad).

    Its period is the working cycle's, 180°·strokes.
    """
    gas = engine.gas
    a = np.radians(np.r_[gas.crank_angle_deg, gas.crank_angle_deg[0] + 180 * engine.strokes])
    p = np.r_[gas.pressure, gas.pressure[0]]
    return CubicSpline(a, p, bc_type="periodic")


def gas_torque(engine: Engine, theta: np.ndarray, speed: float, firings: dict[int, float]):
    """The gas' part of the driving torque: Σ (p − p_crankcase)·A·ds/dθ1 over the cylinders.

    ``firings``: cylinder (from 1) → its firing angle, rad; each follows the spline from it.
    """
    spline = pressure_spline(engine)
    period = math.pi * engine.strokes
    total = np.zeros(theta.size)
    for k, fire in firings.items():
        c = engine.cylinders[k - 1]
        ratio = engine.shaft_ratio(c.crankshaft)  # (ds/dθ1 = ratio·ds/dψ on its own crank)
        kin = slider_crank(ratio * theta, ratio * speed, crank=c.crank, rod=c.rod,
                           offset=c.offset, phase_deg=c.phase_deg, bank_deg=c.bank_deg,
                           e=0.0, f=0.0)
        p = spline(np.mod(theta - fire, period))
        total += (p - engine.gas.crankcase) * (math.pi * c.bore**2 / 4) * ratio * kin.ds
    return total


def one_cylinder(gas: GasCycle | None, *, strokes=4, phase=30.0, bank=90.0,
                 offset=0.002) -> Engine:
    """One cylinder with an offset, firing at θ1 = bank − phase = 60°."""
    c = Cylinder(z=0.0, phase_deg=phase, bank_deg=bank, crank=0.043, rod=0.1435,
                 offset=offset, bore=0.086)
    return Engine(cylinders=(c,), rod=Link(mass=0.55, inertia=0.0021, e=0.036, f=0.0),
                  piston=0.45, strokes=strokes, firing_order=(1,), gas=gas)


def indicated_work(engine: Engine, nodes: int) -> float:
    """∮(p − p_crankcase)·dV over cylinder 1's cycle, by Gauss–Legendre on each interval.

    ``dV = −A·ds``; between two points of the table the pressure is one cubic and ``ds/dθ1``
    analytic, so ``nodes`` points per interval integrate it to rounding once ``nodes`` is
    enough (the caller compares two).
    """
    c = engine.cylinders[0]
    spline = pressure_spline(engine)
    knots = spline.x
    fire = (math.radians(c.bank_deg) - math.radians(c.phase_deg)) % (2 * math.pi)
    x, wts = np.polynomial.legendre.leggauss(nodes)
    total = 0.0
    for a, b in zip(knots[:-1], knots[1:], strict=True):
        phi = 0.5 * (b - a) * x + 0.5 * (a + b)
        kin = slider_crank(phi + fire, 1.0, crank=c.crank, rod=c.rod, offset=c.offset,
                           phase_deg=c.phase_deg, bank_deg=c.bank_deg, e=0.0, f=0.0)
        dv = -(math.pi * c.bore**2 / 4) * kin.ds
        total += 0.5 * (b - a) * float(np.dot(wts, (spline(phi) - engine.gas.crankcase) * dv))
    return total


def trapezoid_bound(engine: Engine, samples: int) -> float:
    """Bound on the sample mean's error for the gas torque g(θ1) over the working cycle.

    g is C² (the spline is) with g''' of bounded variation V; integrating by parts four times,
    its Fourier coefficient at frequency ω_j = 2π·j/L (L the cycle's angle: 4π, or 2π for a
    two-stroke) is at most V/(L·ω_j⁴), and the mean of M equally spaced samples over the cycle
    is off by the coefficients at j = ±M, ±2M, …: at most 2·ζ(4)·V/(L·ω_M⁴). V is the discrete
    variation of g''' on a grid of 64 points in each interval of the table (both sides of each
    of its points), doubled for what the grid misses.
    """
    c = engine.cylinders[0]
    spline = pressure_spline(engine)
    fire = (math.radians(c.bank_deg) - math.radians(c.phase_deg)) % (2 * math.pi)
    area = math.pi * c.bore**2 / 4
    # derivatives of q(φ) = A·ds/dθ1 up to the third, spectrally from 256 samples of s (analytic)
    n = 256
    grid = 2 * np.pi * np.arange(n) / n
    s = slider_crank(grid, 1.0, crank=c.crank, rod=c.rod, offset=c.offset, phase_deg=0.0,
                     bank_deg=0.0, e=0.0, f=0.0).wrist.real
    coef = np.fft.rfft(s) / n
    ks = np.arange(coef.size)
    coef[-1] = 0.0

    def q_derivative(alpha, m):  # d^m/dα^m of A·ds/dα, α measured as the cylinder's own
        terms = (2 - (ks == 0)) * coef * (1j * ks) ** (m + 1)
        return area * (np.exp(1j * np.outer(alpha, ks)) @ terms).real

    variation = 0.0
    previous_end = None
    first_start = None
    for i, (a, b) in enumerate(zip(spline.x[:-1], spline.x[1:], strict=True)):
        phi = np.linspace(a, b, 64)
        alpha = phi + fire + math.radians(c.phase_deg) - math.radians(c.bank_deg)
        local = phi - a
        cc = spline.c[:, i]
        p = [cc[0] * local**3 + cc[1] * local**2 + cc[2] * local + cc[3] - engine.gas.crankcase,
             3 * cc[0] * local**2 + 2 * cc[1] * local + cc[2],
             6 * cc[0] * local + 2 * cc[1],
             6 * cc[0] * np.ones_like(local)]
        q = [q_derivative(alpha, m) for m in range(4)]
        g3 = p[0] * q[3] + 3 * p[1] * q[2] + 3 * p[2] * q[1] + p[3] * q[0]
        variation += float(np.sum(np.abs(np.diff(g3))))
        if previous_end is not None:
            variation += abs(g3[0] - previous_end)
        else:
            first_start = g3[0]
        previous_end = g3[-1]
    variation += abs(first_start - previous_end)
    variation *= 2
    length = math.pi * engine.strokes
    return 2 * (math.pi**4 / 90) * variation / (length * (2 * math.pi * samples / length) ** 4)


@pytest.mark.parametrize("strokes", [4, 2])
@pytest.mark.slow
def test_a_single_cylinders_mean_torque_is_its_indicated_work_over_the_cycle(strokes):
    """Mean driving torque = −W/L, W = ∮(p − p_crankcase)·dV; and every sample exact.

    L is the cycle's angle: 4π for a four-stroke (analysed over 720°), 2π for a two-stroke
    (the example's table squeezed into 360°, analysed over one revolution). Sample by sample
    the tool's driving torque is the inertia torque (from dT/dt) plus the gas part
    (p − p_crankcase)·A·ds/dθ1, p from scipy's periodic spline started at the firing top dead
    centre θ1 = bank − phase: 1e-9 of the largest sample. The mean: W by Gauss–Legendre (20
    and 40 points per interval agree to rounding, 1e-12, and their difference is added to the
    bound); the tool's mean is the mean of its samples, whose error from the exact mean is the
    trapezoid rule's on a C² integrand (:func:`trapezoid_bound`), plus the inertia torque's,
    whose mean is zero and whose aliasing at order 720 is e^{−720·1.9}: none.
    """
    gas = example_gas()
    if strokes == 2:
        gas = GasCycle(crank_angle_deg=tuple(a / 2 for a in gas.crank_angle_deg),
                       pressure=gas.pressure, crankcase=gas.crankcase)
    engine = one_cylinder(gas, strokes=strokes)
    cycle = math.pi * strokes
    speed, samples = 628.3185307179587, 720
    analysis = cycle_analysis(engine, speed, samples)
    assert analysis.revolutions == strokes // 2
    theta = analysis.theta1
    c = engine.cylinders[0]
    fire = (math.radians(c.bank_deg) - math.radians(c.phase_deg)) % (2 * math.pi)
    want = (momentum_loads(engine, theta, speed).torque
            + gas_torque(engine, theta, speed, {1: fire}))
    got = analysis.reactions.driving_torque
    assert np.max(np.abs(got - want)) <= EXACT * np.max(np.abs(want))

    work, finer = indicated_work(engine, 20), indicated_work(engine, 40)
    quadrature = abs(work - finer)
    assert quadrature <= 1e-12 * abs(work)  # the quadrature's own error: rounding
    assert work > 0  # a firing engine does work
    mean = order(analysis, 0).driving_torque
    bound = trapezoid_bound(engine, theta.size) + quadrature / cycle
    rounding = theta.size * EPS * float(np.max(np.abs(got)))
    assert abs(mean - (-work / cycle)) <= bound + rounding
    assert bound < 1e-4 * abs(work / cycle)  # (a bound worth the name)


def test_each_cylinder_of_a_four_follows_cylinder_ones_pressure_from_its_own_firing():
    """A flat four firing 1-3-4-2: the driving torque sample by sample, and 4× one's mean.

    Cylinder 1 fires at its top dead centre t1 = bank (pin at 0°), then 3, 4, 2 at their next
    ones: t1 + π, t1 + 2π, t1 + 3π; each follows the same spline from there. The firings are
    whole numbers of samples apart (π is 360 samples), so the 4-cylinder sample mean is four
    times the single cylinder's (its cylinder 1 alone) to rounding; the inertia torques' means
    are zero (to aliasing at order 720, none).
    """
    rng = np.random.default_rng(2026)
    gas = example_gas()
    bank = 90.0
    four = flat_four(rng, bank_deg=bank, firing_order=(1, 3, 4, 2), gas=gas)
    speed, samples = 628.3185307179587, 720
    analysis = cycle_analysis(four, speed, samples)
    theta = analysis.theta1
    t1 = math.radians(bank) % (2 * math.pi)
    firings = {1: t1, 3: t1 + math.pi, 4: t1 + 2 * math.pi, 2: t1 + 3 * math.pi}
    want = momentum_loads(four, theta, speed).torque + gas_torque(four, theta, speed, firings)
    got = analysis.reactions.driving_torque
    assert np.max(np.abs(got - want)) <= EXACT * np.max(np.abs(want))

    single = Engine(cylinders=four.cylinders[:1], rod=four.rod, piston=four.piston,
                    firing_order=(1,), gas=gas)
    alone = cycle_analysis(single, speed, samples)
    scale = float(np.max(np.abs(got)))
    mean4, mean1 = order(analysis, 0).driving_torque, order(alone, 0).driving_torque
    assert mean1 < 0  # it drives its load
    assert abs(mean4 - 4 * mean1) <= theta.size * EPS * scale * 4


# -- 7. the mounts' torque --------------------------------------------------------------------


def test_the_mounts_torque_is_the_shaking_moment_plus_the_driving_torque():
    """Sample by sample (the load is off the frame), and in the order table (its DFT)."""
    design = load_design(EXAMPLES / "inline_four.toml")
    op = design.operation
    analysis = cycle_analysis(design.mechanism, op.speed, op.samples)
    r = analysis.reactions
    total = r.shaking_moment + r.driving_torque
    scale = float(np.max(np.abs(r.shaking_moment)) + np.max(np.abs(r.driving_torque)))
    assert np.max(np.abs(analysis.mount_torque - total)) <= EPS * scale
    theta = analysis.theta1
    n = theta.size
    for entry in analysis.orders:
        c = np.sum(total * np.exp(-1j * entry.order * theta)) / n
        want = c.real if entry.order == 0 else 2 * abs(c)
        assert entry.mount_torque == pytest.approx(want, abs=4 * n * EPS * scale)


def test_two_mass_rods_on_the_axis_leave_no_shaking_moment():
    """Rods with I = m·e·(l − e), centre on the line, no offset, shafts on the crank's axis.

    Such a rod is two point masses at its pins (same mass, centre and inertia); the big end's
    mass turns on a circle about O (its acceleration points at O), the small end's and the
    piston slide on lines through O: no r × a, no angular momentum change, so the shaking moment
    about z vanishes and the mounts feel the driving torque alone. The shaft on the axis adds
    at × F = 0; the crankshaft's masses none. Zero against the largest term that cancels.
    """
    rng = np.random.default_rng(2026)
    length = 0.14
    cylinders = tuple(Cylinder(z=float(rng.uniform(-0.1, 0.1)),
                               phase_deg=float(rng.uniform(0, 360)),
                               bank_deg=float(rng.uniform(0, 360)),
                               crank=float(rng.uniform(0.03, 0.045)), rod=length)
                      for _ in range(4))
    m, e = 0.55, 0.04
    rod = Link(mass=m, inertia=m * e * (length - e), e=e, f=0.0)
    shaft = BalanceShaft(ratio=-1, at=(0.0, 0.0), inertia=1e-4,
                         eccentrics=(Mass(mr=0.004, phase_deg=33.0, z=0.05),))
    engine = Engine(cylinders=cylinders, rod=rod, piston=0.45,
                    crankshaft=Crankshaft(inertia=0.02, masses=(Mass(mr=0.01, phase_deg=10.0,
                                                                     z=0.1),)),
                    balance_shafts=(shaft,))
    speed = 600.0
    analysis = cycle_analysis(engine, speed, 720)
    ref = momentum_loads(engine, analysis.theta1, speed)
    r = analysis.reactions
    assert np.max(np.abs(ref.moment)) <= ZERO * ref.scale_moment  # the route agrees it is zero
    assert np.max(np.abs(r.shaking_moment)) <= ZERO * ref.scale_moment
    assert np.max(np.abs(analysis.mount_torque - r.driving_torque)) <= ZERO * ref.scale_moment
    assert np.max(np.abs(r.driving_torque)) > 1.0  # (the torque itself is no rounding)


# -- 8. specs ---------------------------------------------------------------------------------


def test_the_inline_four_example_round_trips_through_its_spec():
    design = load_design(EXAMPLES / "inline_four.toml")
    text = dumps_design(design)
    again = loads_design(text)
    assert again.mechanism == design.mechanism
    assert again == design
    assert dumps_design(again) == text


@pytest.mark.parametrize("strokes", [4, 2])
def test_an_engine_with_its_own_lengths_shafts_and_gas_round_trips(strokes):
    rng = np.random.default_rng(2026 + strokes)

    def number(lo, hi):
        return float(rng.uniform(lo, hi))

    cylinders = tuple(Cylinder(z=number(-0.2, 0.2), phase_deg=number(0, 360),
                               bank_deg=number(-90, 90), crank=number(0.03, 0.05),
                               rod=number(0.12, 0.16), offset=number(-0.005, 0.005),
                               bore=number(0.07, 0.09)) for _ in range(3))
    masses = tuple(Mass(mr=number(0, 0.02), phase_deg=number(0, 360), z=number(-0.2, 0.2),
                        label=label) for label in ("", "counterweight", "web \"3\""))
    shafts = tuple(BalanceShaft(ratio=k, at=(number(-0.1, 0.1), number(-0.1, 0.1)),
                                inertia=number(0, 1e-3),
                                eccentrics=tuple(Mass(mr=number(0, 0.005),
                                                      phase_deg=number(0, 360),
                                                      z=number(-0.1, 0.1)) for _ in range(2)))
                   for k in (2, -2))
    cycle = 180 * strokes
    angles = tuple(sorted(number(0, cycle) for _ in range(40)))
    gas = GasCycle(crank_angle_deg=(0.0, *angles), pressure=tuple(
        number(9e4, 6e6) for _ in range(41)), crankcase=number(9e4, 1.1e5))
    engine = Engine(cylinders=cylinders,
                    crankshaft=Crankshaft(inertia=number(0.01, 0.03), mass=number(5, 15),
                                          masses=masses),
                    rod=Link(mass=number(0.4, 0.7), inertia=number(1e-3, 3e-3),
                             e=number(0.02, 0.05), f=number(-0.005, 0.005)),
                    piston=number(0.3, 0.6), balance_shafts=shafts, strokes=strokes,
                    firing_order=(1, 3, 2) if strokes == 2 else (2, 1, 3), gas=gas)
    design = Design(mechanism=engine, operation=Operation(speed=number(100, 700), samples=360),
                    title="three cylinders of their own")
    text = dumps_design(design)
    again = loads_design(text)
    assert again.mechanism == engine
    assert again == design
    assert dumps_design(again) == text


def test_a_spec_with_bores_that_differ_or_are_missing_reads_back_exactly():
    """The writer puts a bore in [mechanism.lengths] only when every cylinder shares it."""
    from dataclasses import replace

    from balancer import examples
    from balancer.spec import dumps_design, loads_design

    design = examples.load("inline_four")
    engine = design.mechanism
    mixed = list(engine.cylinders)
    mixed[2] = replace(mixed[2], bore=0.09)
    unbored = [replace(c, bore=None) if i == 0 else c for i, c in enumerate(engine.cylinders)]
    for cylinders, gas in ((mixed, engine.gas), (unbored, None)):
        changed = replace(engine, cylinders=tuple(cylinders), gas=gas)
        again = loads_design(dumps_design(replace(design, mechanism=changed)))
        assert again.mechanism == changed


# -- 9. the shipped engines -------------------------------------------------------------------


def shipped_engines() -> list[str]:
    """The examples whose spec says ``type = "engine"`` (read as plain TOML)."""
    return sorted(p.stem for p in EXAMPLES.glob("*.toml")
                  if tomllib.loads(p.read_text())["mechanism"]["type"] == "engine")


def firing_angles(engine: Engine) -> dict[int, float]:
    """DESIGN's rule, written here: the first in the order at its first top dead centre at or
    after θ1 = 0, each next at its own first top dead centre after the previous firing (rad)."""
    out: dict[int, float] = {}
    previous = None
    for k in engine.firing_order:
        c = engine.cylinders[k - 1]  # (its pin at ratio·θ1 + phase: ratio ±1)
        ratio = engine.shaft_ratio(c.crankshaft)
        tdc = math.radians(ratio * (c.bank_deg - c.phase_deg)) % (2 * math.pi)
        if previous is None:
            out[k] = tdc
        else:
            step = (tdc - previous) % (2 * math.pi)
            out[k] = previous + (step if step > 1e-12 else 2 * math.pi)
        previous = out[k]
    return out


def test_every_engine_layout_ships_as_an_example():
    """The issue's five: one cylinder, in-line three and four, 60° V6, cross-plane V8."""
    assert set(shipped_engines()) >= {"single_cylinder", "inline_three", "inline_four", "v6",
                                      "v8"}


@pytest.mark.parametrize("name", shipped_engines())
@pytest.mark.slow
def test_a_shipped_engine_shakes_and_drives_as_its_slider_cranks_summed(name):
    """Every figure of the example's cycle, sample by sample, from the momentum sums and the
    gas torque of the spline started at each cylinder's firing: 1e-9 of the largest sample."""
    design = load_design(EXAMPLES / f"{name}.toml")
    engine, op = design.mechanism, design.operation
    analysis = cycle_analysis(engine, op.speed, op.samples)
    theta = analysis.theta1
    want = momentum_loads(engine, theta, op.speed)
    torque = want.torque
    if engine.gas is not None:
        torque = torque + gas_torque(engine, theta, op.speed, firing_angles(engine))
    r = analysis.reactions
    for got, ref, scale in ((r.shaking_force, want.force, want.scale_force),
                            (r.rocking_couple, want.couple, want.scale_moment),
                            (r.shaking_moment, want.moment, want.scale_moment),
                            (r.driving_torque, torque, float(np.max(np.abs(torque))))):
        assert np.max(np.abs(got - ref)) <= EXACT * max(float(np.max(np.abs(ref))),
                                                        ZERO / EXACT * scale)


@pytest.mark.parametrize("name", shipped_engines())
def test_a_shipped_engine_round_trips_through_its_spec(name):
    design = load_design(EXAMPLES / f"{name}.toml")
    text = dumps_design(design)
    again = loads_design(text)
    assert again == design
    assert dumps_design(again) == text


def test_the_single_cylinders_primary_is_what_its_balance_factor_leaves():
    """One cylinder, rod centre on its line, no offset: the piston pin's first harmonic is
    exactly r·cos α (the rest of its motion, √(l² − r²sin²α), has period π), and the rod is
    m_rod·(1 − e/l) at the crank pin plus m_rod·e/l at the piston pin. So order 1 is the
    crankshaft's Σ mr·e^{iφ} and the big end's rotating forward, plus m_rec·r·ω² along the axis,
    half forward and half backward: backward ½·m_rec·r·ω² (the half a counterweight cannot
    reach), forward |Σ mr·e^{iφ} + (m_rod(1 − e/l) + ½m_rec)·r·e^{i·phase}|·ω²."""
    engine = load_design(EXAMPLES / "single_cylinder.toml").mechanism
    speed = 600.0
    analysis = cycle_analysis(engine, speed, 360)
    (c,) = engine.cylinders
    rod = engine.rod
    m_rec = engine.piston + rod.mass * rod.e / c.rod
    rotating = sum(m.mr * np.exp(1j * math.radians(m.phase_deg))
                   for m in engine.crankshaft.masses)
    rotating += (rod.mass * (1 - rod.e / c.rod) + m_rec / 2) * c.crank * np.exp(
        1j * math.radians(c.phase_deg))
    first = order(analysis, 1).shaking_force
    scale = m_rec * c.crank * speed**2
    assert first.backward == pytest.approx(scale / 2, rel=EXACT)
    assert abs(first.forward - abs(rotating) * speed**2) <= ZERO * scale
    assert first.forward < 1e-3 * scale  # (balanced to the spec's rounding of its mr)


def test_the_inline_threes_secondary_couple_is_root_three_s_m_rec_r_A2():
    """Pins 0°, 120°, 240° at z = −s, 0, s: order 2 of the couple Σ i·z·m_rec·A2·r·ω²·cos(2α)·u
    has |Σ z·e^{2iφ}| = √3·s, half turning each way: √3/2·s·m_rec·r·ω²·A2 forward and backward
    (the rods' turning adds no force: their centres are on their lines). The primary couple is
    cancelled, to the spec's rounding, by the end webs (forward) and the shaft (backward)."""
    engine = load_design(EXAMPLES / "inline_three.toml").mechanism
    speed = 600.0
    analysis = cycle_analysis(engine, speed, 720)
    c = engine.cylinders
    s = c[2].z
    assert [x.z for x in c] == [-s, 0.0, s]
    rod = engine.rod
    m_rec = engine.piston + rod.mass * rod.e / c[0].rod
    a2 = harmonic_coefficients(c[0].crank / c[0].rod)[2]
    want = math.sqrt(3) / 2 * s * m_rec * c[0].crank * speed**2 * a2
    second = order(analysis, 2).rocking_couple
    assert second.forward == pytest.approx(want, rel=EXACT)
    assert second.backward == pytest.approx(want, rel=EXACT)
    primary = order(analysis, 1).rocking_couple
    full = math.sqrt(3) / 2 * s * m_rec * c[0].crank * speed**2
    assert primary.forward < 1e-3 * full and primary.backward < 1e-3 * full


@pytest.mark.parametrize("name", shipped_engines())
@pytest.mark.slow
def test_a_shipped_engine_driven_in_the_multibody_formulation_has_its_cycles_figures(name):
    """``verify``'s driven run: the multibody formulation at the operating speed over the
    working cycle, outputs on the analysis' samples. Driven, the crank angle is exact and the
    other coordinates are projected onto the constraints at every output, so the multipliers
    (a route apart from the cycle analysis' group-by-group inverse dynamics) must give the same
    shaking force, rocking couple, shaking moment and driving torque (gas included), and the
    main bearings' reaction: 1e-9 of each one's largest sample (of the moments' largest term
    where that is rounding)."""
    from dataclasses import replace

    from balancer.simulation import simulate

    design = load_design(EXAMPLES / f"{name}.toml")
    engine, op = design.mechanism, design.operation
    analysis = cycle_analysis(engine, op.speed, op.samples)
    n = analysis.theta1.size
    period = 2 * math.pi * analysis.revolutions / op.speed
    settings = replace(design.simulation, drive="constant-speed", omega1=op.speed, theta1=0.0,
                       duration=period * (n - 1) / n)
    traj = simulate(engine, settings, method="multibody", rtol=1e-10, atol=1e-12, outputs=n)
    assert np.allclose(traj.t * op.speed, analysis.theta1, rtol=0, atol=1e-12)
    want = momentum_loads(engine, analysis.theta1, op.speed)
    r = analysis.reactions
    for got, ref, scale in ((traj.shaking_force, r.shaking_force, want.scale_force),
                            (traj.rocking_couple, r.rocking_couple, want.scale_moment),
                            (traj.shaking_moment, r.shaking_moment, want.scale_moment),
                            (traj.driving_torque, r.driving_torque, want.scale_moment),
                            (traj.ground["O"], r.ground["O"], want.scale_force)):
        assert np.max(np.abs(got - ref)) <= EXACT * max(float(np.max(np.abs(ref))), scale)


@pytest.mark.parametrize("method", ["crank-angle", "multibody"])
@pytest.mark.parametrize("shaft", [None, -1, 2])
def test_an_engine_with_eccentrics_moves_under_gravity_as_its_weights_say(shaft, method):
    """The weights of the single cylinder's crankshaft masses (k = 1), and of a shaft's
    eccentric geared at k = −1 or 2, turn the crank. At rest the crank's acceleration is
    −V′(θ)/m(θ): ``V`` the potential of every weight, −ḡ·(Σ first moments: links and rotors),
    differentiated numerically; ``m`` twice the kinetic energy at unit crank rate, from the
    links' own velocities and the rotors' inertias. Free from rest, the energy balances (the
    weights' work from the rotors' first moments)."""
    design = load_design(EXAMPLES / "single_cylinder.toml")
    engine = replace(design.mechanism, gas=None)  # (the weights alone turn it)
    if shaft is not None:
        engine = replace(engine, balance_shafts=(BalanceShaft(
            ratio=shaft, at=(0.03, 0.12), inertia=2e-4,
            eccentrics=(Mass(mr=0.05, phase_deg=150.0),)),))
    mech = mechanism_of(engine)
    assert any(r.eccentrics for _, r in mech.rotors)
    gravity = (2.0, -9.81)
    g = complex(*gravity)

    def potential(theta: float) -> np.ndarray:
        moments = geometry.first_moments(mech, mech.motion(np.array([theta])))
        total = sum(np.asarray(m, dtype=complex).ravel()[0] for m in moments)
        return np.array([-(np.conj(g) * total).real])

    theta0 = 0.7
    slope, error = derivative_with_error(potential, theta0, h=1e-3)
    mo = mech.motion(np.array([theta0]), 1.0, 0.0)
    inertia = 0.0
    for k, link in enumerate(mech.linkage.links):
        v = mo.point_velocity(k, V(link.e, link.f))
        w = float(np.asarray(mo.rate[k]).ravel()[0])
        inertia += (link.mass * float(np.asarray(v.norm2()).ravel()[0]) + link.inertia * w * w
                    + 2 * float(rotors.energy(link.counter_rotor, w)))
    expected = -slope[0] / inertia
    f = make(method, mech, gravity=gravity)
    ev = f.evaluate(0.0, f.initial_state(theta0, 0.0))
    crank = f.link_names.index("crankshaft")
    assert abs(float(ev.alpha[crank]) - expected) <= error / inertia + 1e-9 * abs(expected)
    assert expected != 0  # (the weights do turn it)
    settings = replace(design.simulation, drive="free", theta1=theta0, omega1=0.0,
                       duration=0.5, gravity=gravity)
    traj = simulate(engine, settings, method=method, rtol=1e-10, atol=1e-12)
    # (The integration's own error, 1e3 times its rtol over the run; a weight left out of the
    # equations or of the work breaks the balance by the weights' whole work.)
    assert traj.energy_error <= 1e3 * 1e-10
    assert np.ptp(traj.work) > 0


def test_an_engine_driven_under_gravity_has_its_cycles_driving_torque():
    """Driven at its operating speed under gravity, the multibody formulation's multipliers
    give the cycle analysis' driving torque — the crankshaft masses' and a shaft's weights'
    couple on the crank included, once — and its shaking force and moment, to 1e-9 of each
    one's largest sample."""
    design = load_design(EXAMPLES / "single_cylinder.toml")
    engine = replace(design.mechanism, gas=None, balance_shafts=(BalanceShaft(
        ratio=-1, at=(0.03, 0.12), inertia=2e-4, eccentrics=(Mass(mr=0.05, phase_deg=150.0),)),))
    speed, gravity = 40.0, (2.0, -9.81)  # (slow: the weights' couple a good share)
    analysis = cycle_analysis(engine, speed, 90, gravity=gravity)
    n = analysis.theta1.size
    period = 2 * math.pi * analysis.revolutions / speed
    settings = replace(design.simulation, drive="constant-speed", omega1=speed, theta1=0.0,
                       duration=period * (n - 1) / n, gravity=gravity)
    traj = simulate(engine, settings, method="multibody", rtol=1e-10, atol=1e-12, outputs=n)
    ref = analysis.reactions.driving_torque
    without = cycle_analysis(engine, speed, 90).reactions.driving_torque
    assert np.max(np.abs(ref - without)) > 1e-3 * np.max(np.abs(ref))  # (gravity matters)
    r = analysis.reactions
    for got, want in ((traj.driving_torque, ref), (traj.shaking_moment, r.shaking_moment),
                      (traj.shaking_force, r.shaking_force)):
        assert np.max(np.abs(got - want)) <= EXACT * float(np.max(np.abs(want)))
