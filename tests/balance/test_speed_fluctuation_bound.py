"""``[balance] max_speed_fluctuation``: the least flywheel on the balanced crank, checked twice.

- The balanced design with its flywheel, simulated free from the speed the energy balance gives
  at θ1 = 0 (the multibody formulation: no energy balance, no inverse dynamics), turns with the
  bound's speed fluctuation: the least flywheel, since one a little lighter breaks it.
- The shaking optimum and its certificate are those without the bound (the crank's inertia and
  counter-rotor are inert at constant speed); the flywheel's halves leave the difference of the
  crank's inertia and counter-rotor as settling chose it, where the counter-rotor's range allows.
- A bound the crank's ranges cannot reach is refused naming the key and the inertia needed; bad
  values, engines and linkages with several inputs are refused by the key; the key is written
  back and the written design needs no more flywheel.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.api.motion import simulate
from balancer.balance.optimizer import optimize
from balancer.balance.result import InfeasibleError
from balancer.cli import main
from balancer.cycle import sample_angles
from balancer.mechanisms import mechanism_of
from balancer.model.balance import LinkFreedom
from balancer.spec import dumps_design, load_design, loads_design
from balancer.speed_fluctuation import CrankEnergy, fluctuation_of, speeds

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: The bound of the tests: PB1's balanced crank swings by 0.40 alone at 10 rad/s.
BOUND = 0.05


@pytest.fixture(scope="module")
def pb1():
    return load_design(EXAMPLES / "pb1.toml")


def bounded(design, bound=BOUND, **crank):
    """PB1 with the bound, and the crank's freedom changed by ``crank``."""
    problem = replace(design.balance, max_speed_fluctuation=bound)
    if crank:
        problem = problem.with_link("crank", replace(problem.link("crank"), **crank))
    return replace(design, balance=problem)


def energy_of(model, design) -> CrankEnergy:
    mech = mechanism_of(model)
    return CrankEnergy.of(mech, sample_angles(design.operation.samples, 1), 2 * math.pi,
                          design.operation.gravity)


def simulated_fluctuation(model, design) -> tuple[float, float]:
    """``(δ, mean speed)`` of ``model`` run free over one revolution (multibody formulation).

    From the speed at θ1 = 0 that the energy balance gives for the operating mean speed; the
    revolution's end by interpolation of the crank's angle, the extremes over 40001 outputs.
    """
    speed = design.operation.speed
    omega0 = float(speeds(energy_of(model, design), 0.0, speed)[0])
    settings = replace(design.simulation, theta1=0.0, omega1=omega0, drive="free")
    spec = replace(design, mechanism=model, simulation=settings)
    duration = 1.3 * 2 * math.pi / abs(speed)
    run = simulate(spec, method="multibody", duration=duration, rtol=1e-12, atol=1e-14,
                   outputs=40001)
    theta, omega = run.theta[0], run.omega[0]
    turn = np.flatnonzero(np.abs(theta - theta[0]) >= 2 * math.pi)[0]
    t0, t1 = run.t[turn - 1], run.t[turn]
    a0, a1 = abs(theta[turn - 1] - theta[0]), abs(theta[turn] - theta[0])
    period = t0 + (2 * math.pi - a0) * (t1 - t0) / (a1 - a0)
    within = run.t <= period
    mean = 2 * math.pi / period
    return float((omega[within].max() - omega[within].min()) / mean), mean


@pytest.mark.slow
def test_the_flywheel_turns_the_crank_within_the_bound_and_is_the_least(pb1):
    result = optimize(bounded(pb1), "convex")
    sizing = result.flywheel
    assert result.optimal and sizing is not None and sizing.added > 0
    delta, mean = simulated_fluctuation(result.linkage, pb1)
    assert mean == pytest.approx(abs(pb1.operation.speed), rel=1e-6)
    assert delta == pytest.approx(BOUND, rel=1e-5)  # (the outputs' reach of the extremes)
    assert sizing.after <= BOUND and sizing.after == pytest.approx(BOUND, rel=1e-8)
    energy = energy_of(result.linkage, pb1)
    lighter = fluctuation_of(speeds(energy, -1e-4 * sizing.added, pb1.operation.speed))
    assert lighter > BOUND  # (with a ten-thousandth less, the bound breaks)


def test_the_optimum_and_its_certificate_are_those_without_the_bound(pb1):
    free, bound = optimize(pb1, "convex"), optimize(bounded(pb1), "convex")
    assert bound.objective == pytest.approx(free.objective, rel=1e-12)
    assert bound.lower_bound == pytest.approx(free.lower_bound, rel=1e-12)
    sizing = bound.flywheel
    before, after = free.linkage.link("crank"), bound.linkage.link("crank")
    assert after.inertia - before.inertia == pytest.approx(sizing.inertia, rel=1e-12)
    assert after.counter_rotor - before.counter_rotor == pytest.approx(sizing.counter_rotor,
                                                                      rel=1e-12)
    assert sizing.inertia + sizing.counter_rotor == pytest.approx(sizing.added, rel=1e-12)
    # The counter-rotor takes half, up to its range's end (PB1's 20 kg·m²).
    high = pb1.balance.link("crank").counter_rotor[1]
    assert sizing.counter_rotor == pytest.approx(min(sizing.added / 2,
                                                     high - before.counter_rotor), rel=1e-12)
    for name in ("coupler", "rocker"):  # nothing else moves
        assert bound.linkage.link(name) == free.linkage.link(name)
    assert sizing.before == pytest.approx(
        fluctuation_of(speeds(energy_of(pb1.mechanism, pb1), 0.0, pb1.operation.speed)),
        rel=1e-12)


def test_a_wide_counter_rotor_keeps_the_cranks_moment_balance(pb1):
    """With room on the counter-rotor the flywheel is split evenly: the crank's inertia less
    its counter-rotor, which a change of crank speed makes the frame feel, stays as it was."""
    free = optimize(pb1, "convex")
    result = optimize(bounded(pb1, counter_rotor=(0.0, 1000.0)), "convex")
    before, after = free.linkage.link("crank"), result.linkage.link("crank")
    assert result.flywheel.inertia == pytest.approx(result.flywheel.added / 2, rel=1e-12)
    assert after.inertia - after.counter_rotor == pytest.approx(
        before.inertia - before.counter_rotor, rel=1e-9, abs=1e-9 * after.inertia)


def test_no_flywheel_where_the_balanced_crank_keeps_the_bound(pb1):
    free = optimize(pb1, "convex")
    result = optimize(bounded(pb1, bound=0.5), "convex")
    assert result.flywheel.added == 0 and result.flywheel.balanced <= 0.5
    np.testing.assert_array_equal(result.x, free.x)


def test_a_flywheel_beyond_the_cranks_ranges_is_refused_naming_the_key(pb1, tmp_path, capsys):
    capped = bounded(pb1, inertia=(0.5, 2.0))
    with pytest.raises(InfeasibleError) as caught:
        optimize(capped, "convex")
    (key, needed, given, unit), = caught.value.needed
    assert key == "balance.crank.inertia" and unit == "kg·m²" and needed > given
    # the crank's inertia fixed: all on the counter-rotor, within its range
    fixed = bounded(pb1, inertia=(1.1, 1.1), counter_rotor=(0.0, 1000.0))
    result = optimize(fixed, "convex")
    assert result.flywheel.inertia == 0 and result.flywheel.counter_rotor > 0
    assert result.linkage.link("crank").inertia == pytest.approx(1.1, rel=1e-12)
    spec = tmp_path / "capped.toml"
    spec.write_text(dumps_design(capped))
    assert main(["optimize", str(spec)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "balance.crank.inertia" in err[0]


@pytest.mark.parametrize("bad", [0.0, -0.1, 2.0, 2.5, '"small"'])
def test_bad_bounds_are_refused_by_the_key(bad, tmp_path, capsys):
    text = (EXAMPLES / "pb1.toml").read_text().replace(
        "[balance]\n", f"[balance]\nmax_speed_fluctuation = {bad}\n")
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    assert main(["optimize", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "balance.max_speed_fluctuation" in err[0]


@pytest.mark.parametrize("name", ["inline_four.toml", "fivebar_5r.toml"])
def test_engines_and_linkages_with_several_inputs_are_refused(name, tmp_path, capsys):
    text = (EXAMPLES / name).read_text().replace(
        "[balance]\n", "[balance]\nmax_speed_fluctuation = 0.05\n", 1)
    if "[balance]\n" not in (EXAMPLES / name).read_text():
        text += "\n[balance]\nmax_speed_fluctuation = 0.05\n"
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    assert main(["optimize", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "balance.max_speed_fluctuation" in err[0]


def test_the_key_is_written_back_and_the_written_design_needs_no_more(pb1, tmp_path, capsys):
    spec = bounded(pb1)
    assert loads_design(dumps_design(spec)).balance == spec.balance
    path = tmp_path / "pb1.toml"
    path.write_text(dumps_design(spec))
    out = tmp_path / "out.toml"
    assert main(["optimize", str(path), "--out", str(out), "--no-verify", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    figures = doc["speed_fluctuation"]
    assert figures["bound"] == BOUND and figures["after"] <= BOUND and figures["flywheel"] > 0
    written = load_design(out)
    again = optimize(written, "convex")
    assert again.flywheel.before <= BOUND  # (as written, it keeps the bound)
    # (balanced again it moves by the solvers' accuracy: a flywheel of as little, if any)
    assert again.flywheel.added <= 1e-5 * figures["flywheel"]


def test_the_crank_link_freedom_is_a_dataclass_replace():  # (the helper above relies on it)
    assert replace(LinkFreedom(mass=(1.0, 2.0)), inertia=(0.5, 2.0)).inertia == (0.5, 2.0)


@pytest.mark.slow  # (the full suite's: the fast lane's minute)
def test_regressions_of_the_audit(pb1, tmp_path, capsys):
    """A counterweight on the crank takes no flywheel (its inertia is its shape's): the flywheel
    goes on the counter-rotor, or is refused naming it; what the crank's inertia cannot take
    goes on the counter-rotor; plan --with-masses (a balancing along a motion) leaves the key
    alone; pareto says its points carry no flywheel; a bound below the root finding's
    resolution is refused by its key."""
    design = load_design(EXAMPLES / "pb1_counterweights.toml")
    problem = replace(design.balance, max_speed_fluctuation=BOUND)
    with pytest.raises(InfeasibleError) as caught:
        optimize(replace(design, balance=problem), "convex")
    (key, needed, given, _), = caught.value.needed
    assert key == "balance.crank.counter_rotor" and needed > given == 20.0
    wide = problem.with_link("crank", replace(problem.link("crank"), counter_rotor=(0.0, 1e3)))
    result = optimize(replace(design, balance=wide), "convex")
    assert result.flywheel.inertia == 0 and result.flywheel.after <= BOUND
    assert result.flywheel.counter_rotor == pytest.approx(result.flywheel.added, rel=1e-12)
    split = optimize(bounded(pb1, inertia=(0.5, 2.0), counter_rotor=(0.0, 1e3)), "convex")
    assert split.linkage.link("crank").inertia == pytest.approx(2.0, rel=1e-12)
    assert split.flywheel.after <= BOUND
    text = (EXAMPLES / "servo_press.toml").read_text().replace(
        "[balance]\n", "[balance]\nmax_speed_fluctuation = 1.9\n", 1)
    spec = tmp_path / "press.toml"
    spec.write_text(text)
    assert main(["plan", str(spec), "--with-masses", "--json"]) == 0
    capsys.readouterr()
    from balancer.balance.pareto import pareto_front

    front = pareto_front(bounded(pb1), "driving-torque", 2)
    assert front.notes and "max_speed_fluctuation" in front.notes[0]
    text = (EXAMPLES / "pb1.toml").read_text().replace(
        "[balance]\n", "[balance]\nmax_speed_fluctuation = 1e-320\n")
    spec.write_text(text)
    assert main(["optimize", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "balance.max_speed_fluctuation" in err[0]
