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
from balancer.columns import ANALYSIS_COLUMNS
from balancer.simulation import simulate

EXAMPLE = str(Path(__file__).resolve().parents[2] / "examples" / "meijaard2020.toml")


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
    from balancer.columns import SIMULATION_COLUMNS

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


def test_the_command_line_lists_every_formulation_and_drive():
    # The names the parser offers without importing the mechanisms (for a fast --help), against
    # the mechanisms' own tables and the model's drives.
    from balancer import cli, formulations, mechanisms, model
    from balancer.simulation import motions

    names = set(formulations.GENERAL) | set(motions.METHODS)  # (several inputs: their own)
    for kind in mechanisms.FOLDERS:
        names |= set(mechanisms.mechanism_class(kind).own_formulations)
    assert set(cli.FORMULATION_NAMES) == names
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


#: What each command may not import (SciPy alone costs 0.3–0.7 s of a command that should
#: take well under a second; CVXPY ~1 s; matplotlib, pyarrow and Dask are for plots, tables
#: and sweeps).
_HEAVY = ("scipy", "cvxpy", "matplotlib", "pyarrow", "dask")


@pytest.mark.parametrize(("args", "also"), [
    (["analyze", "meijaard2020.toml"], ("casadi", "clarabel")),
    (["analyze", "engine.toml"], ("casadi", "clarabel")),
    (["analyze", "watt_sixbar.toml", "--json"], ("casadi", "clarabel")),
    (["verify", "meijaard2020.toml", "--duration", "0.2"], ("casadi", "clarabel")),
    (["optimize", "pb1.toml", "--verify-duration", "0.2"], ()),
])
def test_commands_import_only_what_they_need(args, also):
    examples = Path(EXAMPLE).parent
    args = [str(examples / a) if a.endswith(".toml") else a for a in args]
    code = ("import io, json, sys, contextlib\nfrom balancer.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    assert main({args!r}) == 0\n"
            "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules})))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    loaded = set(json.loads(out.strip().splitlines()[-1]))
    assert not loaded & {*_HEAVY, *also}


#: What analysing a four-bar may not load (issue 41): the other mechanisms' folders, the
#: balancing layers and the long cycles' program, the other commands' reports.
_NOT_FOR_A_FOURBAR = ("balancer.mechanisms.engine", "balancer.mechanisms.slidercrank",
                      "balancer.balance", "balancer.model.balance", "balancer.spec.balance",
                      "balancer.linkage.program", "balancer.linkage.kernel",
                      "balancer.report.balancing", "balancer.report.motion",
                      "balancer.report.fronts", "balancer.simulation", "balancer.examples",
                      "balancer.mechanisms.fourbar.opened_loop",
                      "balancer.mechanisms.fourbar.lie_group",
                      "balancer.mechanisms.fourbar.mass_matrix",
                      "balancer.formulations",
                      # a spec without [[motion]], [workspace] or [plan], and nothing written
                      "balancer.motion_analysis", "balancer.linkage.trajectory",
                      "balancer.model.motions", "balancer.model.plan", "balancer.spec.motions",
                      "balancer.spec.writer", "balancer.report.along", "balancer.planning")


def test_analysing_a_fourbar_loads_its_folder_and_the_cycle_analysis_only():
    code = ("import io, json, sys, contextlib\nfrom balancer.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    assert main(['analyze', {EXAMPLE!r}]) == 0\n"
            "print(json.dumps(sorted(m for m in sys.modules if m.startswith('balancer'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    loaded = json.loads(out.strip().splitlines()[-1])
    assert "balancer.mechanisms.fourbar.mechanism" in loaded
    assert not [m for m in loaded if m.startswith(_NOT_FOR_A_FOURBAR)]


@pytest.mark.parametrize(("given", "used"), [(None, "1"), ("3", "3")])
def test_the_command_runs_openblas_on_one_thread_unless_told(given, used):
    import os

    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    code = ("import os, sys\nsys.argv = ['balancer', '--version']\n"
            "from balancer.cli import entry_point\ntry:\n    entry_point()\n"
            "except SystemExit:\n    pass\nprint(os.environ['OPENBLAS_NUM_THREADS'], "
            "'numpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=env).stdout
    assert out.strip().splitlines()[-1] == f"{used} False"  # set before numpy loads


def test_the_command_sets_aside_what_loading_made_and_collects_its_own_garbage():
    """The process's command loads its verb with the collector off, freezes what the loading
    made (balancer.cli._loaded), and runs with the collector on: a command's own cyclic garbage
    is still collected."""
    code = ("import gc, importlib, json, sys\n"
            "sys.argv = ['balancer', 'analyze', " + repr(EXAMPLE) + "]\n"
            "seen = {'loaded before': 'balancer.cli.analyze' in sys.modules}\n"
            "real = importlib.import_module\n"
            "def spy(name, package=None):\n"
            "    if name != '.analyze':\n"
            "        return real(name, package)\n"
            "    seen['loading on'] = gc.isenabled()\n"
            "    verb = real(name, package)\n"
            "    run = verb.run\n"
            "    def watched(args):\n"
            "        seen.update(on=gc.isenabled(), frozen=gc.get_freeze_count())\n"
            "        cycle = []; cycle.append(cycle); del cycle\n"
            "        seen['collected'] = gc.collect()\n"
            "        return run(args)\n"
            "    verb.run = watched\n"
            "    return verb\n"
            "importlib.import_module = spy\n"
            "from balancer.cli import entry_point\ntry:\n"
            "    entry_point()\nexcept SystemExit as e:\n    seen['code'] = e.code\n"
            "print(json.dumps(seen))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    seen = json.loads(out.strip().splitlines()[-1])
    assert seen["code"] == 0 and not seen["loaded before"]
    assert seen["loading on"] is False and seen["on"] is True
    assert seen["frozen"] > 10_000  # numpy's and the layers' objects, out of the collector's way
    assert seen["collected"] >= 1


def test_main_leaves_the_collector_as_it_was(capsys):
    """Called within a longer process, main() neither freezes nor turns off the collector."""
    import gc

    before = (gc.isenabled(), gc.get_freeze_count())
    assert main(["analyze", EXAMPLE]) == 0
    assert (gc.isenabled(), gc.get_freeze_count()) == before


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


# ----------------------------------------------------------------------------------------------
# Polish (issue 14): one prefix, true help, output paths, the constant-speed drive, examples

ROOT = Path(__file__).resolve().parents[2]


def _one_error_line(err: str) -> str:
    assert err.count("\n") == 1, err
    assert err.startswith("balancer: error: ") and err.count("balancer:") == 1, err
    assert "error: error" not in err and "Traceback" not in err
    return err


@pytest.mark.parametrize("argv", [
    [],
    ["frobnicate"],
    ["analyze"],
    ["analyze", EXAMPLE, "--frobnicate"],
    ["analyze", EXAMPLE, "--route", "guess"],
    ["analyze", EXAMPLE, "--gravity", "x"],
    ["analyze", "no-such-spec.toml"],
    ["analyze", EXAMPLE, "--csv", ""],
    ["simulate", EXAMPLE, "--duration", "-1"],
    ["simulate", EXAMPLE, "--method", "euler"],
    ["optimize", EXAMPLE],
    ["example", "nope"],
])
def test_errors_carry_one_prefix(capsys, argv):
    assert main(argv) == 2
    _one_error_line(capsys.readouterr().err)


def test_errors_carry_one_prefix_from_the_installed_script(tmp_path):
    exe = Path(sys.executable).parent / "balancer"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "balancer"]
    for argv in (["analyze"], ["analyze", EXAMPLE, "--route", "x"], ["nope"]):
        done = subprocess.run([*cmd, *argv], capture_output=True, text=True, check=False,
                              cwd=tmp_path)
        assert done.returncode == 2
        _one_error_line(done.stderr)


def test_help_names_each_mechanisms_default_formulations(capsys):
    # Against the mechanisms' own tables: simulate's default is the first formulation that
    # applies (formulations.default_method), verify's the mechanism's verify_method.
    from balancer.formulations import default_method
    from balancer.mechanisms import mechanism_of
    from balancer.mechanisms.fourbar.mechanism import fourbar_linkage
    from balancer.mechanisms.fourbar.model import FourBar

    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    simulate_help = " ".join(capsys.readouterr().out.split())
    with pytest.raises(SystemExit):
        main(["verify", "--help"])
    verify_help = " ".join(capsys.readouterr().out.split())
    fourbar = spec.load_design(ROOT / "examples" / "meijaard2020.toml").mechanism
    engine = spec.load_design(ROOT / "examples" / "engine.toml").mechanism
    watt = spec.load_design(ROOT / "examples" / "watt_sixbar.toml").mechanism
    rocking = fourbar_linkage(FourBar(lengths=(2.9, 3.0, 2.0, 3.2), branch="+",
                                      crank=fourbar.crank, coupler=fourbar.coupler,
                                      rocker=fourbar.rocker))
    assert not mechanism_of(rocking).assembly_range().full
    for model, words in ((fourbar, "for a four-bar"), (engine, "for a slider-crank"),
                         (watt, "for a general linkage whose crank turns fully"),
                         (rocking, "for one whose crank does not")):
        assert f"{default_method(model)} {words}" in simulate_help
    swinging = FourBar(lengths=(2.9, 3.0, 2.0, 3.2), branch="+", crank=fourbar.crank,
                       coupler=fourbar.coupler, rocker=fourbar.rocker)
    for model, words in ((fourbar, "for a four-bar whose crank turns fully"),
                         (swinging, "for one that swings"), (engine, "for a slider-crank"),
                         (watt, "for a general linkage")):
        assert f"{mechanism_of(model).verify_method} {words}" in verify_help
    assert "opened-loop for a slider-crank" not in simulate_help + verify_help


@pytest.mark.parametrize("argv", [
    ["analyze", EXAMPLE, "--csv"],
    ["simulate", EXAMPLE, "--out"],
    ["optimize", str(ROOT / "examples" / "pb1.toml"), "--no-verify", "--out"],
    ["verify", EXAMPLE, "--plot"],
    ["plot", EXAMPLE, "--animate"],
    ["example", "pb1", "--out"],
])
def test_empty_output_paths_are_bad_input(tmp_path, capsys, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    option = argv[-1]
    for args in ([*argv, ""], [*argv[:-1], f"{option}="]):
        assert main(args) == 2
        err = _one_error_line(capsys.readouterr().err)
        assert option in err and "must not be empty" in err
        assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [
    ["analyze", EXAMPLE, "--csv"],
    ["simulate", EXAMPLE, "--duration", "0.01", "--out"],
    ["optimize", str(ROOT / "examples" / "pb1.toml"), "--no-verify", "--out"],
    ["verify", EXAMPLE, "--plot"],
    ["plot", EXAMPLE, "--animate"],
    ["example", "pb1", "--out"],
])
def test_an_existing_output_file_is_kept_without_force(tmp_path, capsys, argv):
    suffix = {"--plot": ".png", "--animate": ".gif", "--csv": ".csv"}.get(argv[-1], ".toml")
    path = tmp_path / f"mine{suffix}"
    path.write_bytes(b"precious")
    assert main([*argv, str(path)]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert argv[-1] in err and "exists" in err and "--force" in err
    assert path.read_bytes() == b"precious"
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


@pytest.mark.parametrize("argv", [
    ["analyze", EXAMPLE, "--csv"],
    ["simulate", EXAMPLE, "--duration", "0.01", "--outputs", "3", "--out"],
    ["example", "pb1", "--out"],
])
def test_force_overwrites_an_existing_output_file(tmp_path, capsys, argv):
    path = tmp_path / "mine.out"
    path.write_bytes(b"old")
    assert main([*argv, str(path), "--force"]) == 0
    assert path.read_bytes() != b"old" and len(path.read_bytes()) > 100
    capsys.readouterr()


def test_constant_speed_drive_takes_the_operating_speed(tmp_path, capsys):
    # meijaard2020: [simulation] omega1 = 0 (a free run from rest), [operation] speed = 10.
    assert main(["simulate", EXAMPLE, "--drive", "constant-speed", "--duration", "0.2",
                 "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["drive"] == "constant-speed"
    assert doc["initial"]["omega"][0] == doc["final"]["omega"][0] == 10.0
    # A non-zero omega1 in the spec is the user's own choice of speed.
    text = Path(EXAMPLE).read_text().replace("omega1 = 0.0", "omega1 = 4.0")
    own = tmp_path / "own.toml"
    own.write_text(text)
    assert main(["simulate", str(own), "--drive", "constant-speed", "--duration", "0.2",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["final"]["omega"][0] == 4.0
    # Neither: bad input naming both places a speed can come from.
    start, end = text.index("[operation]"), text.index("[simulation]")
    none = tmp_path / "none.toml"
    none.write_text((text[:start] + text[end:]).replace("omega1 = 4.0", "omega1 = 0.0"))
    assert main(["simulate", str(none), "--drive", "constant-speed"]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert "simulation.omega1" in err and "[operation] speed" in err
    # The help says so.
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    assert "else the operating speed [operation] speed" in " ".join(
        capsys.readouterr().out.split())


def test_example_lists_prints_and_writes_the_shipped_specs(tmp_path, capsys):
    from balancer import examples

    assert main(["example"]) == 0
    listed = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert listed == list(examples.names())
    assert {"meijaard2020", "pb1", "pb2", "engine", "watt_sixbar"} <= set(listed)
    assert main(["example", "pb2"]) == 0
    assert capsys.readouterr().out == (ROOT / "examples" / "pb2.toml").read_text()
    out = tmp_path / "mine.toml"
    assert main(["example", "pb1.toml", "--out", str(out)]) == 0
    assert capsys.readouterr().err == f"wrote {out}\n"
    assert out.read_bytes() == (ROOT / "examples" / "pb1.toml").read_bytes()
    assert spec.load_design(out) == examples.load("pb1")
    assert main(["example", "--out", str(tmp_path / "x.toml")]) == 2
    assert "NAME" in _one_error_line(capsys.readouterr().err)


def test_examples_are_package_data_with_one_source():
    # The specs live in the package (a pip user has them: hatch's wheel takes every file
    # under balancer/); examples/ at the root is a link to that folder, not a copy.
    import tomllib
    from importlib import resources

    from balancer import examples

    folder = Path(str(resources.files("balancer.examples")))
    assert folder == ROOT / "balancer" / "examples"
    assert (ROOT / "examples").is_symlink()
    assert (ROOT / "examples").resolve() == folder.resolve()
    assert sorted(p.stem for p in folder.glob("*.toml")) == list(examples.names())
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert config["tool"]["hatch"]["build"]["targets"]["wheel"]["packages"] == ["balancer"]
    ignored = (ROOT / ".gitignore").read_text().split()
    assert not any(p in ignored for p in ("*.toml", "examples/", "balancer/examples/"))
    for name in examples.names():  # every shipped example loads
        examples.load(name)


def _csv_header(path: Path) -> list[str]:
    with path.open() as fh:
        rows = list(csv.reader(fh))
    text = path.read_text()
    assert "nan" not in text.lower() and "inf" not in text.lower()
    return rows[0]


@pytest.mark.parametrize(("name", "methods"), [
    ("meijaard2020", ["opened-loop", "lie-group", "multibody", "crank-angle"]),
    ("engine", ["mass-matrix", "complex-masses", "multibody", "crank-angle"]),
    ("quick_return", ["crank-angle", "multibody"]),
])
def test_csv_columns_are_the_mechanisms_whatever_the_route(tmp_path, capsys, name, methods):
    from balancer.columns import SHAKING_COLUMNS, SIMULATION_COLUMNS

    example = str(ROOT / "examples" / f"{name}.toml")
    headers = []
    for method in methods:
        path = tmp_path / f"{method}.csv"
        assert main(["simulate", example, "--method", method, "--duration", "0.005",
                     "--outputs", "3", "--out", str(path)]) == 0
        headers.append(_csv_header(path))
    assert all(h == headers[0] for h in headers), headers
    cycle = tmp_path / "cycle.csv"
    assert main(["analyze", example, "--csv", str(cycle)]) == 0
    assert _csv_header(cycle) == [*headers[0], *SHAKING_COLUMNS]
    if name in ("meijaard2020", "engine"):  # DESIGN.md's fixed columns, first and unchanged
        assert tuple(headers[0][:len(SIMULATION_COLUMNS)]) == SIMULATION_COLUMNS
    if name == "engine":
        assert headers[0][len(SIMULATION_COLUMNS):] == ["C_slider", "x3", "v3", "a3"]
    capsys.readouterr()


def test_slider_columns_agree_with_the_slider_cranks_own_closed_form():
    # The slider-crank formulation's own slider coordinate (its closed form, x = r·cos θ1 +
    # L·cos θ2) against the general kinematics' point on the guide, at the run's crank states.
    from helpers import ROUNDING

    from balancer.columns import simulation_columns

    design = spec.load_design(ROOT / "examples" / "engine.toml")
    traj = simulate(design.mechanism, design.simulation, method="mass-matrix", duration=0.004,
                    outputs=9)
    names, cols = simulation_columns(traj)
    mine = {n: c for n, c in zip(names, cols, strict=True)}
    reach = sum(design.mechanism.lengths)
    omega = float(np.max(np.abs(traj.omega[0])))
    alpha = float(np.max(np.abs(traj.alpha[0])))
    # Rounding of a position of size `reach` through a well-conditioned slider-crank
    # (rod/crank ≈ 3.6: the condition 1/cos of the rod's angle ≤ 1.05), and its rates.
    for key, row, scale in (("x3", 0, reach), ("v3", 1, reach * omega),
                            ("a3", 2, reach * (omega**2 + alpha))):
        assert np.max(np.abs(mine[key] - traj.slider[row])) < 4 * ROUNDING * scale


def test_slider_columns_rates_are_the_positions_derivatives():
    # The quick-return's ram: v and a from the kinematics against finite differences of x
    # over the crank angle (at ω1 = 1, α1 = 0: v = dx/dθ1, a = d²x/dθ1²).
    from helpers import derivative_with_error

    from balancer.columns import slider_columns
    from balancer.mechanisms import mechanism_of

    model = mechanism_of(spec.load_design(ROOT / "examples" / "quick_return.toml").mechanism)

    def column(theta, index):
        return slider_columns(model, np.atleast_1d(theta), 1.0, 0.0)[1][index]

    names = slider_columns(model, np.zeros(1), 1.0, 0.0)[0]
    assert [n[0] for n in names] == ["x", "v", "a"]
    for theta in np.linspace(0.1, 2 * np.pi, 7):
        dx, err1 = derivative_with_error(lambda t: column(t, 0), theta, h=1e-3)
        d2x, err2 = derivative_with_error(lambda t: column(t, 0), theta, h=1e-2, order=2)
        assert abs(column(theta, 1)[0] - dx[0]) < err1
        assert abs(column(theta, 2)[0] - d2x[0]) < err2


def test_a_ratio_to_nothing_is_a_dash_not_nan(tmp_path, capsys):
    # CLI fuzz campaign, seed 3333, case 982: an operating speed of 1e-300 rad/s leaves no
    # inertial shaking force before or after, and the report printed its ratio as "nan". A
    # ratio to zero has no value: the report says so with a dash, and prints no nan or inf.
    import re

    text = (Path(__file__).resolve().parents[2] / "examples" / "pb1.toml").read_text()
    text = re.sub(r"(?m)^speed = .*$", "speed = 1e-300", text, count=1)
    spec = tmp_path / "slow.toml"
    spec.write_text(text)
    assert main(["optimize", str(spec), "--no-verify"]) == 0
    out = capsys.readouterr().out
    assert not re.search(r"\b(nan|inf)\b", out, re.IGNORECASE)
    row = next(line for line in out.splitlines() if line.startswith("shaking force "))
    assert "—" in row.split()


_PB1 = str(ROOT / "examples" / "pb1.toml")


@pytest.mark.parametrize(("argv", "files", "json_too"), [
    (["analyze", EXAMPLE, "--csv", "{tmp}/cycle.csv"], ["cycle.csv"], True),
    (["simulate", EXAMPLE, "--duration", "0.2", "--out", "{tmp}/t.csv"], ["t.csv"], True),
    (["verify", EXAMPLE, "--duration", "0.2", "--plot", "{tmp}/r.png"], ["r.png"], True),
    (["optimize", _PB1, "--no-verify", "--out", "{tmp}/b.toml"], ["b.toml"], True),
    (["plot", _PB1, "--cycle", "{tmp}/c.svg"], ["c.svg"], False),
    (["pareto", _PB1, "--against", "driving-torque", "--points", "3", "--plot",
      "{tmp}/f.svg", "--csv", "{tmp}/f.csv"], ["f.svg", "f.csv"], True),
    (["sweep", _PB1, "--vary", "mechanism.lengths.coupler=2.8:3.2:2", "--out",
      "{tmp}/s.parquet", "--plot", "{tmp}/s.svg", "--workers", "0"], ["s.parquet", "s.svg"],
     True),
    (["example", "pb1", "--out", "{tmp}/e.toml"], ["e.toml"], False),
])
@pytest.mark.slow
def test_every_file_written_is_said_on_stderr_and_never_on_stdout(tmp_path, capsys, argv,
                                                                  files, json_too):
    """Some verbs said 'wrote PATH' on stdout (plot, example, inside optimize's, verify's and
    sweep's reports), others wrote silently (analyze --csv, simulate --out, pareto, sweep
    --plot): now each file written is one 'wrote PATH' line on stderr, and with --json stdout
    is the JSON document alone."""
    for as_json in (False, True) if json_too else (False,):
        folder = tmp_path / ("json" if as_json else "text")
        folder.mkdir()
        args = [a.format(tmp=folder) for a in argv] + (["--json"] if as_json else [])
        assert main(args) == 0
        captured = capsys.readouterr()
        assert captured.err.splitlines() == [f"wrote {folder / name}" for name in files]
        assert "wrote" not in captured.out
        if as_json:
            json.loads(captured.out)
        assert sorted(p.name for p in folder.iterdir()) == sorted(files)


@pytest.mark.parametrize(("verb", "option", "value"), [
    ("analyze", "--gravity", "-1,-9.81"),
    ("simulate", "--duration", "-1e3"),
    ("simulate", "--atol", "-1e-9"),
    ("verify", "--duration", "-0.5e1"),
    ("plot", "--frames", "-1e2"),
    ("sweep", "--seed", "-1e3"),
])
def test_a_value_that_begins_with_a_dash_is_shown_in_its_equals_form(capsys, verb, option,
                                                                       value):
    """`--gravity -1,-9.81` reads as an option of its own, and argparse said only 'expected
    one argument': the line now shows the form that takes it, --gravity=-1,-9.81."""
    assert main([verb, _PB1, option, value]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert option in err and f"{option}={value}" in err and "'-'" in err
    assert main(["analyze", _PB1, "--csv", "--json"]) == 2  # a missing value: no such hint
    assert "=" not in _one_error_line(capsys.readouterr().err)


def test_a_verb_built_alone_is_the_verb_of_the_whole_parser():
    """A command builds only its own verb's arguments (start-up): each verb's parser, and the
    top-level help listing every verb, must be what the whole parser gives."""
    from balancer.cli import build_parser

    def subparsers(parser):
        action = next(a for a in parser._actions if a.dest == "command")
        return action.choices

    whole = build_parser()
    assert build_parser("").format_help() == whole.format_help()
    for verb, full in subparsers(whole).items():
        alone = subparsers(build_parser(verb))[verb]
        assert alone.format_help() == full.format_help(), verb
        assert alone.get_default("verb") == full.get_default("verb") == verb
