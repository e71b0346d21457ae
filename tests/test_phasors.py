"""Phasors (balancer/phasors.py and plots/phasors.py), each by a second route.

- Summed over the planes, the phasors are the cycle analysis's shaking force and rocking couple
  at that order (their Fourier coefficients, with phase), which the inverse dynamics computes.
- A single upright cylinder's primary, in closed form: the crank pin's share turning with the
  crank, ``m_rot·r·ω²``, and the reciprocating mass's ``½·m_rec·r·ω²`` each way (the exact
  piston motion's first harmonic is ``r·cos(θ − β)``: the rod's root has only even ones).
- The figure has a panel per order and load; the command writes it and refuses what it cannot.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer import phasors_figure
from balancer.cli import main
from balancer.cycle import cycle_analysis
from balancer.errors import SpecError
from balancer.mechanisms import mechanism_of
from balancer.phasors import phasors
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("name", ["v8.toml", "inline_three_to_balance.toml", "inline_four.toml",
                                  "single_cylinder.toml", "pb1.toml", "quick_return.toml"])
def test_the_planes_phasors_sum_to_the_cycle_analysis_orders(name):
    design = load_design(EXAMPLES / name)
    speed = design.operation.speed
    mech = mechanism_of(design.mechanism)
    p = phasors(mech, speed, (1, 2, 3, 4))
    a = cycle_analysis(design.mechanism, speed, 720, loads=False)
    theta, r = a.theta1, a.reactions
    # (the scale: the planes' largest phasors at any order, a couple's times its arm)
    reach = max(sum(abs(x) for plane in p.planes for x in plane.force[n]) for n in p.orders)
    scale = reach * max(1.0, max(abs(plane.z) for plane in p.planes))
    for n in p.orders:
        for total, load in ((p.total_force(n), r.shaking_force),
                            (p.total_couple(n), r.rocking_couple)):
            want = (np.mean(load * np.exp(-1j * n * theta)), np.mean(load * np.exp(1j * n * theta)))
            assert abs(total[0] - want[0]) <= 1e-12 * scale
            assert abs(total[1] - want[1]) <= 1e-12 * scale
    # (in one plane: no link's nor eccentric's mass off the crank's plane, read off the model)
    planar = (all(link.z == 0 for link in design.mechanism.links)
              and all(e.z == 0 for _, rotor in mech.rotors for e in rotor.eccentrics))
    assert p.in_one_plane == planar


def test_a_single_upright_cylinders_primary_in_closed_form():
    design = load_design(EXAMPLES / "single_cylinder.toml")
    engine = design.mechanism
    c = engine.cylinders[0]
    engine = replace(engine, crankshaft=replace(engine.crankshaft, masses=()),
                     cylinders=(replace(c, phase_deg=0.0, bank_deg=90.0, offset=0.0),))
    speed = 600.0
    p = phasors(mechanism_of(engine), speed, (1,))
    rod = engine.rod
    share = rod.e / c.rod
    m_rec = engine.piston + rod.mass * share
    m_rot = rod.mass * (1 - share)
    forward, backward = p.total_force(1)
    rw2 = c.crank * speed**2
    # the piston's first harmonic r·cos(θ − β) along u = e^{iβ}: forward ½·m_rec·r·ω² whatever
    # the bank β, backward ½·m_rec·r·ω²·e^{2iβ} (β = 90°: −½)
    assert forward == pytest.approx((m_rot + 0.5 * m_rec) * rw2, rel=1e-12)
    assert backward == pytest.approx(-0.5 * m_rec * rw2, rel=1e-12)


@pytest.mark.slow
def test_the_figure_has_a_panel_per_order_and_load(tmp_path, capsys):
    design = load_design(EXAMPLES / "inline_three_to_balance.toml")
    fig = phasors_figure(phasors(mechanism_of(design.mechanism), design.operation.speed))
    assert len(fig.axes) == 4  # orders 1, 2; force and couple
    planar = load_design(EXAMPLES / "pb1.toml")
    assert len(phasors_figure(phasors(mechanism_of(planar.mechanism),
                                      planar.operation.speed)).axes) == 2
    out = tmp_path / "ph.png"
    assert main(["plot", str(EXAMPLES / "v8.toml"), "--phasors", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    assert main(["plot", str(EXAMPLES / "fivebar_5r.toml"), "--phasors",
                 str(tmp_path / "five.png")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "mechanism.inputs" in err[0]
    assert not (tmp_path / "five.png").exists()


@pytest.mark.parametrize("orders", [(0,), (1, 2.5), (400,)])
def test_an_order_that_is_not_a_whole_number_from_one_is_refused(orders):
    design = load_design(EXAMPLES / "v8.toml")
    with pytest.raises(SpecError, match="whole numbers"):
        phasors(mechanism_of(design.mechanism), 100.0, orders)


def test_a_plane_is_what_moves_in_it():
    design = load_design(EXAMPLES / "inline_four.toml")
    p = phasors(mechanism_of(design.mechanism), design.operation.speed)
    z = {round(plane.z, 9): plane.what for plane in p.planes}
    assert set(z[round(-0.1365, 9)]) == {"rod1", "piston1", "O mass"}
    assert z[round(-0.1635, 9)] == ("O mass",)  # a web's counterweight alone
    assert math.isclose(sorted(z)[0], -0.1635)
    assert all(any(plane.force[n] != (0, 0) for n in p.orders) for plane in p.planes)
