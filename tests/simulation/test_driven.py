"""A driven crank's prescribed motion: the motor's work by quadrature, against the integrator.

A formulation whose state is the crank angle (``complex-masses``) has nothing to integrate when
a motor holds the crank at constant speed but the work of the motor (and of a gas force): the
simulation takes it by quadrature of the vectorised power (``driven_rates``) at the output
times. Here the vectorised power against the formulation's own scalar right-hand side, and the
quadrature's runs against the integrator's (the route it replaces, still taken where the power
is not vectorised or the motion nears a dead point).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import paper_linkage, random_linkage
from helpers import integration_bound
from test_slider_crank import random_slider_crank

from balancer import simulation
from balancer.errors import LockupError
from balancer.formulations import make
from balancer.mechanisms.fourbar.complex_masses import ComplexMasses
from balancer.mechanisms.slidercrank.formulations import SliderComplexMasses
from balancer.model import SimulationSettings


def _cases():
    cases = []
    for seed in range(6):
        rng = np.random.default_rng(700 + seed)
        cases.append((random_linkage(rng, full_turn=True), tuple(rng.uniform(-10, 10, 2))))
        cases.append((random_slider_crank(rng), tuple(rng.uniform(-10, 10, 2))))
    return cases


@pytest.mark.parametrize(("linkage", "gravity"), _cases())
def test_the_vectorised_power_is_the_right_hand_side(linkage, gravity):
    # Two routes through the same equations: the vectorised kinematics over arrays of angles
    # against the scalar ones of the integrator's right-hand side (four-bar: Eq. 2–10 on arrays
    # against position_scalar/rates_scalar; slider-crank: motion() against _transfer). Both
    # round to ε times the terms, magnified by the condition of the position analysis at the
    # angle (1/|sin μ|, μ the transmission angle, here ≥ 0.02): 1e-9 of the largest power.
    rng = np.random.default_rng(1)
    f = make("complex-masses", linkage, gravity=gravity, speed=rng.uniform(-20, 20))
    y0 = f.initial_state(rng.uniform(-math.pi, math.pi), 0.0)
    times = np.linspace(0.0, 3 * math.pi / abs(f.speed), 97)
    rates = f.driven_rates(times)
    keep = np.abs(rates.transmission) > 0.02
    scalar = np.array([f.rhs(t, y0) for t in times[keep]])
    extra = np.array([f.extra_power(t, y0) for t in times[keep]])
    transmission = np.array([f.transmission(t, y0) for t in times[keep]])
    scale = np.max(np.abs(scalar)) + np.max(np.abs(extra))
    assert rates.rates.shape == (times.size, 1)
    assert np.max(np.abs(rates.rates[keep] - scalar)) <= 1e-9 * scale
    assert np.max(np.abs(rates.extra_power[keep] - extra)) <= 1e-9 * scale
    assert np.max(np.abs(np.abs(rates.transmission[keep]) - np.abs(transmission))) < 1e-12
    assert keep.sum() > 48
    free = make("complex-masses", linkage, gravity=gravity)
    assert free.driven_rates(times) is None  # only a prescribed motion has them


def _stepped(monkeypatch, cls):
    """Make ``cls`` step its integrator for the motor's work, as before the quadrature."""
    monkeypatch.setattr(cls, "driven_rates", lambda self, times: None)


@pytest.mark.parametrize(("linkage", "gravity"), _cases()[:4])
def test_the_quadrature_takes_the_integrators_work(linkage, gravity, monkeypatch):
    # The same prescribed motion, its work by quadrature (panels) and by DOP853 (steps): each
    # within its steps·rtol of the truth relative to the energy (tests/helpers.py), so within the
    # sum of both of each other. The states at the output times are the same: the crank angle
    # is prescribed; the kinetic energy is computed from them alike.
    settings = SimulationSettings(duration=1.3, theta1=0.4, omega1=7.0, gravity=gravity,
                                  drive="constant-speed")
    quad = simulation.simulate(linkage, settings, method="complex-masses", rtol=1e-10,
                               atol=1e-12, outputs=77)
    _stepped(monkeypatch, type(make("complex-masses", linkage)))
    steps = simulation.simulate(linkage, settings, method="complex-masses", rtol=1e-10,
                                atol=1e-12, outputs=77)
    # Kronrod panels, 15 points each, at least one per PANEL_ANGLE of crank (the output times
    # fall inside them).
    least = math.ceil(7.0 * 1.3 / simulation.stepper.PANEL_ANGLE)
    assert quad.steps >= least and quad.nfev % 15 == 0 and quad.nfev >= 15 * quad.steps
    assert np.array_equal(quad.t, steps.t) and np.array_equal(quad.theta, steps.theta)
    assert np.array_equal(quad.kinetic_energy, steps.kinetic_energy)
    scale = max(np.max(np.abs(quad.kinetic_energy)), np.max(np.abs(quad.work)))
    assert np.max(np.abs(quad.work - steps.work)) <= integration_bound(quad, steps) * scale
    assert quad.energy_error < 2 * integration_bound(quad)  # T − T0 = W: the torque is right


def test_a_dead_point_ahead_is_left_to_the_integrators_event(monkeypatch):
    # The quadrature has no events: a prescribed motion that comes within the dead-point
    # threshold of a dead point is stepped, and stops there as before. Raising the threshold to
    # the middle of PB1's transmission range makes such a point of the paper's linkage.
    linkage = paper_linkage()
    f = make("complex-masses", linkage, speed=10.0)
    f.initial_state(0.0, 0.0)
    times = np.linspace(0, 2 * math.pi / 10, 721)
    sines = np.abs(f.driven_rates(times).transmission)
    threshold = 0.5 * (sines.min() + sines.max())
    for module in (simulation, simulation.stepper):  # where the runs read it
        monkeypatch.setattr(module, "DEAD_POINT_THRESHOLD", threshold)
    start = float(10 * times[np.argmax(sines)])  # from the best transmission onwards
    settings = SimulationSettings(duration=1.0, theta1=start, omega1=10.0,
                                  drive="constant-speed")
    with pytest.raises(LockupError) as quad:
        simulation.simulate(linkage, settings, method="complex-masses")
    for cls in (ComplexMasses, SliderComplexMasses):
        _stepped(monkeypatch, cls)
    with pytest.raises(LockupError) as steps:
        simulation.simulate(linkage, settings, method="complex-masses")
    assert quad.value.time == steps.value.time and 0 < quad.value.time < 1.0
    assert "dead point" in str(quad.value)


@pytest.mark.parametrize("method", ["complex-masses", "multibody"])
def test_outputs_resampled_to_a_resolution_are_those_asked_for(method):
    # A free motion whose crank turns farther than the resolution between the outputs asked
    # for gets more of them from the steps' dense outputs, without integrating again: the same
    # steps give the same states as a run asked for that many outputs from the start (to the
    # rounding of the projection's Newton steps, taken on differently stacked arrays).
    linkage = paper_linkage()
    settings = SimulationSettings(duration=2.0, theta1=1.0, omega1=6.0)
    resolution = 2 * math.pi / 90
    fine = simulation.simulate(linkage, settings, method=method, outputs=11,
                               resolution=resolution)
    assert fine.t.size > 11
    assert np.max(np.abs(np.diff(fine.theta[0]))) <= resolution * (1 + 1e-9)
    asked = simulation.simulate(linkage, settings, method=method, outputs=fine.t.size)
    assert fine.steps == asked.steps
    assert np.array_equal(fine.t, asked.t)
    for mine, theirs in ((fine.theta, asked.theta), (fine.omega, asked.omega),
                         (fine.alpha, asked.alpha)):
        assert np.max(np.abs(mine - theirs)) <= 1e-13 * max(1.0, np.max(np.abs(theirs)))
    # Driven, the number follows from the speed at once.
    driven = simulation.simulate(linkage, settings, method=method, drive="constant-speed",
                                 outputs=11, resolution=resolution)
    assert driven.t.size == math.ceil(6.0 * 2.0 / resolution) + 1


@pytest.mark.parametrize("example", ["watt_sixbar", "jansen_leg", "stephenson_sixbar",
                                     "quick_return"])
def test_a_driven_multibody_run_is_its_prescribed_motion(example, monkeypatch):
    # The multibody formulation driven at constant speed: its states from the mechanism's
    # position and rate analysis at the prescribed crank angles, the motor's work by
    # quadrature of its own driving torque (the driver's multiplier) — against the same run
    # stepped as a DAE by DOP853 (projected onto the constraints after every step). The
    # states agree to the stepped run's global error (steps·rtol, tests/helpers.py, relative to
    # each quantity's scale), the work likewise; the prescribed states are on the constraints
    # to the position analysis' Newton tolerance (1e-13 of the length scale) and hold the
    # energy balance T − T0 = W to the quadrature's tolerance, a check of the torque against
    # the kinetic energy of the states.
    from pathlib import Path

    from balancer.formulations.multibody import Multibody
    from balancer.spec import load_design

    design = load_design(Path(simulation.__file__).parents[1] / "examples" / f"{example}.toml")
    settings = replace_settings(design, duration=min(design.simulation.duration, 1.0))
    quad = simulation.simulate(design.mechanism, settings, method="multibody", rtol=1e-10,
                               atol=1e-12)
    monkeypatch.setattr(Multibody, "driven_motion", lambda self, times, start: None)
    steps = simulation.simulate(design.mechanism, settings, method="multibody", rtol=1e-10,
                                atol=1e-12)
    assert np.array_equal(quad.t, steps.t)
    bound = integration_bound(steps) + 1e-12
    for name in ("theta", "omega", "alpha", "driving_torque", "shaking_force",
                 "shaking_moment", "work", "kinetic_energy"):
        a, b = np.asarray(getattr(quad, name)), np.asarray(getattr(steps, name))
        scale = max(np.max(np.abs(b)), 1.0 if name == "theta" else 0.0, 1e-300)
        assert np.max(np.abs(a - b)) <= 2 * bound * scale, name
    scale = mechanism_scale(design)
    assert quad.drift[0] <= 1e-13 * scale and quad.drift[1] <= 1e-12 * scale * abs(
        settings.omega1)
    assert quad.energy_error <= 2 * quad.steps * quad.rtol
    assert quad.steps < steps.steps  # panels of PANEL_ANGLE at most, not steps


def replace_settings(design, **changes):
    from dataclasses import replace

    return replace(design.simulation, drive="constant-speed", omega1=design.operation.speed,
                   **changes)


def mechanism_scale(design) -> float:
    from balancer.mechanisms import mechanism_of

    return mechanism_of(design.mechanism).structure.length_scale()


@pytest.mark.parametrize("example", ["watt_sixbar", "stephenson_sixbar", "engine"])
def test_the_crank_angle_formulation_driven_is_a_function_of_time(example, monkeypatch):
    # A driven crank-angle formulation is time-only (its state: θ1, θ̇1 and the motor's work):
    # its right-hand side depends on the time alone (it read the state's θ1, which the
    # time-only integrator holds at a step's start for all its stages: a 5 % energy error on
    # the engine's gas force), and its vectorised rates (the compiled equation mapped over
    # the times) are the single calls' numbers exactly. Its quadrature run agrees with the
    # stepped one to the stepped run's error (steps·rtol of the work's scale).
    from pathlib import Path

    from balancer.formulations.crank_angle import CrankAngle
    from balancer.spec import load_design

    design = load_design(Path(simulation.__file__).parents[1] / "examples" / f"{example}.toml")
    f = make("crank-angle", design.mechanism, speed=design.operation.speed)
    f.initial_state(0.4, 0.0)
    times = np.linspace(0.0, 4 * math.pi / abs(f.speed), 61)
    rates = f.driven_rates(times)
    states = [np.array([f.crank_angle(t), f.speed, 0.0]) for t in times]
    assert np.array_equal(rates.rates, np.array([f.rhs(t, y) for t, y in zip(times, states,
                                                                                strict=True)]))
    assert np.array_equal(rates.extra_power, [f.extra_power(t, y)
                                              for t, y in zip(times, states, strict=True)])
    elsewhere = np.array([7.0, -3.0, 11.0])  # any state: only the time counts
    assert np.array_equal(rates.rates, np.array([f.rhs(t, elsewhere) for t in times]))
    settings = replace_settings(design, duration=min(design.simulation.duration, 0.3))
    quad = simulation.simulate(design.mechanism, settings, method="crank-angle")
    monkeypatch.setattr(CrankAngle, "driven_rates", lambda self, times: None)
    steps = simulation.simulate(design.mechanism, settings, method="crank-angle")
    scale = max(np.max(np.abs(steps.work)), np.max(np.abs(steps.kinetic_energy)))
    assert np.max(np.abs(quad.work - steps.work)) <= (integration_bound(quad, steps)
                                                      + 1e-12) * scale
    assert quad.energy_error <= 2 * quad.steps * quad.rtol


@pytest.mark.parametrize("example", ["watt_sixbar", "stephenson_sixbar"])
@pytest.mark.parametrize("method", ["crank-angle", "multibody"])
@pytest.mark.parametrize("drive", ["free", "constant-speed"])
@pytest.mark.slow
def test_general_linkages_count_the_turns_between_coarse_outputs(example, method, drive):
    # Three output times over a run in which the crank turns several times: the links'
    # angles are followed through the states between them (the steps' ends; a prescribed
    # motion's crank grid, whose states — a carried crank angle among them — the quadrature
    # gives at those times too). The same run with dense outputs is the reference.
    from dataclasses import replace
    from pathlib import Path

    from balancer.spec import load_design

    design = load_design(Path(simulation.__file__).parents[1] / "examples" / f"{example}.toml")
    settings = replace(design.simulation, drive=drive, omega1=2 * design.operation.speed,
                       duration=2.0)
    fine = simulation.simulate(design.mechanism, settings, method=method, outputs=2001)
    coarse = simulation.simulate(design.mechanism, settings, method=method, outputs=3)
    assert np.max(np.abs(coarse.theta[:, -1] - fine.theta[:, -1])) < 1e-6
    assert np.max(np.abs(fine.theta[:, -1] - fine.theta[:, 0])) > 4 * np.pi
