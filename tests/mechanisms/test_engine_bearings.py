"""An engine's main-bearing loads (mechanisms/engine/bearings.py), each by a second route.

- Their sum is the main bearings' summed reaction ``O`` of the core's inverse dynamics (the
  crankshaft's Newton equation), gas and weights included.
- Each cylinder's share is the lever rule applied to what that cylinder alone puts on its main
  bearings: a one-cylinder engine of it, its crankshaft without mass, whose reaction at ``O``
  the core computes on another linkage (no chain momentum, no guide force read back).
- The lever rule's shares in closed form; the outputs (text, JSON, CSV) carry them; the key is
  read back as written and refused when bad.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balancer.cli import main
from balancer.cycle import cycle_analysis, sample_angles
from balancer.errors import SpecError
from balancer.linkage.rotors import Rotor
from balancer.mechanisms import mechanism_of
from balancer.mechanisms.engine.bearings import lever_shares
from balancer.mechanisms.engine.model import Crankshaft
from balancer.spec import dumps_design, load_design, loads_design

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def with_bearings(name: str, gravity: tuple[float, float] = (0.0, 0.0)):
    """A shipped engine with a main bearing between each two cylinders' planes and at each end."""
    design = load_design(EXAMPLES / name)
    zs = sorted({c.z for c in design.mechanism.cylinders})
    planes = (zs[0] - 0.04, *((a + b) / 2 for a, b in zip(zs, zs[1:], strict=False)),
              zs[-1] + 0.04)
    engine = replace(design.mechanism, main_bearings=planes)
    op = replace(design.operation, gravity=gravity)
    return replace(design, mechanism=engine, operation=op)


@pytest.mark.parametrize("name", ["inline_four.toml", "v8.toml", "v6.toml",
                                  "single_cylinder.toml"])
@pytest.mark.parametrize("gravity", [(0.0, 0.0), (0.0, -9.81)])
def test_the_bearings_carry_the_summed_reaction_between_them(name, gravity):
    design = with_bearings(name, gravity)
    a = cycle_analysis(design.mechanism, design.operation.speed, 360, gravity=gravity)
    assert [s.name for s in a.supports] == [f"B{j + 1}"
                                             for j in range(len(design.mechanism.main_bearings))]
    total = sum(s.force for s in a.supports)
    o = a.reactions.ground["O"]
    assert np.max(np.abs(total - o)) <= 1e-12 * np.max(np.abs(o))


@pytest.mark.parametrize("name", ["v8.toml", "inline_four.toml"])
def test_each_cylinders_share_is_the_lever_rule_on_its_one_cylinder_engines_reaction(name):
    """No gas (a one-cylinder engine would fire elsewhere), gravity on."""
    g = (0.0, -9.81)
    design = with_bearings(name, g)
    engine = replace(design.mechanism, gas=None)
    speed = design.operation.speed
    theta = sample_angles(90, 2)
    planes = engine.main_bearings
    want = [np.zeros(theta.size, complex) for _ in planes]
    bare = Crankshaft(inertia=engine.crankshaft.inertia)  # no mass, no masses
    for c in engine.cylinders:
        one = replace(engine, cylinders=(c,), crankshaft=bare, balance_shafts=(),
                      firing_order=None, main_bearings=())
        f = mechanism_of(one).crank_forces(theta, speed, 0.0, gravity=g)
        for j, share in lever_shares(planes, c.z):
            want[j] += share * f.reactions["O"].complex()[:, 0]
    shaft = engine.crankshaft
    for j, share in lever_shares(planes, 0.0):  # the crankshaft's weight, on its axis at z = 0
        want[j] += share * shaft.mass * complex(*g)
    for m in shaft.masses:
        single = Rotor(ratio=1.0, inertia=0.0, eccentrics=(m.eccentric,))
        for j, share in lever_shares(planes, m.z):
            want[j] += share * single.loads(theta, speed, 0.0, g).force
    got = cycle_analysis(engine, speed, theta1=theta, gravity=g).supports
    scale = max(float(np.max(np.abs(w))) for w in want)
    for s, w in zip(got, want, strict=True):
        assert np.max(np.abs(s.force - w)) <= 1e-11 * scale


@pytest.mark.parametrize(("z", "want"), [
    (0.1, ((0, 0.5), (1, 0.5))), (0.0, ((0, 1.0), (1, 0.0))), (0.2, ((1, 1.0), (2, 0.0))),
    (0.25, ((1, 0.75), (2, 0.25))), (0.4, ((1, 0.0), (2, 1.0))),
    (-0.1, ((0, 1.5), (1, -0.5))), (0.5, ((1, -0.5), (2, 1.5)))])
def test_the_lever_rules_shares(z, want):
    """Bearings at 0, 0.2, 0.4 m: inside a bay by its distances; beyond an end, the end bay's
    (the far bearing pulled the other way); the shares' moment about the load is zero."""
    planes = (0.0, 0.2, 0.4)
    got = lever_shares(planes, z)
    assert [j for j, _ in got] == [j for j, _ in want]
    assert [s for _, s in got] == pytest.approx([s for _, s in want], abs=1e-15)
    assert sum(s * (planes[j] - z) for j, s in got) == pytest.approx(0.0, abs=1e-15)


def test_analyze_gives_each_main_bearing_in_its_text_json_and_csv(tmp_path, capsys):
    spec = EXAMPLES / "inline_four.toml"  # (five main bearings)
    design = load_design(spec)
    a = cycle_analysis(design.mechanism, design.operation.speed, design.operation.samples)
    assert main(["analyze", str(spec), "--json", "--csv", str(tmp_path / "four.csv")]) == 0
    doc = json.loads(capsys.readouterr().out)
    bearings = doc["main_bearings"]
    assert [b["name"] for b in bearings] == ["B1", "B2", "B3", "B4", "B5"]
    for b, s in zip(bearings, a.supports, strict=True):
        assert b["z"] == s.z
        assert b["rms"] == pytest.approx(math.sqrt(np.mean(np.abs(s.force) ** 2)), rel=1e-12)
        assert b["max"] == pytest.approx(np.max(np.abs(s.force)), rel=1e-12)
        first = next(o for o in b["orders"] if o["order"] == 1)
        # order 1 of a two-revolution cycle: its DFT bin 2, forward and backward parts
        c = np.fft.fft(s.force) / s.force.size
        assert first["forward"] == pytest.approx(abs(c[2]), rel=1e-9, abs=1e-9 * b["max"])
        assert first["backward"] == pytest.approx(abs(c[-2]), rel=1e-9, abs=1e-9 * b["max"])
    table = np.genfromtxt(tmp_path / "four.csv", delimiter=",", names=True)
    for s in a.supports:
        np.testing.assert_allclose(table[f"R{s.name}x"], s.force.real, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(table[f"R{s.name}y"], s.force.imag, rtol=1e-12, atol=1e-9)
    assert main(["analyze", str(spec)]) == 0
    out = capsys.readouterr().out
    assert "main bearing (N)" in out and "\nB5 " in out
    again = loads_design(dumps_design(design))
    assert again.mechanism.main_bearings == design.mechanism.main_bearings


def test_an_engine_without_main_bearings_has_none():
    design = load_design(EXAMPLES / "v8.toml")
    a = cycle_analysis(design.mechanism, design.operation.speed, 72)
    assert a.supports == ()
    assert "RB1x" not in a.columns()[0]


@pytest.mark.parametrize("value", ["[0.1]", "[0.2, 0.1]", "[0.0, 0.0]", "\"front\"",
                                   "[0.0, nan]"])
def test_bad_main_bearings_are_one_line_naming_the_key(tmp_path, capsys, value):
    text = (EXAMPLES / "v8.toml").read_text()
    spec = tmp_path / "bad.toml"
    spec.write_text(text.replace("[mechanism]\n", f"[mechanism]\nmain_bearings = {value}\n", 1))
    assert main(["analyze", str(spec)]) == 2
    err = capsys.readouterr().err.strip()
    assert "mechanism.main_bearings" in err and len(err.splitlines()) == 1


def test_a_model_refuses_main_bearings_out_of_order():
    engine = load_design(EXAMPLES / "v8.toml").mechanism
    with pytest.raises(SpecError, match="increasing"):
        replace(engine, main_bearings=(0.1, -0.1))


@pytest.mark.parametrize(("old", "new", "key"), [
    ("z = -0.1365", "z = -1e300", "mechanism.cylinders[1].z"),
    ("main_bearings = [-0.182, -0.091, 0.0, 0.091, 0.182]",
     "main_bearings = [-1e300, -0.091, 0.0, 0.091, 0.182]", "mechanism.main_bearings[1]"),
    ("crank = 0.043 ", "crank = 1e-9 ", "crank")])
def test_planes_and_cranks_beyond_what_can_be_computed_are_refused(tmp_path, capsys, old, new,
                                                                   key):
    """The fuzz campaign's: a plane of 1e300 m printed inf in the text (exit 0) and a crank of
    a nanometre named the linkage's hidden points; now each is refused naming its key."""
    text = (EXAMPLES / "inline_four.toml").read_text()
    assert old in text
    spec = tmp_path / "bad.toml"
    spec.write_text(text.replace(old, new, 1))
    assert main(["analyze", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and key in err[0], err


def test_a_cylinders_own_offset_that_stops_the_crank_is_named(tmp_path, capsys):
    """The fuzz campaign's: a cylinder's own offset too large for the common rod was named
    mechanism.lengths.rod; it is the cylinder's offset that stops its crank."""
    text = (EXAMPLES / "inline_four.toml").read_text()
    first = text.index("[[mechanism.cylinders]]")
    end = text.index("\n", text.index("bank_deg", first))
    spec = tmp_path / "offset.toml"
    spec.write_text(text[:end] + "\noffset = 0.12" + text[end:])
    assert main(["analyze", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "mechanism.cylinders[1].offset" in err[0] and "(got 0.12)" in err[0]
