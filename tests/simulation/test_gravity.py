"""Gravity in the cycle analysis (``[operation] gravity``, ``analyze --gravity``).

The frame carries the weights: with gravity ``g`` the shaking force gains the total weight
``m_tot·g`` and the shaking moment the weight's moment about the origin (A0),
``m_tot·(x_c·gy − y_c·gx)`` with ``(x_c, y_c)`` the total centre of mass. The weights are
linear in ``g`` and independent of the speed, so at every sample and any speed the figures with
gravity minus those without are exactly those two terms; at rest (speed 0, no loads) they are
all there is. Routes checked: the centre of mass by hand (the four-bar's pose by circle
intersection, written here), a driven simulation with gravity (another formulation), the spec
and the command line.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import paper_linkage
from helpers import ROUNDING, derivative_with_error

from balancer import spec
from balancer.api import analyze
from balancer.cli import main
from balancer.cycle import cycle_analysis
from balancer.errors import SpecError
from balancer.model import SimulationSettings
from balancer.simulation import simulate

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
G = (0.7, -9.81)


def _fourbar_com(linkage, theta1):
    """Total centre of mass of a four-bar (complex, m) and its mass, written out by hand.

    A2 by intersecting the circles about A1 (radius l2) and A3 (radius l3), on the spec's branch
    ("+" puts A2 left of the directed line A1→A3).
    """
    l1, l2, l3, l4 = linkage.lengths
    a1 = l1 * np.exp(1j * theta1)
    a3 = complex(l4, 0.0)
    d = a3 - a1
    dist = np.abs(d)
    along = (dist**2 + l2**2 - l3**2) / (2 * dist)
    across = np.sqrt(l2**2 - along**2)
    sign = 1.0 if linkage.branch == "+" else -1.0
    a2 = a1 + (d / dist) * (along + sign * 1j * across)
    th = [theta1, np.angle(a2 - a1), np.angle(a3 - a2)]
    starts = [0.0, a1, a2]
    links = [linkage.crank, linkage.coupler, linkage.rocker]
    total = sum(link.mass for link in links)
    com = sum(link.mass * (s + np.exp(1j * t) * complex(link.e, link.f))
              for link, s, t in zip(links, starts, th, strict=True)) / total
    return com, total


def _general_com(analysis):
    """Total centre of mass (complex, m) and mass from the analysis' link frames."""
    mech = analysis.mechanism
    pose = analysis.motion.pose
    total = sum(link.mass for link in mech.linkage.links)
    com = 0.0
    for k, link in enumerate(mech.linkage.links):
        origin = pose.origins[k].x + 1j * pose.origins[k].y
        com = com + link.mass * (origin + np.exp(1j * pose.angles[k]) * complex(link.e, link.f))
    return com / total, total


def _weight_terms(com, total, g):
    force = total * complex(*g) * np.ones_like(com)
    moment = total * (com.real * g[1] - com.imag * g[0])
    return force, moment


def _scale(*analyses) -> float:
    """The magnitude of the terms the figures are computed from, N (N·m per m of reach)."""
    return max(float(np.max(np.abs(x))) for a in analyses
               for x in (a.reactions.shaking_force, a.reactions.driving_torque,
                         *a.reactions.ground.values()))


def test_at_rest_the_frame_carries_the_total_weight_and_its_moment():
    linkage = paper_linkage(loads=False)
    a = cycle_analysis(linkage, 0.0, 72, loads=False, gravity=G)
    com, total = _fourbar_com(linkage, a.theta1)
    force, moment = _weight_terms(com, total, G)
    weight = total * math.hypot(*G)
    # Statics: rounding over terms of the weight's size (moments: times the reach, ~ 5 m);
    # the reactions come through 1/sin(θ3 − θ2) ≤ 1/0.7 on the paper's revolution.
    reach = sum(linkage.lengths)
    tol = ROUNDING * weight / 0.7
    assert np.max(np.abs(a.reactions.shaking_force - force)) < tol
    assert np.max(np.abs(a.reactions.shaking_moment - moment)) < tol * reach
    # The motor holds the linkage against its weights: by virtual work τ = dV/dθ1 with
    # V = −m_tot·(g·r_c), differentiated numerically from the centre of mass by hand.
    def potential(t):
        c, m = _fourbar_com(linkage, np.atleast_1d(t))
        return -m * (G[0] * c.real + G[1] * c.imag)

    for theta, tau in zip(a.theta1[::6], a.reactions.driving_torque[::6], strict=True):
        dv, err = derivative_with_error(potential, theta, h=1e-3, scale=weight * reach)
        assert abs(tau - dv[0]) < err + tol * reach


@pytest.mark.parametrize("speed", [10.0, -37.0])
def test_gravity_adds_the_weights_at_speed_four_bar(speed):
    linkage = paper_linkage()
    without = cycle_analysis(linkage, speed, 90)
    with_g = cycle_analysis(linkage, speed, 90, gravity=G)
    com, total = _fourbar_com(linkage, with_g.theta1)
    force, moment = _weight_terms(com, total, G)
    reach = sum(linkage.lengths)
    tol = ROUNDING * _scale(without, with_g) / 0.7
    df = with_g.reactions.shaking_force - without.reactions.shaking_force
    dm = with_g.reactions.shaking_moment - without.reactions.shaking_moment
    assert np.max(np.abs(df - force)) < tol
    assert np.max(np.abs(dm - moment)) < tol * reach
    assert with_g.gravity == G


@pytest.mark.parametrize("name", ["engine.toml", "watt_sixbar.toml"])
def test_gravity_adds_the_weights_at_speed_slider_crank_and_linkage(name):
    design = spec.load_design(EXAMPLES / name)
    without = analyze(design)
    with_g = analyze(design, gravity=G)
    com, total = _general_com(with_g)
    force, moment = _weight_terms(com, total, G)
    mech = with_g.mechanism
    reach = mech.structure.length_scale() * len(mech.linkage.links)
    # The difference of two evaluations, each within rounding of its terms; the position
    # analysis' condition on these well-conditioned revolutions is of order 10.
    tol = 10 * ROUNDING * _scale(without, with_g)
    df = with_g.reactions.shaking_force - without.reactions.shaking_force
    dm = with_g.reactions.shaking_moment - without.reactions.shaking_moment
    assert np.max(np.abs(df - force)) < tol
    assert np.max(np.abs(dm - moment)) < tol * reach


def test_cycle_with_gravity_agrees_with_a_driven_simulation():
    # The driven constant-speed run with gravity in the opened-loop formulation (the paper's
    # principal vectors), against the cycle analysis (Newton-Euler) at the run's own angles.
    linkage = paper_linkage()
    speed = 10.0
    settings = SimulationSettings(duration=0.6, theta1=0.0, omega1=speed, gravity=(0.0, -9.81),
                                  drive="constant-speed", outputs=31)
    traj = simulate(linkage, settings, method="opened-loop")
    assert np.allclose(traj.omega[0], speed, rtol=1e-12)
    a = cycle_analysis(linkage, speed, gravity=(0.0, -9.81), theta1=traj.theta[0])
    # Two formulations at the same states: 1e-9 relative (DESIGN.md).
    for mine, theirs in ((a.reactions.shaking_force, traj.shaking_force),
                         (a.reactions.shaking_moment, traj.shaking_moment),
                         (a.reactions.driving_torque, traj.driving_torque),
                         (a.reactions.ground["A0"], traj.ground["A0"]),
                         (a.reactions.ground["A3"], traj.ground["A3"])):
        scale = float(np.max(np.abs(theirs)))
        assert np.max(np.abs(mine - theirs)) < 1e-9 * scale


def test_spec_gravity_round_trips_and_is_what_analyze_uses(tmp_path):
    text = (EXAMPLES / "meijaard2020.toml").read_text().replace(
        "samples = 360", "samples = 360\ngravity = [0.7, -9.81]")
    design = spec.loads_design(text)
    assert design.operation.gravity == G
    again = spec.loads_design(spec.dumps_design(design))
    assert again == design
    from_spec = analyze(design)
    given = analyze(spec.loads_design((EXAMPLES / "meijaard2020.toml").read_text()), gravity=G)
    assert np.array_equal(from_spec.reactions.shaking_moment, given.reactions.shaking_moment)
    # The override wins over the spec's; (0, 0) is none.
    none = analyze(design, gravity=(0.0, 0.0))
    assert none.gravity == (0.0, 0.0)
    # No gravity in the spec: nothing written for it.
    plain = spec.load_design(EXAMPLES / "meijaard2020.toml")
    assert "gravity" not in spec.dumps_design(plain).split("[operation]")[1].split("[")[0]


@pytest.mark.parametrize("value", ["[0.0]", "[0.0, nan]", "[0.0, inf]", '["a", 1.0]', "9.81",
                                   "[1, 2, 3]", "[true, 1.0]"])
def test_bad_spec_gravity_is_bad_input_naming_the_key(tmp_path, capsys, value):
    text = (EXAMPLES / "meijaard2020.toml").read_text().replace(
        "samples = 360", f"samples = 360\ngravity = {value}")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(SpecError) as info:
        spec.load_design(path)
    assert info.value.key.startswith("operation.gravity")
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "operation.gravity" in err and str(path) in err


def test_cli_gravity_overrides_the_spec_and_is_reported(capsys):
    example = str(EXAMPLES / "meijaard2020.toml")
    assert main(["analyze", example, "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert plain["gravity"] == [0.0, 0.0]
    assert main(["analyze", example, "--json", "--gravity=0.7,-9.81"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["gravity"] == list(G)
    design = spec.load_design(example)
    a = analyze(design, gravity=G)
    assert doc["shaking_moment"]["max"] == pytest.approx(a.summary.shaking_moment.max, rel=1e-15)
    assert doc["shaking_force"]["rms"] == pytest.approx(a.summary.shaking_force.rms, rel=1e-15)
    assert doc["shaking_moment"]["max"] != plain["shaking_moment"]["max"]
    assert main(["analyze", example, "--gravity", "0,-9.81"]) == 0
    assert "gravity (0, -9.81) m/s² included" in capsys.readouterr().out


@pytest.mark.parametrize("value", ["0", "0,x", "0,nan", "inf,0", "1,2,3", ""])
def test_bad_cli_gravity_is_bad_input_naming_the_option(capsys, value):
    assert main(["analyze", str(EXAMPLES / "meijaard2020.toml"), f"--gravity={value}"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--gravity" in err and repr(value) in err


def test_gravity_beyond_double_precision_names_the_option(capsys):
    assert main(["analyze", str(EXAMPLES / "meijaard2020.toml"), "--gravity=0,-1e300"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--gravity" in err
