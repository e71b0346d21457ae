"""The multibody formulation (any linkage) against the seeds' formulations and physics."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers import integration_bound, rel_err
from test_formulations import _states as four_bar_states
from test_slider_crank import CASES as SLIDER_CASES
from test_slider_crank import _angles as slider_angles

from balancer.formulations import make
from balancer.mechanisms import mechanism_of
from balancer.model import SimulationSettings
from balancer.simulation import simulate
from balancer.spec import loads_design

#: A Watt six-bar with a ternary rocker, loads, a spring to the frame and a counter-rotor.
WATT = """
[mechanism]
type = "linkage"
input = "crank"
[mechanism.points]
A0 = [0.0, 0.0]
A1 = [0.0, 1.0]
A2 = [2.2, 1.8]
A3 = [3.2, 0.0]
B  = [1.4, 2.6]
C  = [3.6, 3.4]
D  = [5.0, 0.5]
[links.ground]
points = ["A0", "A3", "D"]
[links.crank]
points = ["A0", "A1"]
mass = 2.0
inertia = 0.5
com = { e = 0.4, f = 0.1 }
counter_rotor = 0.3
[links.coupler]
points = ["A1", "A2"]
mass = 3.0
inertia = 3.1
com = { e = 1.4, f = 0.3 }
force = [1.3, -1.4]
moment = 0.28
[links.rocker]
points = ["A3", "A2", "B"]
mass = 2.2
inertia = 2.1
com = { e = 1.0, f = 0.2 }
[links.link5]
points = ["B", "C"]
mass = 1.0
inertia = 0.4
com = { e = 1.0, f = -0.1 }
moment = -0.5
[links.link6]
points = ["D", "C"]
mass = 1.2
inertia = 0.6
com = { e = 1.0, f = 0.0 }
[[springs]]
points = ["B", "D"]
stiffness = 40.0
free_length = 2.0
[operation]
speed = 6.0
[simulation]
duration = 1.0
omega1 = 5.0
gravity = [0.0, -9.81]
"""


def _watt():
    return loads_design(WATT, "watt.toml")


@pytest.mark.parametrize(("linkage", "theta1", "omega1", "gravity"), four_bar_states(41, 12))
@pytest.mark.parametrize("driven", [False, True])
def test_multibody_agrees_with_the_opened_loop_at_four_bar_states(linkage, theta1, omega1,
                                                                  gravity, driven):
    # One state, two formulations: DESIGN.md's 1e-9 relative. The states keep
    # |sin(θ3 − θ2)| ≥ 0.05, which bounds the condition of both (≤ 20) — see
    # test_formulations_agree_with_each_other_and_newton_euler.
    speed = omega1 if driven else None
    evals = []
    for name in ("opened-loop", "multibody"):
        f = make(name, linkage, gravity=gravity, speed=speed)
        ev = f.evaluate(0.0, f.initial_state(theta1, omega1))
        evals.append((ev, *f.shaking(ev)))
    (ref, ref_force, ref_moment), (mb, mb_force, mb_moment) = evals
    force = max(abs(ref.ground["A0"]), abs(ref.ground["A3"]), 1.0)
    moment = max(force * max(linkage.lengths), abs(ref.driving_torque), 1.0)
    acc = max(np.max(np.abs(ref.alpha)), omega1**2, 1.0)
    assert rel_err(mb.omega, ref.omega, scale=max(1.0, abs(omega1))) < 1e-12
    assert rel_err(mb.alpha, ref.alpha, scale=acc) < 1e-9
    for point in ("A0", "A3"):
        assert abs(mb.ground[point] - ref.ground[point]) < 1e-9 * force, point
    assert abs(mb.driving_torque - ref.driving_torque) < 1e-9 * moment
    assert abs(mb_force - ref_force) < 1e-9 * force
    assert abs(mb_moment - ref_moment) < 1e-9 * moment


@pytest.mark.parametrize("mech", SLIDER_CASES[:6])
@pytest.mark.parametrize("driven", [False, True])
def test_multibody_agrees_with_the_slider_crank_formulation(mech, driven):
    # One state, two formulations (gas force, gravity, loads): 1e-9 relative; the states keep
    # the rod clear of square to the guide (slider_angles), bounding the condition.
    rng = np.random.default_rng(8)
    g = (0.2, -9.81)
    for t in slider_angles(rng, mech, 3):
        w = rng.uniform(-5, 5)
        evs = []
        for name in ("complex-masses", "multibody"):
            f = make(name, mech, gravity=g, speed=w if driven else None)
            ev = f.evaluate(0.0, f.initial_state(t, w))
            evs.append((ev, *f.shaking(ev)))
        (ref, ref_force, ref_moment), (mb, mb_force, mb_moment) = evs
        force = max(abs(ref.ground["A0"]), abs(ref.slider_normal["slider"]), 1.0)
        arm = sum(map(abs, mech.lengths))
        acc = max(np.max(np.abs(ref.alpha)), w * w, 1.0)
        assert rel_err(mb.alpha[:2], ref.alpha[:2], scale=acc) < 1e-9
        assert abs(mb.ground["A0"] - ref.ground["A0"]) < 1e-9 * force
        assert abs(mb.slider_normal["slider"] - ref.slider_normal["slider"]) < 1e-9 * force
        assert abs(mb.slider_couple["slider"] - ref.slider_couple["slider"]) < 1e-9 * force * arm
        assert abs(mb.driving_torque - ref.driving_torque) < 1e-9 * force * arm
        assert abs(mb_force - ref_force) < 1e-9 * force
        assert abs(mb_moment - ref_moment) < 1e-9 * force * arm


@pytest.mark.parametrize("method", ["multibody", "crank-angle"])
def test_a_free_six_bar_with_a_spring_and_gravity_keeps_its_energy(method):
    # crank-angle: its kinetic energy is computed from the links' own velocities (the core's
    # rates at the states), a route apart from the m(θ1) it integrates with.
    design = _watt()
    traj = simulate(design.mechanism, design.simulation, method=method, rtol=1e-10,
                    atol=1e-12)
    assert traj.method == method
    assert np.ptp(traj.kinetic_energy) > 1.0  # the spring and gravity do work
    # T − T0 − W is a first integral of the integrated system: its error is the integration's
    # (integration_bound: 2·steps·rtol for a quantity quadratic in the rates).
    assert traj.energy_error < 2 * integration_bound(traj)
    # The projection keeps the constraints: its residual before projection is a step's error.
    assert traj.drift[0] < 1e3 * traj.rtol * mechanism_of(design.mechanism).structure.length_scale()


def test_a_stephenson_six_bar_in_its_crank_angle_keeps_its_energy():
    # The four-link group placed by Newton steps on symbols inside the compiled equation; the
    # energy from the links' own velocities by the numpy route (its own Newton's method).
    from pathlib import Path

    from balancer.spec import load_design

    design = load_design(Path(__file__).resolve().parents[2] / "examples"
                         / "stephenson_sixbar.toml")
    settings = SimulationSettings(duration=0.5, omega1=8.0, gravity=(0.0, -9.81))
    traj = simulate(design.mechanism, settings, method="crank-angle", rtol=1e-10, atol=1e-12)
    assert np.ptp(traj.kinetic_energy) > 1e-3 * np.max(traj.kinetic_energy)  # gravity works
    assert traj.energy_error < 2 * integration_bound(traj)


def test_a_driven_six_bar_has_the_cycle_analysis_reactions():
    # Driven, the crank angle is exact and the other coordinates are projected onto the
    # constraints at every output: the states are exact to rounding, so the multipliers must
    # give the inverse dynamics of the prescribed motion (the general core's kinetostatics, a
    # different route from the multipliers of M·q̈ + Φqᵀλ = Q) to 1e-9 relative.
    design = _watt()
    speed = 6.0
    settings = SimulationSettings(duration=0.6, omega1=speed, drive="constant-speed",
                                  gravity=(0.0, -9.81))
    traj = simulate(design.mechanism, settings, method="multibody", rtol=1e-10, atol=1e-12,
                    outputs=41)
    mech = mechanism_of(design.mechanism)
    crank = traj.links.index(mech.linkage.input)
    mo = mech.motion(traj.theta[crank], speed, 0.0)
    forces = mech.inverse_dynamics(mo, gravity=(0.0, -9.81))
    force = traj.largest_reaction
    moment = force * mech.structure.length_scale()
    for point, values in traj.ground.items():
        expected = forces.reactions[point].complex()[:, 0] if forces.reactions[point].x.ndim > 1 \
            else forces.reactions[point].complex()
        assert np.max(np.abs(values - expected)) < 1e-9 * force, point
    torque = np.ravel(forces.driving_torque)
    assert np.max(np.abs(traj.driving_torque - torque)) < 1e-9 * moment
    assert np.max(np.abs(traj.shaking_moment - np.ravel(forces.shaking_moment))) < 1e-9 * moment
    assert np.max(np.abs(traj.omega[crank] - speed)) < 1e-12 * speed
    for k in range(len(traj.links)):
        assert rel_err(traj.omega[k], np.ravel(mo.rate[k]), scale=speed) < 1e-9


def _random_crank_states(mech, count: int, seed: int):
    rng = np.random.default_rng(seed)
    start = mech.structure.ref_angle[mech.structure.input]
    return start + rng.uniform(-np.pi, np.pi, count), rng.uniform(-20.0, 20.0, count)


@pytest.mark.parametrize("example", ["watt", "quick_return.toml", "jansen_leg.toml",
                                     "stephenson_sixbar.toml"])
@pytest.mark.slow
def test_the_crank_angle_equation_agrees_with_the_multibody_at_random_states(example):
    # Lagrange's equation in the crank angle (u = dq/dθ1 and b = d²q/dθ1² from the core's
    # group-by-group solves, projected: m(θ1)·θ̈1 = uᵀ(Q − M·b·θ̇1²)) against the multibody's
    # saddle-point system at the same states, free; and driven, its motor torque against the
    # core's kinetostatics (the links' equations solved for the multipliers, no projection).
    # Both sides are exact to rounding: 1e-9 relative. The Stephenson six-bar's four-link
    # group: Newton steps on symbols from a spline of its table, against the numpy route's.
    from pathlib import Path

    from balancer.spec import load_design

    if example == "watt":
        design = _watt()  # a spring and gravity
        gravity = design.simulation.gravity
    else:
        design = load_design(Path(__file__).resolve().parents[2] / "examples" / example)
        gravity = (0.0, -9.81)
    mech = mechanism_of(design.mechanism)
    crank = make("crank-angle", design.mechanism, gravity=gravity)
    multi = make("multibody", design.mechanism, gravity=gravity)
    theta1, omega1 = _random_crank_states(mech, 25, seed=12)
    i = 3 * mech.structure.input + 2
    alpha_crank, alpha_multi = [], []
    for th, w in zip(theta1, omega1, strict=True):
        alpha_crank.append(crank.rhs(0.0, crank.initial_state(th, w))[1])
        alpha_multi.append(multi.rhs(0.0, multi.initial_state(th, w))[3 * multi.n + i])
    alpha_multi = np.array(alpha_multi)
    assert rel_err(np.array(alpha_crank), alpha_multi, scale=np.max(np.abs(alpha_multi))) < 1e-9
    for speed in (-7.0, 11.0):
        driven = make("crank-angle", design.mechanism, gravity=gravity, speed=speed)
        power = np.array([driven.rhs(0.0, driven.initial_state(th, speed))[2] for th in theta1])
        with np.errstate(all="ignore"):
            mo = mech.motion(theta1, speed, 0.0)
        torque = np.ravel(mech.inverse_dynamics(mo, gravity=gravity).driving_torque)
        assert rel_err(power / speed, torque, scale=np.max(np.abs(torque))) < 1e-9


@pytest.mark.slow
def test_the_six_bar_through_every_verb(tmp_path, capsys):
    import json

    from balancer.cli import main

    spec = tmp_path / "watt.toml"
    spec.write_text(WATT)
    assert main(["simulate", str(spec), "--json", "--duration", "0.2"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc["initial"]["theta"]) == {"crank", "coupler", "rocker", "link5", "link6"}
    assert set(doc["reactions"]) == {"A0", "A3", "D"}
    out = tmp_path / "watt.csv"
    assert main(["simulate", str(spec), "--out", str(out), "--duration", "0.2"]) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert header == ["t", *(f"{q}{k}" for q in ("theta", "omega", "alpha") for k in range(1, 6)),
                      "RA0x", "RA0y", "RA3x", "RA3y", "RDx", "RDy"]
    capsys.readouterr()
    assert main(["verify", str(spec), "--json", "--duration", "0.2",
                 "--plot", str(tmp_path / "v.png")]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["method"] == "multibody"
    assert (tmp_path / "v.png").stat().st_size > 0
    assert math.isfinite(doc["max_shaking_force"])
    assert main(["plot", str(spec), "--animate", str(tmp_path / "a.gif"), "--frames", "6"]) == 0
    assert (tmp_path / "a.gif").stat().st_size > 0


def test_the_multibody_formulation_names_a_change_point_it_cannot_pass():
    # A parallelogram under gravity reaches its change point (all joints in line) where the
    # constraints are dependent: the saddle-point system is singular, so the run stalls and
    # says where, why, and which formulations follow the smooth motion through it.
    from balancer.errors import SolverError
    from balancer.mechanisms.fourbar.model import FourBar
    from balancer.model import Link

    links = [Link(mass=m, inertia=0.01, e=length / 2, f=0.0)
             for m, length in ((1.0, 0.1), (2.0, 0.25), (1.5, 0.1))]
    mech = FourBar(lengths=(0.1, 0.25, 0.1, 0.25), crank=links[0], coupler=links[1],
                   rocker=links[2], branch="+")
    settings = SimulationSettings(duration=5.0, theta1=math.atan2(0.8, 0.6), omega1=0.0,
                                  gravity=(0.0, -9.81))
    # It swings down through θ1 = 0 and on to π: the stall comes at one of them, the one the
    # integration's rounding brings it nearest.
    with pytest.raises(SolverError, match=r"change point θ1 = (0|3\.14159) rad.*multibody "
                                          r"formulation cannot pass it \(opened-loop"):
        simulate(mech, settings, method="multibody", rtol=1e-10, atol=1e-12)


def test_initial_angles_are_continued_from_the_reference_pose():
    # DESIGN.md: a link's angle is its principal value at the reference pose, continuous from
    # there on. Independent route: the reference angle plus the integral of the link's rate
    # (at unit crank rate) over the crank's path, by Simpson's rule; its error is estimated by
    # halving the step (the difference of the two), and the tolerance is ten times that.
    from pathlib import Path

    from scipy.integrate import simpson

    from balancer.formulations import make
    from balancer.spec import load_design

    design = load_design(Path(__file__).resolve().parents[2] / "examples" / "jansen_leg.toml")
    f = make("multibody", design.mechanism)
    s = f.structure
    start = s.ref_angle[s.input]
    largest = 0.0
    for turn in (3.0, -3.0, 2 * math.pi + 1.0):
        angles = f.initial_state(start + turn, 1.0)[2 : 3 * f.n : 3]
        largest = max([largest, *(abs(a) for k, a in enumerate(angles) if k != s.input)])
        estimates = []
        for count in (2001, 4001):
            grid = np.linspace(start, start + turn, count)
            rates = f.mech.motion(grid, 1.0, 0.0).rate
            estimates.append(np.array([s.ref_angle[k] + simpson(np.broadcast_to(
                rates[k], grid.shape), x=grid) for k in range(f.n)]))
        error = np.max(np.abs(estimates[1] - estimates[0]))
        assert np.max(np.abs(angles - estimates[1])) < 10 * error + 1e-12, turn
    # a link other than the crank whose angle passes ±π: what a principal value would miss
    assert largest > math.pi


#: A Watt six-bar a thousand kilometres across (the CLI fuzz campaign's extreme-scale family):
#: inertias about the frames' origins of 1e12 kg·m² beside masses of 1 kg.
HUGE = """title = "fuzz watt1"

[mechanism]
type = "linkage"
input = "crank"

[mechanism.points]
A0 = [0.0, 0.0]
A3 = [-586345.8287192207, 1830256.773688731]
A1 = [-162389.74358819384, 643681.319932425]
A2 = [-1699017.9592077506, -408256.66949369333]
C = [-576049.0880595478, 430234.5338047858]
D = [-854916.1691306151, 1729893.5801045294]
E = [798999.1084870339, 456133.00874369754]

[links]

[links.ground]
points = ["A0", "A3"]

[links.crank]
points = ["A0", "A1"]
mass = 0.322685
inertia = 9236870000.0
com = { e = 305531.0, f = 84984.6 }
counter_rotor = 136893000000.0

[links.coupler]
points = ["A1", "A2", "C"]
mass = 0.418628
inertia = 62331000000.0
com = { s = 1872710.0, sigma = 0.0551977 }

[links.rocker]
points = ["A3", "A2", "D"]
mass = 3.91114
inertia = 2682790000000.0
com = { e = -683579.0, f = -978035.0 }

[links.link5]
points = ["C", "E"]
mass = 0.523308
inertia = 7338710000.0
com = { at = [-123696.43033332226, 123327.47989754786] }

[links.link6]
points = ["D", "E"]
mass = 3.50857
inertia = 1371510000000.0
com = { e = 2207300.0, f = 679464.0 }

[operation]
speed = -3.2291
samples = 36

[simulation]
duration = 1.12957
omega1 = -1.14894
drive = "constant-speed"
"""


def test_a_linkage_of_extreme_scale_simulates_accurately():
    # The saddle-point system's condition was ~1e15 and CasADi's QR failed mid-run (an
    # internal error). Equilibrated by the masses and inertias, it solves; the energy balance
    # holds to the integration's bound.
    design = loads_design(HUGE, "huge.toml")
    traj = simulate(design.mechanism, design.simulation, duration=0.05, rtol=1e-10,
                    atol=1e-12)
    assert np.all(np.isfinite(traj.shaking_moment))
    assert traj.energy_error < 2 * integration_bound(traj)


#: A quick-return 800 m long at 134 rad/s: the crank, the block sliding on the lever and the
#: lever of the linkage fuzz campaign's cases 1088 and 2664 (seed 2026), in round numbers.
QUICK_RETURN = """
[mechanism]
type = "linkage"
input = "crank"
[mechanism.points]
A0 = [0.0, 0.0]
B0 = [0.0, -450.0]
A1 = [120.0, 150.0]
C = [150.0, 300.0]
[[mechanism.sliders]]
link = "block"
guide = "lever"
point = "A1"
direction = [1.0, 5.0]
[links.ground]
points = ["A0", "B0"]
[links.crank]
points = ["A0", "A1"]
mass = 12.0
inertia = 32000.0
com = { e = 17.0, f = 32.0 }
[links.block]
points = ["A1"]
mass = 17.0
inertia = 210000.0
com = { e = -43.0, f = 39.0 }
[links.lever]
points = ["B0", "C"]
mass = 35.0
inertia = 4600000.0
com = { e = 770.0, f = -290.0 }
[operation]
speed = -134.0
"""


@pytest.mark.parametrize("drive", ["constant-speed", "free"])
def test_a_large_fast_linkage_is_not_held_to_the_rounding_of_its_pinned_frames(drive):
    # `balancer verify` (rtol 1e-11, atol 1e-13) of the campaign's quick-returns ran for
    # minutes (30 000 steps a turn): the velocities of the frames pinned at their origins are
    # zero, their accelerations come out of the saddle-point system as the rounding of the
    # others' (1e-6 m/s² of 1e7), and an absolute tolerance of 1e-13 m/s held the steps to
    # that noise. Each component's tolerance is floored at 100 ε of the largest of its kind:
    # a few steps a turn, and the motion the crank-angle formulation (no such components)
    # integrates.
    from dataclasses import replace

    design = loads_design(QUICK_RETURN, "quick_return.toml")
    settings = replace(design.simulation, drive=drive, omega1=design.operation.speed)
    steps = []

    def progress(t: float, duration: float) -> None:  # fail, not crawl, if the steps shrink
        steps.append(t)
        assert len(steps) <= 200, f"{len(steps)} steps by t = {t:.3g} s"

    options = {"duration": 0.01, "rtol": 1e-11, "atol": 1e-13, "outputs": 21}
    run = simulate(design.mechanism, settings, method="multibody", progress=progress,
                   **options)
    ref = simulate(design.mechanism, settings, method="crank-angle", **options)
    assert run.steps < 100  # driven: 508 before the floor
    bound = integration_bound(run, ref)
    assert run.energy_error < 2 * integration_bound(run)
    assert np.max(np.abs(run.theta - ref.theta)) < bound * np.max(np.abs(ref.theta))
    assert (np.max(np.abs(run.shaking_force - ref.shaking_force))
            < bound * np.max(np.abs(ref.shaking_force)))


def test_a_start_many_turns_away_is_followed_over_part_of_a_turn():
    # The crank angle 1000 turns from the reference: the path is not followed step by step
    # (2·10⁵ poses; at 10¹² rad it hung the fuzz campaign) but over the part of a turn, each
    # whole turn adding what a revolution adds — nothing, for Jansen's swinging links.
    from pathlib import Path

    from balancer.formulations import make
    from balancer.spec import load_design

    design = load_design(Path(__file__).resolve().parents[2] / "examples" / "jansen_leg.toml")
    f = make("multibody", design.mechanism)
    s = f.structure
    start = s.ref_angle[s.input]
    near = f.initial_state(start + 3.0, 1.0)[2 : 3 * f.n : 3]
    far = f.initial_state(start + 3.0 + 2000 * math.pi, 1.0)[2 : 3 * f.n : 3]
    others = [k for k in range(f.n) if k != s.input]
    # the same pose: the angles agree to the rounding of the crank angle (ulp(6283) ≈ 1e-12)
    # times the links' transmission (≤ 10 here)
    assert np.max(np.abs(far[others] - near[others])) < 1e-10


@pytest.mark.parametrize("method", ["crank-angle", "multibody"])
@pytest.mark.parametrize("driven", [False, True])
def test_a_compiled_dop853_step_is_scipys_step(method, driven):
    # The twelve stages of a step (and the dense output's three) compiled into one call, the
    # controller SciPy's: from the same state and first step, the same step to rounding (the
    # stages' sums are in another order: a few ulps of the state per stage, 16 stages).
    from scipy.integrate import DOP853

    from balancer.simulation.integrator import CompiledDOP853, Stages, with_extra_work
    from balancer.simulation.stepper import WithExtraWork

    design = _watt()
    f = make(method, design.mechanism, gravity=design.simulation.gravity,
             speed=5.0 if driven else None)
    own = WithExtraWork(f)
    y0 = np.append(f.initial_state(0.3, 4.0), 0.0)
    options = {"rtol": 1e-10, "atol": 1e-12, "first_step": 1e-3}
    ref = DOP853(own.rhs, 0.0, y0, 1.0, **options)
    run = CompiledDOP853(own.rhs, 0.0, y0, 1.0, stages=Stages(with_extra_work(f.symbolic_rhs())),
                         **options)
    eps = np.finfo(float).eps
    ref.step()
    run.step()
    assert run.t == ref.t == 1e-3  # the first step taken as given (an error well within)
    scale = np.max(np.abs(ref.y)) + ref.h_previous * np.max(np.abs(ref.f))
    assert np.max(np.abs(run.y - ref.y)) < 16 * 4 * eps * scale
    mid = 0.5 * (ref.t_old + ref.t)
    assert np.max(np.abs(run.dense_output()(mid) - ref.dense_output()(mid))) < 16 * 4 * eps * scale
    # The next step's size comes from the error estimate, a difference of nearly equal sums of
    # stages: rounding moves it by about ε/rtol relative, no more.
    assert abs(run.h_abs - ref.h_abs) <= 1e3 * eps / options["rtol"] * ref.h_abs
    assert run.nfev == ref.nfev


@pytest.mark.parametrize("driven", [False, True])
def test_projecting_many_states_together_is_projecting_each(driven):
    # A step's output times are projected together (the Newton steps' linear systems
    # stacked): the same states as one by one, but for the rounding of the stacked products.
    design = _watt()
    f = make("multibody", design.mechanism, gravity=design.simulation.gravity,
             speed=4.0 if driven else None)
    rng = np.random.default_rng(7)
    times = np.linspace(0.0, 0.3, 6)
    states = []
    for t in times:
        y = f.initial_state(0.3 + (0.0 if driven else 4.0 * t), 4.0)
        f.theta1_start = 0.3
        k = 2 * 3 * f.n
        y[:k] += 1e-7 * rng.standard_normal(k) * np.maximum(np.abs(y[:k]), 1.0)  # off the
        states.append(y)  # constraints, as an interpolated output is
    together = f.project_many(times, states)
    for t, y, mine in zip(times, states, together, strict=True):
        alone = f.project(t, y)
        assert rel_err(mine, alone) < 1e-13
        pos, vel = f.constraint_residual(t, mine)
        assert pos < 1e-13 * f.scale and vel < 1e-12 * np.max(np.abs(alone))
    # The outputs' dynamics are evaluated in one mapped call of the compiled function: the
    # same numbers as the integrator's single calls of it (its angular accelerations).
    batch = f.evaluate_batch(times, together)
    k = 3 * f.n
    for i, (t, y) in enumerate(zip(times, together, strict=True)):
        single = f.rhs(t, y)[k + 2 : 2 * k : 3]
        assert np.array_equal(batch.alpha[:, i], single)


def test_a_compiled_function_over_columns_is_its_single_calls():
    # Compiled.columns calls a function mapped over BLOCK columns block by block, the last
    # block padded: across every kind of block boundary, each column's outputs are exactly
    # the single call's (the same compiled code on the same inputs).
    from balancer.formulations.compiled import BLOCK

    f = make("multibody", _watt().mechanism)
    rng = np.random.default_rng(11)
    for fn in (f._constraints, f._fast_dynamics):
        for count in (1, BLOCK - 1, BLOCK, BLOCK + 1, 3 * BLOCK + 5):
            x = rng.uniform(-1.0, 1.0, (fn.arg.size, count))
            together = fn.columns(x)
            assert together.shape == (fn.res.size, count)
            for j in range(count):
                assert np.array_equal(together[:, j], fn(x[:, j]), equal_nan=True)
