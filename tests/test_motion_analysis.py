"""The loads along a motion (:mod:`balancer.motion_analysis`) and ``balancer analyze`` on them.

End to end against the momentum theorem: along a smooth motion (the quintic law), the shaking
force and moment are minus the rates of the linear and angular momentum, whose finite
differences in time use only the motion's velocities — so the inverse kinematics' rates, its
accelerations and the time law's derivatives are all checked against each other. Gravity adds
the total weight to the shaking force. The report's figures against the CSV's columns.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
from dataclasses import dataclass

import numpy as np
import pytest
from helpers import derivative_with_error
from linkage.several_inputs_specs import A, B, crank_rocker, fivebar, parallelogram

from balancer.cli import main
from balancer.errors import SpecError
from balancer.linkage import trajectory
from balancer.linkage.inputs import InputState
from balancer.linkage.vectors import V
from balancer.mechanisms import geometry, mechanism_of
from balancer.model import Design
from balancer.motion_analysis import motion_analysis
from balancer.motion_verification import RTOL
from balancer.spec.reader import design_from_dict
from balancer.spec.writer import dumps_design

MOTIONS = [
    {"name": "diamond", "point": "E", "times": [0.0, 1.0, 2.0, 3.0, 4.0],
     "path": [[0.1, 0.35], [0.13, 0.38], [0.16, 0.35], [0.13, 0.32], [0.1, 0.35]],
     "law": "quintic", "samples": 41},
    {"name": "wave", "times": [0.0, 0.5, 1.0], "path": [[0.0, 0.0], [0.2, -0.1], [0.0, 0.0]],
     "law": "spline", "samples": 64},
]


@pytest.fixture(scope="module")
def design() -> Design:
    spec = fivebar() | {"motion": MOTIONS}
    return design_from_dict(spec)


def _momenta(mech, mo) -> np.ndarray:
    px, py, lz = (np.zeros(mo.count) for _ in range(3))
    for k, link in enumerate(mech.linkage.links):
        r, v = mo.point(k, V(link.e, link.f)), mo.point_velocity(k, V(link.e, link.f))
        px += link.mass * v.x
        py += link.mass * v.y
        lz += link.mass * (r.x * v.y - r.y * v.x) + link.inertia * mo.rate[k]
    return np.array([px, py, lz])


@pytest.mark.parametrize("which", [0, 1])
def test_the_frame_feels_the_momentums_rate_along_the_motion(design, which):
    motion = design.motions[which]
    mech = mechanism_of(design.mechanism)
    analysis = motion_analysis(mech, motion)
    r = analysis.reactions
    inner = range(4, motion.samples - 4, 5)  # (the differences stay inside the motion)
    step = 1e-3
    # every time the differences ask for, in one motion (as the differences take them)
    times = sorted({float(analysis.t[i]) + k * h for i in inner for h in (step, 2 * step)
                    for k in range(-3, 4)})
    state = trajectory.input_state(mech.structure, motion, np.array(times))
    table = dict(zip(times, _momenta(mech, mech.motion_at(state)).T, strict=True))
    for i in inner:
        t = float(analysis.t[i])
        rate, err = derivative_with_error(lambda u: table[u], t, h=step)
        got = np.array([r.shaking_force.real[i], r.shaking_force.imag[i], r.shaking_moment[i]])
        assert np.max(np.abs(got + rate)) <= err + 1e-9 * np.max(np.abs(rate)), t


def test_gravity_adds_the_weight_to_the_shaking_force(design):
    mech = mechanism_of(design.mechanism)
    g = (0.3, -9.81)
    plain = motion_analysis(mech, design.motions[0])
    heavy = motion_analysis(mech, design.motions[0], gravity=g)
    total = sum(link.mass for link in mech.linkage.links)
    weight = total * complex(*g)
    gap = heavy.reactions.shaking_force - plain.reactions.shaking_force
    assert np.max(np.abs(gap - weight)) <= 1e-12 * abs(weight)


def _spec_file(tmp_path, design: Design):
    path = tmp_path / "fivebar.toml"
    path.write_text(dumps_design(design))
    return path


@dataclass
class Done:
    """A command's exit code and what it printed."""

    returncode: int
    stdout: str
    stderr: str


def _run(*args: str) -> Done:
    """``balancer ARGS`` in this process (as the golden outputs run it): faster than a
    subprocess, the same parser, verbs and exit codes."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return Done(code, out.getvalue(), err.getvalue())


def test_analyze_runs_every_motion_and_its_figures_are_the_csvs(tmp_path, design):
    spec = _spec_file(tmp_path, design)
    done = _run("analyze", str(spec), "--json")
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert doc["inputs"] == ["left", "right"]
    assert list(doc["motions"]) == ["diamond", "wave"]
    out = tmp_path / "diamond.csv"
    done = _run("analyze", str(spec), "--motion", "diamond", "--csv", str(out))
    assert done.returncode == 0, done.stderr
    assert "motion diamond:" in done.stdout and "torque on left" in done.stdout
    rows = list(csv.reader(io.StringIO(out.read_text())))
    header = rows[0]
    assert header[:10] == ["t", "left", "right", "shaking_force_x", "shaking_force_y",
                           "shaking_moment", "rocking_couple_x", "rocking_couple_y",
                           "torque_left", "torque_right"]
    assert header[10:] == ["RAx", "RAy", "RBx", "RBy"]
    values = np.array(rows[1:], dtype=float)
    assert values.shape[0] == MOTIONS[0]["samples"]
    figures = doc["motions"]["diamond"]
    force = np.hypot(values[:, 3], values[:, 4])
    for key, column in (("shaking_force", force), ("shaking_moment", values[:, 5]),
                        ("torque_left", values[:, 8]), ("torque_right", values[:, 9])):
        assert figures[key]["rms"] == pytest.approx(np.sqrt(np.mean(column**2)), rel=1e-12)
        assert figures[key]["max"] == pytest.approx(np.max(np.abs(column)), rel=1e-12)
    # the inputs' columns are their changes from the reference pose: both zero at the start
    # only where the path starts at the reference pose's point (it does: E at (0.1, 0.35))
    assert np.max(np.abs(values[0, 1:3])) <= 1e-12


@pytest.mark.parametrize(("args", "key"), [
    (("--csv", "OUT"), "--csv"),
    (("--motion", "nowhere"), "--motion"),
])
def test_a_bad_motion_option_is_refused(tmp_path, design, args, key):
    spec = _spec_file(tmp_path, design)
    args = tuple(str(tmp_path / "x.csv") if a == "OUT" else a for a in args)
    done = _run("analyze", str(spec), *args)
    assert done.returncode == 2 and f"{key}:" in done.stderr, done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize("verb", [["plot", "--orders", "o.png"]])
def test_the_revolutions_verbs_say_they_turn_one_crank(tmp_path, design, verb):
    # (plot --cycle draws a motion: tests/plots/test_motion_figure.py)
    spec = _spec_file(tmp_path, design)
    done = _run(verb[0], str(spec), *(str(tmp_path / a) if "." in a else a for a in verb[1:]))
    assert done.returncode == 2, done.stderr
    assert "mechanism.inputs: " in done.stderr and "turns one crank" in done.stderr
    assert "Traceback" not in done.stderr


def test_a_one_input_linkage_runs_along_its_cranks_own_motion():
    spec = crank_rocker() | {
        "operation": {"speed": 10.0},
        # a turn as a motion: the crank's change from the reference over a turn
        "motion": [{"name": "turn", "times": [0.0, 0.5, 1.0],
                    "path": [[0.0], [np.pi], [2 * np.pi]], "law": "spline",
                    "samples": 16}],
    }
    # (a spline through 0, π, 2π is open, not periodic: from rest to rest, as the cubic law)
    assert not design_from_dict(spec).motions[0].closed
    spec["motion"][0]["law"] = "cubic"
    design = design_from_dict(spec)
    analysis = motion_analysis(design.mechanism, design.motions[0])
    mech = mechanism_of(design.mechanism)
    theta = analysis.state.positions[0]
    omega, alpha = analysis.state.rates[0], analysis.state.accelerations[0]
    want = mech.inverse_dynamics(mech.motion_at(InputState.crank(theta, omega, alpha)))
    assert np.array_equal(analysis.reactions.driving_torque,
                          np.asarray(want.driving_torque)[:, 0])


def _balanced_parallelogram() -> dict:
    """The parallelogram five-bar of tests/test_force_balance.py, balanced in closed form:
    p's and q's centres put where the first moments along each direction cancel."""
    spec = parallelogram()
    links = spec["links"]

    def moment(name):
        link = links[name]
        return link["mass"] * complex(link["com"]["e"], link["com"]["f"])

    along_p = -(A * links["r"]["mass"] + moment("s"))
    along_q = -(B * links["s"]["mass"] + moment("r"))
    for name, total in (("p", along_p), ("q", along_q)):
        m = links[name]["mass"]
        links[name]["com"] = {"e": total.real / m, "f": total.imag / m}
    spec["workspace"] = {"p": [-0.4, 0.4], "q": [-0.4, 0.4], "samples": 9}
    spec["motion"] = [{"name": "wave", "times": [0.0, 0.5, 1.0],
                       "path": [[0.0, 0.0], [0.2, -0.1], [0.0, 0.0]], "law": "spline",
                       "samples": 32}]
    return spec


def test_a_balanced_design_keeps_its_centre_of_mass_over_the_workspace():
    from balancer.api import analyze_motions

    along = analyze_motions(design_from_dict(_balanced_parallelogram()))
    assert along.force_balanced
    assert along.workspace is not None and along.workspace.states > 40
    assert along.workspace.centre_of_mass_excursion <= 1e-15
    assert along.motions[0].centre_of_mass_excursion <= 1e-15
    assert np.max(np.abs(along.motions[0].reactions.shaking_force)) <= 1e-12


def test_the_workspace_keeps_the_states_within_the_joints_limits():
    from balancer.motion_analysis import workspace_states

    spec = _balanced_parallelogram()
    spec["workspace"]["joints"] = {"Q": [-0.3, 0.2]}
    design = design_from_dict(spec)
    mech = mechanism_of(design.mechanism)
    state, grid = workspace_states(mech, design.workspace)
    assert grid == 81 and 0 < state.count < grid
    # Q joins r and s (in that order): the angle from r's line to s's, from the points alone
    points = geometry.points(mech, mech.motion_at(state))
    ref = dict(design.mechanism.points)

    def turn(a, b, c, d, where):  # the angle from a→b to c→d
        return np.angle((where[d] - where[c]) / (where[b] - where[a]))

    at_ref = {k: complex(*v) for k, v in ref.items()}
    change = turn("P1", "Q", "P2", "Q", points) - turn("P1", "Q", "P2", "Q", at_ref)
    change = np.remainder(change + np.pi, 2 * np.pi) - np.pi
    assert np.all((change >= -0.3 - 1e-12) & (change <= 0.2 + 1e-12))
    # and those left out are out of the limits (or do not assemble)
    full = design_from_dict(_balanced_parallelogram())
    everything, _ = workspace_states(mech, full.workspace)
    assert everything.count > state.count


def test_optimize_balances_a_linkage_with_several_inputs_and_writes_its_spec(tmp_path):
    spec = _balanced_parallelogram()
    for name in ("p", "q"):  # the original, unbalanced: its cranks' centres on their lines
        spec["links"][name]["com"] = {"e": -0.005, "f": 0.002}
    spec["balance"] = {"force_balance": True, "objective": {"shaking_moment": 1.0},
                       "p": {"counterweight": {"mass": [0.0, 3.0], "radius": 0.1}},
                       "q": {"counterweight": {"mass": [0.0, 3.0], "radius": 0.1}}}
    path = _spec_file(tmp_path, design_from_dict(spec))
    out = tmp_path / "balanced.toml"
    done = _run("optimize", str(path), "--json", "--out", str(out))
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert doc["status"] == "optimal" and doc["force_balanced"]
    assert doc["after"]["shaking_force"]["max"] <= 1e-12
    # verified by simulation: every input driven along each motion in two formulations, and free
    check = doc["verification"]
    assert check["method"] == "multibody" and set(check["motions"]) == {"wave"}
    for run in [*check["motions"].values(), check["free"]]:
        assert run["force_level"] <= 1e-12  # the reaction sums are rounding
        assert run["energy_error"] <= 100 * RTOL  # the quadrature's or integrator's panels
    assert check["motions"]["wave"]["formulations_agree_to"] <= 1e-10
    assert check["motions"]["wave"]["original_max_shaking_force"] > 0.01  # (not rounding)
    # the balanced spec loads again and analyses as force-balanced over its workspace
    done = _run("analyze", str(out), "--json")
    assert done.returncode == 0, done.stderr
    again = json.loads(done.stdout)
    assert again["force_balanced"] and again["workspace"]["centre_of_mass_excursion"] <= 1e-14
    done = _run("optimize", str(path), "--no-verify")
    assert done.returncode == 0 and "along the motions" in done.stdout
    assert "force-balanced: yes" in done.stdout


def test_a_balanced_robots_shaking_force_reads_zero_in_the_report(tmp_path):
    spec = _balanced_parallelogram()
    path = _spec_file(tmp_path, design_from_dict(spec))
    done = _run("analyze", str(path))
    assert done.returncode == 0, done.stderr
    row = next(line for line in done.stdout.splitlines() if line.startswith("shaking force"))
    assert row.split()[2:4] == ["0", "0"], row  # (rounding of the motors' efforts: 1e-17 N)
    assert "moves up to 0 mm from its mean place along it" in done.stdout


@pytest.mark.parametrize(("workspace", "key", "match"), [
    ({"p": [0.1], "q": [-0.4, 0.4]}, "workspace.p", r"must be \[low, high\], two numbers"),
    ({"p": [-0.4, 0.4], "q": [-0.4, 0.4], "joints": {"Z": [0.0, 1.0]}},
     "workspace.joints.Z", "names no point of the linkage"),
    ({"p": [-0.4, 0.4], "q": [-0.4, 0.4], "joints": {"A": [0.0, 1.0]}},
     "workspace.joints.A", "joins two links \\(it is on 3\\)"),
])
def test_a_bad_workspace_is_refused_naming_its_key(workspace, key, match):
    spec = _balanced_parallelogram()
    spec["workspace"] = workspace
    with pytest.raises(SpecError, match=match) as caught:
        design_from_dict(spec)
    assert caught.value.key == key
