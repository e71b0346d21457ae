"""``balancer plan`` end to end: its report, JSON, written spec, CSV, figure and refusals."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from balancer.cli import main

#: A few seconds of optimisation: the full suite's, not the fast lane's.
pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FORBAL = str(EXAMPLES / "forbal2.toml")


def test_plan_reports_writes_and_the_written_spec_runs(capsys, tmp_path):
    out, table, figure = tmp_path / "planned.toml", tmp_path / "p.csv", tmp_path / "p.png"
    code = main(["plan", FORBAL, "--intervals", "40", "--out", str(out), "--csv", str(table),
                 "--plot", str(figure), "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    doc = json.loads(captured.out)
    assert doc["certified"] and doc["planned"] == "diamond planned"
    assert doc["objective_after"] < doc["objective_before"]
    assert doc["after"]["shaking_moment"]["rms"] < doc["before"]["shaking_moment"]["rms"]
    assert len(doc["pace"]) == 41 and doc["out"] == str(out)
    assert figure.stat().st_size > 10_000
    header = next(csv.reader(io.StringIO(table.read_text())))
    assert header[:3] == ["t", "link11", "link21"] and "torque_link21" in header
    assert main(["analyze", str(out), "--motion", "diamond planned", "--json"]) == 0
    along = json.loads(capsys.readouterr().out)
    rms = along["motions"]["diamond planned"]["shaking_moment"]["rms"]
    assert rms == pytest.approx(doc["after"]["shaking_moment"]["rms"], rel=1e-12)


def test_plan_s_text_says_what_is_certified(capsys):
    assert main(["plan", FORBAL, "--intervals", "24"]) == 0
    out = capsys.readouterr().out
    for words in ("time law planned for motion diamond", "RMS before", "RMS after",
                  "shaking moment", "torque on link11",
                  "the optimum is the transcription's global one"):
        assert words in out


def _spec(tmp_path, extra: str) -> str:
    path = tmp_path / "s.toml"
    own = Path(FORBAL).read_text().split("\n[plan]")[0]  # (the example's own [plan] is last)
    path.write_text(own + "\n" + extra)
    return str(path)


@pytest.mark.parametrize(("args", "extra", "code", "words"), [
    (["--motion", "nosuch"], "", 2, "--motion"),
    (["--motion", "revolution"], "", 2, "one-input"),
    (["--intervals", "3"], "", 2, "--intervals"),
    ([], '[plan]\nmeasure = "max"\n', 2, "plan.measure"),
    ([], '[plan]\nmotion = "nosuch"\n', 2, "plan.motion"),
    ([], "[plan]\nmax_speed = { nosuch = 1.0 }\n", 2, "plan.max_speed.nosuch"),
    ([], "[plan]\nmax_speed = -1.0\n", 2, "plan.max_speed"),
    ([], "[plan.objective]\nshaking_moment = 0.0\n", 2, "plan.objective"),
    ([], '[plan]\nname = "circle"\n', 2, "plan.name"),
    ([], "[plan]\nmax_speed = 0.01\n", 1, "lengthen the duration"),
])
def test_plan_refuses_bad_input_in_one_line(tmp_path, capsys, args, extra, code, words):
    assert main(["plan", _spec(tmp_path, extra), *(args or ["--intervals", "24"])]) == code
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_plan_refuses_an_engine(capsys):
    # (an engine's crank turns at its speed; the closed-form four-bar and slider-crank plan)
    assert main(["plan", str(EXAMPLES / "single_cylinder.toml")]) == 2
    assert "mechanism.type" in capsys.readouterr().err
    assert main(["plan", str(EXAMPLES / "meijaard2020.toml"), "--intervals", "16"]) == 0


def test_the_schema_names_the_plan_s_keys_as_the_model_does():
    from balancer.model.plan import LIMIT_KEYS, PLAN_OBJECTIVE_KEYS
    from balancer.spec import schema

    assert tuple(k.name for k in schema.section("plan.objective").keys) == PLAN_OBJECTIVE_KEYS
    limits = tuple(k.name for k in schema.section("plan").keys if k.name.startswith("max_"))
    assert limits == tuple(LIMIT_KEYS)


def test_another_motion_than_the_plan_s_is_named_after_itself(capsys):
    assert main(["plan", FORBAL, "--motion", "circle", "--intervals", "48", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["motion"] == "circle" and doc["planned"] == "circle planned"


def test_a_peak_is_planned_on_the_examples_without_limits(capsys):
    for spec in (str(EXAMPLES / "three_rrr.toml"), FORBAL):
        assert main(["plan", spec, "--measure", "peak", "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["certified"]


@pytest.mark.parametrize(("args", "extra", "words"), [
    (["--duration", "1e-300"], "", "--duration"),
    (["--duration", "1e300"], "", "--duration"),
    ([], "[plan]\nmax_speed = 1e200\n", "plan.max_speed"),
    ([], "[plan]\nmax_acceleration = 1e-300\n", "plan.max_acceleration"),
    ([], '[[motion]]\nname = "fast"\nalong = "diamond"\npace = [[0.0, 1e160], [4.0, 1e160]]\n',
     "pace"),
])
def test_extreme_numbers_are_refused_naming_the_key(tmp_path, capsys, args, extra, words):
    assert main(["plan", _spec(tmp_path, extra), *args]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1 and "internal" not in err


def test_outputs_that_share_a_file_are_refused(tmp_path, capsys):
    same = tmp_path / "same.toml"
    assert main(["plan", FORBAL, "--intervals", "24", "--out", str(same), "--csv",
                 str(same)]) == 2
    err = capsys.readouterr().err
    assert "--csv" in err and "--out" in err and not same.exists()


def test_a_speed_limit_that_stops_the_motion_is_named(tmp_path, capsys):
    assert main(["plan", _spec(tmp_path, "[plan]\nmax_speed = 1e-6\n"), "--intervals",
                 "24"]) == 1
    err = capsys.readouterr().err
    assert "plan.max_speed" in err and "1e-06" in err and len(err.strip().splitlines()) == 1
