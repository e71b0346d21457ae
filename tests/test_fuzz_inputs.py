"""Regressions of the fuzz campaign on linkages with several inputs.

The campaign is ``python -m tests.fuzz.inputs_campaign``.

Each case is a shipped several-input example with one hostile change, run in-process through
``balancer.cli.main``: bad input ends with exit code 2 and one ``balancer: error:`` line that
names the key at fault, never a traceback, and no output file is left behind.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from balancer.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _spec(tmp_path: Path, example: str, *changes: tuple[str, str]) -> Path:
    text = (EXAMPLES / f"{example}.toml").read_text()
    for old, new in changes:
        if old == "$":  # appended
            text += new
            continue
        assert old in text, old
        text = text.replace(old, new, 1)
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return path


def _run(capsys, tmp_path: Path, argv: list[str]) -> tuple[int, str]:
    code = main(argv)
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err and "internal error" not in err, err
    if code != 0:
        assert [ln for ln in lines if not ln.startswith("balancer: note:")] == lines[-1:], err
        assert lines[-1].startswith("balancer: error:"), err
        left = sorted(p.name for p in tmp_path.iterdir() if p.name != "spec.toml")
        assert left == [], f"left behind after a failure: {left}"
    return code, lines[-1] if lines else ""


def test_motion_name_of_wrong_type_names_its_key_once(capsys, tmp_path):
    # Found by the campaign (seed 236): `motion[1].motion[1].name: must be a string` — the
    # reader put the motion's prefix in front of a key that already carried it.
    spec = _spec(tmp_path, "pick_fivebar", ('name = "pick"', "name = 1e-300"))
    code, line = _run(capsys, tmp_path, ["analyze", str(spec)])
    assert code == 2
    assert ": motion[1].name: must be a string" in line, line


def test_plot_along_a_motion_blames_the_mechanism_not_the_motion(capsys, tmp_path):
    # Found by the campaign (seeds 103, 248): a linkage whose mobility is not its inputs'
    # count, drawn with `plot --motion`, was reported under `motion[1].mechanism`.
    text = (EXAMPLES / "forbal2.toml").read_text()  # link12 taken out: 3 degrees of freedom
    spec = tmp_path / "spec.toml"
    spec.write_text(text[:text.index("[links.link12]")] + text[text.index("[links.link21]"):])
    out = tmp_path / "cycle.png"
    code, line = _run(capsys, tmp_path, ["plot", str(spec), "--motion", "figure-eight",
                                         "--cycle", str(out)])
    assert code == 2
    assert ": mechanism: the linkage has 3 degrees of freedom, not 2" in line, line
    assert "motion[1].mechanism" not in line


THREE_RRR_FAR = ("[0.08, -0.05, 0.06]", "[1.5, 0.0, 0.0]")


@pytest.mark.slow  # (0.6 s each: the full suite's)
@pytest.mark.parametrize("extra", [[], ["--json"], ["--motion", "shake", "--csv", "out.csv"]])
def test_inputs_path_where_the_linkage_does_not_assemble(capsys, tmp_path, extra):
    # Found by the campaign (seed 295): the inputs' own path taking a 3-RRR where it does not
    # assemble gave `nan` in the table with exit code 0, and with --json exit code 1 ("the
    # results are not finite numbers"), not naming the path.
    spec = _spec(tmp_path, "three_rrr", THREE_RRR_FAR, ("samples = 200", "samples = 20"))
    argv = ["analyze", str(spec)] + [str(tmp_path / a) if a == "out.csv" else a for a in extra]
    code, line = _run(capsys, tmp_path, argv)
    assert code == 2
    assert ": motion[1].path: the inputs' path leaves the workspace at t = " in line, line


# The classes the campaign found handled as DESIGN.md asks: bad input, exit code 2, the key.
HANDLED = [
    ("fivebar_5r", ('inputs = ["left", "right"]', 'inputs = ["ground", "right"]'),
     "mechanism.inputs"),
    ("fivebar_5r", ('inputs = ["left", "right"]', 'inputs = ["left", "left"]'),
     "mechanism.inputs"),
    ("fivebar_5r", ('inputs = ["left", "right"]', 'inputs = ["left", "upper_left"]'),
     "mechanism.inputs"),
    ("fivebar_5r", ('inputs = ["left", "right"]', 'inputs = ["left"]'), "mechanism"),
    ("pick_fivebar", ('inputs = ["p", "q"]', 'inputs = ["p", "q", "r"]'), "mechanism.inputs"),
    ("three_rrr", ('name = "shake"\n', 'name = "shake"\npoint = "C1"\n'), "motion[1].p"),
    ("pick_fivebar", ("[0.22, 0.25]", "[2.2, 2.5]"), "motion[1].path"),
    ("fivebar_5r", ('law = "spline"', 'law = "bang"'), "motion[2].law"),
    ("forbal2", ("acc_time = 0.5", "acc_time = 2.5"), "motion[1].acc_time"),
    ("pick_fivebar", ("times = [0.0, 0.4, 0.8]", "times = [0.0, 0.8, 0.4]"), "motion[1].times"),
    ("pick_fivebar", ("p = [-0.5, 0.5]", "r = [-0.5, 0.5]"), "workspace.r"),
    ("forbal2", ("B = [-1.6, 1.0]", "E = [-1.6, 1.0]"), "workspace.joints.E"),
    ("forbal2", ("B = [-1.6, 1.0]", "O = [-1.6, 1.0]"), "workspace.joints.O"),
    ("pick_fivebar", ("$", '\n[[motion]]\nname = "pick"\ntimes = [0.0, 1.0]\n'
                           'path = [[0.0, 0.0], [0.0, 0.0]]\n'), "motion[2].name"),
    ("pick_fivebar", ("samples = 200", "samples = 7"), "motion[1].samples"),
    ("pick_fivebar", ("samples = 21", "samples = -3"), "workspace.samples"),
    ("pick_fivebar", ("path = [[0.16867194669263857, 0.2944945065744622], [0.22, 0.25], "
                      "[0.16867194669263857, 0.2944945065744622]]",
                      "path = [[0.16867194669263857, 0.2944945065744622], [0.22], "
                      "[0.16867194669263857, 0.2944945065744622]]"), "motion[1].path"),
]

#: The folded parallelogram: the reference pose singular.
FOLDED = (("P1 = [0.16506712298193568, 0.11292849467900708]", "P1 = [0.2, 0.0]"),
          ("P2 = [-0.06242202548207136, 0.13639461402385225]", "P2 = [0.15, 0.0]"),
          ("Q = [0.10264509749986432, 0.24932310870285934]", "Q = [0.35, 0.0]"),
          ("E = [0.16867194669263857, 0.29449450657446213]", "E = [0.43, 0.0]"))


@pytest.mark.parametrize("verb", ["analyze", "optimize", "pareto", "plot", "simulate", "verify"])
def test_folded_parallelogram_is_bad_input(capsys, tmp_path, verb):
    spec = _spec(tmp_path, "pick_fivebar", *FOLDED)
    extra = {"analyze": ["--json"], "optimize": ["--out", str(tmp_path / "out.toml")],
             "pareto": ["--against", "added-mass", "--points", "3"],
             "simulate": ["--json"], "verify": ["--json"],
             "plot": ["--motion", "pick", "--cycle", str(tmp_path / "c.png")]}[verb]
    code, line = _run(capsys, tmp_path, [verb, str(spec), *extra])
    assert code == 2
    assert ": mechanism.points: the reference pose is singular" in line, line


@pytest.mark.parametrize(("example", "change", "key"), HANDLED)
@pytest.mark.parametrize("verb", ["analyze", "optimize", "simulate"])
def test_bad_input_names_its_key(capsys, tmp_path, example, change, key, verb):
    spec = _spec(tmp_path, example, change)
    argv = [verb, str(spec)]
    argv += (["--out", str(tmp_path / "out.toml"), "--no-verify"] if verb == "optimize"
             else ["--json"])
    if verb == "simulate" and key.startswith("motion[1]"):
        pytest.skip("simulate runs the first motion (or --motion NAME's) alone")
    code, line = _run(capsys, tmp_path, argv)
    assert code == 2, line
    assert f": {key}" in line, line


