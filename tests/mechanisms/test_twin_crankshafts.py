"""Geared twin crankshafts (``[[crankshafts]]``) against two engines and a gear by hand.

A twin-crank engine is two engines whose crankshafts a pair of equal spur gears turns opposite
ways: engine A (the first crankshaft's cylinders and masses, about the origin) at θ1, and
engine B (the second's, built as an engine of its own about the origin) at ``−θ1`` — the same
motions, B's moved to its axis ``ā``. What the frame feels is theirs summed: the shaking force
``F_A + F_B``, the rocking couple ``C_A + C_B``, the shaking moment ``M_A + M_B + ā × F_B``
(B's about its own axis, carried to the origin). B's motor torque ``T_B`` is now the tooth's:
the tooth force ``λ·t`` on B at the pitch point ``ā/2`` (``t = i·ā/|ā|``) turns B about its
axis by ``−(|ā|/2)·λ``, so ``λ = −2·T_B/|ā|``; the first crankshaft's motor drives both,
``T_A − T_B`` (power: B turns at −ω); the main bearings pass A's reaction less the tooth force,
B's axis B's reaction plus it. Each engine alone is checked against closed forms in
``test_engines.py``; here the gear's share is computed by hand.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import cvxpy as cp
import numpy as np
import pytest

from balancer.balance.optimizer import optimize
from balancer.balance.problem import numeric_problem
from balancer.cycle import cycle_analysis
from balancer.errors import SpecError
from balancer.mechanisms import mechanism_of
from balancer.mechanisms.engine.bearings import lever_shares
from balancer.mechanisms.engine.model import (
    BalanceShaft,
    Crankshaft,
    Cylinder,
    Engine,
    GearedCrankshaft,
    Mass,
)
from balancer.model import Link
from balancer.plots.drawing import pitch_circles
from balancer.spec import dumps_design, load_design, loads_design

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: Two routes through the same core at the same states: rounding of sums of a few dozen terms
#: each within 64 ε, times the position analysis' condition (< 10 here).
EXACT = 1e-11


def masses(rng: np.random.Generator, count: int) -> tuple[Mass, ...]:
    return tuple(Mass(mr=float(rng.uniform(0.0, 0.02)), phase_deg=float(rng.uniform(0, 360)),
                      z=float(rng.uniform(-0.1, 0.1))) for _ in range(count))


def twin(rng: np.random.Generator, front: int, rear: int, ratio: int = -1) -> Engine:
    """A random twin: ``front`` cylinders on the first crankshaft, ``rear`` on a geared one
    (at ``ratio``: +1 through an idler of some inertia)."""
    cylinders = []
    for k in range(front + rear):
        crank = float(rng.uniform(0.03, 0.05))
        cylinders.append(Cylinder(
            z=float(rng.uniform(-0.1, 0.1)), phase_deg=float(rng.uniform(0, 360)),
            bank_deg=float(rng.uniform(0, 360)), crank=crank,
            rod=float(rng.uniform(3.0, 4.0)) * crank,
            offset=float(rng.uniform(-0.2, 0.2)) * crank, crankshaft=1 if k < front else 2))
    rod = Link(mass=float(rng.uniform(0.3, 0.8)), inertia=float(rng.uniform(1e-3, 3e-3)),
               e=float(rng.uniform(0.02, 0.05)), f=float(rng.uniform(-0.01, 0.01)))
    at = (float(rng.uniform(0.08, 0.2)) * rng.choice([-1, 1]), float(rng.uniform(-0.1, 0.1)))
    return Engine(
        cylinders=tuple(cylinders), rod=rod, piston=float(rng.uniform(0.3, 0.6)),
        crankshaft=Crankshaft(inertia=0.02, masses=masses(rng, 2)),
        crankshafts=(GearedCrankshaft(at=at, inertia=0.011, masses=masses(rng, 3), ratio=ratio,
                                      idler_inertia=0.004 if ratio == 1 else 0.0),),
        balance_shafts=(BalanceShaft(ratio=2, at=(0.0, -0.1), inertia=4e-4,
                                     eccentrics=masses(rng, 1)),))


def halves(engine: Engine) -> tuple[Engine, Engine]:
    """Engine A (the first crankshaft's cylinders, its masses, the balance shafts) and engine
    B (the geared crankshaft's cylinders and masses, as an engine about the origin)."""
    geared = engine.crankshafts[0]
    a = replace(engine, cylinders=tuple(c for c in engine.cylinders if c.crankshaft == 1),
                crankshafts=())
    b = replace(engine, cylinders=tuple(replace(c, crankshaft=1) for c in engine.cylinders
                                        if c.crankshaft == 2),
                crankshafts=(), balance_shafts=(),
                crankshaft=Crankshaft(inertia=geared.inertia, masses=geared.masses))
    return a, b


def column(v) -> np.ndarray:
    return np.asarray(v.x)[:, 0] + 1j * np.asarray(v.y)[:, 0]


@pytest.mark.parametrize(("front", "rear", "seed", "gravity"), [
    (1, 1, 1, (0.0, 0.0)), (2, 1, 2, (0.0, 0.0)), (2, 3, 3, (0.0, 0.0)),
    (1, 2, 4, (3.0, -9.81))])
def test_a_twin_is_two_engines_and_a_gear_by_hand(front: int, rear: int, seed: int,
                                                  gravity: tuple[float, float]) -> None:
    """Under gravity too: the second crankshaft's masses' weights turn it about its own axis,
    and its gears carry that couple (engine B's motor takes it, as the tooth does)."""
    rng = np.random.default_rng(4400 + seed)
    engine = twin(rng, front, rear)
    a, b = halves(engine)
    theta = rng.uniform(-math.pi, math.pi, 40)
    slow = 0.01 if any(gravity) else 1.0  # (weights beside the inertia, not drowned by it)
    omega, alpha = slow * rng.uniform(100, 600, 40), slow**2 * rng.uniform(-5e4, 5e4, 40)
    both = mechanism_of(engine).crank_forces(theta, omega, alpha, gravity=gravity)
    fa = mechanism_of(a).crank_forces(theta, omega, alpha, gravity=gravity)
    fb = mechanism_of(b).crank_forces(-theta, -omega, -alpha, gravity=gravity)
    at = complex(*engine.crankshafts[0].at)
    force_b = column(fb.shaking_force)
    cases = {
        "shaking force": (column(both.shaking_force), column(fa.shaking_force) + force_b),
        "rocking couple": (column(both.rocking_couple),
                           column(fa.rocking_couple) + column(fb.rocking_couple)),
        "shaking moment": (both.shaking_moment[:, 0],
                           fa.shaking_moment[:, 0] + fb.shaking_moment[:, 0]
                           + (np.conj(at) * force_b).imag),
        "driving torque": (both.driving_torque[:, 0],
                           fa.driving_torque[:, 0] - fb.driving_torque[:, 0]),
    }
    t = 1j * at / abs(at)
    tooth = -2 * fb.driving_torque[:, 0] / abs(at) * t
    cases["tooth force"] = (column(both.teeth["gear2"]), tooth)
    cases["main bearings"] = (column(both.reactions["O"]), column(fa.reactions["O"]) - tooth)
    cases["second axis"] = (column(both.reactions["O2"]), column(fb.reactions["O"]) + tooth)
    cases["balance shaft"] = (column(both.reactions["shaft1"]), column(fa.reactions["shaft1"]))
    for name, (got, want) in cases.items():
        scale = float(np.max(np.abs(want)))
        assert scale > 0, name
        assert np.max(np.abs(got - want)) <= EXACT * scale, name


@pytest.mark.parametrize(("seed", "gravity"), [(5, (0.0, 0.0)), (6, (2.0, -9.81))])
def test_a_twin_turning_one_way_is_two_engines_an_idler_and_its_gears_by_hand(
        seed: int, gravity: tuple[float, float]) -> None:
    """At ratio +1 the idler midway (pitch radius r = |ā|/4, inertia J_I, turning at −θ1)
    meshes with both: B's motor torque is the second pair's tooth force at −r, ``λ_b =
    −T_B/r``; the idler's own equation about its axis, ``−r·(λ_a + λ_b) = J_I·(−α)``, gives
    the first pair's; the first crankshaft's bearings pass A's reaction less ``λ_a·t``, the
    idler's ``(λ_a − λ_b)·t``, B's its own plus ``λ_b·t``; the motor drives A, B and the
    idler, ``T_A + T_B + J_I·α``; the frame takes the idler's change of momentum, ``J_I·α``
    on the shaking moment (it turns at −α)."""
    rng = np.random.default_rng(4400 + seed)
    engine = twin(rng, 2, 2, ratio=1)
    a, b = halves(engine)
    theta = rng.uniform(-math.pi, math.pi, 40)
    slow = 0.01 if any(gravity) else 1.0
    omega, alpha = slow * rng.uniform(100, 600, 40), slow**2 * rng.uniform(-5e4, 5e4, 40)
    both = mechanism_of(engine).crank_forces(theta, omega, alpha, gravity=gravity)
    fa = mechanism_of(a).crank_forces(theta, omega, alpha, gravity=gravity)
    fb = mechanism_of(b).crank_forces(theta, omega, alpha, gravity=gravity)
    at = complex(*engine.crankshafts[0].at)
    idler = engine.crankshafts[0].idler_inertia
    r, t = abs(at) / 4, 1j * at / abs(at)
    lam_b = -fb.driving_torque[:, 0] / r
    lam_a = -lam_b + idler * alpha / r
    force_b = column(fb.shaking_force)
    cases = {
        "shaking force": (column(both.shaking_force), column(fa.shaking_force) + force_b),
        "shaking moment": (both.shaking_moment[:, 0],
                           fa.shaking_moment[:, 0] + fb.shaking_moment[:, 0]
                           + (np.conj(at) * force_b).imag + idler * alpha),
        "driving torque": (both.driving_torque[:, 0],
                           fa.driving_torque[:, 0] + fb.driving_torque[:, 0] + idler * alpha),
        "second pair": (column(both.teeth["gear2b"]), lam_b * t),
        "first pair": (column(both.teeth["gear2a"]), lam_a * t),
        "main bearings": (column(both.reactions["O"]), column(fa.reactions["O"]) - lam_a * t),
        "idler": (column(both.reactions["I2"]), (lam_a - lam_b) * t),
        "second axis": (column(both.reactions["O2"]), column(fb.reactions["O"]) + lam_b * t),
    }
    for name, (got, want) in cases.items():
        scale = float(np.max(np.abs(want)))
        assert scale > 0, name
        assert np.max(np.abs(got - want)) <= EXACT * scale, name


def test_the_square_four_fires_every_180_degrees_at_its_own_top_dead_centres() -> None:
    """Crankshaft 2 turns at −θ1: a pin at phase φ on it is at top dead centre (upright) where
    −θ1 + φ = 90°; 1-2-4-3 then fires at 90°, 270°, 450°, 630°."""
    engine = load_design(EXAMPLES / "square_four.toml").mechanism
    assert isinstance(engine, Engine)
    assert np.allclose(np.degrees(engine.firing_angles()), [90.0, 270.0, 630.0, 450.0])
    for c in engine.cylinders:
        ratio = engine.shaft_ratio(c.crankshaft)
        pin = ratio * c.top_dead_centre(ratio) + math.radians(c.phase_deg)
        assert math.isclose(math.cos(pin - math.radians(c.bank_deg)), 1.0, abs_tol=1e-15)


def test_the_square_fours_primary_cancels_between_its_shafts() -> None:
    """Diagonal pistons move together: the reciprocating primary forces and couples cancel
    between the two crankshafts; the four secondaries add (the flat-plane four's); only the
    crankshafts' own rotating masses leave a primary couple, forward on the first and backward
    on the second, equal."""
    analysis = cycle_analysis(load_design(EXAMPLES / "square_four.toml").mechanism,
                              523.5987755982989, 720)
    scale = float(np.max(np.abs(analysis.reactions.shaking_force)))
    orders = {o.order: o for o in analysis.orders}
    first, second = orders[1.0], orders[2.0]
    assert first.shaking_force.forward <= 1e-12 * scale
    assert first.shaking_force.backward <= 1e-12 * scale
    assert first.rocking_couple.forward == pytest.approx(first.rocking_couple.backward,
                                                         rel=1e-12)
    assert second.shaking_force.forward == pytest.approx(second.shaking_force.backward,
                                                         rel=1e-12)


@pytest.mark.parametrize("shafts", ["", "crankshafts = [1]\n", "crankshafts = [2, 1]\n"])
def test_a_twin_spec_reads_back_as_written(shafts: str) -> None:
    """Its crankshafts, and the counterweights' (none named: every crankshaft's, still so)."""
    text = (EXAMPLES / "square_four.toml").read_text().replace("radius = 0.05 ",
                                                                 f"{shafts}radius = 0.05 ")
    design = loads_design(text)
    again = loads_design(dumps_design(design))
    assert again.mechanism == design.mechanism
    assert again.balance == design.balance


@pytest.mark.parametrize(("old", "new", "key"), [
    ("ratio = -1\n", "ratio = 2\n", "crankshafts[1].ratio"),
    ("ratio = -1\n", "ratio = -1\nidler_inertia = 0.001\n", "crankshafts[1].idler_inertia"),
    ("at = [0.09, 0.0]", "at = [0.0, 0.0]", "crankshafts[1].at"),
    ("crankshaft = 2\n", "crankshaft = 3\n", "mechanism.cylinders[3].crankshaft"),
    ("main_bearings = [-0.09, 0.0, 0.09]  # m: the front",
     "main_bearings = [0.09, 0.0]  # m: the front", "mechanism.main_bearings"),
    ("main_bearings = [-0.09, 0.0, 0.09]  # m: its own",
     "main_bearings = [0.09]  # m: its own", "crankshafts[1].main_bearings"),
    ("main_bearings = [-0.09, 0.0, 0.09]  # m: its own",
     "main_bearings = 0.1  # m: its own", "crankshafts[1].main_bearings"),
    ("radius = 0.05 ", "crankshafts = [1, 3]\nradius = 0.05 ",
     "balance.counterweights.crankshafts"),
])
def test_bad_twin_specs_are_refused_by_key(old: str, new: str, key: str) -> None:
    text = (EXAMPLES / "square_four.toml").read_text()
    assert old in text
    with pytest.raises(SpecError) as err:
        design = loads_design(text.replace(old, new, 1))
        optimize(design, "convex")
    assert err.value.key == key


def test_both_shafts_counterweights_are_the_independent_programs_optimum() -> None:
    """The square four's counterweights on both crankshafts: J = CVXPY's optimum of
    ``‖A·X + b‖²`` over the sites' mass·radius vectors, ``A``'s columns written here (a unit
    mass·radius at ratio k on axis ā in plane z: ``(kω)²·e^{ikθ1}``, ``i·z·F``, ``ā × F``),
    ``b`` the two-engine sum's loads; the engine built with the reported masses has that J."""
    design = load_design(EXAMPLES / "square_four.toml")
    engine, problem, speed = design.mechanism, design.balance, design.operation.speed
    result = optimize(design, "convex")
    theta = result.before.theta1
    base = cycle_analysis(engine, speed, theta1=theta).reactions  # no counterweights to replace
    sites = [(engine.shaft_ratio(k), engine.shaft_axis(k), z, bound)
             for k in problem.counterweights.crankshafts or engine.shafts
             for z, bound in zip(problem.counterweights.planes, problem.counterweights.max_mr,
                                 strict=True)]
    n, count = theta.size, 2 * len(sites)
    force = np.zeros((n, count), complex)
    for i, (k, _, _, _) in enumerate(sites):
        turn = (k * speed) ** 2 * np.exp(1j * k * theta)
        force[:, 2 * i], force[:, 2 * i + 1] = turn, 1j * turn
    planes = np.repeat([z for _, _, z, _ in sites], 2)
    axes = np.repeat([a for _, a, _, _ in sites], 2)
    couple, moment = 1j * planes * force, (np.conj(axes) * force).imag
    w = problem.objective
    rows, rhs = [], []
    for weight, cols, b in ((w.shaking_force, force, base.shaking_force),
                            (w.rocking_couple, couple, base.rocking_couple)):
        rows += [math.sqrt(weight / n) * cols.real, math.sqrt(weight / n) * cols.imag]
        rhs += [math.sqrt(weight / n) * b.real, math.sqrt(weight / n) * b.imag]
    rows.append(math.sqrt(w.shaking_moment / n) * moment)
    rhs.append(math.sqrt(w.shaking_moment / n) * base.shaking_moment)
    a, b = np.vstack(rows), np.concatenate(rhs)
    x = cp.Variable(count)
    cons = [cp.norm(x[2 * i : 2 * i + 2]) <= s[3] for i, s in enumerate(sites)]
    program = cp.Problem(cp.Minimize(cp.sum_squares(a @ x + b)), cons)
    program.solve(solver=cp.CLARABEL)
    assert result.optimal
    assert result.objective == pytest.approx(program.value, rel=1e-6)
    built = result.linkage
    assert isinstance(built, Engine)
    after = cycle_analysis(built, speed, theta1=theta).reactions
    total = (w.shaking_force * np.mean(np.abs(after.shaking_force) ** 2)
             + w.rocking_couple * np.mean(np.abs(after.rocking_couple) ** 2)
             + w.shaking_moment * np.mean(after.shaking_moment ** 2))
    assert result.objective == pytest.approx(total, rel=1e-9)
    placed = {(c.crankshaft, c.z): c for c in result.rotor_masses.counterweights}
    assert {k for k, _ in placed} == {1, 2}
    on_second = [m for m in built.crankshafts[0].masses if m.label == "counterweight"]
    assert sorted(m.z for m in on_second) == sorted(z for k, z in placed if k == 2)


def test_the_drawn_pitch_circles_touch_at_the_pitch_point() -> None:
    """Equal gears 90 mm apart: two circles of 45 mm about the axes, touching midway."""
    circles = pitch_circles(load_design(EXAMPLES / "square_four.toml").mechanism)
    assert len(circles) == 2
    (ca, ra), (cb, rb) = circles
    assert (ca, cb) == (0j, 0.09 + 0j)
    assert ra == pytest.approx(0.045, rel=1e-15) and rb == pytest.approx(0.045, rel=1e-15)


def test_an_original_has_the_designs_geared_crankshafts() -> None:
    """``optimize --out``'s ``[original]`` writes each geared crankshaft with the masses it had
    and reads back equal; one missing, one more, or one on another axis is refused by key
    (the original differs from the design in its masses only)."""
    design = load_design(EXAMPLES / "square_four.toml")
    balanced = optimize(design, "convex").balanced_design(design)
    text = dumps_design(balanced)
    assert "[[original.crankshafts]]" in text
    again = loads_design(text)
    assert again.original == balanced.original
    assert again.original.crankshafts[0].masses == design.mechanism.crankshafts[0].masses
    block = "[[original.crankshafts]]" + text.split("[[original.crankshafts]]")[1].split(
        "\n\n", 1)[0]
    moved = re.sub(r"at = \[0\.09, 0(\.0)?\]", "at = [0.1, 0.0]", block)
    for changed, key in ((text.replace(block, ""), "original.crankshafts"),
                         (text.replace(block, block + "\n\n" + block), "original.crankshafts"),
                         (text.replace(block, moved), "original.crankshafts[1].at")):
        assert changed != text
        with pytest.raises(SpecError) as err:
            loads_design(changed)
        assert err.value.key == key


def test_the_opposed_piston_single_is_point_or_mirror_symmetric_as_its_gears_turn() -> None:
    """Turning the same way (through the idler), the opposed-piston single is point-symmetric
    about the liner's middle c: no shaking force at any sample, a moment. Geared to turn
    opposite ways, it is mirror-symmetric about the line x = c: no x-force and no moment about
    c (the moment about the origin is then c × F), the vertical forces added."""
    text = (EXAMPLES / "opposed_piston.toml").read_text()
    same = load_design(EXAMPLES / "opposed_piston.toml")
    speed = same.operation.speed
    a = cycle_analysis(same.mechanism, speed, 360).reactions
    scale = float(np.max(np.abs(a.ground["O"])))
    assert float(np.max(np.abs(a.shaking_force))) <= 1e-12 * scale
    assert float(np.sqrt(np.mean(a.shaking_moment**2))) > 100.0
    opposite = loads_design(text.replace("ratio = 1\n", "ratio = -1\n").replace(
        "idler_inertia = 0.004", "idler_inertia = 0.0"))
    b = cycle_analysis(opposite.mechanism, speed, 360).reactions
    c = 0.21  # m: the liner's middle
    assert float(np.max(np.abs(b.shaking_force.real))) <= 1e-12 * scale
    assert float(np.max(np.abs(b.shaking_force.imag))) > 1000.0
    about_c = b.shaking_moment - c * b.shaking_force.imag
    assert float(np.max(np.abs(about_c))) <= 1e-12 * scale * c


@pytest.mark.parametrize("ratio", [-1, 1])
def test_each_crankshafts_main_bearings_share_its_loads_and_its_gears(ratio: int) -> None:
    """Mains on both crankshafts, the gears at ``gear_z``: each crankshaft's bearings sum to
    its axis's reaction; and bearing by bearing, a twin's are the two engines' (their own
    mains) with the tooth force shared by the lever rule at the gears' plane — on the first
    crankshaft the force on the gear it drives taken away, on the second its own added."""
    rng = np.random.default_rng(90 + ratio)
    planes, gear_z = (-0.12, 0.0, 0.12), 0.05
    base = twin(rng, 2, 2, ratio=ratio)
    engine = replace(base, main_bearings=planes, crankshafts=(
        replace(base.crankshafts[0], main_bearings=planes, gear_z=gear_z),))
    a, b = halves(engine)
    b = replace(b, main_bearings=planes)
    speed, gravity = 300.0, (0.0, -9.81)
    both = cycle_analysis(engine, speed, 72, gravity=gravity)
    alone_a = cycle_analysis(a, speed, 72, gravity=gravity)
    theta = both.theta1
    alone_b = cycle_analysis(b, ratio * speed, theta1=ratio * theta, gravity=gravity)
    supports = {s.name: s.force for s in both.supports}
    assert sorted(supports) == ["B1", "B2", "B2.1", "B2.2", "B2.3", "B3"]
    r = both.reactions.ground
    scale = float(np.max(np.abs(r["O"])))
    for names, point in ((("B1", "B2", "B3"), "O"), (("B2.1", "B2.2", "B2.3"), "O2")):
        total = sum(supports[n] for n in names)
        assert np.max(np.abs(total - r[point])) <= 1e-12 * scale
    drives, driven = (("gear2", "gear2") if ratio == -1 else ("gear2a", "gear2b"))
    pushed, pushing = both.reactions.teeth[drives], both.reactions.teeth[driven]
    shares = dict(lever_shares(planes, gear_z))
    for j in range(3):
        mine_a = {s.name: s.force for s in alone_a.supports}[f"B{j + 1}"]
        mine_b = {s.name: s.force for s in alone_b.supports}[f"B{j + 1}"]
        share = shares.get(j, 0.0)
        np.testing.assert_allclose(supports[f"B{j + 1}"], mine_a - share * pushed,
                                   atol=1e-11 * scale)
        np.testing.assert_allclose(supports[f"B2.{j + 1}"], mine_b + share * pushing,
                                   atol=1e-11 * scale)


def test_a_twins_bearing_term_is_the_mean_square_of_its_built_engines_bearing_loads() -> None:
    """The square four with its bearing loads weighed alone: at random counterweights on both
    crankshafts, J is the mean square of all six bearings' loads of the engine built with them
    (its cycle analysis, without loads: each crankshaft's lever rule and its gears' tooth
    forces from the inverse dynamics), through the full regressors and through the factor."""
    text = (EXAMPLES / "square_four.toml").read_text().replace(
        "rocking_couple = 1.0\nshaking_force = 0.01                # m²: a 0.1 m lever\n"
        "shaking_moment = 1.0", "rocking_couple = 0.0\nmain_bearing_load = 1.0")
    design = loads_design(text)
    assert design.balance.objective.main_bearing_load == 1.0
    data = numeric_problem(design)
    sites = data.sites
    speed = design.operation.speed
    rng = np.random.default_rng(45)
    for _ in range(3):
        x = data.x0.copy()
        for i in sites.chosen:
            x[sites.entries(i)] = rng.uniform(-0.008, 0.008, 2)  # (within max_mr 0.012)
        built = sites.model_of(design.mechanism, x)
        loads = cycle_analysis(built, speed, theta1=data.states.positions[0],
                               loads=False).supports
        assert len(loads) == 6
        want = float(np.mean(np.concatenate([np.abs(s.force) ** 2 for s in loads])))
        assert data.objective(x) == pytest.approx(want, rel=1e-9)
        assert data.reduced_objective(x) == pytest.approx(want, rel=1e-9)


def test_a_twins_bearing_bound_binds_and_its_design_keeps_it() -> None:
    """A bound on every main bearing of both crankshafts below the unbalanced engine's largest:
    the balanced design keeps it (its cycle analysis, inertial), certified optimal."""
    text = (EXAMPLES / "square_four.toml").read_text()
    design = loads_design(text)
    before = cycle_analysis(design.mechanism, design.operation.speed, 720, loads=False)
    largest = max(float(np.max(np.abs(s.force))) for s in before.supports)
    bound = 0.8 * largest
    bounded = loads_design(text.replace("[balance.objective]",
                                        f"[balance]\nmax_bearing_load = {bound!r}\n\n"
                                        "[balance.objective]"))
    result = optimize(bounded, "convex")
    assert result.optimal
    after = cycle_analysis(result.linkage, design.operation.speed, 720, loads=False)
    assert max(float(np.max(np.abs(s.force))) for s in after.supports) <= bound * (1 + 1e-6)
