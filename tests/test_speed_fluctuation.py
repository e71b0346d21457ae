"""The flywheel for a speed fluctuation (balancer/speed_fluctuation.py), each by a second route.

- ``J(θ)``: twice the kinetic energy at unit crank speed, from the links' centres and angles
  differentiated numerically (positions only: no rates, no inverse dynamics).
- ``½·J'``: the central difference of ``J``.
- ``Q``: minus the derivative of the weights' potential energy (a four-bar under gravity).
- ``W``: an adaptive quadrature of ``Q − Q̄``, ``Q`` from the mechanism at the quadrature's
  nodes (a single-cylinder engine's gas over 720°).
- The least flywheel: the equation of motion integrated in time with it, from the state the
  energy balance gives, returns after one cycle to that state with the required fluctuation.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from balancer.cycle import sample_angles
from balancer.errors import SpecError
from balancer.linkage.vectors import V
from balancer.mechanisms import mechanism_of
from balancer.spec import load_design
from balancer.speed_fluctuation import REFINE, CrankEnergy, fluctuation_of, flywheel, speeds

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

#: A central difference's step, rad: its truncation (h²·J'''/6) and rounding (ε·J/h) both near
#: 1e-10 of J.
STEP = 2e-5


def energy_of(name: str, gravity: tuple[float, float] | None = None,
              samples: int | None = None) -> tuple[object, CrankEnergy]:
    design = load_design(EXAMPLES / name)
    mech = mechanism_of(design.mechanism)
    rev = mech.model.cycle_revolutions
    op = design.operation
    theta = sample_angles(samples or op.samples, rev)
    g = op.gravity if gravity is None else gravity
    return design, CrankEnergy.of(mech, theta, 2 * math.pi * rev, g)


def kinetic_inertia(mech, theta: float) -> float:
    """``2·KE`` at unit crank speed from the links' centres and angles (central differences)."""
    def places(t: float) -> tuple[np.ndarray, np.ndarray]:
        mo = mech.motion(np.array([t]))
        centres = np.array([complex(np.ravel(mo.point(k, V(link.e, link.f)).complex())[0])
                            for k, link in enumerate(mech.linkage.links)])
        angles = np.array([float(np.asarray(mo.pose.angles[k]).ravel()[0])
                           for k in range(len(mech.linkage.links))])
        return centres, angles

    (c1, a1), (c0, a0) = places(theta + STEP), places(theta - STEP)
    v = (c1 - c0) / (2 * STEP)
    w = (a1 - a0) / (2 * STEP)
    total = 0.0
    for link, vk, wk in zip(mech.linkage.links, v, w, strict=True):
        total += link.mass * abs(vk) ** 2 + (link.inertia + link.counter_rotor) * wk**2
    return total


@pytest.mark.parametrize("name", ["pb1.toml", "quick_return.toml"])
def test_the_inertia_seen_by_the_crank_is_twice_the_kinetic_energy_at_unit_speed(name):
    design, energy = energy_of(name, samples=36)
    mech = mechanism_of(design.mechanism)
    for i in range(0, energy.theta.size, 5):
        want = kinetic_inertia(mech, float(energy.theta[i]))
        assert energy.inertia[i] == pytest.approx(want, rel=1e-8)


def test_half_the_slope_of_the_inertia_is_its_central_difference():
    design, energy = energy_of("pb1.toml", samples=36)
    mech = mechanism_of(design.mechanism)
    for i in range(0, energy.theta.size, 5):
        t = float(energy.theta[i])
        ahead = CrankEnergy.of(mech, np.array([t + STEP, t - STEP]), 2 * math.pi)
        slope = (ahead.inertia[0] - ahead.inertia[1]) / (2 * STEP)
        scale = float(np.max(np.abs(energy.inertia)))
        assert energy.half_slope[i] == pytest.approx(0.5 * slope, abs=1e-8 * scale)


def test_the_load_is_minus_the_slope_of_the_weights_potential():
    g = (0.0, -9.81)
    design, energy = energy_of("pb1.toml", gravity=g, samples=36)
    mech = mechanism_of(design.mechanism)

    def potential(t: float) -> float:
        mo = mech.motion(np.array([t]))
        centres = (mo.point(k, V(link.e, link.f)) for k, link in enumerate(mech.linkage.links))
        return -sum(link.mass * (g[0] * np.ravel(c.x)[0] + g[1] * np.ravel(c.y)[0])
                    for link, c in zip(mech.linkage.links, centres, strict=True))

    scale = max(link.mass for link in mech.linkage.links) * 9.81 * mech.drawing().reach
    for i in range(0, energy.theta.size, 5):
        t = float(energy.theta[i])
        want = -(potential(t + STEP) - potential(t - STEP)) / (2 * STEP)
        assert energy.load[i] == pytest.approx(want, abs=1e-8 * scale)
    assert energy.mean_load == pytest.approx(0.0, abs=1e-12 * scale)  # conservative


def test_the_work_is_the_quadrature_of_the_load_about_its_mean():
    """A single cylinder's gas over 720°: W at every 15th sample by Gauss–Legendre quadrature
    (16 nodes between those samples, Q from the mechanism at the nodes) of Q − Q̄."""
    design, energy = energy_of("single_cylinder.toml")
    mech = mechanism_of(design.mechanism)
    n = energy.theta.size
    step = 15
    assert n % step == 0
    ends = np.append(energy.theta[::step], energy.cycle)
    nodes, weights = np.polynomial.legendre.leggauss(16)
    half = np.diff(ends)[:, None] / 2
    at = (ends[:-1, None] + half * (nodes + 1)).ravel()
    f = mech.crank_forces(at, 0.0, 0.0, loads=True)
    load = -np.asarray(f.driving_torque)[:, 0].reshape(half.shape[0], -1)
    pieces = np.sum(load * weights * half, axis=1)
    mean = float(np.sum(pieces)) / energy.cycle
    assert energy.mean_load == pytest.approx(mean, rel=1e-9)
    want = np.concatenate([[0.0], np.cumsum(pieces - mean * 2 * half[:, 0])])[:-1]
    work = energy.work()[::step]
    np.testing.assert_allclose(work, want, rtol=0, atol=2e-8 * float(np.ptp(want)))  # (3e-9 here)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["pb1.toml", "engine.toml"])
def test_the_least_flywheel_runs_with_the_required_fluctuation(name):
    """With it, the equation of motion integrated over a cycle (J, ½J', Q from the mechanism at
    each step) returns to its start, and its speed swings by the required share of its mean."""
    design, energy = energy_of(name)
    mech = mechanism_of(design.mechanism)
    speed = design.operation.speed
    result = flywheel(energy, speed, 0.03)
    assert result.inertia > 0 and result.fluctuation_without > 0.03
    omega0 = float(speeds(energy, result.inertia, speed)[0])
    torque_c = -energy.mean_load

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        one = CrankEnergy.of(mech, np.array([y[0]]), energy.cycle, design.operation.gravity)
        acc = (one.load[0] + torque_c - one.half_slope[0] * y[1] ** 2) / (
            result.inertia + one.inertia[0])
        return [y[1], acc]

    def once_round(_t: float, y: np.ndarray) -> float:
        return y[0] - energy.cycle

    once_round.terminal = True  # type: ignore[attr-defined]
    run = solve_ivp(rhs, (0, 10 * energy.cycle / abs(speed)), [0.0, omega0], method="DOP853",
                    rtol=1e-11, atol=1e-12 * abs(omega0), events=once_round, dense_output=True)
    assert run.status == 1
    period = float(run.t_events[0][0])
    assert run.y_events[0][0][1] == pytest.approx(omega0, rel=1e-8)
    grid = run.sol(np.linspace(0, period, 40001))
    w = grid[1]
    delta = (w.max() - w.min()) / (energy.cycle / period)
    assert energy.cycle / period == pytest.approx(abs(speed), rel=1e-8)
    assert delta == pytest.approx(0.03, rel=1e-6)


def test_no_flywheel_where_the_mechanism_meets_the_fluctuation_alone():
    _, energy = energy_of("v8.toml")
    result = flywheel(energy, 628.3185307179587, 0.05)
    assert result.inertia == 0.0 and result.fluctuation_without <= 0.05
    omega = speeds(energy, 0.0, 628.3185307179587)
    assert fluctuation_of(omega) == pytest.approx(result.fluctuation_without, rel=1e-12)
    assert omega.size == REFINE * energy.theta.size


def test_the_classical_estimate_is_near_the_exact_where_the_inertia_barely_varies():
    """The in-line four: J varies by ±8 %; the estimate of the turning-moment diagram is within
    a fraction of a percent; PB1, whose J more than doubles, is within 1 %."""
    for name, within in (("inline_four.toml", 1e-3), ("pb1.toml", 1e-2)):
        design, energy = energy_of(name)
        result = flywheel(energy, design.operation.speed, 0.02)
        assert result.classical == pytest.approx(result.inertia, rel=within)


@pytest.mark.parametrize("bad", [0.0, -0.1, 2.0, math.nan])
def test_a_fluctuation_out_of_range_is_refused_naming_the_key(bad):
    _, energy = energy_of("pb1.toml", samples=36)
    with pytest.raises(SpecError, match="speed_fluctuation"):
        flywheel(energy, 10.0, bad)


def test_a_load_of_the_speed_is_refused():
    design, _ = energy_of("pb1.toml", samples=36)
    mech = mechanism_of(design.mechanism)

    class Damped(type(mech)):  # a torque on the crank that grows with its speed
        def crank_forces(self, theta, omega=0.0, alpha=0.0, **kwargs):
            f = super().crank_forces(theta, omega, alpha, **kwargs)
            np.asarray(f.driving_torque)[:, 0] += 0.1 * np.asarray(omega)
            return f

    with pytest.raises(SpecError, match="depends on the crank's speed"):
        CrankEnergy.of(Damped(design.mechanism), sample_angles(36), 2 * math.pi)


def test_the_design_is_not_changed():
    design, energy = energy_of("pb1.toml", samples=36)
    again = CrankEnergy.of(mechanism_of(replace(design.mechanism)), energy.theta, energy.cycle)
    np.testing.assert_array_equal(again.inertia, energy.inertia)


def test_analyze_gives_the_flywheel_the_spec_asks_for(tmp_path, capsys):
    """`[operation] speed_fluctuation`: analyze's JSON `flywheel` and text are the API's; the
    key is written back by the spec writer; without it, no flywheel."""
    import json

    from balancer import flywheel as api_flywheel
    from balancer.cli import main
    from balancer.spec import dumps_design, loads_design

    asked = (EXAMPLES / "single_cylinder.toml").read_text()  # (it asks for 0.02)
    text = "\n".join(line for line in asked.splitlines()
                     if not line.startswith("speed_fluctuation"))
    spec = tmp_path / "asked.toml"
    spec.write_text(asked)
    assert main(["analyze", str(spec), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    want = api_flywheel(loads_design(asked)).as_dict()
    assert doc["flywheel"].pop("mechanism_inertia") == pytest.approx(
        want.pop("mechanism_inertia"), rel=1e-12)
    assert doc["flywheel"] == pytest.approx(want, rel=1e-12)
    assert main(["analyze", str(spec)]) == 0
    assert "least flywheel on the crank for a speed fluctuation of 0.02" in capsys.readouterr().out
    again = loads_design(dumps_design(loads_design(asked)))
    assert again.operation.speed_fluctuation == 0.02
    plain = tmp_path / "plain.toml"
    plain.write_text(text)
    assert main(["analyze", str(plain), "--json"]) == 0
    assert "flywheel" not in json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("value", ["0", "-0.1", "2", "\"much\""])
def test_a_bad_speed_fluctuation_is_one_line_naming_the_key(tmp_path, capsys, value):
    from balancer.cli import main

    text = (EXAMPLES / "pb1.toml").read_text()
    spec = tmp_path / "bad.toml"
    spec.write_text(text.replace("[operation]\n", f"[operation]\nspeed_fluctuation = {value}\n", 1))
    assert main(["analyze", str(spec)]) == 2
    err = capsys.readouterr().err.strip()
    assert "operation.speed_fluctuation" in err and len(err.splitlines()) == 1


def test_the_bracketed_root_is_the_roots_closed_form():
    """The Illinois method against closed forms: ∛2, a root at 0, a steep exponential."""
    from balancer.errors import SolverError
    from balancer.speed_fluctuation import bracketed_root

    assert bracketed_root(lambda x: x**3 - 2.0, 0.0, 2.0) == pytest.approx(2 ** (1 / 3),
                                                                            rel=1e-13)
    assert abs(bracketed_root(lambda x: math.sin(x), -1.0, 2.0)) <= 1e-13
    assert bracketed_root(lambda x: math.exp(40 * x) - 3.0, -1.0, 1.0) == pytest.approx(
        math.log(3.0) / 40, rel=1e-12)
    with pytest.raises(SolverError):
        bracketed_root(lambda x: x * x + 1.0, -1.0, 1.0)


def test_a_mechanism_too_slow_to_run_alone_gets_the_flywheel_it_needs(tmp_path, capsys):
    """The fuzz campaign's: at 0.1 rad/s the single cylinder alone stops within its cycle (its
    gas work swings more than its kinetic energy): the least flywheel still, the mechanism's
    own fluctuation none (JSON null); at 0.5 rad/s a finite one, both as the energy balance
    says; a linkage with several inputs refuses the key, naming it."""
    import json

    from balancer.cli import main

    text = (EXAMPLES / "single_cylinder.toml").read_text()
    for speed, alone in (("0.1", None), ("0.5", 1252.0)):
        spec = tmp_path / f"slow{speed}.toml"
        spec.write_text("\n".join(
            f"speed = {speed}" if line.startswith("speed = ") else line
            for line in text.splitlines()))
        assert main(["analyze", str(spec), "--json"]) == 0
        doc = json.loads(capsys.readouterr().out)["flywheel"]
        if alone is None:
            assert doc["fluctuation_without"] is None
        else:
            assert doc["fluctuation_without"] == pytest.approx(alone, rel=1e-3)
        design = load_design(spec)
        mech = mechanism_of(design.mechanism)
        energy = CrankEnergy.of(mech, sample_angles(720, 2), 4 * math.pi)
        omega = speeds(energy, doc["inertia"], design.operation.speed)
        assert fluctuation_of(omega) == pytest.approx(0.02, rel=1e-9)
    five = (EXAMPLES / "fivebar_5r.toml").read_text()
    spec = tmp_path / "five.toml"
    spec.write_text(five.replace("[operation]\n", "[operation]\nspeed_fluctuation = 0.02\n", 1)
                    if "[operation]\n" in five else five + "\n[operation]\nspeed = 1.0\n"
                    "speed_fluctuation = 0.02\n")
    assert main(["analyze", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "operation.speed_fluctuation" in err[0]
