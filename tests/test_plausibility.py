"""A note on stderr for a unit that looks wrong (mm written as m, rpm as rad/s); never for the
shipped examples, never a change of the exit code."""

from __future__ import annotations

import json
import re
import tomllib
from dataclasses import replace
from pathlib import Path

import pytest
from golden.record import NOT_RUN

from balancer import examples
from balancer.cli import main
from balancer.plausibility import length_note, speed_note, tip_speed
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
PB1 = (EXAMPLES / "pb1.toml").read_text()


def _spec(tmp_path: Path, text: str, name: str = "spec.toml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _notes(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("balancer: note: ")]


@pytest.mark.parametrize("name", [
    pytest.param(name, marks=pytest.mark.skip(reason=NOT_RUN[name])) if name in NOT_RUN
    else name for name in examples.names()])
@pytest.mark.slow
def test_no_shipped_example_gets_a_note(name, capsys):
    path = EXAMPLES / f"{name}.toml"
    assert length_note(tomllib.loads(path.read_text())) is None
    assert speed_note(load_design(path)) is None
    assert main(["analyze", str(path), "--json"]) == 0
    assert capsys.readouterr().err == ""


def test_lengths_in_millimetres_get_one_note_and_the_same_exit_code(tmp_path, capsys):
    """PB1 with its lengths in millimetres assembles (every length 1000 times): it is
    analysed as before, with one line naming the lengths."""
    text = PB1
    for key, value in (("crank", "1.0"), ("coupler", "3.0"), ("rocker", "2.0"),
                       ("frame", "3.2")):
        text, n = re.subn(rf"^{key} = {re.escape(value)}\b", f"{key} = {float(value) * 1000}",
                          text, flags=re.M)
        assert n == 1
    assert main(["analyze", _spec(tmp_path, text), "--json"]) == 0
    captured = capsys.readouterr()
    json.loads(captured.out)
    notes = _notes(captured.err)
    assert notes == captured.err.splitlines() and len(notes) == 1
    assert ("mechanism.lengths.crank = 1000 m, mechanism.lengths.coupler = 3000 m, "
            "mechanism.lengths.rocker = 2000 m and 1 more are longer than 100 m") in notes[0]
    assert notes[0].endswith("lengths are in metres (mm written as m?)")


@pytest.mark.parametrize("verb", [["analyze"], ["simulate"], ["verify"], ["optimize"],
                                  ["plot", "--cycle", "{tmp}/c.png"],
                                  ["pareto", "--against", "driving-torque"],
                                  ["sweep", "--vary", "links.crank.mass=1:2:2", "--out",
                                   "{tmp}/s.parquet", "--workers", "0"]])
def test_a_length_in_millimetres_is_noted_before_the_error_it_causes(tmp_path, capsys, verb):
    """One length in millimetres: the linkage cannot assemble (exit 2, as before), and the
    note says why it probably does not, first."""
    spec = _spec(tmp_path, PB1.replace("coupler = 3.0", "coupler = 2500.0", 1))
    args = [verb[0], spec, *(a.format(tmp=tmp_path) for a in verb[1:])]
    assert main(args) == 2
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == ("balancer: note: mechanism.lengths.coupler = 2500 m is longer than "
                        "100 m: lengths are in metres (mm written as m?)")
    assert len(lines) == 2 and lines[1].startswith("balancer: error: ")


def test_a_speed_in_rpm_is_noted_naming_the_key(tmp_path, capsys):
    """1000 rad/s turns PB1's rocker pin, 4 m from the crank's pivot, at 4000 m/s."""
    spec = _spec(tmp_path, re.sub(r"^speed = .*$", "speed = 1000.0", PB1, count=1,
                                  flags=re.M))
    assert main(["analyze", spec, "--json"]) == 0
    captured = capsys.readouterr()
    json.loads(captured.out)
    [note] = captured.err.splitlines()
    assert note.startswith("balancer: note: operation.speed = 1000 rad/s ")
    assert "faster than sound (340 m/s)" in note and "rpm written as rad/s?" in note


def test_points_centres_of_mass_and_springs_are_lengths_too():
    data = tomllib.loads((EXAMPLES / "quick_return.toml").read_text())
    data["mechanism"]["points"]["D"] = [350.0, 0.0]
    data["links"]["rod"]["com"] = {"e": 0.0, "f": 120.0}
    data["springs"] = [{"points": ["A0", "D"], "stiffness": 1.0, "free_length": 400.0}]
    note = length_note(data)
    assert "mechanism.points.D = [350, 0] m (350 m from the origin)" in note
    assert "links.rod.com (120 m from its link's first point)" in note
    assert "springs[1].free_length = 400 m" in note


def test_a_point_is_as_fast_as_its_own_motion_moves_it():
    """A geared crankshaft 1 m from the first turns its pins about its own axis: the square
    four's at 5000 rpm move at about 20 m/s, not at ω times their distance from the first
    crankshaft's pivot (543 m/s)."""
    design = load_design(EXAMPLES / "square_four.toml")
    far = replace(design.mechanism, crankshafts=(
        replace(design.mechanism.crankshafts[0], at=(1.0, 0.0)),))
    fastest = tip_speed(far)
    assert fastest is not None and 0.037 < fastest < 0.06  # a 37.5 mm crank, its rod's ends
    assert speed_note(replace(design, mechanism=far)) is None
