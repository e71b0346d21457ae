"""Balancing engines by counterweights and shafts (``optimize``; DESIGN.md, "Balancing an engine").

The tool assembles a conic program from its own rotors' regressors and the base engine's cycle
analysis; here every check is built apart from it:

- an independent CVXPY program of each shipped example, its loads from the momentum sums of
  ``tests/mechanisms/test_engines.py`` (closed-form slider-cranks) and each mass·radius written
  out by hand (``F = X·(kω)²·e^{ikθ1}``, couple ``i·z·F``, moment ``at × F``), solved by CVXPY's own
  canonicalisation: the tool's optimum equals its optimum to the solvers' tolerance, and the
  tool's certified lower bound is below it;
- the optimality conditions at the tool's optimum from that same quadratic form: where a bound
  does not hold a mass·radius the gradient vanishes, where it does the gradient points inwards
  along it;
- the report's counterweights and shafts added to the original engine by hand (not by the
  tool's ``with_rotor_masses``) give the optimum's figures;
- closed forms: Lanchester shafts sized by the optimiser are ``m_rec·r·A2/2``; an in-line
  three's end webs cancel the forward half of its primary couple and a shaft at −1× the backward
  half, each of the size the couple's halves give.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import replace

import cvxpy as cp
import numpy as np
import pytest
from test_engines import EXAMPLES, flat_four, harmonic_coefficients, momentum_loads

from balancer.balance.optimizer import optimize
from balancer.balance.pareto import pareto_front
from balancer.balance.problem import NumericProblem, numeric_problem
from balancer.balance.rotor_front import END_ROOM
from balancer.cli import main
from balancer.mechanisms import mechanism_of
from balancer.mechanisms.engine.model import BalanceShaft, Cylinder, Engine, Mass
from balancer.model import Design, Link, Operation
from balancer.model.balance import (
    CounterweightPlanes,
    Objective,
    RotorBalanceProblem,
    ShaftFreedom,
)
from balancer.spec import design_from_dict, load_design
from balancer.sweeps import Vary, read_table, sweep, with_values

#: What two solvers' optima of the same program agree to: Clarabel's tolerances (1e-10 on the
#: scaled program) leave the objective within about 1e-8 of its optimum; CVXPY's default run
#: of the same solver as loosely, so 1e-7 relative between the two.
SOLVERS = 1e-7
#: Exact routes (closed forms, the same figures by another route): DESIGN's 1e-9 relative.
EXACT = 1e-9

EXAMPLES_TO_BALANCE = ("inline_three_to_balance", "v8_to_balance")


# -- the independent program ------------------------------------------------------------------


def sites(problem: RotorBalanceProblem) -> list[tuple[int, complex, float, float]]:
    """Each chosen mass·radius: (ratio, axis, plane, bound), counterweights first."""
    out = []
    if problem.counterweights is not None:
        cw = problem.counterweights
        out += [(1, 0j, z, b) for z, b in zip(cw.planes, cw.max_mr, strict=True)]
    for s in problem.shafts:
        out += [(s.ratio, complex(*s.at), z, b) for z, b in zip(s.planes, s.max_mr, strict=True)]
    return out


def base_engine(engine: Engine, problem: RotorBalanceProblem) -> Engine:
    """The engine without the labelled counterweights of the chosen planes."""
    planes = () if problem.counterweights is None else problem.counterweights.planes
    kept = tuple(m for m in engine.crankshaft.masses
                 if not (m.label == "counterweight" and m.z in planes))
    return replace(engine, crankshaft=replace(engine.crankshaft, masses=kept))


def quadratic(design: Design, theta: np.ndarray):
    """``J(X) = ‖A·X + b‖²`` over ``X`` = (Re, Im) of each site's mass·radius: ``(A, b)``."""
    engine, problem, speed = design.mechanism, design.balance, design.operation.speed
    w = problem.objective
    n = theta.size
    base = momentum_loads(base_engine(engine, problem), theta, speed)
    chosen = sites(problem)
    force = np.zeros((n, 2 * len(chosen)), complex)
    for i, (k, _, _, _) in enumerate(chosen):
        turn = (k * speed) ** 2 * np.exp(1j * k * theta)
        force[:, 2 * i], force[:, 2 * i + 1] = turn, 1j * turn
    planes = np.repeat([z for _, _, z, _ in chosen], 2)
    axes = np.repeat([a for _, a, _, _ in chosen], 2)
    couple = 1j * planes * force
    moment = axes.real * force.imag - axes.imag * force.real
    rows, rhs = [], []
    for weight, a, b in ((w.shaking_force, force.real, base.force.real),
                         (w.shaking_force, force.imag, base.force.imag),
                         (w.rocking_couple, couple.real, base.couple.real),
                         (w.rocking_couple, couple.imag, base.couple.imag),
                         (w.shaking_moment, moment, base.moment)):
        if weight:
            rows.append(math.sqrt(weight / n) * a)
            rhs.append(math.sqrt(weight / n) * b)
    if w.unbalance:
        rows.append(math.sqrt(w.unbalance) * speed**2 * np.eye(2 * len(chosen)))
        rhs.append(np.zeros(2 * len(chosen)))
    return np.vstack(rows), np.concatenate(rhs)


def oracle(design: Design, theta: np.ndarray) -> float:
    """The optimum of the program, by CVXPY."""
    a, b = quadratic(design, theta)
    bounds = [bound for _, _, _, bound in sites(design.balance)]
    x = cp.Variable(a.shape[1])
    cons = [cp.norm(x[2 * i : 2 * i + 2]) <= bound for i, bound in enumerate(bounds)]
    prob = cp.Problem(cp.Minimize(cp.sum_squares(a @ x + b)), cons)
    prob.solve(solver=cp.CLARABEL)
    assert prob.status == cp.OPTIMAL
    return float(prob.value)


def built_by_hand(design: Design, result) -> Engine:
    """The original engine with the report's counterweights and shafts added."""
    engine, problem = design.mechanism, design.balance
    masses = result.rotor_masses
    kept = base_engine(engine, problem).crankshaft.masses
    added = tuple(Mass(mr=c.mr, phase_deg=c.phase_deg, z=c.z) for c in masses.counterweights)
    shafts = tuple(BalanceShaft(ratio=s.ratio, at=s.at, eccentrics=tuple(
        Mass(mr=e.mr, phase_deg=e.phase_deg, z=e.z) for e in s.eccentrics))
        for s in masses.shafts)
    return replace(engine, crankshaft=replace(engine.crankshaft, masses=kept + added),
                   balance_shafts=engine.balance_shafts + shafts)


def vector(result) -> np.ndarray:
    """``X`` of the report's masses, in the order of :func:`sites`."""
    placed = list(result.rotor_masses.counterweights) + [
        e for s in result.rotor_masses.shafts for e in s.eccentrics]
    return np.concatenate([[c.mr * math.cos(math.radians(c.phase_deg)),
                            c.mr * math.sin(math.radians(c.phase_deg))] for c in placed])


# -- the shipped examples ---------------------------------------------------------------------


@pytest.fixture(scope="module", params=EXAMPLES_TO_BALANCE)
def balanced(request):
    design = load_design(EXAMPLES / f"{request.param}.toml")
    return design, optimize(design, "convex"), optimize(design, "nlp")


def test_the_optimum_is_the_independent_programs(balanced):
    """J of both backends = CVXPY's optimum; the certified bound below it, the gap tiny."""
    design, convex, nlp = balanced
    theta = convex.before.theta1
    best = oracle(design, theta)
    for result in (convex, nlp):
        assert result.optimal
        assert abs(result.objective - best) <= SOLVERS * best
        assert result.lower_bound <= best * (1 + SOLVERS)
        assert result.gap <= 1e-6
    assert convex.original_objective > 2 * best  # (there was something to balance)


def test_an_engines_problem_is_the_linkages_with_its_sites_after_the_links(balanced):
    """One balancing problem: the engine's is a NumericProblem whose design vector is the
    linkage's entries (held) then each site's ``(Re x, Im x)``; its J at random masses is the
    momentum sums' ``‖A·X + b‖²`` (the unbalance's rows ``√w_U·ω²`` in it), through the full
    regressors and through the factor; J(x0) the original's."""
    design, convex, _ = balanced
    data = numeric_problem(design)
    assert isinstance(data, NumericProblem) and data.force_balance is None
    a, b = quadratic(design, convex.before.theta1)
    start = mechanism_of(design.mechanism).layout.size
    count = 2 * len(sites(design.balance))
    assert data.sites is not None and data.sites.start == start
    mech = mechanism_of(design.mechanism)
    np.testing.assert_array_equal(data.x0[:start], mech.layout.vector(mech.linkage))
    rng = np.random.default_rng(41)
    bounds = np.repeat([bound for *_, bound in sites(design.balance)], 2)
    for _ in range(5):
        chosen = rng.uniform(-1, 1, count) * bounds
        x = data.x0.copy()
        x[start : start + count] = chosen
        want = float(np.sum((a @ chosen + b) ** 2))
        assert data.objective(x) == pytest.approx(want, rel=1e-9)
        assert data.reduced_objective(x) == pytest.approx(want, rel=1e-9)
    assert data.original_objective == pytest.approx(convex.original_objective, rel=1e-12)


def test_the_optimality_conditions_hold_at_the_optimum(balanced):
    """∇J = 2Aᵀ(AX + b): zero at a mass off its bound; along −X at a mass on it (λ ≥ 0)."""
    design, _, result = balanced
    a, b = quadratic(design, result.before.theta1)
    x = vector(result)
    grad = 2 * a.T @ (a @ x + b)
    scale = 2 * np.linalg.norm(a, 2) * (np.linalg.norm(a @ x + b) + np.linalg.norm(b))
    for i, (_, _, _, bound) in enumerate(sites(design.balance)):
        g, xi = grad[2 * i : 2 * i + 2], x[2 * i : 2 * i + 2]
        if np.linalg.norm(xi) < bound * (1 - 1e-6):
            assert np.linalg.norm(g) <= 1e-9 * scale
        else:
            assert abs(g[0] * xi[1] - g[1] * xi[0]) <= 1e-6 * scale * bound
            assert g @ xi <= 1e-9 * scale * bound


def test_the_reported_masses_added_by_hand_give_the_optimums_figures(balanced):
    """Each objective term's RMS and J itself, from the engine built by hand."""
    design, _, result = balanced
    theta = result.before.theta1
    speed = design.operation.speed
    loads = momentum_loads(built_by_hand(design, result), theta, speed)
    w = design.balance.objective
    terms = {"rocking_couple": float(np.sqrt(np.mean(np.abs(loads.couple) ** 2))),
             "shaking_force": float(np.sqrt(np.mean(np.abs(loads.force) ** 2))),
             "shaking_moment": float(np.sqrt(np.mean(loads.moment**2))),
             "unbalance": float(np.linalg.norm(vector(result))) * speed**2}
    after = result.term_rms(result.after)
    for name, value in after.items():
        assert value == pytest.approx(terms[name], rel=EXACT, abs=EXACT * loads.scale_moment)
    total = sum(getattr(w, name) * terms[name] ** 2 for name in terms)
    assert result.objective == pytest.approx(total, rel=EXACT)


def test_the_inline_three_example_is_its_balanced_answer_rounded():
    """``inline_three.toml`` (the shipped engine) is the optimiser's design, rounded.

    Its two end-web counterweights per web summed, and its shaft's eccentrics: the optimum's to
    the spec's four significant figures.
    """
    design = load_design(EXAMPLES / "inline_three_to_balance.toml")
    result = optimize(design, "convex")
    shipped = load_design(EXAMPLES / "inline_three.toml").mechanism
    for c in result.rotor_masses.counterweights:
        web = sum(m.mr * np.exp(1j * math.radians(m.phase_deg))
                  for m in shipped.crankshaft.masses if m.z == c.z)
        want = c.mr * np.exp(1j * math.radians(c.phase_deg))
        assert abs(web - want) <= 1e-3 * abs(want)
    (shaft,) = shipped.balance_shafts
    (new,) = result.rotor_masses.shafts
    for e, f in zip(new.eccentrics, shaft.eccentrics, strict=True):
        assert e.z == f.z and e.mr == pytest.approx(f.mr, rel=1e-3)
        assert e.phase_deg == pytest.approx(f.phase_deg, abs=0.01)


# -- closed forms -----------------------------------------------------------------------------


def test_lanchester_shafts_sized_by_the_optimiser_are_m_rec_r_a2_over_two():
    """A flat four with two shafts at ±2× to size for its shaking force alone: each mr is
    m_rec·r·A2/2 (the second order's amplitude 4·m_rec·r·ω²·A2 along the cylinders, half of it
    turning each way; a shaft's force mr·(2ω)²), at 1e-9."""
    rng = np.random.default_rng(31)
    four = flat_four(rng, bank_deg=90.0)
    problem = RotorBalanceProblem(
        objective=Objective(shaking_moment=0.0, shaking_force=1.0),
        shafts=(ShaftFreedom(ratio=2, at=(-0.075, -0.1), planes=(0.0,), max_mr=(0.01,)),
                ShaftFreedom(ratio=-2, at=(0.075, -0.1), planes=(0.0,), max_mr=(0.01,))))
    design = Design(mechanism=four, operation=Operation(speed=600.0, samples=360),
                    balance=problem)
    result = optimize(design, "convex")
    c = four.cylinders[0]
    m_rec = four.piston + four.rod.mass * four.rod.e / c.rod
    want = m_rec * c.crank * harmonic_coefficients(c.crank / c.rod)[2] / 2
    for shaft in result.rotor_masses.shafts:
        (e,) = shaft.eccentrics
        assert e.mr == pytest.approx(want, rel=EXACT)
        assert e.phase_deg == pytest.approx(90.0, abs=1e-7)  # along the cylinders at θ1 = 0
    assert result.after.orders[2].shaking_force.forward <= EXACT * 4 * m_rec * c.crank * 600**2


def test_an_inline_threes_end_webs_cancel_the_forward_primary_couple_and_a_shaft_the_backward():
    """Pins 0°, 120°, 240° at z = −s, 0, s, upright (β = 90°), no crankshaft masses: the primary
    couple is c_f·e^{iθ1} + c_b·e^{−iθ1} with
    c_f = i·r·ω²·(m_rec/2 + m_rod(1 − e/l))·Σ z_k·e^{iφ_k} (the big ends turn with the crank) and
    c_b = i·r·ω²·(m_rec/2)·Σ z_k·e^{i(2β − φ_k)}. End webs at ±a: couple i·a·ω²·(X₊ − X₋)·e^{iθ1},
    so the least pair is X₊ = −X₋ = −c_f/(2i·a·ω²); a shaft at −1× with eccentrics at ±b the same
    with c_b and e^{−iθ1}. At 1e-9 of the vectors."""
    s, a, b, speed = 0.091, 0.1135, 0.115, 600.0
    rod = Link(mass=0.48, inertia=0.0019, e=0.038, f=0.0)
    crank, length, beta = 0.0473, 0.145, math.radians(90.0)
    phases = (0.0, 120.0, 240.0)
    cylinders = tuple(Cylinder(z=z, phase_deg=p, bank_deg=90.0, crank=crank, rod=length)
                      for z, p in zip((-s, 0.0, s), phases, strict=True))
    three = Engine(cylinders=cylinders, rod=rod, piston=0.38)
    problem = RotorBalanceProblem(
        objective=Objective(shaking_moment=0.0, rocking_couple=1.0),
        counterweights=CounterweightPlanes(planes=(a, -a), max_mr=(0.05, 0.05)),
        shafts=(ShaftFreedom(ratio=-1, at=(0.065, -0.085), planes=(b, -b), max_mr=(0.05, 0.05)),))
    design = Design(mechanism=three, operation=Operation(speed=speed, samples=360),
                    balance=problem)
    result = optimize(design, "convex")
    m_rec = three.piston + rod.mass * rod.e / length
    rotating = rod.mass * (1 - rod.e / length)
    zs = np.array([-s, 0.0, s])
    phi = np.radians(phases)
    c_f = 1j * crank * speed**2 * (m_rec / 2 + rotating) * np.sum(zs * np.exp(1j * phi))
    c_b = 1j * crank * speed**2 * (m_rec / 2) * np.sum(zs * np.exp(1j * (2 * beta - phi)))
    web = -c_f / (2j * a * speed**2)
    ecc = -c_b / (2j * b * speed**2)
    got = vector(result)
    want = np.array([web.real, web.imag, -web.real, -web.imag,
                     ecc.real, ecc.imag, -ecc.real, -ecc.imag])
    assert np.max(np.abs(got - want)) <= EXACT * abs(web)
    first = result.after.orders[1].rocking_couple
    assert max(first.forward, first.backward) <= EXACT * abs(c_f)


# -- the command line -------------------------------------------------------------------------


@pytest.mark.slow
def test_optimize_writes_a_spec_that_analyses_and_verifies_again(tmp_path, capsys):
    out = tmp_path / "balanced.toml"
    spec = str(EXAMPLES / "inline_three_to_balance.toml")
    assert main(["optimize", spec, "--out", str(out), "--json"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    assert doc["status"] == "optimal"
    assert len(doc["crankshaft_counterweights"]) == 2
    assert all("mass" in c for c in doc["crankshaft_counterweights"])
    (shaft,) = doc["balance_shafts"]
    assert shaft["ratio"] == -1 and len(shaft["eccentrics"]) == 2
    # (the simulation's outputs are other angles than the analysis' samples: its largest
    # sample is at most the analysis' largest, and within the curve's sag between outputs)
    driven = doc["verification"]["driven"]["max_rocking_couple"]
    largest = doc["after"]["rocking_couple"]["max"]
    assert 0.99 * largest <= driven <= largest * (1 + 1e-6)
    again = load_design(out)
    assert len(again.mechanism.balance_shafts) == 1
    assert main(["analyze", str(out), "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert figures["rocking_couple"]["rms"] == pytest.approx(
        doc["after"]["rocking_couple"]["rms"], rel=EXACT)


CW, SHAFT = "[balance.counterweights]\n", "[[balance.shafts]]\n"


@pytest.mark.parametrize(("table", "message"), [
    ("[balance]\nforce_balance = true\n", "balance.force_balance"),
    (CW + "planes = [0.1, 0.1]\nmax_mr = 0.01\n", "balance.counterweights.planes"),
    (CW + "planes = [0.1, 0.2]\nmax_mr = [0.01]\n", "balance.counterweights.max_mr"),
    (CW + "planes = [0.1]\n", "balance.counterweights.max_mr"),
    (SHAFT + "ratio = 0\nplanes = [0.1]\nmax_mr = 0.01\n", "balance.shafts[1].ratio"),
    (SHAFT + "ratio = -1\nplanes = [0.1]\nmax_mr = -0.01\n", "balance.shafts[1].max_mr"),
    ("[balance.objective]\nadded_mass = 1.0\n", "balance.objective.added_mass"),
    ("[balance.objective]\nrocking_couple = 1.0\n", "balance"),
])
def test_a_wrong_engine_balance_is_refused_naming_its_key(tmp_path, capsys, table, message):
    text = (EXAMPLES / "inline_three.toml").read_text() + "\n" + table
    spec = tmp_path / "spec.toml"
    spec.write_text(text)
    assert main(["optimize", str(spec), "--no-verify"]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


# -- fronts: the least shaking against the mass·radius added -------------------------------------


def without_unbalance(design: Design, **weights: float) -> Design:
    """The design whose objective is its own without the unbalance term (or ``weights``)."""
    w = replace(design.balance.objective, unbalance=0.0, **weights)
    return replace(design, balance=replace(design.balance, objective=w))


def capped_oracle(design: Design, theta: np.ndarray, per_mr: float, epsilon: float) -> float:
    """min J' subject to each bound and Σ |X_i|·per_mr ≤ ε, by CVXPY."""
    a, b = quadratic(design, theta)
    bounds = [bound for _, _, _, bound in sites(design.balance)]
    x = cp.Variable(a.shape[1])
    sizes = [cp.norm(x[2 * i : 2 * i + 2]) for i in range(len(bounds))]
    cons = [size <= bound for size, bound in zip(sizes, bounds, strict=True)]
    cons.append(per_mr * cp.sum(cp.hstack(sizes)) <= epsilon)
    prob = cp.Problem(cp.Minimize(cp.sum_squares(a @ x + b)), cons)
    prob.solve(solver=cp.CLARABEL)
    assert prob.status == cp.OPTIMAL
    return float(prob.value)


def masses_of(design: Design, x: np.ndarray) -> Engine:
    """The base engine with ``x``'s masses (in :func:`sites`' order) added by hand."""
    engine, problem = design.mechanism, design.balance
    placed = [(k, at, z, complex(x[2 * i], x[2 * i + 1]))
              for i, (k, at, z, _) in enumerate(sites(problem))]
    cws = tuple(Mass(mr=abs(c), phase_deg=math.degrees(np.angle(c)), z=z)
                for k, at, z, c in placed if k == 1 and at == 0)
    shafts = tuple(BalanceShaft(ratio=s.ratio, at=s.at, eccentrics=tuple(
        Mass(mr=abs(c), phase_deg=math.degrees(np.angle(c)), z=z)
        for k, at, z, c in placed if (k, at) == (s.ratio, complex(*s.at))))
        for s in problem.shafts)
    base = base_engine(engine, problem)
    return replace(base, crankshaft=replace(base.crankshaft,
                                            masses=base.crankshaft.masses + cws),
                   balance_shafts=base.balance_shafts + shafts)


def chosen_of(design: Design, x: np.ndarray) -> np.ndarray:
    """The chosen mass·radius vectors of a balancing's design vector, in :func:`sites`' order.

    The design vector's layout: the linkage's entries, then two per site, the chosen first.
    """
    start = mechanism_of(design.mechanism).layout.size
    return np.asarray(x)[start : start + 2 * len(sites(design.balance))]


@pytest.fixture(scope="module", params=EXAMPLES_TO_BALANCE)
def front(request):
    design = load_design(EXAMPLES / f"{request.param}.toml")
    return design, pareto_front(design, "added-mass", 5)


@pytest.mark.slow
def test_each_point_of_an_engines_front_is_the_independent_programs_optimum(front):
    """At each point's ε: CVXPY's least J' (the spec's weights, no unbalance term) under the
    bounds and Σ|mr|/radius ≤ ε is the point's (√J')², and the certified bound below it."""
    design, result = front
    theta = optimize(design, "convex").before.theta1
    plain = without_unbalance(design)
    per_mr = 1.0 / design.balance.counterweights.radius
    assert result.minimised == "rms"  # (both examples weigh the couple and the force)
    extent = result.points[-1].value
    for p in result.points:
        if p.epsilon < 1e-6 * extent:
            # (nothing added: CVXPY's own feasibility tolerance, 1e-8 absolute, is then most of
            # the cap; the next test checks this end against the base engine instead)
            continue
        best = capped_oracle(plain, theta, per_mr, p.epsilon)
        assert p.least**2 == pytest.approx(best, rel=SOLVERS, abs=SOLVERS * result.points[0]
                                           .least**2)
        assert p.lower_bound**2 <= best * (1 + SOLVERS)
        # (within the solver's feasibility on the cap, in units of the front's span)
        assert p.value <= p.epsilon + SOLVERS * result.points[-1].value


def test_an_engines_front_runs_from_nothing_added_to_the_optimum_without_unbalance(front):
    """The first point adds nothing (the base engine's J'); the last is ``optimize``'s optimum
    of the same objective; the least falls and the mass grows along the front."""
    design, result = front
    theta = optimize(design, "convex").before.theta1
    plain = without_unbalance(design)
    a, b = quadratic(plain, theta)
    assert result.points[0].least == pytest.approx(float(np.linalg.norm(b)), rel=1e-7)
    # (the end's ε is the least mass within END_ROOM of the problem's scale — the original's
    # √J' — of the optimum: the program stays feasible)
    best = math.sqrt(optimize(plain, "convex").objective)
    room = 2 * END_ROOM * result.original[1] + SOLVERS * best
    assert abs(result.points[-1].least - best) <= room
    least = [p.least for p in result.points]
    assert all(x >= y * (1 - SOLVERS) for x, y in zip(least, least[1:], strict=False))


def test_an_engines_front_points_figures_are_its_masses_added_by_hand(front):
    """Each point's design built by hand: its RMS couple, force and moment by the momentum sums,
    √J' from them, and its mass Σ|mr|/radius."""
    design, result = front
    speed = design.operation.speed
    theta = optimize(design, "convex").before.theta1
    w = design.balance.objective
    radius = design.balance.counterweights.radius
    for p in result.points:
        x = chosen_of(design, p.x)
        loads = momentum_loads(masses_of(design, x), theta, speed)
        want = {"rocking_couple": float(np.sqrt(np.mean(np.abs(loads.couple) ** 2))),
                "shaking_force": float(np.sqrt(np.mean(np.abs(loads.force) ** 2))),
                "shaking_moment": float(np.sqrt(np.mean(loads.moment**2)))}
        for name, value in want.items():
            assert p.figures[name] == pytest.approx(value, rel=EXACT,
                                                    abs=EXACT * loads.scale_moment)
        j = sum(getattr(w, n) * v**2 for n, v in want.items())
        assert p.least == pytest.approx(math.sqrt(j), rel=EXACT)
        mass = sum(math.hypot(x[2 * i], x[2 * i + 1]) for i in range(x.size // 2)) / radius
        assert p.value == pytest.approx(mass, rel=EXACT)


def test_an_engines_front_of_the_couple_alone_is_of_its_rms():
    """With the rocking couple the only term, the front is of its RMS (N·m), and without a
    radius of Σ|mr| (kg·m). In-line three: at its optimum end the couple left is what neither
    counterweights nor a −1× shaft reach, every order n ≥ 2 not a multiple of three, each
    √3/2·s·m_rec·r·ω²·A_n turning either way (mean square 2·a_n² per order)."""
    design = without_unbalance(load_design(EXAMPLES / "inline_three_to_balance.toml"),
                               shaking_force=0.0)
    design = replace(design, balance=replace(design.balance, counterweights=replace(
        design.balance.counterweights, radius=None)))
    result = pareto_front(design, "added-mass", 3)
    assert result.minimised == "rocking_couple" and result.unit == "kg·m"
    for p in result.points:
        assert p.least == pytest.approx(p.figures["rocking_couple"], rel=EXACT)
        x = chosen_of(design, p.x)
        assert p.value == pytest.approx(sum(np.hypot(x[0::2], x[1::2])), rel=EXACT)
    engine = design.mechanism
    c = engine.cylinders
    m_rec = engine.piston + engine.rod.mass * engine.rod.e / c[0].rod
    speed = design.operation.speed
    coefficients = harmonic_coefficients(c[0].crank / c[0].rod, orders=tuple(range(2, 41)))
    # What no counterweight or −1× shaft reaches: every order from the second, each of the
    # in-line three's orders 2 and 4 (mod 3: ±1) turning both ways, √3/2·s·m_rec·r·ω²·A_n.
    s = c[2].z
    left = [math.sqrt(3) / 2 * s * m_rec * c[0].crank * speed**2 * coefficients[n]
            for n in coefficients if n % 3]
    rms = math.sqrt(sum(2 * a**2 for a in left))
    assert result.points[-1].least == pytest.approx(rms, rel=1e-6)


def test_pareto_of_an_engine_on_the_command_line(tmp_path, capsys, monkeypatch):
    """``--json`` names each point's figures and the units; a plot and a CSV are written."""
    monkeypatch.chdir(tmp_path)
    spec = str(EXAMPLES / "v8_to_balance.toml")
    assert main(["pareto", spec, "--against", "added-mass", "--points", "4", "--json",
                 "--plot", "front.png", "--csv", "front.csv"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    assert doc["against"] == "added-mass" and doc["minimised"] == "rms"
    for p in doc["points"]:
        assert {"rms", "shaking_moment", "rocking_couple", "shaking_force", "added_mass",
                "epsilon", "lower_bound", "knee"} <= set(p)
    assert doc["units"]["added_mass, epsilon"] == "kg"
    assert (tmp_path / "front.png").stat().st_size > 0
    header = (tmp_path / "front.csv").read_text().splitlines()[0].split(",")
    assert header[:5] == ["rms", "added_mass", "epsilon", "lower_bound", "knee"]


@pytest.mark.parametrize(("args", "key"), [
    (["--against", "driving-torque"], "--against"),
    (["--against", "shaking-force"], "--against"),
])
def test_pareto_of_an_engine_refuses_another_second_objective(tmp_path, capsys, args, key):
    assert main(["pareto", str(EXAMPLES / "v8_to_balance.toml"), *args]) == 2
    err = capsys.readouterr().err
    assert key in err and "added-mass" in err and "Traceback" not in err


def test_pareto_of_an_engine_weighing_only_the_unbalance_is_refused(tmp_path, capsys):
    text = (EXAMPLES / "v8_to_balance.toml").read_text()
    text = text.replace("rocking_couple = 1.0", "rocking_couple = 0.0").replace(
        "shaking_force = 0.04", "shaking_force = 0.0")
    spec = tmp_path / "only.toml"
    spec.write_text(text)
    assert main(["pareto", str(spec), "--against", "added-mass"]) == 2
    assert "balance.objective" in capsys.readouterr().err


# -- sweeps of engines -------------------------------------------------------------------------


@pytest.mark.slow
def test_a_sweep_of_an_engine_balances_each_point_as_the_independent_program_does(tmp_path):
    """In-line three over its crank radius and a shaft's plane: each row's couple before by
    the momentum sums, its optimum (J from the row's after figures: no unbalance term, no
    moment weight) CVXPY's, the certified bound below it, the added mass the masses at the
    radius."""
    spec = EXAMPLES / "inline_three_to_balance.toml"
    out = tmp_path / "three.parquet"
    varies = [Vary.parse("mechanism.lengths.crank=0.035:0.045:2"),
              Vary.parse("balance.shafts.0.planes.0=0.10:0.12:2")]
    result = sweep(spec, varies, out, workers=0)
    assert result.statuses == {"optimal": 4} and result.headline == "rocking_couple"
    rows = read_table(out)
    data = tomllib.loads(spec.read_text())
    for i in range(4):
        values = {v.key: rows[v.key][i] for v in varies}
        design = design_from_dict(with_values(data, values))
        w = design.balance.objective
        assert w.unbalance == 0 and w.shaking_moment == 0
        theta = optimize(design, "convex").before.theta1
        loads = momentum_loads(design.mechanism, theta, design.operation.speed)
        couple = float(np.sqrt(np.mean(np.abs(loads.couple) ** 2)))
        assert rows["rocking_couple_before"][i] == pytest.approx(couple, rel=EXACT)
        best = oracle(design, theta)
        j = (w.rocking_couple * rows["rocking_couple_after"][i] ** 2
             + w.shaking_force * rows["shaking_force_after"][i] ** 2)
        assert j == pytest.approx(best, rel=SOLVERS)
        assert rows["lower_bound"][i] ** 2 <= best * (1 + SOLVERS)
        assert rows["added_mass"][i] > 0


@pytest.mark.slow
def test_a_sweep_of_an_engine_draws_its_rocking_couple(tmp_path, capsys, monkeypatch):
    """``sweep --plot`` of an engine: the atlas of the balanced rocking couple."""
    monkeypatch.chdir(tmp_path)
    spec = str(EXAMPLES / "v8_to_balance.toml")
    assert main(["sweep", spec, "--vary", "mechanism.cylinders.1.bank_deg=44:46:2",
                 "--out", "v8.parquet", "--workers", "0", "--plot", "atlas.png"]) == 0
    rows = read_table(tmp_path / "v8.parquet")
    assert rows["status"] == ["optimal", "optimal"]
    assert all(a < b for a, b in zip(rows["rocking_couple_after"],
                                     rows["rocking_couple_before"], strict=True))
    assert (tmp_path / "atlas.png").stat().st_size > 0


# -- what a review found: bounds far beyond the engine, messages ------------------------------


def test_a_front_with_bounds_far_beyond_the_engine_is_the_same_front(tmp_path):
    """max_mr 1000 kg·m (no bound holds): the front still runs from nothing added to the
    optimum of the example's own front (whose bounds do not hold at its end either), its
    cap measured in the front's extent, not the bounds' sum."""
    text = (EXAMPLES / "inline_three_to_balance.toml").read_text()
    spec = tmp_path / "big.toml"
    spec.write_text(text.replace("max_mr = 0.025 ", "max_mr = 1000 ").replace(
        "max_mr = 0.012 ", "max_mr = 1000 "))
    big = pareto_front(load_design(spec), "added-mass", 3)
    own = pareto_front(load_design(EXAMPLES / "inline_three_to_balance.toml"), "added-mass", 3)
    assert big.points[0].value <= 1e-6 * own.points[-1].value
    # (the variables are scaled by the bounds, here 4·10⁴ times the masses the front uses:
    # Clarabel's relative accuracy of 1e-10 on them is then some 4e-6 of the masses)
    assert big.points[-1].least == pytest.approx(own.points[-1].least, rel=1e-5)
    for p in big.points:
        assert p.lower_bound <= p.least * (1 + 1e-9)


def test_a_bound_beyond_double_precision_is_refused_naming_it(tmp_path, capsys):
    text = (EXAMPLES / "inline_three_to_balance.toml").read_text()
    spec = tmp_path / "huge.toml"
    spec.write_text(text.replace("max_mr = 0.025 ", "max_mr = 1e200 "))
    assert main(["optimize", str(spec), "--no-verify"]) == 2
    err = capsys.readouterr().err
    assert "balance.counterweights.max_mr" in err and "Traceback" not in err


def test_a_wrong_crankshaft_mass_is_named_once(tmp_path, capsys):
    text = (EXAMPLES / "v8_to_balance.toml").read_text()
    spec = tmp_path / "neg.toml"
    spec.write_text(text.replace("{ mr = 0.0161, phase_deg = 225.0", "{ mr = -0.0161, "
                                 "phase_deg = 225.0", 1))
    assert main(["analyze", str(spec)]) == 2
    err = capsys.readouterr().err
    assert " links.crankshaft.masses[2].mr: must be zero or positive" in err


def test_an_engine_front_of_the_shaking_moment_alone_says_so(tmp_path, capsys):
    design = without_unbalance(load_design(EXAMPLES / "inline_three_to_balance.toml"),
                               rocking_couple=0.0, shaking_force=0.0, shaking_moment=1.0)
    front = pareto_front(design, "added-mass", 2)
    doc = front.as_dict()
    assert doc["minimised"] == "shaking_moment" and front.masses


def test_a_loose_bound_of_an_engine_front_point_is_tightened_by_another_solve(monkeypatch):
    """The engine front's certificate gets the convex program's retry: a first bound left loose
    is solved again with other settings, the highest kept, tight again and below the point."""
    from balancer.balance import rotor_front
    from balancer.balance.convex import CERTIFY_AGAIN

    exact = rotor_front._RotorFront.certified
    calls: list[int] = []

    def first_loose(self, solution, cap):
        calls.append(1)
        bound = exact(self, solution, cap)
        return bound * (1 - 1e-3) if len(calls) == 1 else bound

    monkeypatch.setattr(rotor_front._RotorFront, "certified", first_loose)
    front = rotor_front.rotor_front(load_design(EXAMPLES / "inline_three_to_balance.toml"),
                                    "added-mass", 3)
    assert len(calls) >= 3 + 1  # (at least) the loose point solved again
    scale = max(p.least for p in front.points)
    for p in front.points:
        assert p.lower_bound <= p.least + 1e-9 * scale  # (the certificate's rounding)
        assert p.least - p.lower_bound <= 10 * CERTIFY_AGAIN * scale
