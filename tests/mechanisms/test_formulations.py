"""The four formulations of the equations of motion against each other and against physics."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import CLASS_EXAMPLES, paper_linkage, random_angles, random_link, random_linkage
from helpers import drift_bound, growth, integration_bound, rel_err

from balancer.cycle import cycle_analysis
from balancer.errors import LockupError
from balancer.formulations import DEAD_POINT_THRESHOLD, make
from balancer.mechanisms.fourbar import assembly, inverse
from balancer.mechanisms.fourbar import kinematics as kin
from balancer.mechanisms.fourbar.mechanism import FourBarMechanism
from balancer.mechanisms.fourbar.model import FourBar
from balancer.model import Link, SimulationSettings
from balancer.simulation import simulate

#: The paper's four formulations of the four-bar.
METHODS = tuple(FourBarMechanism.own_formulations)

#: Tight integrator tolerances for comparing formulations.
TIGHT = {"rtol": 1e-11, "atol": 1e-13}


def _states(seed, n=60):
    """Random linkages (loads, gravity, counter-rotors; both branches, every Grashof class)
    with states away from dead points."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        linkage = random_linkage(rng)
        t = random_angles(rng, linkage, 1)[0]
        if abs(kin.position_of(linkage, t).sin_transmission[0]) < 0.05:
            continue
        out.append((linkage, t, rng.uniform(-4, 4), tuple(rng.uniform(-10, 10, 2))))
    return out


@pytest.mark.parametrize(("linkage", "theta1", "omega1", "gravity"), _states(40))
@pytest.mark.parametrize("driven", [False, True])
def test_formulations_agree_with_each_other_and_newton_euler(linkage, theta1, omega1, gravity,
                                                             driven):
    # Formulations at one state agree to DESIGN.md's 1e-9 relative: _states keeps
    # |sin(θ3 − θ2)| ≥ 0.05, which bounds the condition of the position and rate analyses (≤ 20)
    # and of the equations of motion. Angles and rates come from the position and rate analyses
    # alone (no equations of motion): rounding, ≤ ROUNDING·20 ≈ 3e-13 relative, within 1e-12.
    speed = omega1 if driven else None
    evals = {}
    for name in METHODS:
        f = make(name, linkage, gravity=gravity, speed=speed)
        evals[name] = f.evaluate(0.0, f.initial_state(theta1, omega1))
    ref = evals["opened-loop"]
    # Independent route: with the accelerations found, Newton–Euler needs no motor in free
    # motion and the same motor torque when driven; it gives the same reactions.
    mo = kin.motion_of(linkage, theta1, omega1, ref.alpha[0])
    ne = inverse.newton_euler(linkage, mo, gravity=gravity)
    force = max(abs(ne.ground["A0"][0]), abs(ne.ground["A3"][0]), 1.0)
    moment = max(abs(ne.shaking_moment[0]), force * max(linkage.lengths))
    acc = max(np.max(np.abs(ref.alpha)), omega1**2, 1.0)
    assert abs(ne.driving_torque[0] - ref.driving_torque) < 1e-9 * moment
    assert rel_err([mo.alpha[1][0], mo.alpha[2][0]], ref.alpha[1:], scale=acc) < 1e-9
    for name, ev in evals.items():
        assert rel_err(ev.omega, ref.omega, scale=max(1.0, abs(omega1))) < 1e-12, name
        assert rel_err(ev.alpha, ref.alpha, scale=acc) < 1e-9, name
        assert abs(ev.ground["A0"] - ne.ground["A0"][0]) < 1e-9 * force, name
        assert abs(ev.ground["A3"] - ne.ground["A3"][0]) < 1e-9 * force, name
        assert abs(ev.driving_torque - ref.driving_torque) < 1e-9 * moment, name
        d = np.remainder(ev.theta - ref.theta + np.pi, 2 * np.pi) - np.pi
        assert np.max(np.abs(d)) < 1e-12, name


#: The paper's example (Eq. 56): free from rest at θ1 = 1 rad for 5 s, no gravity.
PAPER_FREE = SimulationSettings(duration=5.0, theta1=1.0, omega1=0.0)


@pytest.fixture(scope="module")
def paper_runs():
    """The paper's example by every formulation."""
    return {m: simulate(paper_linkage(), PAPER_FREE, method=m, **TIGHT) for m in METHODS}


@pytest.fixture(scope="module")
def paper_growth(paper_runs):
    """How much the paper's free motion amplifies integration errors (helpers.growth)."""
    return growth(simulate, paper_linkage(), PAPER_FREE, method="complex-masses", **TIGHT,
                  reference=paper_runs["complex-masses"])


def test_paper_example_final_states_agree(paper_runs, paper_growth):
    ref = paper_runs["opened-loop"]
    for name, tr in paper_runs.items():
        for key in ("theta", "omega", "alpha"):
            a = np.array(tr.state(-1)[key])
            b = np.array(ref.state(-1)[key])
            # Two integrations of one free motion: their bounds, amplified by the motion.
            tol = paper_growth.bound(lambda run, key=key: getattr(run, key), tr, ref)
            assert np.max(np.abs(a - b)) < tol, (name, key)
        for key in ("theta", "omega", "alpha"):
            # No integration yet: rounding at the paper's well-conditioned start
            # (|sin(θ3 − θ2)| ≈ 0.9), ~ROUNDING·|value| ≈ 1e-14, within 1e-12.
            assert tr.state(0)[key] == pytest.approx(ref.state(0)[key], abs=1e-12)


def test_paper_example_reaction_histories_agree(paper_runs, paper_growth):
    ref = paper_runs["opened-loop"]
    for name, tr in paper_runs.items():
        assert np.array_equal(tr.t, ref.t)
        for key in ("A0", "A3"):
            # Reactions along two integrations of one free motion: their bounds, amplified.
            tol = paper_growth.bound(lambda run, key=key: run.ground[key], tr, ref)
            assert np.max(np.abs(tr.ground[key] - ref.ground[key])) < tol, (name, key)


def test_paper_example_energy_and_drift(paper_runs):
    for name, tr in paper_runs.items():
        # T − T0 − W is a first integral; T is quadratic in the rates: twice the bound.
        assert tr.energy_error < 2 * integration_bound(tr), name
        pos, vel = drift_bound(tr, paper_linkage().lengths)
        assert tr.drift[0] < pos and tr.drift[1] < vel, name
        # The loads do work: the kinetic energy really changes.
        assert np.ptp(tr.kinetic_energy) > 0.1


def test_paper_example_reactions_are_the_inverse_dynamics_of_the_motion(paper_runs):
    """Along the simulated motion, Newton–Euler with the simulated accelerations gives the
    simulated reactions and needs no motor (free motion)."""
    tr = paper_runs["mass-matrix"]
    linkage = paper_linkage()
    mo = kin.motion_of(linkage, tr.theta[0], tr.omega[0], tr.alpha[0])
    ne = inverse.newton_euler(linkage, mo)
    # Two routes at the same states (no integration between them): DESIGN.md's 1e-9 relative;
    # the paper's motion keeps |sin(θ3 − θ2)| ≥ 0.7. A torque's scale is a force's times a
    # length (N·m).
    scale = np.max(np.abs(tr.ground["A0"]))
    assert np.max(np.abs(ne.ground["A0"] - tr.ground["A0"])) < 1e-9 * scale
    assert np.max(np.abs(ne.driving_torque)) < 1e-9 * scale * max(linkage.lengths)


def _bai(lengths):
    """Bai, Xia & Ge (2024), Sect. 7: masses and inertias; centres of mass at mid-link (the paper
    does not give them)."""
    masses = (0.1, 0.25, 0.18)
    inertias = (0.001, 0.016, 0.006)
    links = [Link(mass=m, inertia=i, e=length / 2, f=0.0)
             for m, i, length in zip(masses, inertias, lengths, strict=False)]
    return FourBar(lengths=lengths, crank=links[0], coupler=links[1], rocker=links[2])


@pytest.mark.slow
def test_bai_crank_rocker_with_gravity():
    linkage = _bai((0.12, 0.25, 0.26, 0.3))
    # Their initial attitudes: q_A = (1, 0), q_B = (0.3044, 0.9534), q_D = (−0.3996, 0.9167),
    # printed to four digits. Their q_B has length 1.0008: their state closes the loop with a
    # coupler 0.25·|q_B| long (the printed vectors lie within √2·5e-5, half a unit of the
    # fourth digit in each component, of that solution). Ours differ from theirs by what that
    # length changes in the position analysis, plus that rounding.
    q_b, q_d = complex(0.3044, 0.9534), complex(-0.3996, 0.9167)
    pos = kin.position_of(linkage, 0.0)
    lengths = list(linkage.lengths)
    lengths[1] *= abs(q_b)
    theirs = kin.position(tuple(lengths), 0.0, linkage.branch)
    rounding = math.sqrt(2) * 5e-5
    assert abs(pos.l2[0] / 0.25 - q_b) < abs(theirs.l2[0] - pos.l2[0]) / 0.25 + rounding
    assert abs(-pos.l3[0] / 0.26 - q_d) < abs(theirs.l3[0] - pos.l3[0]) / 0.26 + rounding
    settings = SimulationSettings(duration=5.0, theta1=0.0, omega1=0.0, gravity=(0.0, -9.81))
    runs = {m: simulate(linkage, settings, method=m, **TIGHT) for m in METHODS}
    ref = runs["opened-loop"]
    amplified = growth(simulate, linkage, settings, method="complex-masses", **TIGHT,
                       reference=runs["complex-masses"])
    for name, tr in runs.items():
        assert tr.energy_error < 2 * integration_bound(tr), name  # first integral, quadratic
        tol = amplified.bound(lambda run: run.theta, tr, ref)  # one free motion, amplified
        assert np.max(np.abs(tr.theta[:, -1] - ref.theta[:, -1])) < tol, name
    # With gravity only, energy is conserved: the motion is periodic and returns to rest height
    # (to the first integral's bound, relative to the energies).
    scale = max(np.max(np.abs(ref.kinetic_energy)), np.max(np.abs(ref.work)))
    assert np.max(np.abs(ref.work + (ref.kinetic_energy[0] - ref.kinetic_energy))) < (
        2 * integration_bound(ref) * scale)


@pytest.mark.slow
def test_bai_parallelogram_keeps_its_coupler_parallel():
    linkage = _bai((0.1, 0.25, 0.1, 0.25))
    assert str(assembly.classify(linkage.lengths)) == "change-point"
    # Their initial attitudes q0 = [0.6; 0.8; 1; 0; 0.6; 0.8], momentum 0.
    settings = SimulationSettings(duration=5.0, theta1=math.atan2(0.8, 0.6), omega1=0.0,
                                  gravity=(0.0, -9.81))
    runs = {m: simulate(linkage, settings, method=m, **TIGHT) for m in METHODS}
    ref = runs["complex-masses"]
    amplified = growth(simulate, linkage, settings, method="complex-masses", **TIGHT,
                       reference=ref)
    for name, tr in runs.items():
        # Not integration error: every state is projected onto the loop closure (to 1e-15·Σl,
        # or put on the smooth assembly near a change point), which holds the parallelogram;
        # rounding of angles of a few radians and of that projection, within 1e-12.
        assert np.max(np.abs(np.sin(tr.theta[1]))) < 1e-12, name  # coupler ∥ frame
        rocker = np.remainder(tr.theta[2] - tr.theta[0], 2 * np.pi)  # rocker ∥ crank
        assert np.max(np.abs(rocker - np.pi)) < 1e-12, name
        assert tr.energy_error < 2 * integration_bound(tr), name  # first integral, quadratic
        # It swings through both change points (θ1 = 0 and −π) like a pendulum.
        assert tr.theta[0].min() < -np.pi < 0 < tr.theta[0].max()
        # A pendulum shears its errors into a phase error: the bound, amplified by the motion.
        tol = amplified.bound(lambda run: run.theta[0], tr, ref)
        assert np.max(np.abs(tr.theta[0] - ref.theta[0])) < tol, name


def _triple_rocker():
    rng = np.random.default_rng(3)
    lengths = CLASS_EXAMPLES["triple-rocker"]
    links = [random_link(rng, length, loads=False, rotor=False) for length in lengths[:3]]
    return FourBar(lengths=lengths, crank=links[0], coupler=links[1], rocker=links[2])


@pytest.mark.slow
def test_non_minimal_formulations_swing_through_a_dead_point():
    linkage = _triple_rocker()
    rng = assembly.assembly_range(linkage.lengths)
    (lo, hi), = rng.intervals
    settings = SimulationSettings(duration=3.0, theta1=0.0, omega1=6.0)
    runs = {m: simulate(linkage, settings, method=m, **TIGHT)
            for m in ("opened-loop", "mass-matrix")}
    ref = runs["opened-loop"]
    # The crank turns back at the ends of its range, where coupler and rocker align. Beyond hi
    # the loop cannot close: the closure's residual grows at d|A1A3|/dθ1 = l1·l4·sin(hi)/(l2 +
    # l3) per radian, and the projected states keep it within one step's drift.
    l1, l2, l3, l4 = linkage.lengths
    overshoot = drift_bound(ref, linkage.lengths)[0] * (l2 + l3) / (l1 * l4 * abs(math.sin(hi)))
    # The crank stops there (ω1 = 0): the nearest output, within half an output step Δt/2 of
    # it, is below hi by at most ½·|α1|·(Δt/2)², α1 taken at the outputs around it.
    top = int(np.argmax(ref.theta[0]))
    dt = ref.t[1] - ref.t[0]
    sampling = 0.5 * np.max(np.abs(ref.alpha[0][max(top - 1, 0) : top + 2])) * (dt / 2) ** 2
    assert hi - sampling < ref.theta[0].max() <= hi + overshoot
    assert np.any(np.diff(np.sign(np.sin(ref.theta[2] - ref.theta[1]))) != 0)
    amplified = growth(simulate, linkage, settings, method="opened-loop", **TIGHT, reference=ref)
    for name, tr in runs.items():
        assert tr.energy_error < 2 * integration_bound(tr), name  # first integral, quadratic
        tol = amplified.bound(lambda run: run.theta, tr, ref)  # one free motion, amplified
        assert np.max(np.abs(tr.theta[:, -1] - ref.theta[:, -1])) < tol, name


@pytest.mark.parametrize("method", ["complex-masses", "lie-group"])
@pytest.mark.slow
def test_crank_angle_formulations_stop_at_a_dead_point(method):
    linkage = _triple_rocker()
    settings = SimulationSettings(duration=3.0, theta1=0.0, omega1=6.0)
    reference = simulate(linkage, settings, method="opened-loop", **TIGHT, outputs=30001)
    # The reference passes the dead point where sin(θ3 − θ2) changes sign, the crank at the end
    # of its range.
    s = np.sign(np.sin(reference.theta[2] - reference.theta[1]))
    k = int(np.argmax(s != s[0]))
    first = reference.t[k]
    with pytest.raises(LockupError, match="dead point") as info:
        simulate(linkage, settings, method=method, **TIGHT)
    # ``first`` is within one output step after the dead point; the run stops where
    # |sin(θ3 − θ2)| falls to the threshold, threshold/|θ̇3 − θ̇2| before it (sin(θ3 − θ2) is
    # linear in time there; twice that for its curvature and the rate's change over a step).
    rate = np.min(np.abs(reference.omega[2] - reference.omega[1])[k - 1 : k + 1])
    dt = reference.t[1] - reference.t[0]
    assert abs(info.value.time - first) < dt + 2 * DEAD_POINT_THRESHOLD / rate
    # Near the end hi of the crank's range |sin(θ3 − θ2)| ≈ c·√(hi − θ1): the run stops
    # (threshold/c)² before hi; twice that for the next term and the integration error.
    (_, hi), = assembly.assembly_range(linkage.lengths).intervals
    c = abs(kin.position_of(linkage, hi - 1e-8).sin_transmission[0]) / 1e-4
    assert abs(info.value.theta1 - hi) < 2 * (DEAD_POINT_THRESHOLD / c) ** 2
    partial = info.value.partial
    # Outputs are taken up to the event time to simulate's 1e-14·max(1, t) slack; 1e-12 ≥ it.
    assert partial.t[-1] <= info.value.time + 1e-12
    assert partial.energy_error < 2 * integration_bound(partial)  # first integral, quadratic


def test_driven_crank_that_cannot_turn_locks():
    rng = np.random.default_rng(4)
    lengths = CLASS_EXAMPLES["rocker-crank"]
    links = [random_link(rng, length, loads=False, rotor=False) for length in lengths[:3]]
    linkage = FourBar(lengths=lengths, crank=links[0], coupler=links[1], rocker=links[2])
    _, (_, hi) = assembly.assembly_range(lengths).intervals  # the interval of θ1 = 1 rad
    settings = SimulationSettings(duration=2.0, theta1=1.0, omega1=2.0, drive="constant-speed")
    with pytest.raises(LockupError, match="locks") as info:
        simulate(linkage, settings, method="opened-loop")
    # The prescribed motion reaches hi at (hi − 1)/2 s: no integration, the rounding of θ1 taken
    # into its 2π window and of the division, a few ε·(|hi| + 2π)/(hi − 1) ≈ 1e-14 relative.
    assert info.value.time == pytest.approx((hi - 1.0) / 2.0, rel=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_driven_motion_matches_the_cycle_analysis(method):
    """A crank held at constant speed: the simulation's torque and reactions are the cycle
    analysis's, and the motor's work balances the kinetic energy and the loads' work."""
    linkage = paper_linkage()
    speed = 4.0
    settings = SimulationSettings(duration=2 * np.pi / speed, theta1=0.0, omega1=speed,
                                  drive="constant-speed", outputs=73)
    tr = simulate(linkage, settings, method=method, **TIGHT)
    # The paper's Newton–Euler route in closed form
    # (balancer.mechanisms.fourbar.inverse.newton_euler).
    ca = cycle_analysis(linkage, speed, theta1=tr.theta[0], route="newton-euler")
    # The motion is prescribed (every state is put on θ1 = θ0 + ω·t and its loop closure), so
    # no integration error enters the reactions: the formulations' algebraic 1e-9 (DESIGN.md)
    # at the paper's well-conditioned positions (|sin(θ3 − θ2)| ≥ 0.7).
    ground = ca.reactions.ground
    scale = np.max(np.abs(ground["A0"]))
    assert np.max(np.abs(tr.ground["A0"] - ground["A0"])) < 1e-9 * scale
    assert np.max(np.abs(tr.ground["A3"] - ground["A3"])) < 1e-9 * scale
    tau_scale = np.max(np.abs(ca.reactions.driving_torque))
    assert np.max(np.abs(tr.driving_torque - ca.reactions.driving_torque)) < 1e-9 * tau_scale
    assert np.max(np.abs(tr.shaking_moment - ca.reactions.shaking_moment)) < 1e-9 * tau_scale
    # The motor's work is integrated: T − T0 − W a first integral, quadratic in the rates.
    assert tr.energy_error < 2 * integration_bound(tr)
    # Prescribed: θ̇1 = ω and θ̈1 = 0 up to rounding.
    assert np.allclose(tr.omega[0], speed) and np.allclose(tr.alpha[0], 0.0, atol=1e-12)


def test_counter_rotors_enter_every_formulation():
    base = paper_linkage()
    from dataclasses import replace

    linkage = base.with_links({"crank": replace(base.crank, counter_rotor=0.7),
                               "rocker": replace(base.rocker, counter_rotor=1.3)})
    settings = SimulationSettings(duration=2.0, theta1=1.0, omega1=0.5)
    runs = {m: simulate(linkage, settings, method=m, **TIGHT) for m in METHODS}
    plain = simulate(base, settings, method="opened-loop", **TIGHT)
    ref = runs["opened-loop"]
    assert np.max(np.abs(plain.theta[:, -1] - ref.theta[:, -1])) > 1e-3  # they matter
    amplified = growth(simulate, linkage, settings, method="complex-masses", **TIGHT,
                       reference=runs["complex-masses"])
    for name, tr in runs.items():
        tol = amplified.bound(lambda run: run.theta, tr, ref)  # one free motion, amplified
        assert np.max(np.abs(tr.theta[:, -1] - ref.theta[:, -1])) < tol, name
        assert tr.energy_error < 2 * integration_bound(tr), name  # first integral, quadratic


@pytest.mark.slow
def test_formulations_agree_at_every_state_along_a_trajectory(paper_runs):
    """The states of the paper's motion, put into each formulation's own state: accelerations
    and reactions agree to 1e-9 relative (the paper checked 501 such states)."""
    traj = paper_runs["opened-loop"]
    linkage = paper_linkage()
    results = {}
    for name in METHODS:
        f = make(name, linkage)
        evs = [f.evaluate(0.0, f.initial_state(th, w)) for th, w in
               zip(traj.theta[0], traj.omega[0], strict=True)]
        results[name] = (np.array([e.alpha for e in evs]), np.array([e.ground["A0"] for e in evs]),
                         np.array([e.ground["A3"] for e in evs]))
    # One state, several formulations: DESIGN.md's 1e-9 relative (the paper's motion keeps
    # |sin(θ3 − θ2)| ≥ 0.7, a well-conditioned set of states).
    ref = results["opened-loop"]
    acc_scale = np.max(np.abs(ref[0]))
    force_scale = max(np.max(np.abs(ref[1])), np.max(np.abs(ref[2])))
    for name, (alpha, ra0, ra3) in results.items():
        assert np.max(np.abs(alpha - ref[0])) < 1e-9 * acc_scale, name
        assert np.max(np.abs(ra0 - ref[1])) < 1e-9 * force_scale, name
        assert np.max(np.abs(ra3 - ref[2])) < 1e-9 * force_scale, name
    # And the simulated accelerations are those of the states themselves (the same state up
    # to its projection, to 1e-15·Σl: the algebraic level again).
    assert np.max(np.abs(ref[0].T - traj.alpha)) < 1e-9 * acc_scale


@pytest.mark.parametrize("driven", [False, True])
@pytest.mark.parametrize("cls", ["crank-rocker", "change-point"])
def test_the_opened_loops_outputs_at_many_states_are_its_single_state_equations(cls, driven):
    # The opened loop evaluates and projects a run's outputs all at once (Eq. 22, 27 as a
    # stack of 5×5 systems; least-norm Gauss–Newton steps by the pseudo-inverse). Against the
    # integrator's own single-state route (its right-hand side: the pose by cmath, one LAPACK
    # solve) the accelerations agree to rounding of a system whose condition the states'
    # transmission (≥ 0.05) bounds; states near a change point take the reduced equation in
    # both. Projected states close the loop (Eq. 26) and its rate (Eq. 5) to rounding, and
    # move least-norm: the correction of the free angles lies in the row space of G.
    rng = np.random.default_rng(3)
    lengths = CLASS_EXAMPLES[cls]
    linkage = FourBar(lengths=lengths, branch="+", **{
        name: random_link(rng, length, loads=True, rotor=name != "coupler")
        for name, length in zip(FourBar.chain_links, lengths, strict=False)})
    f = make("opened-loop", linkage, gravity=(0.3, -9.81), speed=3.0 if driven else None)
    times, states = [], []
    for theta1 in np.linspace(0.05, 2 * np.pi - 0.05, 40):
        if kin.position_of(linkage, theta1, check=False).sin_transmission[0] ** 2 < 0.05**2 \
                and not f.near_change_point(theta1):
            continue
        f.theta1_start = theta1
        y = f.initial_state(theta1, rng.uniform(-4, 4))
        times.append(0.0)
        states.append(y)
    assert any(f.near_change_point(y[0]) for y in states) == (cls == "change-point")
    f.theta1_start = 0.05  # one run's: the smooth motion's branch near a change point
    batch = f.evaluate_batch(times, states)
    for i, (t, y) in enumerate(zip(times, states, strict=True)):
        alpha = f.rhs(t, y)[3:6]
        acc = max(np.max(np.abs(alpha)), y[3] ** 2, 1.0)
        assert rel_err(batch.alpha[:, i], alpha, scale=acc) < 1e-12
    scale = sum(lengths)
    off = [y + np.r_[1e-7 * rng.standard_normal(6), np.zeros(y.size - 6)] for y in states]
    f.theta1_start = 0.0  # driven: the crank angle prescribed at each state's time
    times = [y[0] / f.speed if driven else 0.0 for y in off]
    projected = f.project_many(times, off)
    for t, y0, y in zip(times, off, projected, strict=True):
        if f.near_change_point(y[0]):
            continue
        pos, vel = f.constraint_residual(t, y)
        assert pos < 1e-14 * scale and vel < 1e-13 * max(1.0, np.max(np.abs(y[3:6]))) * scale
        free = slice(1, 3) if driven else slice(0, 3)
        _, g = f._closure(y[0:3])
        move = (y - y0)[free]
        rows = g[:, free]
        along = rows.T @ np.linalg.lstsq(rows.T, move, rcond=None)[0]
        assert np.linalg.norm(move - along) < 1e-6 * np.linalg.norm(move) + 1e-15


@pytest.mark.parametrize("method", [*METHODS, "multibody"])
@pytest.mark.parametrize("drive", ["free", "constant-speed"])
@pytest.mark.slow
def test_coarse_output_times_keep_count_of_the_turns(method, drive):
    # A double crank turning three revolutions between two output times: the links' angles,
    # continuous over the motion, take the branch the motion reached, followed through the
    # integrator's steps (a prescribed motion's crank grid) between the outputs, not predicted
    # from the rates at the outputs alone (which put the coupler a turn astray). The same run
    # with dense outputs is the reference: the same steps, its outputs interpolated; the last
    # output is a step's end in both, to the dense output's interpolation error at most.
    links = [Link(mass=1.0, inertia=0.1, e=0.5 * length, f=0.0) for length in (3.2, 2.0, 3.0)]
    linkage = FourBar(lengths=(3.2, 2.0, 3.0, 1.0), crank=links[0], coupler=links[1],
                      rocker=links[2], branch="+")
    settings = SimulationSettings(duration=2.0, theta1=0.3, omega1=10.0, drive=drive)
    fine = simulate(linkage, settings, method=method, outputs=2001)
    coarse = simulate(linkage, settings, method=method, outputs=3)
    assert np.max(np.abs(coarse.theta[:, -1] - fine.theta[:, -1])) < 1e-6
    assert np.max(np.abs(coarse.theta[:, 1] - fine.theta[:, 1000])) < 1e-6
    assert np.all(np.abs(fine.theta[:, -1] - fine.theta[:, 0]) > 2 * np.pi)  # turns to count
