"""The slider-crank (Wunderlich 1964, Sect. 3–4) through the pipeline, each quantity checked by a
second route: finite differences, momentum and energy, the other inverse-dynamics route, the
other formulation, closed forms."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from helpers import ROUNDING, derivative_with_error, growth, integration_bound, rel_err

from balancer import spec
from balancer.cli import main
from balancer.cycle import cycle_analysis
from balancer.errors import AssemblyError, SpecError
from balancer.formulations import make
from balancer.linkage.vectors import cross
from balancer.mechanisms.slidercrank import conditions as sc_cond
from balancer.mechanisms.slidercrank import dynamics as sd
from balancer.mechanisms.slidercrank import kinematics as sk
from balancer.mechanisms.slidercrank import massmodels as sm
from balancer.mechanisms.slidercrank.model import SliderCrank
from balancer.model import GasForce, Link, SimulationSettings
from balancer.simulation import simulate

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
GAS = GasForce(angles=(0.0, 1.0, 2.5, 4.0), values=(-300.0, -120.0, 10.0, -40.0))


def _link(rng, length, *, loads=True):
    return Link(mass=rng.uniform(0.3, 3.0), inertia=rng.uniform(0.01, 0.2),
                e=rng.uniform(-0.5, 1.5) * length, f=rng.uniform(-0.3, 0.3) * length,
                force=tuple(rng.uniform(-5, 5, 2)) if loads else (0.0, 0.0),
                moment=rng.uniform(-1, 1) if loads else 0.0)


def random_slider_crank(rng, *, loads=True, rotor=True, full_turn=True) -> SliderCrank:
    while True:
        r, big_l = rng.uniform(0.05, 0.3), rng.uniform(0.1, 0.8)
        e = rng.uniform(-0.3, 0.3) * big_l
        if sk.assembly_range((r, big_l, e)).full == full_turn or not full_turn:
            if not sk.assembly_range((r, big_l, e)).empty:
                break
    crank = _link(rng, r, loads=loads)
    if rotor:
        crank = replace(crank, counter_rotor=rng.uniform(0, 0.1))
    return SliderCrank(lengths=(r, big_l, e), crank=crank, rod=_link(rng, big_l, loads=loads),
                       slider=_link(rng, r, loads=loads), branch=str(rng.choice(["+", "-"])),
                       gas_force=GAS if loads else GasForce())


def _angles(rng, mech, n):
    """``n`` crank angles 0.05 rad inside the assembly range: the rod stays clear of square to
    the guide, which bounds the condition of the analyses (1/|cos θ2|)."""
    rng_ = sk.assembly_range(mech.lengths)
    (a, b), *_ = rng_.intervals
    return rng.uniform(a + 0.05, b - 0.05, n)


CASES = [random_slider_crank(np.random.default_rng(seed), full_turn=seed % 3 != 0)
         for seed in range(12)]


@pytest.mark.parametrize("mech", CASES)
def test_kinematics_against_finite_differences(mech):
    rng = np.random.default_rng(1)
    for t0 in _angles(rng, mech, 3):
        w0, a0 = rng.uniform(-3, 3), rng.uniform(-5, 5)

        def at(t, t0=t0, w0=w0, a0=a0):
            return sk.motion_of(mech, t0 + w0 * t + 0.5 * a0 * t * t, w0 + a0 * t, a0)

        mo = at(0.0)
        if mo.singular[0]:
            continue
        r, big_l, e = mech.lengths
        # Rounding of a few operations on lengths ≤ r + L + |e|: ROUNDING times that (an
        # absolute 1e-15 m would be a few ulps of the larger mechanisms' positions).
        reach = r + big_l + abs(e)
        assert abs(mo.A2[0].imag - e) < ROUNDING * reach
        # |l̄2| from A2 − A1, numbers ≤ reach (≤ 2L for these cases): ≲ 8ε·reach ≈ 3.6e-15·L.
        assert abs(abs(mo.l2[0]) - big_l) < 1e-14 * big_l
        assert abs(mo.l1[0] + mo.l2[0] - mo.A2[0]) < ROUNDING * reach  # the loop
        side = np.sign(mo.x[0] - mo.A1[0].real)
        assert side == (1 if mech.branch == "+" else -1)
        # Against finite differences: their own error bound, plus the analytic value's
        # rounding, ROUNDING times the condition 1/|cos θ2| times its terms (rates up to
        # max(|ω1|, |ω2|) times lengths up to the reach).
        condition = 1 / abs(np.cos(mo.theta2[0]))
        rates = max(abs(mo.omega[0][0]), abs(mo.omega[1][0]))

        def tol(error, terms, condition=condition):
            return error + ROUNDING * condition * terms

        v, error = derivative_with_error(lambda t: at(t).x, scale=reach)
        assert np.max(np.abs(v - mo.v)) < tol(error, rates * reach)
        a, error = derivative_with_error(lambda t: at(t).v, scale=rates * reach)
        assert np.max(np.abs(a - mo.a)) < tol(error, abs(mo.a[0]) + rates**2 * reach)
        u2 = lambda t: at(t).l2 / abs(at(t).l2)  # noqa: E731
        du2, error = derivative_with_error(u2)
        w2 = np.imag(np.conj(u2(0.0)) * du2)
        assert np.max(np.abs(w2 - mo.omega[1])) < tol(error, rates)
        alpha2, error = derivative_with_error(lambda t: at(t).omega[1], scale=rates)
        terms = abs(mo.alpha[1][0]) + rates**2
        assert np.max(np.abs(alpha2 - mo.alpha[1])) < tol(error, terms)


def test_assembly_range_and_dead_points():
    lengths = (0.2, 0.3, 0.2)  # r + |e| > L: the crank cannot turn
    rng = sk.assembly_range(lengths)
    assert not rng.full and len(rng.intervals) == 1
    for end in rng.intervals[0]:
        mo = sk.motion(lengths, end)
        # Rod square to the guide: rounding of the end (an arc sine) and of e − r·sin θ1,
        # ~ROUNDING·0.4 m (no ill-conditioning in this forward evaluation); within 1e-12 m.
        assert mo.singular[0] and abs(abs(mo.l2[0].imag) - 0.3) < 1e-12  # rod square to guide
    with pytest.raises(AssemblyError):
        sk.motion(lengths, -math.pi / 2)  # the arc that is excluded: e − r·sin θ1 > L
    assert sk.assembly_range((0.1, 0.3, 0.15)).full


@pytest.mark.parametrize("mech", CASES)
@pytest.mark.parametrize("gravity", [(0.0, 0.0), (0.4, -9.81)])
def test_the_two_inverse_dynamics_routes_agree(mech, gravity):
    rng = np.random.default_rng(2)
    t = _angles(rng, mech, 40)
    mo = sk.motion_of(mech, t, rng.uniform(-4, 4, t.size), rng.uniform(-8, 8, t.size))
    keep = ~mo.singular
    a = sd.newton_euler(mech, mo, gravity=gravity)
    b = sd.mass_matrix(mech, mo, gravity=gravity)
    force = max(np.max(np.abs(a.ground["A0"])), np.max(np.abs(a.slider_normal["slider"])), 1.0)
    moment = max(np.max(np.abs(a.shaking_moment)), np.max(np.abs(a.driving_torque)), 1.0)
    # Two routes at the same states: 1e-9 relative (DESIGN.md), the states kept clear of the
    # dead points (_angles) and singular ones left out.
    for x, y, scale in ((a.ground["A0"], b.ground["A0"], force),
                        (a.slider_normal["slider"], b.slider_normal["slider"], force),
                        (a.shaking_force, b.shaking_force, force),
                        (a.driving_torque, b.driving_torque, moment),
                        (a.shaking_moment, b.shaking_moment, moment)):
        assert rel_err(x[keep], y[keep], scale=scale) < 1e-9


#: Largest transfer function dx/dθ1 (m/rad) of the states of the momentum test: bounds the
#: condition of the analyses there.
CONDITION = 20


@pytest.mark.parametrize("mech", CASES[:6])
def test_shaking_force_moment_and_torque_against_momentum_and_energy(mech):
    """Shaking force = loads − dP/dt; shaking moment = load moments − dH/dt (the gas force is
    internal: it cancels); τ·θ̇1 = dT/dt − power of loads and gas."""
    rng = np.random.default_rng(3)
    g = (0.3, -9.81)
    for t0 in _angles(rng, mech, 3):
        w0, a0 = rng.uniform(0.5, 2.0), rng.uniform(-2, 2)

        def at(t, t0=t0, w0=w0, a0=a0):
            return sk.motion_of(mech, t0 + w0 * t + 0.5 * a0 * t * t, w0 + a0 * t, a0)

        mo = at(0.0)
        if abs(mo.transfer[0][0]) > CONDITION:
            continue
        rea = sd.newton_euler(mech, mo, gravity=g)
        r, big_l, _ = mech.lengths
        c1, c2, c3 = mech.links
        z1, z2 = c1.com / r, c2.com / big_l

        def momentum(t, at=at, z1=z1, z2=z2):
            m = at(t)
            v = (z1 * m.vector_rate(0), m.vector_rate(0) + z2 * m.vector_rate(1), m.v + 0j)
            return sum(link.mass * vk for link, vk in zip(mech.links, v, strict=True))

        loads = [link.force_complex + link.mass * complex(*g) for link in mech.links]
        # Each against a finite difference: the difference's error bound (its values made of
        # terms m·|v|, m·|r|·|v|, I·|ω|) plus Newton–Euler's rounding, ROUNDING times the
        # condition (≤ CONDITION) times the terms it sums (reactions, moments, powers).
        vel = (z1 * mo.vector_rate(0), mo.vector_rate(0) + z2 * mo.vector_rate(1), mo.v + 0j)
        momentum_terms = float(sum(link.mass * np.max(np.abs(v))
                                   for link, v in zip(mech.links, vel, strict=True)))
        arm = r + big_l + abs(mech.lengths[2])
        reactions = max(np.max(np.abs(rea.ground["A0"])),
                        np.max(np.abs(rea.slider_normal["slider"])))
        rounding = ROUNDING * CONDITION
        dp, error = derivative_with_error(momentum, scale=momentum_terms)
        expected = sum(loads) - dp
        tol = error + rounding * max(reactions, np.max(np.abs(dp)), sum(abs(f) for f in loads))
        assert np.max(np.abs(rea.shaking_force - expected)) < tol
        coms = sm.link_centres_of_mass(mech, mo)
        load_moment = sum(cross(c, f) + link.moment for c, f, link in zip(coms, loads,
                                                                           mech.links,
                                                                           strict=True))
        rotations = sum(link.inertia * abs(mo.omega[k][0]) for k, link in enumerate(mech.links[:2]))
        dh, error = derivative_with_error(lambda t: sd.angular_momentum(mech, at(t)),
                                          scale=arm * momentum_terms + rotations)
        exp_m = load_moment - dh
        moments = max(arm * reactions, np.max(np.abs(rea.driving_torque)), np.max(np.abs(dh)))
        assert np.max(np.abs(rea.shaking_moment - exp_m)) < error + rounding * moments
        dt, error = derivative_with_error(lambda t: sd.kinetic_energy(mech, at(t)))
        power = sum(np.real(np.conj(f) * v) for f, v in zip(loads, vel, strict=True))
        power = power + mech.crank.moment * mo.omega[0] + mech.rod.moment * mo.omega[1]
        power = power + mech.gas_force.at(mo.theta1) * mo.v
        powers = max(abs(w0) * moments, np.max(np.abs(dt)),
                     abs(mech.gas_force.at(mo.theta1)[0] * mo.v[0]))
        assert np.max(np.abs(rea.driving_torque * w0 - (dt - power))) < error + rounding * powers


@pytest.mark.parametrize("mech", CASES)
def test_wunderlich_similarity_to_rounding(mech):
    rng = np.random.default_rng(4)
    mo = sk.motion_of(mech, _angles(rng, mech, 60))
    w = sm.wunderlich_slider_crank(mech)
    com = sm.total_com_direct(mech, mo)
    scale = sum(abs(x) for x in mech.lengths)
    # Wunderlich's similarity to rounding (DESIGN.md): two mass-weighted sums of vectors
    # ≲ scale, ~ROUNDING·scale; within 1e-12·scale.
    assert rel_err(w.trace(mo), com, scale=scale) < 1e-12
    # The generating slider-crank is the original scaled and turned by α1 (Eq. 18).
    b1, b2 = w.generating_joints(mo)
    assert rel_err(np.abs(b1 - w.B0), abs(w.scale) * mech.lengths[0], scale=scale) < 1e-12
    assert rel_err(np.abs(b2 - b1), abs(w.scale) * mech.lengths[1], scale=scale) < 1e-12


def test_wunderlich_circle_and_point_cases():
    rng = np.random.default_rng(5)
    mech = random_slider_crank(rng, loads=False, rotor=False)
    r, big_l, _ = mech.lengths
    t = sk.assembly_range(mech.lengths).intervals[0]
    mo = sk.motion_of(mech, np.linspace(t[0] + 0.01, t[1] - 0.01, 80))
    # Eq. 20b alone: the rod's centre of mass beyond the crank pin, σ2 = −m3/m2 → a circle
    # about B0 of radius |α1|·r (Eq. 14b).
    c2, c3 = mech.rod, mech.slider

    def rounding(linkage):
        # The centre of mass from terms m_k·|r_k| (counterweights far out make them large):
        # ROUNDING times those over the total mass.
        terms = sum(link.mass * np.abs(rk) for link, rk in
                    zip(linkage.links, sm.link_centres_of_mass(linkage, mo), strict=True))
        return ROUNDING * float(np.max(terms)) / linkage.total_mass

    s2 = -(c3.mass / c2.mass) * big_l
    m20b = mech.with_link("rod", replace(c2, e=s2, f=0.0))
    w = sm.wunderlich_slider_crank(m20b)
    assert w.is_circle and not w.is_stationary
    radius = np.abs(sm.total_com_direct(m20b, mo) - w.B0)
    tol = rounding(m20b)
    assert np.ptp(radius) < tol and abs(radius[0] - abs(w.alpha[1]) * r) < tol
    # Eq. 20a alone: the crank's beyond A0, σ1 = −(m2 + m3)/m1 → an arc about B0 (Eq. 14a).
    m20a = mech.with_link("crank", replace(mech.crank, e=-(c2.mass + c3.mass) / mech.crank.mass
                                           * r, f=0.0))
    w = sm.wunderlich_slider_crank(m20a)
    assert w.is_circle
    radius = np.abs(sm.total_com_direct(m20a, mo) - w.B0)
    assert np.ptp(radius) < rounding(m20a)
    # Both: a point (Eq. 14c), at B0 = m3·s3.
    both = sc_cond.force_balanced_by_counterweights(mech)
    assert sm.wunderlich_slider_crank(both).is_stationary and sc_cond.is_force_balanced(both)
    com = sm.total_com_direct(both, mo)
    assert np.max(np.abs(com - c3.mass * c3.com / both.total_mass)) < rounding(both)


@pytest.mark.parametrize("method", ["complex-masses", "mass-matrix"])
@pytest.mark.parametrize("drive", ["free", "constant-speed"])
def test_eq20_balanced_design_has_no_simulated_shaking_force(method, drive):
    """Issue 5: with (20a) and (20b) the simulated shaking force vanishes at integration-error
    level, free and driven, in both formulations."""
    rng = np.random.default_rng(6)
    mech = sc_cond.force_balanced_by_counterweights(random_slider_crank(rng, loads=False))
    settings = SimulationSettings(duration=1.0, theta1=0.3, omega1=8.0, drive=drive)
    tr = simulate(mech, settings, method=method, rtol=1e-11, atol=1e-13)
    reactions = tr.largest_reaction
    assert reactions > 1.0
    # Not integration error: the shaking force of a force-balanced mechanism vanishes at every
    # state, so its reactions' sum cancels to the formulation's accuracy (1e-9 relative).
    assert np.max(np.abs(tr.shaking_force)) < 1e-9 * reactions
    assert tr.energy_error < 2 * integration_bound(tr)  # first integral, quadratic in rates


@pytest.mark.parametrize("mech", CASES[:8])
@pytest.mark.parametrize("driven", [False, True])
def test_formulations_agree_at_states(mech, driven):
    rng = np.random.default_rng(7)
    g = (0.2, -9.81)
    for t in _angles(rng, mech, 4):
        w = rng.uniform(-5, 5)
        evs = []
        for name in ("complex-masses", "mass-matrix"):
            f = make(name, mech, gravity=g, speed=w if driven else None)
            evs.append(f.evaluate(0.0, f.initial_state(t, w)))
        a, b = evs
        mo = sk.motion_of(mech, t, w, a.alpha[0])
        ne = sd.newton_euler(mech, mo, gravity=g)
        # Formulations and Newton–Euler at one state: 1e-9 relative (DESIGN.md); _angles
        # keeps the states clear of the dead points.
        force = max(abs(ne.ground["A0"][0]), abs(ne.slider_normal["slider"][0]), 1.0)
        assert abs(a.alpha[0] - b.alpha[0]) < 1e-9 * max(1.0, abs(a.alpha[0]), w * w)
        assert abs(ne.driving_torque[0] - a.driving_torque) < 1e-9 * max(1.0, force)
        for ev in evs:
            assert abs(ev.ground["A0"] - ne.ground["A0"][0]) < 1e-9 * force
            assert abs(ev.slider_normal["slider"] - ne.slider_normal["slider"][0]) < 1e-9 * force
            arm = sum(map(abs, mech.lengths))
            couple = ne.slider_couple["slider"][0]
            assert abs(ev.slider_couple["slider"] - couple) < 1e-9 * force * arm
            assert abs(ev.shaking_moment - ne.shaking_moment[0]) < 1e-9 * max(1.0, force)


@pytest.mark.slow
def test_engine_simulations_agree_and_balance_energy():
    design = spec.load_design(EXAMPLES / "engine.toml")
    runs = {}
    for method in ("complex-masses", "mass-matrix"):
        for drive in ("free", "constant-speed"):
            runs[method, drive] = simulate(design.mechanism, design.simulation, method=method,
                                           drive=drive, rtol=1e-12, atol=1e-14)
    # A steep gas-force cycle at 9000 rpm (energies of hundreds of joules, three and a half
    # revolutions). In free motion the two integrations differ by their bounds, amplified by
    # the motion (its speed, hence its phase, follows an error of its energy).
    free = replace(design.simulation, drive="free")
    amplified = growth(simulate, design.mechanism, free, method="mass-matrix", rtol=1e-12,
                       atol=1e-14, reference=runs["mass-matrix", "free"])
    for drive in ("free", "constant-speed"):
        a, b = runs["complex-masses", drive], runs["mass-matrix", drive]
        quantities = {"theta": lambda tr: tr.theta}
        quantities.update({f"slider {k}": lambda tr, k=k: tr.slider[k] for k in range(3)})
        for name, quantity in quantities.items():
            if drive == "free":
                tol = amplified.bound(quantity, a, b)
            else:
                # Driven, the motion is prescribed (θ1 = θ0 + ω·t, the rest by the position
                # analysis): rounding, ROUNDING times the condition 1/|cos θ2| and the size.
                condition = 1 / np.min(np.abs(np.cos(a.theta[1])))
                tol = ROUNDING * condition * np.max(np.abs(quantity(a)))
            assert np.max(np.abs(quantity(a)[..., -1] - quantity(b)[..., -1])) < tol, (drive,
                                                                                        name)
        # T − T0 − W is a first integral of the integrated system (the gas force's work is
        # integrated with the motion): it drifts by the integration's own error, twice for
        # the kinetic energy's square of the rates.
        for tr in (a, b):
            assert tr.energy_error < 2 * integration_bound(tr), (tr.method, drive)
    # Driven at constant speed, the simulation's torque is the cycle analysis's.
    tr = runs["complex-masses", "constant-speed"]
    # The general core's free-body equations group by group (route "newton-euler"), not the
    # closed forms the formulation evaluates its reactions with.
    ca = cycle_analysis(design.mechanism, design.simulation.omega1, theta1=tr.theta[0],
                        route="newton-euler")
    # Prescribed motion, two routes at the same states: 1e-9 relative (DESIGN.md).
    scale = np.max(np.abs(ca.reactions.driving_torque))
    assert np.max(np.abs(tr.driving_torque - ca.reactions.driving_torque)) < 1e-9 * scale


@pytest.mark.slow
def test_partial_balancing_matches_the_classic_closed_form():
    """An in-line engine with only a crank counterweight, minimising w_x·RMS(Fx)² + w_y·RMS(Fy)²:
    the counterweight's force is a pure first harmonic, so the optimum balances the rotating
    masses and the fraction w_x/(w_x + w_y) of the reciprocating mass (the rod split into two
    masses at its joints; its centre of mass on its line)."""
    from balancer.balance.nlp import NlpSolver
    from balancer.balance.optimizer import optimize
    from balancer.balance.problem import numeric_problem
    from balancer.mechanisms import mechanism_of

    base = spec.load_design(EXAMPLES / "engine.toml")
    for wx, wy in ((1.0, 1.0), (3.0, 1.0), (1.0, 4.0)):
        text = spec.dumps_design(base).replace(
            "shaking_force_x = 1.0", f"shaking_force_x = {wx}").replace(
            "shaking_force_y = 1.0", f"shaking_force_y = {wy}")
        design = spec.loads_design(text)
        result = optimize(design, backend="convex")
        crank = result.linkage.crank
        expected = sc_cond.classic_counterweight(base.mechanism, wx / (wx + wy))
        closed = replace(base.mechanism.crank, e=(expected / crank.mass).real, f=0.0)
        data = numeric_problem(design)
        closed_mech = mechanism_of(base.mechanism.with_link("crank", closed))
        x_closed = closed_mech.layout.vector(closed_mech.linkage)
        j_closed = data.objective(x_closed)
        # The objective is quadratic and flat at the optimum: the solver certifies its design
        # within J − J_low of the optimum (its lower bound), which the closed form's objective
        # must meet (to rounding); the counterweight (m·e, m·f of the crank: indices 1, 2)
        # then to √(that/λ), λ the objective's least curvature in it.
        rounding = ROUNDING * j_closed
        certified = result.objective - result.lower_bound + rounding
        assert result.objective == pytest.approx(j_closed, rel=0, abs=certified)
        curvature = _least_curvature(data.objective, x_closed, (1, 2), abs(expected))
        assert abs(crank.mass * crank.com - expected) < np.sqrt(certified / curvature)
        # IPOPT on the designer's parameters converges on the counterweight itself: its
        # distance from the optimum is at most its gradient over the least curvature (the
        # objective is quadratic in it), the gradient from differences exact for a quadratic
        # but for the objective's rounding.
        nlp = NlpSolver(data).solve(data.x0)
        got = complex(nlp.x[1], nlp.x[2])
        step = 1e-3 * abs(expected)
        gradient = np.hypot(*(_difference(data.objective, nlp.x, i, step) for i in (1, 2)))
        residual = gradient / (2 * curvature) + 2 * rounding / (step * 2 * curvature)
        assert abs(got - expected) < residual
    # Equal weights: the classic half of the reciprocating mass, and only the first harmonic
    # moved (the secondary is the reciprocating mass's, which a crank counterweight cannot touch).
    design = base
    result = optimize(design, backend="nlp")
    before = result.before.orders
    after = result.after.orders
    # Untouched but for rounding: ~ROUNDING·|R|/|H2|, the reactions that sum to the shaking
    # force relative to the second harmonic (|R|/|H2| ≈ 8 here): ≈ 1e-13, within 1e-9.
    assert after[2].shaking_force.x == pytest.approx(before[2].shaking_force.x, rel=1e-9)
    assert after[1].shaking_force.x < before[1].shaking_force.x
    # A crank counterweight cancels only forward order 1: the backward part stays.
    assert after[1].shaking_force.backward == pytest.approx(before[1].shaking_force.backward,
                                                            rel=1e-9)


def _difference(objective, x, i, step):
    """Central difference of ``objective`` in coordinate ``i`` (exact for a quadratic)."""
    e = np.zeros_like(x)
    e[i] = step
    return (objective(x + e) - objective(x - e)) / (2 * step)


def _least_curvature(objective, x, indices, step):
    """Least eigenvalue of the Hessian of a quadratic ``objective``/2 in ``indices`` (λ with
    J(x + d) − J(x) − ∇J·d = dᵀ·H·d ≥ λ·|d|²), from central second differences."""
    n = len(indices)
    hessian = np.empty((n, n))
    for a, i in enumerate(indices):
        for b, k in enumerate(indices):
            ei, ek = np.zeros_like(x), np.zeros_like(x)
            ei[i], ek[k] = step, step
            hessian[a, b] = (objective(x + ei + ek) - objective(x + ei - ek)
                             - objective(x - ei + ek) + objective(x - ei - ek)) / (8 * step**2)
    return float(np.min(np.linalg.eigvalsh(hessian)))


def test_full_force_balance_with_a_rod_counterweight():
    """Eq. 20a–b as constraints in both backends: crank and rod counterweights."""
    from balancer.balance.optimizer import optimize

    text = (EXAMPLES / "engine.toml").read_text()
    text = text.replace("force_balance = false", "force_balance = true").replace(
        "[balance.crank]", "[balance.rod]\nmass = [0.07, 0.3]\ncom_radius = 0.1\n"
        "com_about = \"A1\"\nmin_gyration = 0.02\n\n[balance.crank]").replace(
        "mass = [0.9, 1.4]", "mass = [0.9, 3.0]").replace("com_radius = 0.03", "com_radius = 0.06")
    design = spec.loads_design(text)
    for backend in ("convex", "nlp"):
        result = optimize(design, backend=backend)
        assert result.success
        # The optimiser restores Eq. 20a–b to rounding after its solve; Clarabel's feasibility
        # tolerance (1e-10) bounds the residual even without.
        assert sc_cond.force_balance_error(result.linkage) < 1e-10
        # The shaking force then vanishes but for that residual times the accelerations
        # (≲ 1e-10 of the total mass's, a few times the original's shaking force) and the
        # reactions' rounding in their sum: within 1e-8 of the original's.
        before = result.before.summary.shaking_force.max
        assert result.after.summary.shaking_force.max < 1e-8 * before
        assert result.linkage.rod.e < 0  # the counterweight beyond the crank pin (Eq. 20b)


def test_slider_crank_spec_errors_and_round_trip(tmp_path):
    design = spec.load_design(EXAMPLES / "engine.toml")
    assert design.mechanism.type == "slider-crank" and len(design.mechanism.gas_force.values) > 1
    assert spec.loads_design(spec.dumps_design(design)) == design
    text = (EXAMPLES / "engine.toml").read_text()
    bad = {
        "rocker under a slider-crank": (text.replace("[links.rod]", "[links.rocker]"),
                                        "links.rocker"),
        "offset beyond reach": (text.replace("offset = 0.0 ", "offset = 0.5 "),
                                "mechanism.lengths.offset"),
        "frame length": (text.replace("offset = 0.0 ", "frame = 0.1 "), "mechanism.lengths"),
        "gas table lengths": (text.replace("force = [-3500.0, ", "force = ["),
                              "links.slider.gas_force"),
        "gas on the crank": (text.replace("com = { e = -0.004, f = 0.0 }",
                                          "com = { e = -0.004, f = 0.0 }\ngas_force = 1.0"),
                             "links.crank.gas_force"),
        "counter-rotor on the slider": (text.replace("mass = 0.060", "mass = 0.060\n"
                                                     "counter_rotor = 1.0"),
                                        "links.slider.counter_rotor"),
        "balance of a rocker": (text + "\n[balance.rocker]\nmass = [1.0, 2.0]\n",
                                "balance.rocker"),
    }
    for name, (body, key) in bad.items():
        with pytest.raises(SpecError) as info:
            spec.loads_design(body, source="e.toml")
        assert key in str(info.value), name
    path = tmp_path / "bad.toml"
    path.write_text(bad["offset beyond reach"][0])
    assert main(["analyze", str(path)]) == 2


@pytest.mark.slow
def test_slider_crank_through_the_command_line(tmp_path, capsys):
    engine = str(EXAMPLES / "engine.toml")
    assert main(["analyze", engine, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    # Reactions by ground point, and the slider on its ground guide by its link's name.
    assert set(doc["reactions"]) == {"A0", "slider"} and doc["shaking_force"]["rms"] > 0
    assert set(doc["reactions"]["slider"]) == {"max", "couple_max"}
    out = tmp_path / "run.csv"
    assert main(["simulate", engine, "--out", str(out), "--duration", "0.005"]) == 0
    capsys.readouterr()
    header = out.read_text().splitlines()[0].split(",")
    assert header[:14] == ["t", "theta1", "theta2", "theta3", "omega1", "omega2", "omega3",
                           "alpha1", "alpha2", "alpha3", "RA0x", "RA0y", "RA3x", "RA3y"]
    assert header[14:] == ["C_slider", "x3", "v3", "a3"]  # the guide's couple, the slider
    balanced = tmp_path / "balanced.toml"
    assert main(["optimize", engine, "--out", str(balanced), "--json",
                 "--verify-duration", "0.005"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["status"] == "optimal" and set(doc["links"]) == {"crank", "rod", "slider"}
    assert main(["verify", str(balanced), "--duration", "0.005", "--plot",
                 str(tmp_path / "v.png")]) == 0
    assert "complex-masses" in capsys.readouterr().out
    assert main(["simulate", engine, "--method", "lie-group"]) == 2
    assert "slider-crank" in capsys.readouterr().err
    assert main(["plot", engine, "--animate", str(tmp_path / "e.gif"), "--frames", "6"]) == 0


@pytest.mark.parametrize("n", [2, 3, 5, 15, 100])
def test_a_gas_force_table_is_scipys_periodic_cubic_spline(n):
    # The table's spline (a cyclic tridiagonal system solved with numpy) against SciPy's
    # CubicSpline(bc_type="periodic"): the same spline. Knots jittered about a uniform grid keep
    # h_max/h_min ≤ 3, so the system (strictly diagonally dominant) has a condition below ~10
    # and the two agree to a few hundred roundings of the largest value: 1e-12 relative.
    from scipy.interpolate import CubicSpline

    from balancer.model import GasForce

    rng = np.random.default_rng(300 + n)
    step = 2 * np.pi / n
    angles = step * (np.arange(n) + rng.uniform(-0.25, 0.25, n))
    angles[0] = 0.0
    values = rng.normal(0.0, 1e4, n)
    gas = GasForce(angles=tuple(angles), values=tuple(values))
    ref = CubicSpline(np.append(angles, 2 * np.pi), np.append(values, values[0]),
                      bc_type="periodic")
    t = np.linspace(-3 * np.pi, 3 * np.pi, 2001)
    assert np.max(np.abs(gas.at(t) - ref(np.mod(t, 2 * np.pi)))) < 1e-12 * np.max(
        np.abs(values))
    # One angle at a time (an integrator's state), in plain floats: the same spline.
    one = np.array([gas.at(float(x)) for x in t[::50]])
    assert all(isinstance(gas.at(float(x)), float) for x in t[:3])
    assert np.max(np.abs(one - ref(np.mod(t[::50], 2 * np.pi)))) < 1e-12 * np.max(
        np.abs(values))
