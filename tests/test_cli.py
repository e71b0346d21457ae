"""The command line: analyze's table, JSON and CSV, exit codes, and the installed script."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from helpers import growth, integration_bound

from balancer import spec
from balancer.cli import main
from balancer.report import ANALYSIS_COLUMNS
from balancer.simulate import simulate

EXAMPLE = str(Path(__file__).resolve().parent.parent / "examples" / "meijaard2020.toml")


def test_analyze_table(capsys):
    assert main(["analyze", EXAMPLE]) == 0
    out = capsys.readouterr().out
    for words in ("shaking force", "shaking moment", "driving torque", "RA0", "RA3",
                  "force-balanced: no", "crank-rocker"):
        assert words in out


def test_analyze_json_has_the_fixed_fields(capsys):
    assert main(["analyze", EXAMPLE, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    for name in ("shaking_force", "shaking_moment", "driving_torque"):
        assert set(doc[name]) >= {"rms", "max"}
        assert doc[name]["max"] >= doc[name]["rms"] > 0
    assert doc["force_balanced"] is False
    assert set(doc["reactions"]) == {"A0", "A3"}


def test_analyze_routes_agree_through_the_cli(capsys):
    docs = []
    for route in ("newton-euler", "mass-matrix"):
        assert main(["analyze", EXAMPLE, "--json", "--route", route]) == 0
        docs.append(json.loads(capsys.readouterr().out))
    # Two routes over the paper's well-conditioned revolution (|sin(θ3 − θ2)| ≥ 0.7): rounding,
    # ~ROUNDING·1.4 of the terms (a few times the figures) ≲ 1e-13; within 1e-12.
    for name in ("shaking_force", "shaking_moment", "driving_torque"):
        for k in ("rms", "max"):
            assert docs[0][name][k] == pytest.approx(docs[1][name][k], rel=1e-12)


def test_analyze_csv(tmp_path, capsys):
    path = tmp_path / "cycle.csv"
    assert main(["analyze", EXAMPLE, "--csv", str(path)]) == 0
    capsys.readouterr()
    with path.open() as fh:
        rows = list(csv.reader(fh))
    assert tuple(rows[0]) == ANALYSIS_COLUMNS
    data = np.array(rows[1:], dtype=float)
    assert data.shape == (360, len(ANALYSIS_COLUMNS))
    col = {name: data[:, i] for i, name in enumerate(ANALYSIS_COLUMNS)}
    # The CSV reads back exactly (17 digits): the sum's rounding, ~ε·|R| ≈ 1e-13 N for
    # reactions of hundreds of newtons; within 1e-9 N.
    assert np.allclose(col["shaking_force_x"], col["RA0x"] + col["RA3x"], rtol=0, atol=1e-9)
    assert np.allclose(col["omega1"], 10.0) and np.allclose(col["alpha1"], 0.0)


def test_csv_into_a_missing_folder_is_bad_input_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "no" / "cycle.csv"
    assert main(["analyze", EXAMPLE, "--csv", str(path)]) == 2
    assert "--csv" in capsys.readouterr().err
    assert not path.parent.exists()


def test_bad_arguments_exit_2_with_one_line(capsys):
    assert main(["analyze"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "SPEC" in err
    assert main(["frobnicate", EXAMPLE]) == 2
    assert main(["analyze", EXAMPLE, "--route", "guess"]) == 2


def test_analyze_without_operating_speed_is_bad_input(tmp_path, capsys):
    text = Path(EXAMPLE).read_text()
    start = text.index("[operation]")
    end = text.index("[simulation]")
    path = tmp_path / "noop.toml"
    path.write_text(text[:start] + text[end:])
    assert main(["analyze", str(path)]) == 2
    assert "operation.speed" in capsys.readouterr().err


def test_analyze_of_a_crank_that_cannot_turn_is_bad_input(tmp_path, capsys):
    text = Path(EXAMPLE).read_text().replace("crank = 1.0", "crank = 2.9")
    path = tmp_path / "rocking.toml"
    path.write_text(text)
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert "full revolution" in err
    # Found after loading, the message still names the file and the key.
    assert err.startswith(f"balancer: error: {path}: mechanism.lengths: ")
    assert err.count("\n") == 1


def test_installed_console_script_runs():
    exe = Path(sys.executable).parent / "balancer"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "balancer"]
    done = subprocess.run([*cmd, "analyze", EXAMPLE, "--json"], capture_output=True, text=True,
                          check=False)
    assert done.returncode == 0, done.stderr
    assert "shaking_moment" in json.loads(done.stdout)


def test_simulate_json_has_the_fixed_fields(capsys):
    assert main(["simulate", EXAMPLE, "--json", "--duration", "1"]) == 0
    doc = json.loads(capsys.readouterr().out)
    for when in ("initial", "final"):
        assert set(doc[when]) == {"theta", "omega", "alpha"}
        assert all(len(doc[when][k]) == 3 for k in ("theta", "omega", "alpha"))
    assert doc["initial"]["theta"][0] == 1.0 and doc["initial"]["omega"] == [0.0, 0.0, 0.0]
    # T − T0 − W, a first integral quadratic in the rates: twice the integration's bound.
    run = SimpleNamespace(steps=doc["steps"], rtol=doc["rtol"])
    assert doc["energy_error"] < 2 * integration_bound(run)


def test_simulate_methods_agree_through_the_cli(capsys):
    docs = []
    for method in ("opened-loop", "complex-masses", "mass-matrix", "lie-group"):
        assert main(["simulate", EXAMPLE, "--json", "--method", method, "--rtol", "1e-11",
                     "--atol", "1e-13"]) == 0
        docs.append(json.loads(capsys.readouterr().out))
    # Integrations of one free motion: their bounds (steps·rtol, from the JSON), amplified by
    # the motion (helpers.growth, by the library).
    design = spec.load_design(EXAMPLE)
    amplified = growth(simulate, design.mechanism, design.simulation, method="complex-masses",
                       rtol=1e-11, atol=1e-13)
    runs = [SimpleNamespace(steps=doc["steps"], rtol=doc["rtol"]) for doc in docs]
    first = docs[0]["final"]
    for doc, run in zip(docs[1:], runs[1:], strict=True):
        for key in ("theta", "omega", "alpha"):
            tol = amplified.bound(lambda tr, key=key: getattr(tr, key), run, runs[0])
            assert np.allclose(doc["final"][key], first[key], rtol=0, atol=tol)


def test_simulate_csv_columns(tmp_path, capsys):
    from balancer.report import SIMULATION_COLUMNS

    path = tmp_path / "run.csv"
    assert main(["simulate", EXAMPLE, "--out", str(path), "--duration", "0.5",
                 "--outputs", "11"]) == 0
    assert "energy balance" in capsys.readouterr().out
    with path.open() as fh:
        rows = list(csv.reader(fh))
    assert tuple(rows[0]) == SIMULATION_COLUMNS == (
        "t", "theta1", "theta2", "theta3", "omega1", "omega2", "omega3",
        "alpha1", "alpha2", "alpha3", "RA0x", "RA0y", "RA3x", "RA3y")
    data = np.array(rows[1:], dtype=float)
    assert data.shape == (11, 14)
    assert np.allclose(data[:, 0], np.linspace(0, 0.5, 11))


def test_simulate_lockup_exits_1_and_writes_nothing(tmp_path, capsys):
    text = Path(EXAMPLE).read_text().replace("crank = 1.0", "crank = 2.9")
    spec = tmp_path / "rocking.toml"
    spec.write_text(text.replace('drive = "free"', 'drive = "constant-speed"').replace(
        "omega1 = 0.0", "omega1 = 3.0"))
    out = tmp_path / "run.csv"
    assert main(["simulate", str(spec), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "locks" in err and "t = " in err and err.count("\n") == 1
    assert not out.exists()


def test_simulate_bad_arguments(capsys):
    assert main(["simulate", EXAMPLE, "--method", "euler"]) == 2
    assert main(["simulate", EXAMPLE, "--duration", "-1"]) == 2
    assert main(["simulate", EXAMPLE, "--rtol", "abc"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 3 and "Traceback" not in err


def test_simulate_initial_angle_outside_the_assembly_range(tmp_path, capsys):
    text = Path(EXAMPLE).read_text().replace("crank = 1.0", "crank = 2.9")
    spec = tmp_path / "rocking.toml"
    spec.write_text(text.replace("theta1 = 1.0", "theta1 = 3.0"))
    assert main(["simulate", str(spec)]) == 2
    assert "simulation.theta1" in capsys.readouterr().err


def test_progress_is_shown_on_a_terminal_only():
    import io

    from balancer.cli import _Progress

    class Tty(io.StringIO):
        def isatty(self):
            return True

    tty, pipe = Tty(), io.StringIO()
    for stream in (tty, pipe):
        p = _Progress(stream=stream, delay=0.0)
        p(2.5, 5.0)
        p.done()
    assert "50.0 %" in tty.getvalue() and pipe.getvalue() == ""


def test_the_command_line_lists_every_formulation_and_drive():
    # The names the parser offers without importing the mechanisms (for a fast --help), against
    # the mechanisms' own tables and the model's drives.
    import importlib

    from balancer import cli, model
    from balancer.mechanisms import FORMULATION_NAMES, REGISTRY
    from balancer.mechanisms.base import CRANK_ANGLE, MULTIBODY

    names = set(MULTIBODY) | set(CRANK_ANGLE)
    for module, cls in REGISTRY.values():
        names |= set(getattr(importlib.import_module(module), cls).formulations)
    assert set(FORMULATION_NAMES) == names
    assert cli.DRIVES == model.DRIVES


def test_help_imports_no_numerics():
    # `balancer --help` is answered before numpy, SciPy or CasADi are imported.
    import subprocess
    import sys

    code = ("import sys\nfrom balancer.cli import main\ntry:\n    main(['--help'])\n"
            "except SystemExit:\n    pass\nprint(sorted(m for m in ('numpy', 'scipy', 'casadi')"
            " if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"


def test_version_is_the_installed_packages(capsys):
    from importlib.metadata import version

    from balancer.cli import main

    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out == f"balancer {version('balancer')}\n"


def test_simulate_help_states_the_default_formulation_it_uses(capsys):
    # The help said "multibody for a general linkage" after crank-angle became the default of
    # every general linkage whose crank turns fully.
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "crank-angle for a general linkage whose crank turns fully" in text
    watt = str(Path(EXAMPLE).parent / "watt_sixbar.toml")
    assert main(["simulate", watt, "--json", "--duration", "0.01"]) == 0
    assert json.loads(capsys.readouterr().out)["method"] == "crank-angle"
