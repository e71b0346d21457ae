"""The crank's speed fluctuation as a bound of a linkage's balancing (``max_speed_fluctuation``).

Checked against routes of their own: the bound's ``J(θ)`` rows (the driving torque at rest
under unit crank acceleration, a linear map of the design vector) against the kinetic energy
from the links' velocities written here, ``2·T/ω1²``, and against the flywheel's own
``CrankEnergy`` (inverse dynamics at four crank states); the reported fluctuations against
that estimate of the original and the balanced mechanisms; the cutting planes' optimum against
the program with every pair of samples; the bound kept by the design, certified.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.balance.convex import ConvexSolver, solve_program
from balancer.balance.optimizer import optimize
from balancer.balance.pareto import pareto_front
from balancer.balance.problem import numeric_problem
from balancer.balance.result import InfeasibleError
from balancer.errors import SpecError
from balancer.linkage.vectors import V
from balancer.mechanisms import mechanism_of
from balancer.spec import dumps_design, loads_design
from balancer.speed_fluctuation import CrankEnergy

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PB1 = (EXAMPLES / "pb1.toml").read_text()
BALANCE = "force_balance = true              # exact shaking-force balance (Eq. 57–58)"


def bounded(delta: float, flywheel: float = 1.0, *, capped: bool = False,
            samples: int = 72) -> str:
    """PB1 with the bound (``capped``: its links' inertias within [0.5, 3] kg·m², no
    counter-rotors) at ``samples`` angles."""
    text = PB1.replace(BALANCE, f"force_balance = true\nmax_speed_fluctuation = {delta}\n"
                                f"flywheel = {flywheel}")
    if capped:
        text = text.replace("counter_rotor = [0.0, 20.0]       # kg·m²",
                            "counter_rotor = 0.0\ninertia = [0.5, 3.0]")
    return text.replace("samples = 360", f"samples = {samples}")


def kinetic_inertia(mech, theta: np.ndarray) -> np.ndarray:
    """``2·T/ω1²`` at unit crank speed: Σ m·|v_G|² + I·ω_k², from the links' velocities."""
    mo = mech.motion(theta, 1.0, 0.0)
    out = np.zeros(theta.size)
    for k, body in enumerate(mech.linkage.moving):
        link = mech.linkage.link(body.name)
        v = mo.point_velocity(k, V(link.e, link.f))
        out += link.mass * (np.asarray(v.x) ** 2 + np.asarray(v.y) ** 2)
        out += (link.inertia + link.counter_rotor) * np.asarray(mo.rate[k]) ** 2
    return out


def test_the_bounds_inertia_is_the_kinetic_energys_and_the_flywheels() -> None:
    """J(θ) of the bound's rows at the original and at a changed design: equal to 2T/ω² from
    velocities and to the flywheel's CrankEnergy, to 1e-12 of its largest."""
    design = loads_design(bounded(0.3, samples=36))
    data = numeric_problem(design)
    swing = data.fluctuation
    assert swing is not None
    theta = np.asarray(data.states.positions[0], dtype=float)
    rng = np.random.default_rng(5)
    model = design.mechanism
    changed = model.with_links({name: replace(
        model.link(name), mass=model.link(name).mass * rng.uniform(0.5, 2.0),
        inertia=model.link(name).inertia * rng.uniform(0.5, 2.0),
        counter_rotor=rng.uniform(0.0, 1.0)) for name in ("crank", "rocker")})
    for linkage in (model, changed):
        mech = mechanism_of(linkage)
        got = swing.values(mech.parameters())
        for want in (kinetic_inertia(mech, theta),
                     CrankEnergy.of(mech, theta, 2 * math.pi).inertia):
            assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))


def test_the_reported_fluctuations_are_the_turning_moment_estimates_and_the_bound_holds() -> None:
    """PB1 with δ ≤ 0.3 and a 1 kg·m² flywheel: the design keeps it, certified optimal; the
    report's before and after are (J_max − J_min)/(2·(I_f + J̄)) of each mechanism's own
    CrankEnergy."""
    design = loads_design(bounded(0.3))
    result = optimize(design)
    assert result.optimal
    figures = result.speed_fluctuation
    assert figures is not None and (figures.bound, figures.flywheel) == (0.3, 1.0)
    theta = np.asarray(result.before.theta1, dtype=float)
    for model, reported in ((design.mechanism, figures.before), (result.linkage, figures.after)):
        j = CrankEnergy.of(mechanism_of(model), theta, 2 * math.pi).inertia
        assert reported == pytest.approx((j.max() - j.min()) / (2 * (1.0 + j.mean())),
                                         rel=1e-10)
    assert figures.before > 0.3 >= figures.after * (1 - 1e-9)


def test_the_cutting_planes_optimum_is_the_programs_with_every_pair() -> None:
    """The working set of pairs the cutting planes keep gives the optimum of the program with
    all N² pairs (N = 24 samples), its design within the bound."""
    design = loads_design(bounded(0.3, samples=24))
    data = numeric_problem(design)
    cut = ConvexSolver(data)
    few = solve_program(cut._stage1, cut.settings)
    assert len(cut._pairs) < 24 * 24
    every = ConvexSolver(data)
    every._pairs = [(i, j) for i in range(24) for j in range(24) if i != j]
    every._cones, every._relaxed = every._constraints()
    every._stage1 = every._first_stage()
    full = solve_program(every._stage1, every.settings)
    assert few.u is not None and full.u is not None
    j_few = data.reduced_objective(cut.layout.x(few.u))
    j_full = data.reduced_objective(every.layout.x(full.u))
    assert j_few == pytest.approx(j_full, rel=1e-7)
    assert data.fluctuation.excess(cut.layout.x(few.u)) <= 1e-8 * data.fluctuation.scale


def test_an_unreachable_bound_is_refused_naming_its_key() -> None:
    """Links whose inertias are capped cannot keep δ at 0.1 with 1 kg·m² of flywheel."""
    with pytest.raises(InfeasibleError) as err:
        optimize(loads_design(bounded(0.1, capped=True)), "convex")
    assert "balance.max_speed_fluctuation" in str(err.value)


def test_the_bound_reads_back_and_bad_ones_are_refused_by_key() -> None:
    design = loads_design(bounded(0.3, 2.5))
    assert loads_design(dumps_design(design)).balance == design.balance
    for text, key in ((PB1.replace(BALANCE, "force_balance = true\nflywheel = 1.0"),
                       "balance.flywheel"),
                      (bounded(-0.2), "balance.max_speed_fluctuation"),
                      (bounded(0.2, -1.0), "balance.flywheel")):
        with pytest.raises(SpecError) as err:
            loads_design(text)
        assert err.value.key == key


def test_a_front_refuses_the_bound_by_its_key() -> None:
    """pareto's programs do not hold the bound's rows: exit 2, naming it."""
    with pytest.raises(SpecError) as err:
        pareto_front(loads_design(bounded(0.3)), "driving-torque", 5)
    assert err.value.key == "balance.max_speed_fluctuation"
