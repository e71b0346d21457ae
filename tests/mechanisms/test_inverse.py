"""Inverse dynamics: the two routes against each other and against momentum and energy."""

from __future__ import annotations

import math
import zlib
from fractions import Fraction

import numpy as np
import pytest
from conftest import CLASS_EXAMPLES, paper_linkage, random_angles, random_link, random_linkage
from helpers import ROUNDING, derivative_with_error, rel_err
from hypothesis import given, settings
from hypothesis import strategies as st

from balancer import cycle
from balancer.errors import AssemblyError
from balancer.linkage.loads import Reactions
from balancer.mechanisms.fourbar import inverse
from balancer.mechanisms.fourbar import kinematics as kin
from balancer.mechanisms.fourbar import massmodels as mm
from balancer.mechanisms.fourbar.conditions import (
    berkof_counter_rotors,
    force_balanced_by_crank_and_rocker,
)
from balancer.mechanisms.fourbar.model import FourBar

#: Least |sin(θ3 − θ2)| of the states of the finite-difference tests.
FD_MARGIN = 0.3


def _states(seed, n_linkages=40, per=25, margin=0.05, speed=4.0, **kw):
    """Random linkages with states (θ1, ω1, α1) and a gravity vector.

    ``margin`` is the least |sin(θ3 − θ2)| kept: it bounds the condition of the position and
    rate analyses and of the reactions (≤ 1/margin), so that the two routes agree to
    DESIGN.md's 1e-9 relative. Finite-difference tests use a wider one so that the higher
    derivatives, which set their truncation error, stay moderate.
    """
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n_linkages):
        linkage = random_linkage(rng, **kw)
        t = random_angles(rng, linkage, per)
        keep = np.abs(kin.position_of(linkage, t).sin_transmission) > margin
        t = t[keep]
        out.append((linkage, t, rng.uniform(-speed, speed, t.size),
                    rng.uniform(-2 * speed, 2 * speed, t.size), tuple(rng.uniform(-10, 10, 2))))
    return out


def _fd_states(seed):
    return _states(seed, n_linkages=15, per=4, margin=FD_MARGIN, speed=2.0)


def _fd_tolerance(error: float, *terms) -> float:
    """A finite difference's error bound plus the rounding of the analytic route: ROUNDING
    times the condition (≤ 1/FD_MARGIN) times the largest of the terms it is made of."""
    return error + ROUNDING / FD_MARGIN * max(float(np.max(np.abs(t))) for t in terms)


def _scale(r: Reactions) -> dict[str, float]:
    return {
        "force": max(np.max(np.abs(r.ground["A0"])), np.max(np.abs(r.ground["A3"])), 1.0),
        "moment": max(np.max(np.abs(r.shaking_moment)), np.max(np.abs(r.driving_torque)), 1.0),
    }


@pytest.mark.parametrize(("linkage", "t", "w", "a", "g"), _states(20))
def test_newton_euler_and_mass_matrix_routes_agree(linkage, t, w, a, g):
    # Two routes at the same states: 1e-9 relative (DESIGN.md), the states filtered (_states).
    mo = kin.motion_of(linkage, t, w, a)
    ne = inverse.newton_euler(linkage, mo, gravity=g)
    mx = inverse.mass_matrix(linkage, mo, gravity=g)
    s = _scale(ne)
    assert rel_err(ne.ground["A0"], mx.ground["A0"], scale=s["force"]) < 1e-9
    assert rel_err(ne.ground["A3"], mx.ground["A3"], scale=s["force"]) < 1e-9
    assert rel_err(ne.driving_torque, mx.driving_torque, scale=s["moment"]) < 1e-9
    assert rel_err(ne.shaking_moment, mx.shaking_moment, scale=s["moment"]) < 1e-9


@pytest.mark.parametrize("name", list(CLASS_EXAMPLES))
@pytest.mark.parametrize("branch", ["+", "-"])
def test_routes_agree_for_every_grashof_class(name, branch):
    rng = np.random.default_rng(zlib.crc32(f"{name}{branch}".encode()))  # the same every run
    lengths = CLASS_EXAMPLES[name]
    linkage = FourBar(
        lengths=lengths,
        branch=branch,
        crank=random_link(rng, lengths[0], loads=True, rotor=True),
        coupler=random_link(rng, lengths[1], loads=True, rotor=False),
        rocker=random_link(rng, lengths[2], loads=True, rotor=True),
    )
    t = random_angles(rng, linkage, 200)
    # Away from singular positions (as _states): the routes agree to 1e-9 relative.
    t = t[np.abs(kin.position_of(linkage, t).sin_transmission) > 0.05]
    mo = kin.motion_of(linkage, t, rng.uniform(-3, 3, t.size), rng.uniform(-3, 3, t.size))
    ne = inverse.newton_euler(linkage, mo, gravity=(0.0, -9.81))
    mx = inverse.mass_matrix(linkage, mo, gravity=(0.0, -9.81))
    s = _scale(ne)
    for x, y, key in ((ne.ground["A0"], mx.ground["A0"], "force"),
                      (ne.ground["A3"], mx.ground["A3"], "force"),
                      (ne.driving_torque, mx.driving_torque, "moment"),
                      (ne.shaking_moment, mx.shaking_moment, "moment")):
        assert rel_err(x, y, scale=s[key]) < 1e-9


def _trajectory(linkage, t0, w0, a0):
    """Motion along θ1(t) = t0 + w0·t + a0·t²/2 as a function of t."""
    return lambda t: kin.motion_of(linkage, t0 + w0 * t + 0.5 * a0 * t * t, w0 + a0 * t, a0)


def _momentum_terms(linkage, mo) -> float:
    """The magnitude of the terms of the linear momentum: Σ m·(|v_joint| + |ω|·|s̄|)."""
    vel_a1, vel_a2 = mo.joint_velocities
    joint_vel = (0.0, vel_a1, vel_a2)
    return float(sum(c.mass * np.max(np.abs(joint_vel[k]) + abs(c.com) * np.abs(mo.omega[k]))
                     for k, c in enumerate(linkage.links)))


def _linear_momentum(linkage, mo):
    vel_a1, vel_a2 = mo.joint_velocities
    joint_vel = (0.0, vel_a1, vel_a2)
    return sum(
        c.mass * (joint_vel[k] + c.com / linkage.lengths[k] * mo.vector_rate(k))
        for k, c in enumerate(linkage.links)
    )


@pytest.mark.parametrize(("linkage", "t", "w", "a", "g"), _fd_states(21))
def test_shaking_force_is_loads_minus_rate_of_linear_momentum(linkage, t, w, a, g):
    for t0, w0, a0 in zip(t, w, a, strict=True):
        traj = _trajectory(linkage, t0, w0, a0)
        r = inverse.newton_euler(linkage, traj(0.0), gravity=g)
        dp, error = derivative_with_error(
            lambda s, traj=traj: _linear_momentum(linkage, traj(s)),
            scale=_momentum_terms(linkage, traj(0.0)))
        loads = sum(c.force_complex + c.mass * complex(*g) for c in linkage.links)
        expected = loads - dp
        tol = _fd_tolerance(error, r.ground["A0"], r.ground["A3"], loads, dp)
        assert np.max(np.abs(r.shaking_force - expected)) < tol


@pytest.mark.parametrize(("linkage", "t", "w", "a", "g"), _fd_states(24))
def test_total_mass_times_centre_of_mass_acceleration(linkage, t, w, a, g):
    """Linear momentum is m_tot times the velocity of the total centre of mass (Eq. 16/32)."""
    for t0, w0, a0 in zip(t, w, a, strict=True):
        traj = _trajectory(linkage, t0, w0, a0)
        v_com, error = derivative_with_error(
            lambda s, traj=traj: mm.total_com_frame(linkage, traj(s).pos),
            scale=max(linkage.lengths))
        mo = traj(0.0)
        p = _linear_momentum(linkage, mo)
        tol = _fd_tolerance(linkage.total_mass * error, p, _momentum_terms(linkage, mo))
        assert np.max(np.abs(p - linkage.total_mass * v_com)) < tol


@pytest.mark.parametrize(("linkage", "t", "w", "a", "g"), _fd_states(22))
def test_shaking_moment_is_load_moment_minus_rate_of_angular_momentum(linkage, t, w, a, g):
    grav = complex(*g)
    for t0, w0, a0 in zip(t, w, a, strict=True):
        traj = _trajectory(linkage, t0, w0, a0)
        mo = traj(0.0)
        r = inverse.newton_euler(linkage, mo, gravity=g)
        # Its terms: m·|r|·|v| and I·|ω| of each link, ≤ the momentum's terms times the reach.
        reach = sum(linkage.lengths[:3])
        dh, error = derivative_with_error(
            lambda s, traj=traj: inverse.angular_momentum(linkage, traj(s)),
            scale=reach * _momentum_terms(linkage, mo)
            + sum(c.inertia * abs(w[0]) for c, w in zip(linkage.links, mo.omega, strict=True)))
        coms = mm.link_centres_of_mass(linkage, mo.pos)
        load_moment = sum(
            kin.cross(rk, c.force_complex + c.mass * grav) + c.moment
            for rk, c in zip(coms, linkage.links, strict=True)
        )
        expected = load_moment - dh
        arm = max(linkage.lengths)  # the moments' terms: forces times lever arms
        tol = _fd_tolerance(error, arm * r.ground["A0"], arm * r.ground["A3"], r.driving_torque,
                            load_moment, dh)
        assert np.max(np.abs(r.shaking_moment - expected)) < tol


@pytest.mark.parametrize(("linkage", "t", "w", "a", "g"), _fd_states(23))
def test_driving_torque_power_balances_kinetic_energy(linkage, t, w, a, g):
    grav = complex(*g)
    for t0, w0, a0 in zip(t, w, a, strict=True):
        if abs(w0) < 0.2:
            continue
        traj = _trajectory(linkage, t0, w0, a0)
        mo = traj(0.0)
        r = inverse.newton_euler(linkage, mo, gravity=g)
        dT, error = derivative_with_error(
            lambda s, traj=traj: inverse.kinetic_energy(linkage, traj(s)))
        # Power of the loads and of gravity at the centres of mass.
        vel_a1, vel_a2 = mo.joint_velocities
        joint_vel = (0.0, vel_a1, vel_a2)
        power = 0.0
        for k, c in enumerate(linkage.links):
            v = joint_vel[k] + c.com / linkage.lengths[k] * mo.vector_rate(k)
            power = power + kin.inner(v, c.force_complex + c.mass * grav) + c.moment * mo.omega[k]
        expected = dT - power
        tol = _fd_tolerance(error, r.driving_torque * w0, dT, power)
        assert np.max(np.abs(r.driving_torque * w0 - expected)) < tol


def test_force_balanced_paper_example_has_no_shaking_force():
    linkage = force_balanced_by_crank_and_rocker(paper_linkage(loads=False))
    mo = kin.motion_of(linkage, np.linspace(0, 2 * np.pi, 100), 1.7, 0.9)
    for route in inverse.ROUTES:
        r = inverse.inverse_dynamics(linkage, mo, route=route)
        # Rounding: Eq. 57 is met to rounding and RA0 + RA3 cancels to ~ROUNDING·|R| times
        # the condition (|sin(θ3 − θ2)| ≥ 0.7 over the paper's revolution): ~2e-14·|R|.
        assert np.max(np.abs(r.shaking_force)) < 1e-12 * np.max(np.abs(r.ground["A0"]))
        assert np.max(np.abs(r.ground["A0"])) > 1.0  # the individual reactions are far from zero


def test_berkof_complete_balance_has_no_shaking_moment_at_any_motion():
    from dataclasses import replace

    base = paper_linkage(loads=False)
    l2 = base.lengths[1]
    c2 = base.coupler
    coupler = replace(c2, e=1.2, f=0.0, inertia=c2.mass * 1.2 * (l2 - 1.2))
    linkage = force_balanced_by_crank_and_rocker(base.with_link("coupler", coupler))
    j1, j3 = berkof_counter_rotors(linkage)
    linkage = linkage.with_links({
        "crank": replace(linkage.crank, counter_rotor=j1),
        "rocker": replace(linkage.rocker, counter_rotor=j3),
    })
    rng = np.random.default_rng(5)
    t = rng.uniform(-np.pi, np.pi, 300)
    mo = kin.motion_of(linkage, t, rng.uniform(-5, 5, 300), rng.uniform(-20, 20, 300))
    for route in inverse.ROUTES:
        r = inverse.inverse_dynamics(linkage, mo, route=route)
        # Rounding, as above: the conditions hold to rounding, and the sums cancel to
        # ~ROUNDING·1.4 of their terms (reactions times lever arms, a few times the torque).
        scale = np.max(np.abs(r.driving_torque))
        assert np.max(np.abs(r.shaking_force)) < 1e-12 * np.max(np.abs(r.ground["A0"]))
        assert np.max(np.abs(r.shaking_moment)) < 1e-12 * scale


def test_cycle_analysis_samples_and_figures(paper):
    ca = cycle.cycle_analysis(paper, 10.0, 360, route="newton-euler")
    assert ca.samples == 360 and ca.motion.theta1.size == 360
    assert np.allclose(np.diff(ca.theta1), 2 * np.pi / 360)
    sf = np.abs(ca.reactions.shaking_force)
    # The same numbers by other operations (the RMS of the magnitudes scaled by their largest
    # against unscaled: an ulp or two in each square, which the mean keeps and the root
    # halves): ≤ 3ε ≈ 7e-16.
    assert ca.summary.shaking_force.max == pytest.approx(sf.max(), rel=1e-15)
    assert ca.summary.shaking_force.rms == pytest.approx(np.sqrt(np.mean(sf**2)), rel=1e-15)
    other = cycle.cycle_analysis(paper, 10.0, 360, route="mass-matrix")
    # The two routes over the paper's well-conditioned revolution (|sin(θ3 − θ2)| ≥ 0.7): they
    # differ by rounding, ~ROUNDING·1.4 of the terms (a few times the figures): ≲ 1e-13.
    for name in ("shaking_force", "shaking_moment", "driving_torque"):
        a, b = getattr(ca.summary, name), getattr(other.summary, name)
        assert a.rms == pytest.approx(b.rms, rel=1e-12)
        assert a.max == pytest.approx(b.max, rel=1e-12)


_VALUE = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e300, max_value=1e300)


@settings(max_examples=200, deadline=None)
@given(re=st.lists(_VALUE, min_size=1, max_size=40), im=st.lists(_VALUE, min_size=1,
                                                                 max_size=40),
       complex_=st.booleans(), holes=st.sets(st.integers(0, 39), max_size=5))
@pytest.mark.slow
def test_figures_of_any_samples_against_exact_arithmetic(re, im, complex_, holes):
    """Figure.of (its fast sums of squares, its scaled fallback, its NaN samples left out)
    against the RMS and maximum of the same magnitudes in exact rational arithmetic. Each
    magnitude is one correctly rounded hypot (ε/2); the float sum of n squares is off by
    n·ε of the sum at most, and the root halves it: (n + 2)·ε relative covers both routes."""
    n = min(len(re), len(im)) if complex_ else len(re)
    values = (np.array(re[:n]) + 1j * np.array(im[:n])) if complex_ else np.array(re[:n])
    for i in holes:
        if i < n:
            values[i] = np.nan
    figure = cycle.Figure.of(values)
    kept = [abs(complex(v)) for v in values if not np.isnan(v)]
    if not kept:
        assert math.isnan(figure.rms) and math.isnan(figure.max)
        return
    top = max(kept)
    # The largest of the magnitudes: each a correctly rounded hypot here, numpy's within an
    # ulp of it (overflow aside).
    assert figure.max == pytest.approx(top, rel=2.3e-16, abs=0.0) or math.isinf(figure.max)
    if not math.isfinite(top) or math.isinf(figure.max):  # a magnitude above 1.8e308
        assert figure.rms == figure.max
        return
    if top == 0:
        assert figure.rms == 0
        return
    exact = top * math.sqrt(float(sum((Fraction(v) / Fraction(top)) ** 2 for v in kept)
                                  / len(kept)))
    assert figure.rms == pytest.approx(exact, rel=(len(kept) + 2) * 2.3e-16, abs=0.0)


@pytest.mark.parametrize("workers", [1, 2])
def test_cycle_analysis_in_chunks_equals_one_evaluation_of_all_angles(paper, monkeypatch, workers):
    """The chunked (and threaded) evaluation fills every sample, in order, with the values of
    one whole-array evaluation: 1000 angles in chunks of 64, the last one short. (To rounding,
    not bitwise: numpy's vectorised sin/cos may round differently at a loop's tail.)"""
    monkeypatch.setattr(cycle, "CHUNK", 64)
    monkeypatch.setattr(cycle, "WORKERS", workers)
    ca = cycle.cycle_analysis(paper, 10.0, 1000, route="newton-euler")
    mo = kin.motion(paper.lengths, ca.theta1, 10.0, 0.0, paper.branch)
    whole = inverse.inverse_dynamics(paper, mo, route="newton-euler")
    # An ulp of sin/cos carried through the analysis: ROUNDING times its condition.
    condition = 1 / np.min(np.abs(mo.pos.sin_transmission))
    r = ca.reactions
    pairs = {"RA0": (r.ground["A0"], whole.ground["A0"]),
             "RA3": (r.ground["A3"], whole.ground["A3"]),
             **{name: (getattr(r, name), getattr(whole, name)) for name in
                ("shaking_force", "shaking_moment", "driving_torque")}}
    for name, (values, expected) in pairs.items():
        assert rel_err(values, expected) < ROUNDING * condition, name


def test_cycle_analysis_refuses_a_crank_that_cannot_turn():
    rng = np.random.default_rng(0)
    lengths = CLASS_EXAMPLES["rocker-crank"]
    linkage = FourBar(lengths=lengths, crank=random_link(rng, 2, loads=False, rotor=False),
                      coupler=random_link(rng, 3, loads=False, rotor=False),
                      rocker=random_link(rng, 1, loads=False, rotor=False))
    with pytest.raises(AssemblyError, match="full revolution"):
        cycle.cycle_analysis(linkage, 10.0)


def test_speed_scaling_without_loads(paper):
    """Without loads every inertial quantity scales with the square of the speed."""
    free = paper.without_loads()
    a = cycle.cycle_analysis(free, 3.0, 90, route="newton-euler")
    b = cycle.cycle_analysis(free, 6.0, 90, route="newton-euler")
    # Rounding: ~ROUNDING·1.4 (the paper's revolution is well conditioned) ≈ 2e-14.
    assert rel_err(b.reactions.ground["A0"], 4 * a.reactions.ground["A0"]) < 1e-13
    assert rel_err(b.reactions.shaking_moment, 4 * a.reactions.shaking_moment) < 1e-13


def test_parallelogram_cycle_passes_its_change_points_smoothly():
    """A parallelogram (change-point linkage) stays a parallelogram through θ1 = 0 and π.

    Independent route: its motion is known in closed form (coupler translates, θ3 = θ1 + π),
    so the shaking force is ω²·e^{iθ1}·(m1·ζ1·l1 + m2·l1 − m3·(ζ3 − 1)·l3) and the shaking
    moment is minus the rate of the closed-form angular momentum.
    """
    from balancer.model import Link

    l1, l2 = 1.0, 2.0
    crank = Link(mass=1.0, inertia=0.1, e=0.4, f=0.1)
    coupler = Link(mass=2.0, inertia=0.5, e=1.1, f=0.2)
    rocker = Link(mass=1.5, inertia=0.2, e=0.3, f=-0.1)
    linkage = FourBar(lengths=(l1, l2, l1, l2), branch="+", crank=crank, coupler=coupler,
                      rocker=rocker)
    speed = 7.0
    ca = cycle.cycle_analysis(linkage, speed, 72, route="newton-euler")
    th = ca.theta1
    # At the change points (θ1 = 0, π) the individual reactions are unbounded: flagged, NaN.
    at_change = np.isclose(np.cos(th) ** 2, 1.0, rtol=0, atol=1e-15)
    assert np.array_equal(ca.singular, at_change) and at_change.sum() == 2
    assert np.all(np.isnan(ca.reactions.ground["A0"][at_change]))
    assert np.all(np.isfinite(ca.reactions.ground["A0"][~at_change]))
    for name in ("shaking_force", "shaking_moment", "driving_torque"):
        assert np.all(np.isfinite(getattr(ca.reactions, name)))
        assert np.isfinite(getattr(ca.summary, name).rms)
    # At a change point the figures are extrapolated from four evaluations δ = 1e-4 rad away
    # (weights Σ|w| ≤ 15), where the reactions, ~1/δ times their usual size, cancel in the
    # sums: rounding 15·ROUNDING·|R(δ)|, times a lever arm for moments. The extrapolation's
    # truncation, O(δ⁴) = 1e-16 relative, is far below it.
    near = cycle.cycle_analysis(linkage, speed, theta1=np.array([1, 2, 3, 4]) * 1e-4,
                                route="newton-euler")
    r_near = max(np.max(np.abs(r)) for r in near.reactions.ground.values())
    force_tol = 15 * ROUNDING * r_near
    moment_tol = force_tol * max(linkage.lengths)
    # Constant kinetic energy: no driving torque (to the extrapolation's rounding at θ1 = 0).
    assert abs(ca.reactions.driving_torque).max() < moment_tol
    coupler_angle = ca.motion.pose.angles[1]
    assert np.max(np.abs(np.sin(coupler_angle))) < 1e-12  # coupler parallel to the frame
    z1, z3 = crank.com / l1, rocker.com / l1
    u = np.exp(1j * th)
    force = speed**2 * u * (crank.mass * z1 * l1 + coupler.mass * l1 - rocker.mass * (z3 - 1) * l1)
    assert np.max(np.abs(ca.reactions.shaking_force - force)) < force_tol

    def momentum(t):
        w = speed
        e = np.exp(1j * (th + w * t))
        r1, v1 = z1 * l1 * e, 1j * w * z1 * l1 * e
        r2, v2 = l1 * e + coupler.com, 1j * w * l1 * e
        r3 = l2 + (z3 - 1) * (-l1 * e)
        v3 = (z3 - 1) * (-1j * w * l1 * e)
        return (crank.inertia * w + crank.mass * kin.cross(r1, v1) + coupler.mass
                * kin.cross(r2, v2) + rocker.inertia * w + rocker.mass * kin.cross(r3, v3))

    moment, error = derivative_with_error(momentum)
    moment = -moment
    assert np.max(np.abs(ca.reactions.shaking_moment - moment)) < error + moment_tol
    other = cycle.cycle_analysis(linkage, speed, 72, route="mass-matrix")
    assert np.max(np.abs(other.reactions.shaking_moment - moment)) < error + moment_tol


@pytest.mark.parametrize("scale", [1.0, 1e200, 1e-200])
def test_figures_of_a_cycle_longer_than_a_chunk(scale):
    """Figure.of takes a long cycle's magnitudes a chunk at a time (no copy of them): the
    figures of 2·CHUNK + 5 random complex samples, at ordinary and extreme magnitudes (the
    scaled route), against math.fsum of the squares of the exactly scaled parts (each
    magnitude one hypot, ε/2; the chunked float sums of n squares within n·ε, halved by the
    root)."""
    rng = np.random.default_rng(11)
    n = 2 * cycle.CHUNK + 5
    parts = rng.normal(size=n) + 1j * rng.normal(size=n)
    figure = cycle.Figure.of(parts * scale)
    mags = [math.hypot(z.real, z.imag) for z in parts]
    top = max(mags)
    assert figure.max == pytest.approx(top * scale, rel=4.5e-16, abs=0.0)
    rms = math.sqrt(math.fsum(m * m for m in mags) / n) * scale
    assert figure.rms == pytest.approx(rms, rel=(n + 4) * 2.3e-16, abs=0.0)
