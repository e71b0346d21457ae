"""Bad sizes and output paths are refused before any work (exit 2, one line naming them).

"Before any work" is checked without a clock: the work that would come first is replaced by
a function that fails the test if it is called, or the modules it would load are looked for.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from balancer import simulation
from balancer.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PB1 = str(EXAMPLES / "pb1.toml")


def _never(what: str):
    def fail(*args, **kwargs):
        raise AssertionError(f"{what} began before the input was refused")
    return fail


@pytest.mark.parametrize("args", [
    ["plot", PB1, "--cycle", "{tmp}/c.jpg"],
    ["plot", PB1, "--animate", "{tmp}/a.avi"],
    ["verify", PB1, "--plot", "{tmp}/r.jpg"],
    ["pareto", PB1, "--against", "driving-torque", "--plot", "{tmp}/f.eps"],
    ["sweep", PB1, "--vary", "mechanism.lengths.coupler=2.8:3.2:2", "--out", "{tmp}/s.parquet",
     "--plot", "{tmp}/atlas.jpeg", "--workers", "0"],
])
@pytest.mark.slow
def test_a_figure_path_of_no_type_is_refused_before_any_work(tmp_path, args):
    """`plot --cycle c.jpg` loaded matplotlib (2.4 s on a busy machine) before it was refused,
    where a missing folder was refused at once: now neither matplotlib nor the spec
    is loaded first."""
    args = [a.format(tmp=tmp_path) for a in args]
    code = ("import contextlib, io, json, sys\nimport balancer.spec\n"
            "def load(*args, **kwargs):\n    raise AssertionError('the spec was loaded')\n"
            "balancer.spec.load_design = load\nfrom balancer.cli import main\n"
            "err = io.StringIO()\nwith contextlib.redirect_stderr(err):\n"
            f"    code = main({args!r})\n"
            "print(json.dumps([code, err.getvalue(), 'matplotlib' in sys.modules]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    exit_code, err, matplotlib = json.loads(out.strip().splitlines()[-1])
    assert exit_code == 2, err
    assert err.count("\n") == 1 and "the file type comes from the extension" in err
    assert not matplotlib
    assert list(tmp_path.iterdir()) == []


def test_frames_beyond_the_limit_are_refused_naming_it(tmp_path, capsys, monkeypatch):
    """`plot --animate a.gif --frames 100000` ran past 20 s: now refused, naming the limit."""
    monkeypatch.setattr("balancer.cli.plot.animate", _never("the animation"))
    gif = tmp_path / "a.gif"
    assert main(["plot", PB1, "--animate", str(gif), "--frames", "100000"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--frames" in err and "3600" in err and "100000" in err
    assert not gif.exists()


def test_the_frames_limit_is_in_the_help(capsys):
    with pytest.raises(SystemExit):
        main(["plot", "--help"])
    assert "at most 3600" in capsys.readouterr().out


def test_verify_refuses_a_driven_run_too_long_before_simulating_anything(capsys, monkeypatch):
    """`verify --duration 1e6` ran past 20 s (the Stephenson six-bar's driven run laid out
    1e8 guide times): the driven run's quadrature panels are counted before any run starts,
    the free one included, and the error names the option."""
    monkeypatch.setattr(simulation.stepper.Stepper, "run", _never("a simulation"))
    spec = str(EXAMPLES / "stephenson_sixbar.toml")
    assert main(["verify", spec, "--duration", "1e6"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--duration" in err and "quadrature panels" in err


def test_verify_runs_first_the_run_the_step_budget_may_refuse(tmp_path, capsys, monkeypatch):
    """A gravity of 1e10 m/s² makes PB1's free run need millions of steps, refused from the
    rate of its first steps: that run comes first, before the driven run's quadrature."""
    spec = tmp_path / "heavy.toml"
    spec.write_text(Path(PB1).read_text().replace(
        "[simulation]\n", "[simulation]\ngravity = [0.0, -1e10]\n"))
    assert "gravity = [0.0, -1e10]" in spec.read_text()
    monkeypatch.setattr(simulation.stepper.Stepper, "_prescribed", _never("the driven run"))
    assert main(["verify", str(spec)]) == 2
    err = capsys.readouterr().err
    assert "simulation.duration" in err and "integration steps" in err


def test_optimize_refuses_its_check_s_duration_before_optimizing(capsys, monkeypatch):
    """The check by simulation comes at the end of optimize: a --verify-duration it would
    refuse is refused before the optimisation."""
    monkeypatch.setattr("balancer.cli.optimize.optimize", _never("the optimisation"))
    assert main(["optimize", PB1, "--verify-duration", "1e6"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--verify-duration" in err and "panels" in err


def test_a_prescribed_motion_in_absolute_coordinates_counts_its_panels_first(capsys,
                                                                            monkeypatch):
    """The multibody formulation's driven motion laid out its outputs and guide times (1e8
    for 1e5 s of the Stephenson six-bar) before its quadrature's panels were counted."""
    monkeypatch.setattr(simulation.stepper.Stepper, "_guide_times", _never("laying out the times"))
    spec = str(EXAMPLES / "stephenson_sixbar.toml")
    assert main(["simulate", spec, "--method", "multibody", "--duration", "1e5"]) == 2
    err = capsys.readouterr().err
    assert "--duration" in err and "quadrature panels" in err
