"""Counterweights: the original link plus the reported body is the balanced link.

The check composes the two bodies by another route than the one that found the counterweight:
the composite's centre of mass as the mass-weighted mean of the two centres and its inertia by
the parallel-axis theorem about that centre (the module subtracts first moments and inertias
about the link frame's origin instead).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from balancer.balance.counterweights import STEEL_DENSITY, UNCHANGED, counterweight
from balancer.balance.optimizer import optimize
from balancer.report import optimization_json
from balancer.spec import load_design

EPS = 2.0**-52


@dataclass(frozen=True)
class Body:
    mass: float
    e: float
    f: float
    inertia: float


def compose(a: Body, b: Body) -> tuple[Body, dict[str, float]]:
    """``a`` and ``b`` as one body, and the magnitude of the terms each result sums."""
    m = a.mass + b.mass
    sa, sb = complex(a.e, a.f), complex(b.e, b.f)
    s = (a.mass * sa + b.mass * sb) / m
    parts = [a.inertia, a.mass * abs(sa - s) ** 2, b.inertia, b.mass * abs(sb - s) ** 2]
    sizes = {"mass": abs(a.mass) + abs(b.mass),
             "moment": abs(a.mass * sa) + abs(b.mass * sb),
             "inertia": sum(abs(p) for p in parts)
             + (abs(a.mass) * abs(sa) ** 2 + abs(b.mass) * abs(sb) ** 2)}
    return Body(m, s.real, s.imag, math.fsum(parts)), sizes


def assert_reproduces(original, balanced, weight) -> None:
    """Original + counterweight = balanced: mass, first moment and inertia about the centre.

    Each compared quantity is a short sum whose rounding is a few ε of its terms' magnitudes
    (both routes): 16·ε of those, and a floor of subnormals (a product of two lengths can
    underflow).
    """
    added = Body(weight.mass, weight.e, weight.f, weight.inertia)
    whole, size = compose(Body(original.mass, original.e, original.f, original.inertia), added)
    tol = 16 * EPS
    floor = 1e-300
    assert abs(whole.mass - balanced.mass) <= tol * size["mass"] + floor
    s_whole = whole.mass * complex(whole.e, whole.f)
    s_bal = balanced.mass * complex(balanced.e, balanced.f)
    # A change of first moment below UNCHANGED of the link's own (its mass times its reach)
    # is rounding by the module's definition, and reported as none.
    mass = max(original.mass, balanced.mass)
    j = max(original.inertia + original.mass * (original.e**2 + original.f**2),
            balanced.inertia + balanced.mass * (balanced.e**2 + balanced.f**2))
    reach = max(math.hypot(original.e, original.f), math.hypot(balanced.e, balanced.f),
                math.sqrt(j / mass))
    unchanged = UNCHANGED * mass * reach
    assert abs(s_whole - s_bal) <= tol * size["moment"] + unchanged + floor
    # A counterweight's inertia above −UNCHANGED of the link's (about its frame's origin) is
    # rounding by the same definition, and reported as zero.
    assert abs(whole.inertia - balanced.inertia) <= tol * size["inertia"] * (
        1 + size["moment"] ** 2 / max(size["mass"], 1e-300) / max(size["inertia"], 1e-300)
    ) + UNCHANGED * j + floor


_MASS = st.floats(0.05, 50.0)
_LEN = st.floats(-3.0, 3.0)
_INERTIA = st.floats(0.0, 20.0)


@settings(max_examples=300, deadline=None)
@given(m0=_MASS, e0=_LEN, f0=_LEN, i0=_INERTIA, m1=_MASS, e1=_LEN, f1=_LEN, i1=_INERTIA)
@pytest.mark.slow
def test_any_change_of_a_link_is_the_reported_body(m0, e0, f0, i0, m1, e1, f1, i1):
    original, balanced = Body(m0, e0, f0, i0), Body(m1, e1, f1, i1)
    w = counterweight("link", original, balanced)
    if w.exact:
        assert_reproduces(original, balanced, w)
    assert w.kind in ("none", "add", "remove", "rebuild")
    if w.kind == "add":
        assert w.mass > 0 and w.inertia >= 0
    if w.kind == "remove":
        assert w.mass < 0 and w.inertia <= 1e-9 * (i0 + i1 + m0 * (e0**2 + f0**2) + 1)
    if w.disc_radius is not None:
        # A solid steel disc: I = m·R²/2 about its axis, m = ρ·π·R²·t.
        assert w.inertia == pytest.approx(w.mass * w.disc_radius**2 / 2, rel=8 * EPS)
        volume = math.pi * w.disc_radius**2 * w.disc_thickness
        assert w.mass == pytest.approx(STEEL_DENSITY * volume, rel=8 * EPS)


def test_an_added_body_is_found_as_it_was_added():
    original = Body(2.0, 0.4, 0.0, 0.5)
    body = Body(0.7, -0.25, 0.1, 0.003)
    balanced, _ = compose(original, body)
    w = counterweight("crank", original, balanced)
    assert w.kind == "add" and w.exact
    assert (w.mass, w.e, w.f, w.inertia) == pytest.approx(
        (body.mass, body.e, body.f, body.inertia), rel=1e-13, abs=1e-15)
    same = counterweight("crank", original, original)
    assert same.kind == "none" and same.mass == 0


def test_a_moment_moved_with_the_mass_kept_is_a_rebuild():
    w = counterweight("rocker", Body(2.0, 0.4, 0.0, 0.5), Body(2.0, 0.6, 0.0, 0.5))
    assert w.kind == "rebuild" and not w.exact


@pytest.mark.parametrize("example", ["pb1", "pb2", "engine", "watt_sixbar",
                                     "pb1_counterweights", "pb2_counterweights",
                                     "engine_counterweights"])
def test_optimized_examples_report_counterweights_that_rebuild_the_balanced_links(example):
    design = load_design(f"examples/{example}.toml")
    result = optimize(design, "convex")
    assert result.success
    weights = result.counterweights
    assert set(weights) == set(result.linkage.link_names)
    for name, w in weights.items():
        # A free link whose mass the optimum keeps but whose centre of mass moves (PB1's crank
        # and rocker) is no body added: it is to be rebuilt.
        assert w.exact or w.kind == "rebuild", name
        if w.exact:
            assert_reproduces(result.original.link(name), result.linkage.link(name), w)
    # A link whose mass moves by less than UNCHANGED of itself (a bound met to the solver's
    # rounding) has no counterweight: the sum may miss that much of the links' masses.
    assert result.added_mass == pytest.approx(
        result.linkage.total_mass - result.original.total_mass, rel=1e-12,
        abs=UNCHANGED * (result.linkage.total_mass + result.original.total_mass))
    doc = optimization_json(result, result.before, result.after)
    assert set(doc["counterweights"]) == set(weights)
    assert {"mass", "e", "f", "inertia"} <= set(doc["counterweights"][name])
    assert doc["added_mass"] == result.added_mass


# ---- counterweight-only redesign ([balance.<link>] counterweight) ----------------------------


def _counterweight_optimum_by_cvxpy(data) -> float:
    """The least RMS of the counterweight problem, formulated apart from the optimiser.

    In the counterweights' own variables (mass ``m``, first moment ``S`` and inertia ``J``
    about the link frame's origin, per link) and the counter-rotors, written directly as a CVXPY
    program: ``x = x0 + Σ counterweight entries``, ``‖K·x‖`` minimised subject to force balance
    ``A·x = b``, each mass in its range, its centre within the radius of its point
    (``‖S − m·c‖ ≤ r·m``) and its inertia about its centre at least ``m·ρ²``
    (``‖S‖²/m ≤ J − ρ²·m``). The optimiser instead shifts the link's own entries by the original
    link's (:attr:`NumericProblem.offset`) and solves Clarabel's standard form.
    """
    import cvxpy as cp
    import numpy as np

    x = data.x0.copy() + 0.0 * cp.Variable()  # an affine expression
    cons = []
    for b in data.links:
        if b.offset is None:
            continue
        m, s, j = cp.Variable(), cp.Variable(2), cp.Variable()
        c = np.array([b.com_centre.real, b.com_centre.imag])
        cons += [m >= b.mass[0], m <= b.mass[1], cp.norm(s - m * c) <= b.com_radius * m,
                 cp.quad_over_lin(s, m) <= j - b.gyration**2 * m]
        basis = np.zeros((data.size, 4))
        basis[b.entries, :] = np.eye(4)
        x = x + basis @ cp.hstack([m, s, j])
    for b in data.rotor_links:
        lo, hi = b.counter_rotor
        if lo < hi:
            rotor = cp.Variable()
            cons += [rotor >= lo, rotor <= hi]
            unit = np.zeros(data.size)
            unit[b.rotor] = 1.0
            x = x + unit * (rotor - data.x0[b.rotor])
    a, rhs = data.force_balance
    cons.append(a @ x == rhs)
    problem = cp.Problem(cp.Minimize(cp.norm(data.rows @ x)), cons)
    problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)
    assert problem.status == "optimal"
    return float(problem.value)


@pytest.mark.parametrize("backend", ["convex", "nlp"])
def test_counterweights_only_reach_the_optimum_of_an_independent_formulation(backend):
    from balancer.balance.problem import numeric_problem

    design = load_design("examples/pb1_counterweights.toml")
    result = optimize(design, backend)
    assert result.success and result.optimal, result.message
    data = numeric_problem(design)
    best = _counterweight_optimum_by_cvxpy(data)
    # Both are Clarabel's optimum to its tolerances (1e-10, scaled by the original's RMS of
    # ~215 N·m); the product's own claim is a gap of 1e-6 of that scale.
    assert result.rms == pytest.approx(best, rel=1e-6)
    assert result.rms_lower_bound <= best * (1 + 1e-9)
    # The objective by the Newton–Euler cycle analysis of the balanced design.
    assert result.after.summary.shaking_moment.rms == pytest.approx(result.rms, rel=1e-9)


def test_counterweights_are_within_their_bounds_and_build_the_balanced_links():
    design = load_design("examples/pb1_counterweights.toml")
    result = optimize(design, "convex")
    freedom = dict(design.balance.links)
    for name in ("crank", "rocker"):
        w = result.counterweights[name]
        bounds = freedom[name].counterweight
        assert w.kind == "add" and w.exact
        assert_reproduces(result.original.link(name), result.linkage.link(name), w)
        assert bounds.mass[0] <= w.mass <= bounds.mass[1]
        # Its centre within the radius of com_about (A0: the crank's origin; A3: the rocker's
        # second point, at its length along its frame's x-axis).
        about = 0.0 if name == "crank" else design.mechanism.lengths[2]
        assert abs(complex(w.e, w.f) - about) <= bounds.radius * (1 + 1e-12)
        # Its inertia about its centre is a difference of inertias about the frame's origin
        # (ΔJ − Δm·|c̄|², terms of some 30 kg·m² here for 0.008): its rounding is a few ε of
        # those terms.
        old, new = result.original.link(name), result.linkage.link(name)
        terms = (w.mass * abs(complex(w.e, w.f)) ** 2 + old.inertia + old.mass * abs(old.com) ** 2
                 + new.inertia + new.mass * abs(new.com) ** 2)
        assert w.inertia >= w.mass * bounds.gyration**2 - 16 * EPS * terms
    assert result.added_mass == pytest.approx(
        result.linkage.total_mass - result.original.total_mass, rel=1e-12)
    assert result.counterweights["coupler"].kind == "none"


def test_counterweight_spec_round_trips_and_refuses_what_contradicts_it():
    from balancer.errors import SpecError
    from balancer.spec import dumps_design, loads_design

    design = load_design("examples/pb1_counterweights.toml")
    again = loads_design(dumps_design(design))
    assert again.balance == design.balance
    text = Path("examples/pb1_counterweights.toml").read_text()
    line = 'counterweight = { mass = [0.01, 6.3], radius = 1.0, gyration = 0.05 }'
    cases = {
        "mass = [1.0, 2.0]\n" + line: "balance.crank.mass",
        "counterweight = { radius = 1.0 }": "balance.crank.counterweight.mass",
        "counterweight = { mass = [-0.1, 1.0], radius = 1.0 }":
            "balance.crank.counterweight.mass",
        "counterweight = { mass = [0.1, 1.0], radius = 1.0, gyraton = 0.1 }":
            "balance.crank.counterweight.gyraton",
    }
    for replacement, key in cases.items():
        bad = text.replace(line, replacement, 1)
        with pytest.raises(SpecError) as info:
            loads_design(bad)
        assert info.value.key == key, (replacement, info.value)


def test_a_counterweight_too_small_to_balance_is_diagnosed_with_what_it_needs():
    """Force balance fixes the crank's first moment (Eq. 57: m1·s̄1 = −m2·(1 − s̄2/l2)·l1), so
    its counterweight must carry ΔS = that − m1₀·s̄1₀: mass × distance from A0 = |ΔS|. The
    diagnosis (each bound alone, by its own conic program) must say so: the least radius at the
    largest mass, and the least mass at the given radius, both |ΔS| (to the 4 significant
    digits it rounds up to)."""
    import math as m

    from balancer.balance.result import InfeasibleError
    from balancer.spec import loads_design

    text = Path("examples/pb1_counterweights.toml").read_text().replace(
        "radius = 1.0, gyration", "radius = 0.1, gyration")
    design = loads_design(text)
    with pytest.raises(InfeasibleError) as info:
        optimize(design, "convex")
    needed = {key: value for key, value, _, _ in info.value.needed}
    linkage = design.mechanism
    l1, l2, _, _ = linkage.lengths
    crank, coupler = linkage.link("crank"), linkage.link("coupler")
    required = -coupler.mass * (1 - coupler.com / l2) * l1
    delta = abs(required - crank.mass * crank.com)
    radius, mass = needed["balance.crank.counterweight.radius"], needed[
        "balance.crank.counterweight.mass"]
    top = dict(design.balance.links)["crank"].counterweight.mass[1]
    assert radius == pytest.approx(delta / top, rel=1e-3) and radius >= delta / top
    assert mass == pytest.approx(delta / 0.1, rel=1e-3) and mass >= delta / 0.1
    assert m.isfinite(radius) and m.isfinite(mass)


def test_optimize_reports_the_analyze_figures_and_the_inertial_ones_apart(tmp_path, capsys):
    """The engine carries a gas force: ``optimize --json``'s ``before`` and ``after`` are
    ``analyze --json``'s figures of the spec and of the balanced spec it writes (loads
    included), ``inertial`` the optimiser's own view (the result's ``before``/``after``), and the
    Python API's document is the same."""
    import json

    import balancer
    from balancer.cli import main

    out = tmp_path / "engine_balanced.toml"
    assert main(["optimize", "examples/engine.toml", "--backend", "convex", "--no-verify",
                 "--json", "--out", str(out)]) == 0
    doc = json.loads(capsys.readouterr().out)
    for spec, key in (("examples/engine.toml", "before"), (str(out), "after")):
        assert main(["analyze", spec, "--json"]) == 0
        analysed = json.loads(capsys.readouterr().out)
        for name in ("shaking_force", "shaking_moment", "driving_torque"):
            assert doc[key][name] == analysed[name], (key, name)
    result = balancer.optimize(balancer.load_design("examples/engine.toml"), backend="convex")
    assert doc["inertial"]["before"] == result.before.summary.as_dict()
    assert doc["inertial"]["after"] == result.after.summary.as_dict()
    # The gas force makes the two differ: the inertial view leaves it out. (It pushes the
    # piston and the head apart, so the frame's shaking force is the same to rounding; the
    # crank's torque is not.)
    assert doc["before"]["shaking_force"]["rms"] == pytest.approx(
        doc["inertial"]["before"]["shaking_force"]["rms"], rel=1e-12)
    assert doc["before"]["driving_torque"]["rms"] > 1.4 * doc["inertial"]["before"][
        "driving_torque"]["rms"]
    api = balancer.to_dict(result)
    assert api["before"] == doc["before"] and api["after"] == doc["after"]


@pytest.mark.parametrize("example", ["pb1_counterweights", "pb2_counterweights",
                                     "engine_counterweights"])
def test_counterweight_examples_are_built_from_the_original_links_exactly(example):
    """With counterweights only, every changed link is its original plus one added body (to
    rounding), and PB2's complete balance is reached by them: zero shaking moment."""
    design = load_design(f"examples/{example}.toml")
    result = optimize(design, "convex")
    assert result.optimal, result.message
    for name, w in result.counterweights.items():
        assert w.kind in ("add", "none") and w.exact, name
        assert_reproduces(result.original.link(name), result.linkage.link(name), w)
    if example == "pb2_counterweights":
        # Within the optimiser's gap tolerance of the original's RMS (PB2's optimum is zero).
        assert result.rms <= 1e-6 * result.before.summary.shaking_moment.rms
        assert set(result.counterweights) == {"crank", "coupler", "rocker"}


@pytest.mark.parametrize("seed", range(8))
def test_random_counterweight_problems_end_feasible_or_say_what_is_missing(seed):
    """Random crank-rockers, counterweights on crank and rocker with random bounds: either an
    optimum whose counterweights meet their bounds and rebuild the balanced links exactly, with
    force balance to rounding, or an InfeasibleError naming a counterweight's bound."""
    import numpy as np
    from conftest import random_linkage

    from balancer.balance.result import InfeasibleError
    from balancer.mechanisms.fourbar.conditions import force_balance_error
    from balancer.model import Design, Operation
    from balancer.model.balance import (
        BalanceProblem,
        CounterweightFreedom,
        LinkFreedom,
        Objective,
    )

    rng = np.random.default_rng(seed)
    linkage = random_linkage(rng, loads=False, rotors=True, full_turn=True)
    links = {}
    for name, about, length in (("crank", "A0", linkage.lengths[0]),
                                ("rocker", "A3", linkage.lengths[2])):
        mass = linkage.link(name).mass
        links[name] = LinkFreedom(
            com_about=about, counter_rotor=(0.0, rng.uniform(0.5, 5.0)),
            counterweight=CounterweightFreedom(
                mass=(0.01 * mass, mass * rng.uniform(2.0, 6.0)),
                radius=length * rng.uniform(1.0, 3.0), gyration=0.05 * length))
    design = Design(mechanism=linkage, operation=Operation(speed=10.0, samples=72),
                    balance=BalanceProblem(objective=Objective(), links=links))
    try:
        result = optimize(design, "convex")
    except InfeasibleError as exc:
        assert ".counterweight." in str(exc)
        return
    assert result.success, result.message
    assert force_balance_error(result.linkage) < 1e-12
    for name, freedom in links.items():
        w = result.counterweights[name]
        assert w.kind == "add" and w.exact, (name, w)
        assert_reproduces(result.original.link(name), result.linkage.link(name), w)
        cw = freedom.counterweight
        assert cw.mass[0] * (1 - 1e-12) <= w.mass <= cw.mass[1] * (1 + 1e-12)
        about = 0.0 if name == "crank" else linkage.lengths[2]
        assert abs(complex(w.e, w.f) - about) <= cw.radius * (1 + 1e-12)
        assert w.inertia >= w.mass * cw.gyration**2 * (1 - 1e-12)
