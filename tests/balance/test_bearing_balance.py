"""Balancing an engine for its main bearings: the objective term and the bound, each checked.

- ``main_bearing_load``'s J at random counterweights is the mean square of the bearings' loads
  of the engine built with them, by the chain-momentum route (not the problem's regressors).
- The optimum is an independent program's: CVXPY over the bearings' loads assembled from the
  base engine's (chain momentum) and each counterweight's centrifugal force shared by the lever
  rule by hand, with every bound and ``max_bearing_load`` as cones.
- The bound holds at the balanced design, and binds; the least feasible bound the error names is
  the threshold (just above it: optimal; just below: infeasible).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

import cvxpy as cp
import numpy as np
import pytest

from balancer.balance.optimizer import Optimizer, optimize
from balancer.balance.problem import numeric_problem
from balancer.balance.result import GAP_TOLERANCE, InfeasibleError
from balancer.cli import main
from balancer.cycle import cycle_analysis
from balancer.mechanisms.engine.bearings import lever_shares
from balancer.model.balance import ShaftFreedom
from balancer.spec import dumps_design, load_design, loads_design

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: Clarabel's and the tie-break's accuracy on the optimum, relative.
SOLVERS = 1e-7


@pytest.fixture(scope="module")
def design():
    return load_design(EXAMPLES / "inline_four_mains.toml")


def bearing_map(design, theta):
    """``B(x) = B0 + Σ C_i·x_i`` per bearing, ``(S, N)`` and ``(S, N, 2·planes)``, by hand."""
    engine, problem = design.mechanism, design.balance
    speed = design.operation.speed
    planes = problem.counterweights.planes
    base = replace(engine, crankshaft=replace(engine.crankshaft, masses=tuple(
        m for m in engine.crankshaft.masses
        if not (m.label == "counterweight" and m.z in planes))))
    b0 = np.array([s.force for s in cycle_analysis(base, speed, theta1=theta,
                                                    loads=False).supports])
    cols = np.zeros((len(engine.main_bearings), theta.size, 2 * len(planes)), complex)
    turn = speed**2 * np.exp(1j * theta)
    for i, z in enumerate(planes):
        for j, share in lever_shares(engine.main_bearings, z):
            cols[j, :, 2 * i] += share * turn
            cols[j, :, 2 * i + 1] += share * 1j * turn
    return b0, cols


def analyze_inertial(engine, speed, theta) -> np.ndarray:
    """The engine's inertial shaking force at ``theta``, complex, N (its cycle analysis)."""
    return cycle_analysis(engine, speed, theta1=theta, loads=False).reactions.shaking_force


def chosen(result) -> np.ndarray:
    """The balanced counterweights as ``(Re, Im)`` per plane, kg·m."""
    return np.concatenate([[c.mr * math.cos(math.radians(c.phase_deg)),
                            c.mr * math.sin(math.radians(c.phase_deg))]
                           for c in result.rotor_masses.counterweights])


def test_the_bearing_term_is_the_mean_square_of_the_built_engines_bearing_loads(design):
    weights = replace(design.balance.objective, unbalance=0.0, shaking_force=0.0)
    plain = replace(design, balance=replace(design.balance, objective=weights))
    data = numeric_problem(plain)
    sites = data.sites
    speed = design.operation.speed
    rng = np.random.default_rng(44)
    for _ in range(4):
        x = data.x0.copy()
        for i in sites.chosen:
            x[sites.entries(i)] = rng.uniform(-0.02, 0.02, 2)
        built = sites.model_of(design.mechanism, x)
        loads = cycle_analysis(built, speed, theta1=data.states.positions[0],
                               loads=False).supports
        want = float(np.mean(np.concatenate([np.abs(s.force) ** 2 for s in loads])))
        assert data.objective(x) == pytest.approx(want, rel=1e-9)
        assert data.reduced_objective(x) == pytest.approx(want, rel=1e-9)


@pytest.mark.slow
def test_the_optimum_is_the_independent_programs_and_the_bound_binds(design):
    result = optimize(design, "nlp")
    assert result.optimal
    theta = result.before.theta1
    b0, cols = bearing_map(design, theta)
    problem = design.balance
    w = problem.objective
    speed = design.operation.speed
    n_sites = cols.shape[2]
    x = cp.Variable(n_sites)
    loads = [b0[j] + cols[j] @ x for j in range(b0.shape[0])]
    count = b0.shape[0] * theta.size
    mean_square = sum(cp.sum_squares(cp.real(b)) + cp.sum_squares(cp.imag(b))
                      for b in loads) / count
    # the shaking force: the base engine's (its inertial analysis) and each counterweight's
    planes = problem.counterweights.planes
    engine = design.mechanism
    base = replace(engine, crankshaft=replace(engine.crankshaft, masses=tuple(
        m for m in engine.crankshaft.masses
        if not (m.label == "counterweight" and m.z in planes))))
    f0 = analyze_inertial(base, speed, theta)
    turn = speed**2 * np.exp(1j * theta)
    fcols = np.column_stack([c for _ in planes for c in (turn, 1j * turn)])
    shaking = f0 + fcols @ x
    force_ms = (cp.sum_squares(cp.real(shaking)) + cp.sum_squares(cp.imag(shaking))) / theta.size
    cost = (w.main_bearing_load * mean_square + w.shaking_force * force_ms
            + w.unbalance * speed**4 * cp.sum_squares(x))
    bound = problem.max_bearing_load
    cons = [cp.norm(x[2 * i : 2 * i + 2]) <= m
            for i, m in enumerate(problem.counterweights.max_mr)]
    cons += [cp.abs(b) <= bound for b in loads]
    oracle = cp.Problem(cp.Minimize(cost), cons)
    oracle.solve(solver=cp.CLARABEL)
    assert oracle.status == cp.OPTIMAL
    assert result.objective == pytest.approx(oracle.value, rel=SOLVERS)
    assert result.lower_bound <= oracle.value * (1 + SOLVERS)
    after = b0 + cols @ chosen(result)
    largest = float(np.max(np.abs(after)))
    assert largest <= bound * (1 + 1e-9)
    assert largest >= bound * (1 - 1e-4)  # it binds: without it the optimum goes above
    free = replace(design, balance=replace(problem, max_bearing_load=None))
    unbounded = b0 + cols @ chosen(optimize(free, "convex"))
    assert float(np.max(np.abs(unbounded))) > bound * 1.05


@pytest.mark.slow
def test_an_unreachable_bound_names_the_least_one_that_is(design):
    with pytest.raises(InfeasibleError) as caught:
        optimize(replace(design, balance=replace(design.balance, max_bearing_load=5000.0)),
                 "convex")
    (key, least, given, unit), = caught.value.needed
    assert (key, given, unit) == ("balance.max_bearing_load", 5000.0, "N")
    assert least > 5000.0
    for factor, ok in ((1 + 1e-6, True), (1 - 1e-4, False)):
        trial = replace(design, balance=replace(design.balance, max_bearing_load=least * factor))
        if ok:
            assert optimize(trial, "convex").optimal
        else:
            with pytest.raises(InfeasibleError):
                optimize(trial, "convex")


def test_the_spec_keys_are_written_back_and_refused_where_they_cannot_apply(design, tmp_path,
                                                                            capsys):
    again = loads_design(dumps_design(design))
    assert again.balance.max_bearing_load == design.balance.max_bearing_load
    assert again.balance.objective.main_bearing_load == design.balance.objective.main_bearing_load
    text = (EXAMPLES / "inline_four_mains.toml").read_text()
    cases = [
        (text.replace("main_bearings = [", "# main_bearings = ["), "balance.max_bearing_load"),
        (text.replace("max_bearing_load = 7000.0", "# "), "balance.objective.main_bearing_load"),
        (text.replace("max_bearing_load = 7000.0", "max_bearing_load = -1.0"),
         "balance.max_bearing_load"),
        ((EXAMPLES / "pb1.toml").read_text().replace(
            "[balance.objective]\n", "[balance.objective]\nmain_bearing_load = 1.0\n"),
         "main_bearing_load")]
    for i, (spec_text, key) in enumerate(cases):
        spec = tmp_path / f"bad{i}.toml"
        spec.write_text(spec_text if i != 1 else spec_text.replace(
            "main_bearings = [", "# main_bearings = ["))
        assert main(["optimize", str(spec)]) == 2, spec_text[-300:]
        err = capsys.readouterr().err.strip()
        assert key in err and len(err.splitlines()) == 1


@pytest.mark.slow
def test_the_engine_front_keeps_the_bound(design):
    """pareto --against added-mass: every point within the bearings' bound (to Clarabel's
    tolerance: a front's points are its programs' optima, not projected as optimize's design
    is), from the least added mass that meets it."""
    from balancer.balance.pareto import pareto_front

    front = pareto_front(design, "added-mass", 3)
    data = Optimizer.of(replace(design, balance=replace(
        design.balance, objective=replace(design.balance.objective, unbalance=0.0)))).data
    rows = data.regressors.supports
    for p in front.points:
        assert float(np.max(np.abs(rows @ p.x))) <= design.balance.max_bearing_load * (1 + 1e-6)
    assert front.points[0].value > 0.1  # (none added would leave the centre main at 16 kN)


@pytest.mark.slow
def test_regressions_of_the_audit(design):
    """A crankshaft without mass (the default) balances with the NLP backend too (it divided by
    its zero mass); a shaft at ratio 1 on the crank's axis bears on its own bearings, not on the
    mains: the objective's bearing term is the analysis's, and the bound holds in it."""
    bare = replace(design, mechanism=replace(design.mechanism, crankshaft=replace(
        design.mechanism.crankshaft, mass=0.0)))
    nlp, convex = optimize(bare, "nlp"), optimize(bare, "convex")
    assert nlp.optimal and nlp.objective == pytest.approx(convex.objective, rel=SOLVERS)
    shaft = ShaftFreedom(ratio=1, at=(0.0, 0.0), planes=(-0.2, 0.2), max_mr=(0.02, 0.02))
    coaxial = replace(design, balance=replace(design.balance, shafts=(shaft,)))
    result = optimize(coaxial, "convex")
    assert result.optimal
    after = result.term_rms(result.after)
    w = coaxial.balance.objective
    want = (w.main_bearing_load * after["main_bearing_load"] ** 2
            + w.shaking_force * after["shaking_force"] ** 2
            + w.unbalance * after["unbalance"] ** 2)
    assert result.objective == pytest.approx(want, rel=1e-9)
    largest = max(float(np.max(np.abs(s.force))) for s in result.after.supports)
    assert largest <= coaxial.balance.max_bearing_load * (1 + 1e-9)


def test_a_bound_without_the_bearing_term_sees_the_rods_inertia(design):
    """The fuzz campaign's: with main_bearing_load's weight 0 the rods' inertias were taken for
    inert (the objective does not see them) and zeroed in the bound's rows, which then refused
    a bound the design meets (7735 N 'least' against 6661)."""
    plain = replace(design, balance=replace(design.balance, objective=replace(
        design.balance.objective, main_bearing_load=0.0)))
    result = optimize(plain, "convex")
    assert result.optimal
    largest = max(float(np.max(np.abs(s.force))) for s in result.after.supports)
    assert largest <= design.balance.max_bearing_load * (1 + 1e-9)
    data = numeric_problem(plain)
    rows = data.regressors.supports
    assert float(np.max(np.abs(rows @ data.x0))) == pytest.approx(
        max(float(np.max(np.abs(s.force))) for s in result.before.supports), rel=1e-12)


@pytest.mark.slow
def test_the_front_of_the_bearing_load_against_added_mass(design):
    """With main_bearing_load weighed alone, pareto --against added-mass is the front of the
    RMS main-bearing load (N) against the counterweights' mass: from the least mass that keeps
    the bound; each point's RMS is the built engine's bearing loads' (chain momentum), above
    its certified bound, and falls as the mass grows."""
    from balancer.balance.pareto import pareto_front

    weights = replace(design.balance.objective, unbalance=0.0, shaking_force=0.0)
    alone = replace(design, balance=replace(design.balance, objective=weights))
    front = pareto_front(alone, "added-mass", 4)
    assert front.minimised == "main_bearing_load"
    data = numeric_problem(alone)
    speed = design.operation.speed
    radius = design.balance.counterweights.radius
    for p in front.points:
        built = data.sites.model_of(design.mechanism, p.x)
        loads = cycle_analysis(built, speed, theta1=data.states.positions[0],
                               loads=False).supports
        rms = math.sqrt(float(np.mean(np.concatenate([np.abs(s.force) ** 2 for s in loads]))))
        assert p.least == pytest.approx(rms, rel=1e-9)
        assert p.figures["main_bearing_load"] == pytest.approx(rms, rel=1e-9)
        assert p.lower_bound <= p.least * (1 + 1e-9)
        mass = sum(abs(data.sites.vector(p.x, i)) for i in data.sites.chosen) / radius
        assert p.value == pytest.approx(mass, rel=1e-9)
    least = [p.least for p in front.points]
    assert all(a >= b * (1 - 1e-7) for a, b in zip(least, least[1:], strict=False))


def test_four_counterweights_against_eight(design):
    """The in-line four's outer webs alone (four of its eight planes: a restriction of its
    problem) under the same bound: its objective is no lower than the eight webs' certified
    bound (J4 ≥ J4* ≥ J8* ≥ bound8), the mass·radius added less; each design keeps the
    bound."""
    cws = design.balance.counterweights
    four = tuple(z for z in cws.planes if abs(z) in (0.1635, 0.0185))
    assert len(four) == 4
    fewer = replace(design, balance=replace(design.balance, counterweights=replace(
        cws, planes=four, max_mr=cws.max_mr[:4])))
    eight, webs4 = optimize(design, "convex"), optimize(fewer, "convex")
    assert eight.optimal and webs4.optimal
    assert webs4.objective >= eight.lower_bound
    assert webs4.rotor_masses.mr_sum < eight.rotor_masses.mr_sum
    for result in (eight, webs4):
        after = cycle_analysis(result.linkage, design.operation.speed,
                               theta1=result.after.theta1, loads=False)
        largest = max(float(np.max(np.abs(s.force))) for s in after.supports)
        assert largest <= design.balance.max_bearing_load * (1 + 1e-6)


def largest_alone(design, **weights):
    """The in-line four with the largest main-bearing load weighed (and ``weights``), no bound."""
    w = replace(design.balance.objective, rocking_couple=0.0, shaking_force=0.0,
                main_bearing_load=0.0, unbalance=0.0, largest_bearing_load=1.0)
    return replace(design, balance=replace(design.balance, objective=replace(w, **weights),
                                           max_bearing_load=None))


def built_largest(design, x, data) -> float:
    """The largest main-bearing load of the engine built with ``x``, by its cycle analysis, N."""
    built = data.sites.model_of(design.mechanism, x)
    loads = cycle_analysis(built, design.operation.speed, theta1=data.states.positions[0],
                           loads=False).supports
    return max(float(np.max(np.abs(s.force))) for s in loads)


def test_the_largest_load_term_is_the_built_engines_largest_bearing_load(design):
    """``largest_bearing_load``'s J at random counterweights is w_L times the square of the
    largest load of the built engine's bearings (its cycle analysis, not the regressors)."""
    spec = largest_alone(design, largest_bearing_load=0.25, shaking_force=0.5)
    data = numeric_problem(spec)
    rng = np.random.default_rng(4401)
    for _ in range(3):
        x = data.x0.copy()
        for i in data.sites.chosen:
            x[data.sites.entries(i)] = rng.uniform(-0.02, 0.02, 2)
        largest = built_largest(design, x, data)
        assert data.largest_support_load(x) == pytest.approx(largest, rel=1e-9)
        built = data.sites.model_of(design.mechanism, x)
        force = analyze_inertial(built, design.operation.speed, data.states.positions[0])
        want = 0.25 * largest**2 + 0.5 * float(np.mean(np.abs(force) ** 2))
        assert data.objective(x) == pytest.approx(want, rel=1e-9)
        assert data.reduced_objective(x) == pytest.approx(want, rel=1e-9)


def least_largest_oracle(design, theta, weights):
    """CVXPY's epigraph of ``w_L·max|B|² + w_F·mean|F|² + w_U·Σ(mr·ω²)²`` over the bearings'
    loads by hand (:func:`bearing_map`), in real second-order cones and scaled units (loads in
    tens of kN, mass·radius by its bound: CVXPY's complex ``abs`` of these loads, unscaled,
    came back "optimal" 6 % above the optimum). The mass·radius vectors it chooses, kg·m."""
    problem = design.balance
    speed = design.operation.speed
    b0, cols = bearing_map(design, theta)
    unit, per = 1e4, max(problem.counterweights.max_mr)
    rows = np.concatenate(list(cols)) * per / unit
    rows0 = np.concatenate(list(b0)) / unit
    y, t = cp.Variable(cols.shape[2]), cp.Variable()
    parts = cp.hstack([cp.reshape(rows.real @ y + rows0.real, (rows0.size, 1), order="C"),
                       cp.reshape(rows.imag @ y + rows0.imag, (rows0.size, 1), order="C")])
    cons = [cp.SOC(t * np.ones(rows0.size), parts, axis=1)]
    cons += [cp.norm(y[2 * i : 2 * i + 2]) <= m / per
             for i, m in enumerate(problem.counterweights.max_mr)]
    planes = problem.counterweights.planes
    engine = design.mechanism
    base = replace(engine, crankshaft=replace(engine.crankshaft, masses=tuple(
        m for m in engine.crankshaft.masses
        if not (m.label == "counterweight" and m.z in planes))))
    turn = speed**2 * np.exp(1j * theta)
    fcols = np.column_stack([c for _ in planes for c in (turn, 1j * turn)]) * per / unit
    f0 = analyze_inertial(base, speed, theta) / unit
    cost = (weights.largest_bearing_load * cp.square(t)
            + weights.shaking_force * (cp.sum_squares(fcols.real @ y + f0.real)
                                       + cp.sum_squares(fcols.imag @ y + f0.imag)) / theta.size
            + weights.unbalance * (speed**2 * per / unit) ** 2 * cp.sum_squares(y))
    with warnings.catch_warnings():  # ("almost solved" is enough: its design is evaluated)
        warnings.simplefilter("ignore", UserWarning)
        cp.Problem(cp.Minimize(cost), cons).solve(solver=cp.CLARABEL)
    assert y.value is not None
    x = np.asarray(y.value) * per
    for i, m in enumerate(problem.counterweights.max_mr):  # within its bounds exactly
        x[2 * i : 2 * i + 2] *= min(1.0, m / float(np.linalg.norm(x[2 * i : 2 * i + 2])))
    return x


@pytest.mark.slow
def test_the_least_largest_load_is_the_independent_programs(design):
    """The min–max objective against CVXPY's epigraph over the bearings' loads by hand
    (:func:`least_largest_oracle`): alone (the least largest load, which the bound's diagnosis
    also names) and with the free force and the unbalance weighed. The oracle's design is no
    better than the certified bound, ours no worse than the oracle's by more than the certified
    tolerance; the design's largest load is the built engine's; the NLP backend leaves the
    convex (exact) optimum as it is."""
    problem = design.balance
    for weights in ({}, {"shaking_force": 0.3, "unbalance": 1e-6}):
        spec = largest_alone(design, **weights)
        result = optimize(spec, "nlp")
        assert result.optimal, result.message
        assert "nlp" not in [s.name for s in result.stages]  # (no IPOPT run: nothing to gain)
        data = numeric_problem(spec)
        theta = result.before.theta1
        oracle = data.x0.copy()
        for k, i in enumerate(data.sites.chosen):
            oracle[data.sites.entries(i)] = least_largest_oracle(
                design, theta, spec.balance.objective)[2 * k : 2 * k + 2]
        ours, theirs = result.objective, data.objective(oracle)
        assert theirs >= result.lower_bound * (1 - 1e-12)
        assert math.sqrt(ours) - math.sqrt(theirs) <= GAP_TOLERANCE * result.scale
        b0, cols = bearing_map(design, theta)
        largest = float(np.max(np.abs(b0 + cols @ chosen(result))))
        assert data.largest_support_load(result.x) == pytest.approx(largest, rel=1e-9)
        assert built_largest(design, result.x, data) == pytest.approx(largest, rel=1e-9)
        assert result.term_rms(result.after)["largest_bearing_load"] == pytest.approx(
            largest, rel=1e-9)
        if not weights:
            with pytest.raises(InfeasibleError) as caught:  # the bound's least, by its route
                optimize(replace(design, balance=replace(problem, max_bearing_load=5000.0)),
                         "convex")
            (_, least, _, _), = caught.value.needed
            assert abs(largest - least) <= GAP_TOLERANCE * result.scale


@pytest.mark.slow
def test_the_front_of_the_largest_bearing_load_against_added_mass(design):
    """With largest_bearing_load weighed alone, pareto --against added-mass is the front of the
    largest main-bearing load (N) against the counterweights' mass: each point's figure is the
    built engine's largest bearing load, above its certified bound, falling as the mass grows,
    down to the optimiser's least largest load."""
    from balancer.balance.pareto import pareto_front

    spec = largest_alone(design)
    front = pareto_front(spec, "added-mass", 3)
    assert front.minimised == "largest_bearing_load"
    data = numeric_problem(spec)
    for p in front.points:
        largest = built_largest(design, p.x, data)
        assert p.least == pytest.approx(largest, rel=1e-9)
        assert p.figures["largest_bearing_load"] == pytest.approx(largest, rel=1e-9)
        assert p.lower_bound <= p.least * (1 + 1e-9)
        assert p.least - p.lower_bound <= 1e-6 * p.least
    least = [p.least for p in front.points]
    assert all(a >= b * (1 - 1e-7) for a, b in zip(least, least[1:], strict=False))
    best = optimize(spec, "convex")
    assert least[-1] == pytest.approx(math.sqrt(best.objective), rel=SOLVERS)


def test_the_largest_load_key_is_written_back_and_needs_the_main_bearings(design, tmp_path,
                                                                          capsys):
    spec = largest_alone(design, largest_bearing_load=0.5)
    again = loads_design(dumps_design(spec))
    assert again.balance.objective == spec.balance.objective
    assert "largest_bearing_load" not in dumps_design(design)  # (written where weighed)
    text = (EXAMPLES / "inline_four_mains.toml").read_text()
    bad = (text.replace("max_bearing_load = 7000.0", "# ")
           .replace("main_bearing_load = 1.0", "largest_bearing_load = 1.0")
           .replace("main_bearings = [", "# main_bearings = ["))
    path = tmp_path / "bad.toml"
    path.write_text(bad)
    assert main(["optimize", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "balance.objective.largest_bearing_load" in err and len(err.splitlines()) == 1
