"""What the designer reads: counterweight rows, objective units, what got worse, plain words.

Each figure a report adds is checked by a route of its own: the total centre of mass' excursion
from the four-bar's closed-form positions written here, the largest ground load from
``analyze``'s per-point extremes, the counterweights by composing bodies, the objective's RMS
from the weights and ``J``.
"""

from __future__ import annotations

import cmath
import json
import math
import re
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from balancer.api import analyze
from balancer.balance.counterweights import UNCHANGED, counterweight
from balancer.balance.optimizer import optimize
from balancer.cli import main
from balancer.report import counterweight_text, optimization_json, optimization_text, worse_figures
from balancer.spec import load_design, loads_design

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


@dataclass(frozen=True)
class Body:
    mass: float
    e: float
    f: float
    inertia: float


# ---------------------------------------------------------------------------------------------
# Counterweight rows


def test_a_rounding_difference_is_no_body():
    """A balanced crank of 0.40000000000040004 kg against 0.4 kg (the designer's case) is
    unchanged: its differences are far inside UNCHANGED of the link's scales."""
    original = Body(0.4, -0.05, 0.0, 0.002)
    balanced = Body(0.40000000000040004, -0.05 * (1 + 3e-12), 2e-15, 0.002 * (1 + 1e-12))
    w = counterweight("crank", original, balanced)
    assert w.kind == "none"
    doc = w.as_dict()
    assert doc["mass"] == 0 and doc["inertia"] == 0
    assert doc["e"] is None and doc["f"] is None


def test_a_difference_above_the_threshold_is_a_body():
    original = Body(0.4, -0.05, 0.0, 0.002)
    balanced = Body(0.4 * (1 + 1e-6), -0.05, 0.0, 0.002)
    assert counterweight("crank", original, balanced).kind != "none"
    assert UNCHANGED <= 1e-8  # far below any change a designer builds


def test_a_first_moment_moved_at_constant_mass_is_a_link_to_rebuild_with_the_difference_beside():
    original, balanced = Body(2.0, 0.4, 0.0, 0.5), Body(2.0, 0.6, 0.1, 0.5)
    w = counterweight("rocker", original, balanced)
    doc = w.as_dict()
    # What JSON gives to build is the new link itself, as the text does: every figure physical.
    assert w.kind == "rebuild" and w.rebuilt == (2.0, 0.6, 0.1, 0.5)
    assert (doc["mass"], doc["e"], doc["f"], doc["inertia"]) == w.rebuilt
    # The difference beside it: original + change = balanced, first moment and inertia about
    # the link frame's origin (a few rounding units of the terms).
    change = doc["change"]
    assert change["mass"] == 0.0
    moment = complex(*change["first_moment"])
    assert moment == pytest.approx(2.0 * complex(0.6, 0.1) - 2.0 * 0.4, rel=1e-14)
    assert complex(*doc["first_moment"]) == moment
    j0 = 0.5 + 2.0 * 0.4**2
    j1 = 0.5 + 2.0 * abs(complex(0.6, 0.1)) ** 2
    assert change["inertia"] == pytest.approx(j1 - j0, rel=1e-14)


def test_a_link_to_rebuild_whose_mass_barely_moves_is_given_as_the_new_link():
    """The Jansen leg's j, held 5e-7 off its mass bound while its centre moves: the difference
    body would be 2.7e-7 kg at half a kilometre with a negative inertia; JSON gives the new
    link (0.54 kg, its centre, its inertia), the change beside it."""
    original = Body(0.54, 0.25, 0.0, 0.01125)
    balanced = Body(0.54 * (1 + 5e-7), 0.4962, 0.0615, 0.0054)
    w = counterweight("j", original, balanced)
    doc = w.as_dict()
    assert w.kind == "rebuild"
    assert doc["mass"] == balanced.mass and doc["inertia"] == 0.0054 > 0
    assert (doc["e"], doc["f"]) == (0.4962, 0.0615)
    assert doc["change"]["mass"] == pytest.approx(0.54 * 5e-7, rel=1e-6)


def _rows(text: str) -> dict[str, list[str]]:
    """The counterweight table's rows by link: the cells after the name."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("counterweight "))
    out = {}
    for line in lines[start + 2:]:
        if not line or line.startswith("added mass"):
            break
        name = line.split()[0]
        out[name] = line
    return out


def test_rebuild_rows_give_the_new_link_never_a_negative_inertia():
    """PB2's balanced links are no single body added: the rows show each new link's own
    mass, centre of mass and inertia, which are the balanced spec's links."""
    design = load_design(EXAMPLES / "pb2.toml")
    result = optimize(design, "convex")
    text = counterweight_text(result.counterweights)
    rows = _rows(text)
    assert set(rows) == {"crank", "coupler", "rocker"}
    for name, line in rows.items():
        w = result.counterweights[name]
        assert w.kind == "rebuild"
        numbers = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?",
                                                 line.split("rebuild the link as", 1)[1])]
        mass, e_mm, f_mm, inertia = numbers[:4]
        link = result.linkage.link(name)
        assert mass == pytest.approx(link.mass, rel=1e-5)
        assert inertia == pytest.approx(link.inertia, rel=1e-5) and inertia > 0
        assert e_mm == pytest.approx(1e3 * link.e, rel=1e-5, abs=1e-6 * 1e3 * abs(link.e))
    assert "rebuild:" in text


def test_the_json_keeps_the_difference_of_every_row():
    """For every link, original + counterweight = the balanced link (mass, first moment,
    inertia about the frame's origin), from the JSON's own numbers."""
    for example in ("pb1", "pb2", "pb1_counterweights", "engine"):
        design = load_design(EXAMPLES / f"{example}.toml")
        result = optimize(design, "convex")
        doc = optimization_json(result, *result.operating)
        for name, w in doc["counterweights"].items():
            a, b = doc["original_links"][name], doc["links"][name]
            change = w["change"]
            scale_m = max(a["mass"], b["mass"])
            assert a["mass"] + change["mass"] == pytest.approx(b["mass"], abs=1e-9 * scale_m)
            s0, s1 = complex(a["e"], a["f"]), complex(b["e"], b["f"])
            reach = max(abs(s0), abs(s1), math.sqrt((a["inertia"] + b["inertia"]) / scale_m))
            moment = complex(*change["first_moment"])
            assert abs(a["mass"] * s0 + moment - b["mass"] * s1) <= 1e-9 * scale_m * reach
            j0 = a["inertia"] + a["mass"] * abs(s0) ** 2
            j1 = b["inertia"] + b["mass"] * abs(s1) ** 2
            assert abs(j0 + change["inertia"] - j1) <= 1e-9 * max(j0, j1)
            if w["kind"] == "rebuild":  # the new link itself
                assert (w["mass"], w["e"], w["f"], w["inertia"]) == (
                    b["mass"], b["e"], b["f"], b["inertia"])
            elif w["e"] is not None:  # the body added or removed
                assert w["mass"] == change["mass"]
                assert moment == pytest.approx(w["mass"] * complex(w["e"], w["f"]), rel=1e-12)
            else:
                assert w["mass"] == 0


# ---------------------------------------------------------------------------------------------
# A counterweight that may be none


def _balanced_pb2_with_optional_counterweights(tmp_path: Path) -> Path:
    """PB2's complete balance, then asked again with counterweights of 0 to 5 kg on each link.

    Nothing is left to balance: the right answer adds nothing.
    """
    design = load_design(EXAMPLES / "pb2.toml")
    balanced = optimize(design, "convex").balanced_design(design)
    from balancer.spec import dumps_design

    text = dumps_design(replace(balanced, original=None))
    head = text[: text.index("[balance.crank]")]
    head += """[balance.crank]
counterweight = { mass = [0.0, 5.0], radius = 1.0, gyration = 0.05 }
counter_rotor = [0.0, 20.0]

[balance.coupler]
counterweight = { mass = [0.0, 5.0], radius = 1.0 }

[balance.rocker]
counterweight = { mass = [0.0, 5.0], radius = 1.0 }
counter_rotor = [0.0, 20.0]
"""
    path = tmp_path / "optional.toml"
    path.write_text(head)
    return path


@pytest.mark.parametrize("backend", ["convex", "nlp"])
def test_a_counterweight_that_may_be_none_is_none_when_none_is_needed(tmp_path, backend):
    design = load_design(_balanced_pb2_with_optional_counterweights(tmp_path))
    assert dict(design.balance.links)["crank"].counterweight.mass == (0.0, 5.0)
    result = optimize(design, backend)
    assert result.optimal
    assert {w.kind for w in result.counterweights.values()} == {"none"}
    assert result.added_mass == 0
    for name in result.linkage.link_names:
        old, new = result.original.link(name), result.linkage.link(name)
        assert (new.mass, new.e, new.f) == (old.mass, old.e, old.f)


def test_a_counterweight_that_may_be_none_is_still_used_where_it_helps(tmp_path):
    """PB1 with optional counterweights on all three links balances completely (with the
    coupler's, Berkof's conditions can be met), as with the example's positive bounds. (Within
    0.5 m of A1 the coupler's counterweight cannot spread its mass far enough to give the
    coupler the inertia that needs: a 1.9 m disc 0.15 mm thick is no counterweight.)"""
    text = (EXAMPLES / "pb1_counterweights.toml").read_text()
    text = text.replace("mass = [0.01, 6.3]", "mass = [0.0, 6.3]")
    text = text.replace("mass = [0.01, 6.6]", "mass = [0.0, 6.6]")
    text += "\n[balance.coupler]\ncounterweight = { mass = [0.0, 5.0], radius = 1.0 }\n"
    result = optimize(loads_design(text), "convex")
    assert result.optimal
    assert result.after.summary.shaking_moment.rms <= 1e-6 * result.scale
    assert all(w.kind == "add" for w in result.counterweights.values())


def test_a_negative_counterweight_mass_is_still_refused(tmp_path):
    from balancer.errors import SpecError

    text = (EXAMPLES / "pb1_counterweights.toml").read_text().replace(
        "mass = [0.01, 6.3]", "mass = [-0.5, 6.3]")
    with pytest.raises(SpecError) as info:
        loads_design(text)
    assert info.value.key == "balance.crank.counterweight.mass"


# ---------------------------------------------------------------------------------------------
# Objective in its unit


def test_a_force_objective_is_reported_in_newtons(capsys):
    """The engine's objective weighs the shaking force's components alike (w = 1): √(J/w) is
    the RMS shaking force, in N, and equals the after-analysis' figure."""
    assert main(["optimize", str(EXAMPLES / "engine.toml"), "--no-verify"]) == 0
    out = capsys.readouterr().out
    first = out.splitlines()[1]
    assert "N·m" not in first
    rms = float(re.search(r"RMS shaking force (\S+) N ", first).group(1))
    result = optimize(load_design(EXAMPLES / "engine.toml"))
    assert rms == pytest.approx(result.after.summary.shaking_force.rms, rel=1e-5)
    assert result.single_term.name == "shaking_force"


def test_a_weighted_single_term_is_its_rms(tmp_path):
    """With w = 4 on the shaking moment alone, J = 4·mean(M²): the report's RMS is √(J/4)."""
    text = (EXAMPLES / "pb1.toml").read_text().replace(
        "shaking_moment = 1.0", "shaking_moment = 4.0")
    assert "shaking_moment = 4.0" in text
    result = optimize(loads_design(text), "convex")
    assert result.in_unit(result.rms) == pytest.approx(
        result.after.summary.shaking_moment.rms, rel=1e-9)
    assert f"RMS shaking moment {result.in_unit(result.rms):.6g} N·m" in result.message


def test_several_terms_give_j_and_each_terms_rms(capsys, tmp_path):
    text = (EXAMPLES / "engine.toml").read_text().replace(
        "shaking_moment = 0.0", "shaking_moment = 2.0")
    path = tmp_path / "two.toml"
    path.write_text(text)
    assert main(["optimize", str(path), "--no-verify", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    terms = doc["objective_terms"]
    assert set(terms) == {"shaking_moment", "shaking_force"}
    assert terms["shaking_force"]["unit"] == "N" and terms["shaking_moment"]["unit"] == "N·m"
    # J = Σ w·RMS² over the terms (the inertial figures after).
    j = sum(t["weight"] * t["after"] ** 2 for t in terms.values())
    assert j == pytest.approx(doc["objective"], rel=1e-9)
    assert terms["shaking_force"]["after"] == pytest.approx(
        doc["inertial"]["after"]["shaking_force"]["rms"], rel=1e-12)
    assert main(["optimize", str(path), "--no-verify"]) == 0
    out = capsys.readouterr().out
    assert "J = " in out.splitlines()[1] and "(N·m)²" in out.splitlines()[1]
    assert re.search(r"shaking force\s+\S+\s+\S+\s+\S+\s+N\n", out)


# ---------------------------------------------------------------------------------------------
# What got worse


def test_the_largest_ground_load_is_analyzes_largest_reaction(capsys):
    for example in ("pb1", "watt_sixbar", "engine"):
        path = str(EXAMPLES / f"{example}.toml")
        assert main(["analyze", path, "--json"]) == 0
        analysis = json.loads(capsys.readouterr().out)
        largest = max(r["max"] for r in analysis["reactions"].values())
        assert main(["optimize", path, "--json", "--no-verify"]) == 0
        doc = json.loads(capsys.readouterr().out)
        assert doc["before"]["max_ground_reaction"] == largest
        assert isinstance(doc["warnings"], list)


def test_a_figure_more_than_doubled_is_a_warning():
    """The same four-bar with every link three times as heavy: every inertial figure triples
    (the shaking is linear in the masses, at the same geometry)."""
    design = load_design(EXAMPLES / "meijaard2020.toml")
    heavy = design.mechanism.with_links({
        name: replace(design.mechanism.link(name), mass=3 * design.mechanism.link(name).mass,
                      inertia=3 * design.mechanism.link(name).inertia)
        for name in design.mechanism.link_names})
    from balancer.cycle import cycle_analysis

    before = cycle_analysis(design.mechanism, 10.0, 360, loads=False)
    after = cycle_analysis(heavy, 10.0, 360, loads=False)
    for name in ("shaking_force", "shaking_moment", "driving_torque"):
        assert getattr(after.summary, name).rms == pytest.approx(
            3 * getattr(before.summary, name).rms, rel=1e-12)
    warnings = worse_figures(before, after)
    assert len(warnings) == 7  # RMS and max of three figures, and the ground load
    assert any(w.startswith("the driving torque's RMS rises 3×") for w in warnings)
    assert not worse_figures(after, before)


def test_warnings_are_in_the_text_report():
    design = load_design(EXAMPLES / "pb1.toml")
    result = optimize(design, "convex")
    before, after = result.operating
    text = optimization_text(result, after, before)  # the other way round: all worse
    assert "warning: the shaking force's RMS rises" in text


# ---------------------------------------------------------------------------------------------
# Plain words


def _closed_form_com(spec: dict, theta1: np.ndarray) -> np.ndarray:
    """The total centre of mass of a four-bar from its own closed-form positions (branch +:
    A2 left of the directed line A1→A3)."""
    lengths = spec["mechanism"]["lengths"]
    l1, l2, l3, l4 = (lengths[k] for k in ("crank", "coupler", "rocker", "frame"))
    a1 = l1 * np.exp(1j * theta1)
    d = l4 - a1
    cos_g = (l2**2 + np.abs(d) ** 2 - l3**2) / (2 * l2 * np.abs(d))
    a2 = a1 + l2 * np.exp(1j * (np.angle(d) + np.arccos(cos_g)))
    frames = {"crank": (0.0, a1), "coupler": (a1, a2), "rocker": (a2, l4 + 0j)}
    total = 0
    mass = 0
    for name, (start, end) in frames.items():
        link = spec["links"][name]
        com = link["com"]
        s = complex(com["e"], com["f"]) if "e" in com else cmath.rect(com["s"], com["sigma"])
        direction = (end - start) / np.abs(end - start)
        total = total + link["mass"] * (start + s * direction)
        mass += link["mass"]
    return total / mass


def test_force_balance_in_words_and_the_excursion_by_an_own_route(capsys):
    path = EXAMPLES / "meijaard2020.toml"
    spec = tomllib.loads(path.read_text())
    theta1 = 2 * np.pi * np.arange(360) / 360
    com = _closed_form_com(spec, theta1)
    own = float(np.max(np.abs(com - com.mean())))
    analysis = analyze(load_design(path))
    # Two sums of three products over 360 angles: rounding, ~1e-15 of the reach.
    assert analysis.centre_of_mass_excursion == pytest.approx(own, rel=1e-12)
    assert main(["analyze", str(path)]) == 0
    out = capsys.readouterr().out
    assert (f"force-balanced: no (the total centre of mass moves up to {1e3 * own:.4g} mm "
            "from its mean place") in out
    assert "residual 1 of the first moments" not in out


def test_a_balanced_design_says_its_centre_of_mass_stands_still(capsys, tmp_path):
    out_spec = tmp_path / "b.toml"
    assert main(["optimize", str(EXAMPLES / "pb1.toml"), "--out", str(out_spec),
                 "--no-verify"]) == 0
    capsys.readouterr()
    assert main(["analyze", str(out_spec), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["force_balanced"] is True
    assert doc["centre_of_mass_excursion"] <= 1e-12 * 0.7318
    assert main(["analyze", str(out_spec)]) == 0
    assert "force-balanced: yes (the total centre of mass stands still" in \
        capsys.readouterr().out


def test_a_driven_simulation_says_its_speed(capsys):
    assert main(["simulate", str(EXAMPLES / "meijaard2020.toml"), "--drive",
                 "constant-speed", "--duration", "0.2"]) == 0
    out = capsys.readouterr().out
    assert "constant-speed motion at 10 rad/s (95.49 rpm)" in out
    assert main(["simulate", str(EXAMPLES / "meijaard2020.toml"), "--drive",
                 "constant-speed", "--duration", "0.2", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["speed"] == 10.0


def test_a_front_against_a_shaking_force_that_force_balance_zeroes_is_refused(capsys):
    code = main(["pareto", str(EXAMPLES / "pb1.toml"), "--against", "shaking-force"])
    assert code == 2
    err = capsys.readouterr().err
    assert "force_balance = false" in err and "--against" in err
    assert len(err.strip().splitlines()) == 1
