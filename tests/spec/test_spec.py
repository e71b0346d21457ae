"""Design specs: reading, validation errors (one class each), and exact round trips."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from conftest import random_linkage

from balancer import spec
from balancer.cli import main
from balancer.errors import AssemblyError, SpecError
from balancer.model import Design, Operation, SimulationSettings

DATA = Path(__file__).resolve().parents[1] / "data"

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

BASE = """
[mechanism]
type = "four-bar"
branch = "+"
[mechanism.lengths]
crank = 1.0
coupler = 3.0
rocker = 2.0
frame = 3.2
[links.crank]
mass = 2.1
inertia = 1.1
com = { s = 0.6, sigma = 0.3 }
[links.coupler]
mass = 3.0
inertia = 3.1
com = { e = 1.2, f = 0.5 }
[links.rocker]
mass = 2.2
inertia = 2.1
com = { s = 1.66, sigma = -0.4 }
[operation]
speed = 10.0
"""


def test_the_example_loads_with_the_papers_values():
    design = spec.load_design(EXAMPLES / "meijaard2020.toml")
    m = design.mechanism
    assert m.lengths == (1.0, 3.0, 2.0, 3.2)
    # Polar → (e, f) → polar: a cos/sin, a hypot/atan2, each within an ulp or two: ≲ 4 ulp of
    # 0.6 (4.4e-16) and of the angles 0.3, 0.4 (≤ 2.2e-16); within 1e-15.
    assert m.crank.s == pytest.approx(0.6, abs=1e-15)
    assert m.crank.sigma == pytest.approx(0.3, abs=1e-15)
    assert m.rocker.sigma == pytest.approx(-0.4, abs=1e-15)
    assert m.coupler.force == (1.3, -1.4)
    assert design.simulation.theta1 == 1.0 and design.simulation.duration == 5.0


def test_round_trip_is_exact_for_the_example():
    design = spec.load_design(EXAMPLES / "meijaard2020.toml")
    text = spec.dumps_design(design)
    again = spec.loads_design(text)
    assert again == design
    assert spec.dumps_design(again) == text


@pytest.mark.parametrize("seed", range(20))
def test_round_trip_is_exact_for_random_designs(seed):
    rng = np.random.default_rng(seed)
    design = Design(
        mechanism=random_linkage(rng),
        operation=Operation(speed=float(rng.uniform(-20, 20)), samples=int(rng.integers(8, 999))),
        simulation=SimulationSettings(
            duration=float(rng.uniform(0.1, 9)),
            theta1=float(rng.normal()),
            omega1=float(rng.normal()),
            gravity=(float(rng.normal()), -9.81),
            drive=str(rng.choice(["free", "constant-speed"])),
            method=str(rng.choice(["opened-loop", "lie-group"])),
            rtol=1e-9,
            atol=1e-11,
            outputs=int(rng.integers(2, 2000)),
        ),
        title=f"random design {seed} with \"quotes\" and a backslash \\",
    )
    assert spec.loads_design(spec.dumps_design(design)) == design


def _load(text: str) -> Design:
    return spec.loads_design(text, source="test.toml")


BAD = {
    "missing key": (BASE.replace("mass = 2.1\n", ""), "links.crank.mass", "missing"),
    "wrong type": (BASE.replace("mass = 3.0", 'mass = "heavy"'), "links.coupler.mass", "number"),
    "bool is no number": (BASE.replace("mass = 3.0", "mass = true"), "links.coupler.mass",
                          "number"),
    "non-positive length": (BASE.replace("rocker = 2.0", "rocker = -2.0"),
                            "mechanism.lengths.rocker", "positive"),
    "zero length": (BASE.replace("crank = 1.0", "crank = 0"), "mechanism.lengths.crank",
                    "positive"),
    "non-positive mass": (BASE.replace("mass = 2.2", "mass = 0.0"), "links.rocker.mass",
                          "positive"),
    "non-positive inertia": (BASE.replace("inertia = 3.1", "inertia = -1"),
                             "links.coupler.inertia", "positive"),
    "unknown key (typo)": (BASE.replace("mass = 2.1", "mas = 2.1"), "links.crank",
                           "did you mean 'mass'"),
    "unknown table": (BASE + "\n[simulaton]\nduration = 1\n", "simulaton", "did you mean"),
    "unknown link": (BASE + "\n[links.slider]\nmass = 1\n", "links.slider", "unknown key"),
    "bad branch": (BASE.replace('branch = "+"', 'branch = "left"'), "mechanism.branch",
                   "must be one of"),
    "bad type": (BASE.replace('type = "four-bar"', 'type = "five-bar"'), "mechanism.type",
                 "must be one of"),
    "cannot assemble": (BASE.replace("frame = 3.2", "frame = 9.0"), "mechanism.lengths",
                        "cannot be assembled at any crank angle"),
    "counter-rotor on the coupler": (
        BASE.replace("com = { e = 1.2, f = 0.5 }", "com = { e = 1.2, f = 0.5 }\ncounter_rotor = 1"),
        "links.coupler.counter_rotor", "ground pivot"),
    "mixed centre of mass": (BASE.replace("com = { e = 1.2, f = 0.5 }", "com = { e = 1.2, s = 1 }"),
                             "links.coupler.com", "either"),
    "zero speed": (BASE.replace("speed = 10.0", "speed = 0"), "operation.speed", "non-zero"),
    "not finite": (BASE.replace("speed = 10.0", "speed = inf"), "operation.speed", "finite"),
    "bad force": (BASE.replace("mass = 2.2", "mass = 2.2\nforce = [1.0]"), "links.rocker.force",
                  "two numbers"),
    "bad drive": (BASE + '\n[simulation]\ndrive = "motor"\n', "simulation.drive", "one of"),
    "bad samples": (BASE.replace("speed = 10.0", "speed = 10.0\nsamples = 2.5"),
                    "operation.samples", "integer"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_specs_raise_spec_error_naming_the_key(case):
    text, key, words = BAD[case]
    with pytest.raises(SpecError) as info:
        _load(text)
    message = str(info.value)
    assert key in message and words in message and "test.toml" in message
    assert "\n" not in message
    assert info.value.exit_code == 2


@pytest.mark.parametrize("case", list(BAD))
def test_bad_specs_exit_2_with_one_line(case, tmp_path, capsys):
    text, key, _ = BAD[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and key in err and str(path) in err
    assert "Traceback" not in err


def test_cannot_assemble_is_an_assembly_error():
    with pytest.raises(AssemblyError):
        _load(BAD["cannot assemble"][0])


def test_value_is_named_in_the_message():
    with pytest.raises(SpecError, match=r"got -2\.0"):
        _load(BAD["non-positive length"][0])


def test_missing_file_and_invalid_toml(tmp_path, capsys):
    assert main(["analyze", str(tmp_path / "nope.toml")]) == 2
    assert "no such file" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text("[mechanism\n")
    assert main(["analyze", str(bad)]) == 2
    assert "not valid TOML" in capsys.readouterr().err


def test_save_design_is_atomic(tmp_path):
    design = spec.load_design(EXAMPLES / "meijaard2020.toml")
    target = tmp_path / "out.toml"
    spec.save_design(design, target)
    assert spec.load_design(target) == design
    assert [p.name for p in tmp_path.iterdir()] == ["out.toml"]


def test_strings_and_keys_read_back_as_written():
    # balancer.tomltext against Python's TOML reader (the other route): every ASCII character,
    # the control characters among them, and some beyond, as a key and as a string value.
    import tomllib

    from balancer import tomltext

    texts = [chr(c) for c in range(128)] + ["a.b", "a b", 'q"uote', "back\\slash", "ü", "", "é.x"]
    for text in texts:
        if not text:
            continue  # TOML has no empty bare key; quoted, "" is a key, checked below
        doc = tomllib.loads(f"{tomltext.key(text)} = {tomltext.string(text)}\n")
        assert doc == {text: text}, repr(text)
    assert tomllib.loads(f"{tomltext.key('')} = 1") == {"": 1}
    for x in (0.1, -2.5e-300, 1e300, 3, 5e-324):
        assert tomllib.loads(f"x = {tomltext.number(x)}")["x"] == x


def test_a_linkage_with_names_toml_must_quote_round_trips_through_its_balanced_spec():
    # Linkage fuzz campaign, seed 9090, case 298: a link named "a.b" was written as
    # [balance.a.b], a table b inside a table a, and the balanced spec did not load again. Link
    # and point names that are no bare keys (a dot, a space, a quote) are quoted wherever the
    # spec names them: links, points, [balance.<link>] and its com_about.
    text = (Path(spec.__file__).parent.parent / "examples" / "watt_sixbar.toml").read_text()
    text = text.replace("[links.crank]", '[links."a.b"]').replace(
        "[balance.crank]", '[balance."a.b"]').replace('input = "crank"', 'input = "a.b"')
    point = 'A "0"'  # a quote and a space: a quoted key, an escaped string
    quoted = '"A \\"0\\""'
    text = text.replace("A0 = [", f"{quoted} = [").replace('"A0"', quoted)
    design = spec.loads_design(text)
    assert "a.b" in design.mechanism.link_names
    assert point in dict(design.mechanism.points)
    assert design.balance.link("a.b").com_about == point
    written = spec.dumps_design(design)
    again = spec.loads_design(written)
    assert again == design
    assert spec.dumps_design(again) == written


@pytest.mark.parametrize(("edit", "key"), [
    ('counter_rotor = 0.0', "links.crank.counter_rotor"),
    ('stiffness = 6313.2', "springs[1].stiffness"),
    ('free_length = ', "springs[1].free_length"),
    ('com = { e = -0.53901', "links.coupler.com"),
])
def test_an_absurd_scale_names_its_own_key(edit, key, tmp_path, capsys):
    # Linkage fuzz campaign, seed 777: a counter-rotor of 1e200 kg·m² was named as the link's
    # inertia (the two were one term of the moment's scale) and a centre of mass 1e200 m out
    # as a spring's free length (the reach entered the spring's force under its key). Each
    # input is a term of its own: the message names the one at fault.
    text = (DATA / "spring_linkage_at_rest.toml").read_text()
    if edit == "counter_rotor = 0.0":
        text = text.replace("[links.crank]\n", "[links.crank]\ncounter_rotor = 1e200\n", 1)
    elif edit.startswith("stiffness"):
        text = re.sub(r"stiffness = [^\n]*", "stiffness = 1e200", text, count=1)
    elif edit.startswith("free_length"):
        text = re.sub(r"free_length = [^\n]*", "free_length = 1e200", text, count=1)
    else:
        text = text.replace(edit, "com = { e = 1e200", 1)
    path = tmp_path / "spec.toml"
    path.write_text(text)
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{key}:" in err and "1e+200" in err, err


_QUICK_RETURN = (EXAMPLES / "quick_return.toml").read_text()
_QR_LINKS = ("crank", "block", "rocker", "rod", "ram")


@pytest.mark.parametrize(("old", "new", "key", "names"), [
    ('guide = "ground"', 'guide = "frame"', "mechanism.sliders[2].guide", (*_QR_LINKS, "ground")),
    ('link = "ram"', 'link = "slide"', "mechanism.sliders[2].link", (*_QR_LINKS, "ground")),
    ('input = "crank"', 'input = "ground"', "mechanism.input", (*_QR_LINKS, "ground")),
    ('point = "D"', 'point = "C"', "mechanism.sliders[2].point", ("D",)),
])
def test_an_unknown_link_or_point_is_named_with_those_the_spec_has(old, new, key, names):
    """`guide = "frame"` said 'unknown link' without the links or that the frame is called
    ground: every such message now lists the names that would do."""
    assert _QUICK_RETURN.count(old) == 1
    with pytest.raises(SpecError) as info:
        spec.loads_design(_QUICK_RETURN.replace(old, new))
    assert info.value.key == key
    message = str(info.value)
    assert all(re.search(rf"\b{name}\b", message) for name in names), message
    if "ground" in names:
        assert "the frame is called ground" in message


def test_a_spring_on_an_unknown_point_names_the_points():
    text = _QUICK_RETURN + '\n[[springs]]\npoints = ["Q9", "D"]\nstiffness = 1.0\n' \
        'free_length = 1.0\n'
    with pytest.raises(SpecError) as info:
        spec.loads_design(text)
    assert info.value.key == "springs[1].points"
    assert "'Q9'" in str(info.value) and "the points are A0, " in str(info.value)


def test_a_balance_table_for_a_link_the_mechanism_lacks_lists_its_links():
    text = (EXAMPLES / "pb1.toml").read_text() + "\n[balance.frame]\nmass = [1.0, 2.0]\n"
    with pytest.raises(SpecError) as info:
        spec.loads_design(text)
    assert info.value.key == "balance.frame"
    assert "crank, coupler, rocker" in str(info.value)


@pytest.mark.parametrize(("example", "anchor", "weight", "kind"), [
    ("pb1", "[balance.objective]", "unbalance", "four-bar"),
    ("engine", "[balance.objective]", "unbalance", "slider-crank"),
    ("quick_return", "[balance.objective]", "unbalance", "linkage"),
    ("inline_three_parts", "[balance.objective]", "driving_torque", "engine"),
    ("inline_three_parts", "[balance.objective]", "added_mass", "engine"),
])
def test_an_objective_weight_of_another_mechanism_is_refused_as_such(example, anchor, weight,
                                                                       kind):
    """A linkage's `unbalance = 1.0` said "unknown key 'unbalance'; did you mean 'unbalance'?"
    (the fuzz campaign of issue 41): a weight of the other mechanisms' objective is said not to
    apply, with the keys that do; an engine's `driving_torque` likewise."""
    text = (EXAMPLES / f"{example}.toml").read_text()
    assert text.count(anchor) == 1
    with pytest.raises(SpecError) as info:
        spec.loads_design(text.replace(anchor, f"{anchor}\n{weight} = 1.0"), source="test.toml")
    message = str(info.value)
    assert info.value.key == f"balance.objective.{weight}"
    assert f"does not apply to a{'n' if kind == 'engine' else ''} {kind}'s balancing" in message
    assert "did you mean" not in message and "shaking_moment" in message, message


def test_a_hint_never_names_the_key_it_refuses():
    from balancer.spec.tables import hint

    assert hint("unbalance", ("unbalance", "shaking_moment")) == ""
    assert hint("unbalanc", ("unbalance", "shaking_moment")) == "; did you mean 'unbalance'?"


def test_an_array_in_an_error_is_shown_as_the_spec_writes_it():
    """A refused array is shown as TOML's array, not as the model's Python tuple: a body with
    no points read '(got ())' (fuzz campaign)."""
    root = Path(__file__).resolve().parents[2]
    text = (root / "examples" / "quick_return.toml").read_text()
    assert 'points = ["A1"]' in text
    with pytest.raises(SpecError) as info:
        spec.loads_design(text.replace('points = ["A1"]', "points = []"))
    message = str(info.value)
    assert "links.block.points" in message, message
    assert "(got ())" not in message and "(got [])" in message, message
    assert SpecError("x", key="k", value=((1.0, 2.0), 3)).args[0].endswith(
        "(got [[1.0, 2.0], 3])")
