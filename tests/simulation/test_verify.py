"""optimize and verify end to end: the balanced design is proven by an independent simulation."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from helpers import integration_bound

from balancer import spec
from balancer.balance.result import GAP_TOLERANCE
from balancer.cli import main
from balancer.mechanisms.fourbar.conditions import berkof_residuals, force_balance_error
from balancer.verification import verify

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def pb2_balanced(tmp_path_factory):
    out = tmp_path_factory.mktemp("pb2") / "balanced.toml"
    assert main(["optimize", str(EXAMPLES / "pb2.toml"), "--out", str(out), "--no-verify",
                 "--json"]) == 0
    return out


def test_pb2_balanced_spec_is_complete_and_balanced(pb2_balanced):
    design = spec.load_design(pb2_balanced)
    assert design.original is not None and design.balance is not None
    linkage = design.mechanism
    # The optimiser restores Eq. 58 to rounding after its solve; Clarabel's feasibility
    # tolerance (1e-10) bounds it even without.
    assert force_balance_error(linkage) < 1e-10
    res = berkof_residuals(linkage)
    # Not derived: no tolerance of the optimiser maps onto Berkof's residuals (they are met
    # to ~1e-13 here; 1e-7 is far above that and far below a design that is not balanced).
    assert max(abs(res.coupler_offset), abs(res.coupler_inertia), abs(res.crank_rotor),
               abs(res.rocker_rotor)) < 1e-7


def test_pb2_verifies_at_integration_error_level_driven_and_free(pb2_balanced):
    """Issue 4: reaction sums and shaking moment at integration-error level in both motions,
    simulated by a formulation the optimiser did not use."""
    design = spec.load_design(pb2_balanced)
    v = verify(design, duration=2.0)
    assert v.method != "mass-matrix"
    lever = max(design.mechanism.lengths)
    res = berkof_residuals(design.mechanism)
    residual = max(abs(res.coupler_offset), abs(res.coupler_inertia), abs(res.crank_rotor),
                   abs(res.rocker_rotor))
    for run in (v.driven, v.free):
        assert run.trajectory is not None and run.original is not None
        tr = run.trajectory
        # Not integration error: the balanced design's shaking force and moment vanish at
        # every state but for its balance residuals (Eq. 58 to rounding; Berkof's, relative
        # to m·l², so to the moments' terms), so what remains is those and the formulation's
        # accuracy, 1e-9 relative (DESIGN.md), of the terms that cancel: the reactions, and
        # for the moment the reactions times a lever arm and the torque.
        reactions = tr.largest_reaction
        moments = max(reactions * lever, np.max(np.abs(tr.driving_torque)))
        assert run.force_level < 1e-9
        assert run.force_ratio < 1e-9 * reactions / run.original_max_shaking_force
        assert run.moment_ratio < ((1e-9 + residual) * moments
                                   / run.original_max_shaking_moment)
        # The original really shakes in this motion.
        assert run.original_max_shaking_moment > 1.0
        assert tr.energy_error < 2 * integration_bound(tr)  # first integral, quadratic


def test_pb1_optimize_json(tmp_path, capsys):
    out = tmp_path / "pb1_balanced.toml"
    assert main(["optimize", str(EXAMPLES / "pb1.toml"), "--json", "--out", str(out),
                 "--verify-duration", "1"]) == 0
    doc = json.loads(capsys.readouterr().out)
    for key in ("before", "after", "links", "status", "verification"):
        assert key in doc
    for name in ("shaking_force", "shaking_moment", "driving_torque"):
        assert set(doc["before"][name]) == {"rms", "max"} == set(doc["after"][name])
    assert doc["status"] == "optimal" and doc["success"] is True
    assert set(doc["links"]) == {"crank", "coupler", "rocker"}
    assert "counter_rotor" in doc["links"]["rocker"]
    # The written spec analyses to the same figures (below); its reactions are the terms that
    # cancel in the balanced design's shaking force.
    assert main(["analyze", str(out), "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    reactions = max(again["reactions"][p]["max"] for p in ("A0", "A3"))
    # Exact force balance: the shaking force vanishes but for the routes' accuracy, 1e-9 of
    # the reactions (DESIGN.md).
    assert doc["after"]["shaking_force"]["max"] < 1e-9 * reactions
    assert doc["after"]["shaking_moment"]["rms"] < doc["before"]["shaking_moment"]["rms"]
    # The RMS of the balanced design (Newton–Euler route) is the optimiser's objective (mass
    # matrices): mean square = J. The routes agree to 1e-9 of the largest moment M, so the
    # mean squares to 2·1e-9·M·RMS: relative to J = RMS², 2e-9·M/RMS.
    after = doc["after"]["shaking_moment"]
    assert after["rms"] ** 2 == pytest.approx(doc["objective"],
                                              rel=2e-9 * after["max"] / after["rms"])
    # "optimal" means √J within GAP_TOLERANCE·scale of the certified √J_low: J − J_low within
    # GAP_TOLERANCE·scale·2√J.
    certified = GAP_TOLERANCE * doc["scale"] * 2 * np.sqrt(doc["objective"])
    assert doc["lower_bound"] == pytest.approx(doc["objective"], rel=0, abs=certified)
    ver = doc["verification"]
    # Each verification run: its shaking force vanishes to 1e-9 of its reactions
    # (max_shaking_force / force_level).
    levels = [run["max_shaking_force"] / run["force_level"]
              for run in (ver["driven"], ver["free"]) if run["force_level"]]
    assert ver["max_shaking_force"] < 1e-9 * max(levels, default=reactions)
    assert ver["max_shaking_moment"] > 0
    # Two analyses of the same design, read back exactly from the spec: the same numbers but
    # for rounding in the spec's centre-of-mass forms, ~ROUNDING ≈ 1e-14; within 1e-12.
    assert again["shaking_moment"]["rms"] == pytest.approx(doc["after"]["shaking_moment"]["rms"],
                                                           rel=1e-12)
    assert again["force_balanced"] is True


def test_convex_and_nlp_backends_agree_through_the_cli(capsys):
    objectives = []
    for backend in ("convex", "nlp"):
        assert main(["optimize", str(EXAMPLES / "pb1.toml"), "--json", "--backend", backend,
                     "--no-verify"]) == 0
        objectives.append(json.loads(capsys.readouterr().out))
    # Both "optimal": √J of each within GAP_TOLERANCE·scale of the same certified bound, so
    # their J within GAP_TOLERANCE·scale·2√J of each other.
    convex, nlp = objectives
    certified = GAP_TOLERANCE * convex["scale"] * 2 * np.sqrt(max(convex["objective"],
                                                                  nlp["objective"]))
    assert convex["objective"] == pytest.approx(nlp["objective"], rel=0, abs=certified)


def test_optimize_without_balance_section_is_bad_input(capsys):
    path = str(EXAMPLES / "meijaard2020.toml")
    assert main(["optimize", path]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"balancer: error: {path}: balance: missing required table")


def test_infeasible_bounds_exit_1_naming_the_bound(tmp_path, capsys):
    text = (EXAMPLES / "pb1.toml").read_text().replace("com_radius = 1.0", "com_radius = 0.15")
    path = tmp_path / "tight.toml"
    path.write_text(text)
    out = tmp_path / "never.toml"
    assert main(["optimize", str(path), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "balance.crank.com_radius" in err and err.count("\n") == 1
    assert not out.exists()


@pytest.mark.slow
def test_verify_plots_and_json(tmp_path, capsys, pb2_balanced):
    plot = tmp_path / "report.png"
    assert main(["verify", str(pb2_balanced), "--plot", str(plot), "--duration", "0.5",
                 "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert {"max_shaking_force", "max_shaking_moment", "driven", "free"} <= set(doc)
    assert doc["plots"] == [str(plot)]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.png"]  # exactly what was asked
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(("suffix", "magic"), [(".svg", b"<svg"), (".pdf", b"%PDF")])
@pytest.mark.slow
def test_verify_plot_type_comes_from_the_extension(tmp_path, capsys, pb2_balanced, suffix,
                                                   magic):
    plot = tmp_path / f"report{suffix}"
    assert main(["verify", str(pb2_balanced), "--plot", str(plot), "--duration", "0.2"]) == 0
    assert magic in plot.read_bytes()[:500]
    assert sorted(p.name for p in tmp_path.iterdir()) == [plot.name]
    capsys.readouterr()


@pytest.mark.parametrize("name", ["report.txt", "report", "report.gif"])
def test_verify_plot_with_an_unknown_extension_is_refused_before_any_work(tmp_path, capsys,
                                                                          pb2_balanced, name):
    assert main(["verify", str(pb2_balanced), "--plot", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--plot" in err and ".png, .svg, .pdf" in err
    assert list(tmp_path.iterdir()) == []


def test_verify_of_an_unbalanced_design_reports_its_shaking(capsys):
    assert main(["verify", str(EXAMPLES / "meijaard2020.toml"), "--duration", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "vanish" not in out and "driven at the operating speed" in out


def test_animation(tmp_path, capsys):
    gif = tmp_path / "run.gif"
    assert main(["plot", str(EXAMPLES / "pb1.toml"), "--animate", str(gif), "--frames", "8"]) == 0
    from PIL import Image

    with Image.open(gif) as im:
        assert im.n_frames == 8
    assert main(["plot", str(EXAMPLES / "pb1.toml")]) == 2
    for name in ("run.png", "run.txt", "run"):  # the type comes from the extension
        assert main(["plot", str(EXAMPLES / "pb1.toml"), "--animate", str(tmp_path / name)]) == 2
        assert not (tmp_path / name).exists()
    capsys.readouterr()


def test_balanced_design_round_trips(pb2_balanced):
    design = spec.load_design(pb2_balanced)
    assert spec.loads_design(spec.dumps_design(design)) == design
    assert np.isfinite(design.mechanism.crank.counter_rotor)


def _without_simulation(example: str, folder: Path) -> Path:
    """The example's spec without its ``[simulation]`` table."""
    import re

    text = (EXAMPLES / f"{example}.toml").read_text()
    text = re.sub(r"\n\[simulation\]\n(?:[^\[\n][^\n]*\n|\n)*?(?=\n*(?:\[|#|$))", "\n", text)
    assert "[simulation]" not in text
    path = folder / f"{example}_no_simulation.toml"
    path.write_text(text)
    return path


def test_a_check_without_a_simulation_table_is_sized_to_the_machine(tmp_path, capsys):
    """An engine at 9000 rpm with no [simulation]: each run lasts CHECK_REVOLUTIONS
    revolutions at the operating speed (not the 5 s default: 750 revolutions), the free run
    coasting from that speed (from rest nothing would move); the balanced spec written back
    leaves the defaults unsaid, so that verifying it is sized the same way."""
    from balancer.verification import CHECK_REVOLUTIONS

    path = _without_simulation("engine", tmp_path)
    design = spec.load_design(path)
    speed = design.operation.speed
    check = verify(design)
    for run in (check.driven, check.free):
        doc = run.as_dict()
        assert doc["duration"] == pytest.approx(CHECK_REVOLUTIONS * 2 * np.pi / speed,
                                                rel=1e-12)
        assert run.trajectory.omega[0][0] == pytest.approx(speed, rel=1e-12)
    # driven at constant speed: exactly that many revolutions
    assert check.driven.as_dict()["revolutions"] == pytest.approx(CHECK_REVOLUTIONS, rel=1e-9)
    out = tmp_path / "balanced.toml"
    assert main(["optimize", str(path), "--no-verify", "--out", str(out)]) == 0
    assert "[simulation]" not in out.read_text()
    # a spec that gives its duration keeps it
    given = verify(spec.load_design(EXAMPLES / "engine.toml"))
    assert given.driven.as_dict()["duration"] == pytest.approx(0.02, rel=1e-9)


def test_a_run_that_would_take_too_long_is_refused_up_front():
    """From the rate of its first steps, a run projected beyond its wall-clock budget is
    refused with the figures, naming the key (verify gives each run CHECK_SECONDS: gravity of
    1e10 m/s² made the single cylinder's free run take half a minute)."""
    from balancer.errors import SpecError
    from balancer.simulation import simulate

    design = spec.load_design(EXAMPLES / "meijaard2020.toml")
    with pytest.raises(SpecError, match=r"^simulation\.duration: would take about .* s on this "
                                        r"machine .* more than the 1e-06 s a check may take"):
        simulate(design.mechanism, design.simulation, duration=300.0, max_seconds=1e-6)
